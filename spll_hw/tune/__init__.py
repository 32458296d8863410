"""Hyperparameter tuning of the sPLL network with Optuna (thesis 2.8-2.9, 3.4-3.5).

- :mod:`~spll_hw.tune.space`: the search space (thesis Table 5 by default) and its constraints.
- :mod:`~spll_hw.tune.objective`: one trial = build the network, simulate every sample ``repeats``
  times with phase noise, mean ridge CV accuracy; a stratified subset first, for pruning.
- :mod:`~spll_hw.tune.storage`: SQLite file or any SQLAlchemy URL (PostgreSQL for many machines).
- :mod:`~spll_hw.tune.study`: create / validate / resume a study and run it in N processes.
- :mod:`~spll_hw.tune.report`: best network as TOML, importances (fANOVA), history, plots.

Optuna is an optional dependency (``pip install -e ".[tune]"``); :func:`import_optuna` raises a
clear ``ImportError`` naming that extra when it is missing.
"""

from __future__ import annotations

#: How to install what this subpackage needs.
INSTALL_HINT = 'pip install -e ".[tune]"  (Optuna, and psycopg for PostgreSQL storage)'


def import_optuna():
    """The ``optuna`` module, or ``ImportError`` telling which extra to install."""
    try:
        import optuna
    except ImportError as exc:
        raise ImportError(
            f"spll-hw tune needs Optuna, which is not installed; install the 'tune' extra: "
            f"{INSTALL_HINT}"
        ) from exc
    return optuna
