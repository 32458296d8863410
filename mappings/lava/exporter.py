"""The ``spll_hw.exporters`` entry points of ``spll-hw export --to lava`` and ``--to
lava-standard`` (light to import: Lava and the export module load only when one runs); both
write through :mod:`mappings.lava.export` and are read back for the export check by
:mod:`mappings.lava.check`."""

from __future__ import annotations

import sys
from pathlib import Path

from spll_hw.exporters import reads_back, time_step

from . import check


@reads_back(check.read_exact)
def export_folder(network, out: str | Path, *, profile=None, dt=None) -> list[Path]:
    """lava.json + lava_<tag>.npz: parameters of spll-hw's own TDE/CCO Lava processes (float
    and fixed point; running them needs spll-hw's mappings.lava), quantization.md

    The ``spll_hw.exporters`` entry point of ``spll-hw export --to lava``: :func:`export_lava`
    plus the quantization report of ``profile`` (default ``loihi2``) at ``dt``.
    """
    import quantize
    from mappings.folder import ExportFolder

    from .export import write_lava

    profile = profile or "loihi2"
    dt = time_step(dt, "lava")
    chosen = quantize.load_profile(profile)
    _refuse_saturating(network, chosen.dt if dt is None else dt, profile)
    with ExportFolder(out) as folder:
        try:
            write_lava(folder, network, dt, profile)
        except ValueError as exc:  # quantize names the parameter; say at which step
            step = "the profile's dt" if dt is None else f"dt = {dt:g} s"
            raise ValueError(f"{exc} (target lava, profile {profile}, {step})") from exc
        q = quantize.quantize(network, chosen if dt is None else chosen.with_dt(dt))
        folder.text("quantization.md", f"# The network under {q.profile.name}\n\n"
                    f"{q.report_markdown()}\n")  # fmt: skip
    return folder.files


#: Time constants whose decay saturates at the fastest when shorter than a step.
TAU_NAMES = ("tau_cco_syn", "tau_cco", "tau_tde_fac", "tau_tde_trg", "tau_tde")


def _refuse_saturating(network, dt: float, profile: str) -> None:
    """``ValueError`` naming the parameter where a time constant of ``network`` is shorter
    than the step ``dt`` [s]: its decay would clamp to the fastest and the export run wrong
    (quantize only warns). Anything but a Network is left to quantize to refuse."""
    from spll_hw.network import Network

    if not isinstance(network, Network):
        return
    for name in TAU_NAMES:
        for i, params in enumerate(network.spll):
            tau = getattr(params, name)
            if tau < dt:
                raise ValueError(
                    f"sPLL {i}: {name} = {tau:g} s is shorter than the time step dt = {dt:g} s of "
                    f"target lava (profile {profile}): its decay would clamp to the fastest "
                    "(use a smaller --dt)"
                )


@reads_back(check.read_standard)
def export_standard(network, out: str | Path, *, profile=None, dt=None) -> list[Path]:
    """params.npz, run.py (lava-nc and numpy only: python run.py spikes.npy 1.0 prints TDE and
    CCO counts as JSON), lava_compat.py: the standard sPLL on Lava's own LIF and Dense.

    The ``spll_hw.exporters`` entry point of ``spll-hw export --to lava-standard``. ``dt`` [s]
    is the integers' step, their gate levels placed by the first placement whose export check
    passes there (:func:`.dt_choice.choose_placement`); without one, the coarsest of 50, 25 and
    10 µs that represents the network and whose export check passes with one of the placements
    (:func:`.dt_choice.choose_dt`, each step's result on stderr: 50 µs for most networks), or a
    ``ValueError`` naming each step's outcome and the worst sPLLs. The integers are Loihi's own
    formats, so ``profile`` does not apply and raises ``ValueError``. Writing needs no lava-nc.
    """
    if profile is not None:
        raise ValueError("lava-standard export uses Loihi's own number formats: drop --profile")
    from .dt_choice import choose_dt, choose_placement
    from .export import write_standard
    from .standard import EXPORT_LEVELS, lava_standard

    dt = time_step(dt, "lava-standard")
    if dt is None:
        chosen = choose_dt(network, log=lambda line: print(line, file=sys.stderr, flush=True))
    else:
        chosen = choose_placement(network, dt)
    if chosen.error is None:
        raise ValueError(chosen.reason)  # the writer's refusal at the user's step
    params = lava_standard(network, dt=chosen.dt, levels=EXPORT_LEVELS, placement=chosen.placement)
    return write_standard(params, out)
