"""NIR export: an sPLL network as a Neuromorphic Intermediate Representation graph, in two
constructions written by one folder writer.

* :mod:`.exact`: the exact sPLL (``spll-hw export --to nir``, :func:`export_folder`). CCO as a
  ``CubaLIF`` node with its offset current as bias, the TDE as a documented composite of
  standard nodes plus one extension node whose semantics live in metadata; :func:`to_nir`
  builds the ``nir.NIRGraph``, :func:`from_nir` reads it back, :func:`write_nir` /
  :func:`read_nir` go through NIR's HDF5 file format.
* :mod:`.standard`: the standard construction (``--to nir-standard``, :func:`export_standard`):
  the sPLL from ``CubaLIF``, ``LIF``, ``Linear`` and ``Affine`` nodes only
  (:mod:`spll_hw.construction.gate`), written for one time step, so snnTorch, Norse and
  any clocked NIR consumer run it as it is.
* :mod:`.files`: the one writer (``network.nir``, and beside a clocked graph ``standard.json``,
  ``README.md`` and ``spll_grid.py``) and reader of NIR files.
* :mod:`.executor`: spll-hw's executor of graphs of standard nodes by the clocked consumers' rules
  (Euler steps of ``dt``); :mod:`.consumers` runs a graph in it, snnTorch or Norse.
* :mod:`.check`: how ``spll-hw export`` checks a written folder (its ``read_back``).

The ``nir`` package is an optional dependency (``pip install -e '.[nir]'``), imported only when
a function runs.
"""

from pathlib import Path

from spll_hw.exporters import (
    chooses_by_check,
    costs_as,
    exports_multichannel,
    lists_consumers,
    reads_back,
    runs_golden,
    time_step,
)
from spll_hw.exporters.dt_ladder import at_step, write_chosen

from . import check, standard
from .consumers import folder_consumers
from .dt_choice import choose_dt, choose_placement
from .exact import FORMAT, from_nir, read_nir, to_nir, write_nir
from .files import write_folder
from .multichannel import export_multichannel
from .multichannel_standard import export_multichannel_standard


def _multichannel(config, out, saved=None, threshold=float("inf"), *, data=None,
                  options=None) -> list[Path]:  # fmt: skip
    """A multichannel network and its readout as one NIR graph
    (:func:`mappings.nir.multichannel.export_multichannel`): the continuous-time graph, so
    no step and no check (``ValueError`` where ``options`` name either); ``data`` is not
    used."""
    if options is not None and (options.dt is not None or options.check_duration is not None):
        raise ValueError(
            "--to nir writes the continuous-time graph, unchecked: drop --dt and "
            "--check-duration (--to nir-standard: one graph per step, checked)"
        )
    return export_multichannel(config, out, saved, threshold)


def _multichannel_standard(config, out, saved=None, threshold=float("inf"), *, data=None,
                           options=None) -> list[Path]:  # fmt: skip
    """A multichannel network for clocked consumers, channel group by channel group, and its
    readout (:func:`mappings.nir.multichannel_standard.export_multichannel_standard`)."""
    return export_multichannel_standard(config, out, saved, threshold, data=data, options=options)


def _consumers(folder: Path) -> str:
    """The consumers ``standard.json`` names (:func:`mappings.nir.consumers.folder_consumers`)."""
    return folder_consumers(folder)


@exports_multichannel(_multichannel)
@runs_golden
@costs_as(check.cost_exact)
@reads_back(check.read_exact)
def export_folder(network, out: str | Path, *, profile=None, dt=None) -> list[Path]:
    """network.nir: NIR graph (HDF5; the TDE gate in metadata, so running it needs spll-hw's
    reader mappings.nir.read_nir).

    The ``spll_hw.exporters`` entry point of ``spll-hw export --to nir``. The graph is the
    continuous-time float network: ``profile`` and ``dt`` do not apply and raise ``ValueError``.
    """
    if profile is not None or dt is not None:
        raise ValueError("NIR export is the continuous-time float network: drop --profiles/--dt")
    return write_folder(out, to_nir(network))


@exports_multichannel(_multichannel_standard)
@lists_consumers(_consumers)
@chooses_by_check(check.cost_standard, check.read_standard)
def export_standard(network, out: str | Path, *, profile=None, dt=None, checked=None,
                    max_error=None, allow_error=False,
                    duration=None) -> list[Path]:  # fmt: skip
    """network.nir from standard NIR nodes only (CubaLIF, LIF, Linear, Affine) that snnTorch,
    Norse and other NIR consumers run; standard.json: gate levels and the graph's conventions.

    The ``spll_hw.exporters`` entry point of ``spll-hw export --to nir-standard``. ``dt`` [s]
    is written into the graph, with :data:`~mappings.nir.standard.EXPORT_LEVELS` gate levels
    placed by the first placement whose export check passes at that step
    (:func:`.dt_choice.choose_placement`; the closest where none does); without ``dt``, the
    coarsest of 100, 50, 20 and 10 µs whose export check passes with one of the placements
    (:func:`.dt_choice.choose_dt`: 100 µs, snnTorch's fixed step, for most networks). Both
    judge the check within ``max_error`` (a fraction; ``None``: the declared tolerance,
    :func:`~spll_hw.exporters.takes_check_limit`) on reference inputs of ``duration`` [s];
    where no step passes, a ``ValueError`` naming the limit and the sPLLs no step represents
    (with ``allow_error``: the step closest to golden, the README saying so). The check, run
    from memory, is handed to ``checked`` (:func:`~spll_hw.exporters.hands_on_check`) with the
    very graph it ran, which is what is written
    (:func:`spll_hw.exporters.dt_ladder.write_chosen`). ``profile`` does not apply (the graph
    is in floating point) and raises ``ValueError``.
    """
    if profile is not None:
        raise ValueError("nir-standard export is a floating-point graph: drop --profiles")

    def write(built, readme: str) -> list[Path]:
        return write_folder(out, built.graph, info=built.info(), readme=readme)

    dt = time_step(dt, standard.TARGET)
    choose = choose_dt if dt is None else at_step(choose_placement, dt)
    return write_chosen(network, choose, write, checked, max_error, allow_error, duration)


__all__ = [
    "FORMAT",
    "export_folder",
    "export_standard",
    "from_nir",
    "read_nir",
    "to_nir",
    "write_nir",
]
