"""The ``spll_hw.exporters`` entry points of ``spll-hw export --to lava`` and ``--to
lava-standard`` (Lava itself loads only when a folder runs); both write through
:mod:`mappings.lava.export` and are read back for the export check by :mod:`mappings.lava.check`."""

from __future__ import annotations

from pathlib import Path

import quantize
from mappings.folder import ExportFolder
from spll_hw.exporters import (
    chooses_by_check,
    costs_as,
    exports_multichannel,
    reads_back,
    time_step,
)
from spll_hw.exporters.dt_ladder import at_step, write_chosen
from spll_hw.exporters.multichannel import write_groups_only

from . import check
from .dt_choice import choose_dt, choose_placement
from .export import refuse_saturating, write_lava, write_standard


@costs_as(check.cost_exact)
@reads_back(check.read_exact)
def export_folder(network, out: str | Path, *, profile=None, dt=None) -> list[Path]:
    """lava.json + lava_<tag>.npz: parameters of spll-hw's own TDE/CCO Lava processes (float
    and fixed point; running them needs spll-hw's mappings.lava), profile.toml (the chip
    profile, whole), quantization.md

    The ``spll_hw.exporters`` entry point of ``spll-hw export --to lava``: :func:`export_lava`
    (which writes ``profile``, a bundled name or a TOML file, whole into the folder, so that
    ``--check FOLDER`` needs no file outside it) plus the quantization report of ``profile``
    (default ``loihi2``) at ``dt`` [s].
    """
    profile = profile or "loihi2"
    dt = time_step(dt, "lava")
    chosen = quantize.load_profile(profile)
    refuse_saturating(network, chosen.dt if dt is None else dt, profile)
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


def _multichannel(config, out, saved=None, threshold=None, *, data=None,
                  options=None) -> list[Path]:  # fmt: skip
    """A multichannel network's channel groups, each a lava-standard export checked on its
    channels' signals (:func:`spll_hw.exporters.multichannel.write_groups_only`; no readout)."""
    return write_groups_only("lava-standard", config, out, saved, data=data, options=options)


@exports_multichannel(_multichannel)
@chooses_by_check(check.cost_standard, check.read_standard)
def export_standard(network, out: str | Path, *, profile=None, dt=None, checked=None,
                    max_error=None, allow_error=False,
                    duration=None) -> list[Path]:  # fmt: skip
    """params.npz, run.py (lava-nc and numpy only: python run.py spikes.npy 1.0 prints TDE and
    CCO counts as JSON), lava_compat.py: the standard sPLL on Lava's own LIF and Dense.

    The ``spll_hw.exporters`` entry point of ``spll-hw export --to lava-standard``. ``dt`` [s]
    is the integers' step, their gate levels placed and refractory periods held by the first
    placement and hold whose export check passes there (:func:`.dt_choice.choose_placement`;
    the closest where none does); without one, the coarsest of 50, 25 and 10 µs that
    represents the network and whose export check passes with one of them
    (:func:`.dt_choice.choose_dt`, each step's result on stderr: 50 µs for most networks),
    else a clock per sPLL (:func:`.dt_choice.clock_trial`: each sPLL at its own step, for
    offline runs; :mod:`.clocks`), else that clock with graded CCO currents
    (:func:`.dt_choice.graded_clock_trial`). A step passes where the whole verdict of its check
    does, the folder's own: sPLLs that fail it (a ``g_cco`` under half of Loihi's smallest
    weight: an open-loop CCO, :meth:`~.standard.LavaStandard.open_loop`) fail the step, and the
    ladder goes on. Both judge the check within ``max_error`` (a fraction; ``None``: the
    declared tolerance,
    :func:`~spll_hw.exporters.takes_check_limit`) on reference inputs of ``duration`` [s];
    where no step passes, a ``ValueError`` naming the limit, each step's outcome and the worst
    sPLLs (with ``allow_error``: the step closest to golden, the README saying so). The check, run
    from memory, is handed to ``checked`` (:func:`~spll_hw.exporters.hands_on_check`) with the
    very integers it ran, which are what is written. The integers are Loihi's own formats, so
    ``profile`` does not apply and raises ``ValueError``. Writing needs no lava-nc.
    """
    if profile is not None:
        raise ValueError("lava-standard export uses Loihi's own number formats: drop --profiles")

    dt = time_step(dt, "lava-standard")

    def write(params, readme: str) -> list[Path]:
        return write_standard(params, out, readme=readme)

    choose = choose_dt if dt is None else at_step(choose_placement, dt)
    return write_chosen(network, choose, write, checked, max_error, allow_error, duration)
