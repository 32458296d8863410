"""The sPLL from standard neurons: exports that chip toolchains and NIR consumers run as they are.

:mod:`.construction` realises the TDE's multiplicative gate with standard neurons (a K-level
multiplier of level and AND neurons); :mod:`.reference` simulates the construction on a fine
clock with exact integration between steps, so what the construction itself costs against the
golden model is measurable per K.
"""

from .construction import DEFAULT_LEVELS, DEFAULT_PLACEMENT, PLACEMENTS, Gate, gate_levels

__all__ = ["DEFAULT_LEVELS", "DEFAULT_PLACEMENT", "PLACEMENTS", "Gate", "gate_levels"]
