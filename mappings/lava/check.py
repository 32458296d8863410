"""How the export check (:mod:`spll_hw.exporters.check`) runs a Lava folder again: the
``read_back`` of ``spll-hw export --to lava`` and ``--to lava-standard``.

* ``lava``: both tags' parameters are read back (:func:`~mappings.lava.export.load_export`)
  and must be those of the network under the folder's profile and ``dt``
  (:func:`~mappings.lava.run.make_spec`); the ``fixed_pt`` tag then runs as
  ``golden-fixed-point`` of that profile and ``dt``, which Lava's bit-accurate models compute
  spike for spike (``lava-fixed``; Lava's own runtime does one to two thousand steps a second,
  too slow for a check of seconds at 10 µs).
* ``lava-standard``: the integers of ``params.npz`` are read back
  (:func:`~mappings.lava.export.read_standard`) and run by Loihi's LIF and Dense arithmetic in
  the Rust core (:func:`~mappings.lava.loihi.simulate_fixed`), which the folder's ``run.py``
  on lava-nc matches spike for spike (``tests/test_standard_lava.py``); its tolerance is
  ``standard-fixed-point``'s at that ``dt``. A folder whose integers read back as those
  ``standard-fixed-point`` builds for the network
  (:meth:`~mappings.lava.standard.LavaStandard.difference`) runs as that backend does, so the
  check the export ran from memory while choosing its ``dt`` is the folder's
  (:attr:`~spll_hw.exporters.FolderRun.reads_as`). A folder with a clock per set of sPLLs
  (:mod:`mappings.lava.clocks`) runs each set at its own step, as ``standard-fixed-point``
  with ``clock=per-spll`` does.
"""

from __future__ import annotations

import math
from dataclasses import replace
from functools import partial
from pathlib import Path

import numpy as np

import quantize
from quantize.profiles import at_step
from spll_hw import backends
from spll_hw.exporters import FolderCost, FolderRun
from spll_hw.exporters.dt_ladder import more_levels
from spll_hw.network import Network

from .clocks import ClockedStandard, run_integers
from .export import folder_profile, load_export, refuse_saturating
from .export import read_standard as read_integers
from .neuron_graph import lava_graph
from .run import TAGS, make_spec
from .standard import EXPORT_LEVELS


def read_exact(folder: str | Path, network: Network) -> FolderRun:
    """The ``read_back`` of ``--to lava`` (module docstring)."""
    folder = Path(folder)
    fixed = load_export(folder, "fixed_pt")
    profile, chip = _folder_profile(folder, str(fixed.info["profile"]))
    for tag in TAGS:
        stored = fixed if tag == "fixed_pt" else load_export(folder, tag)
        made = make_spec(network, tag, fixed.dt, chip if tag == "fixed_pt" else None)
        _same(stored, made, folder / f"lava_{tag}.npz", profile)
    run = FolderRun.by_backend(
        f"`lava_fixed_pt.npz` read back (the integers of the network under profile {profile} at "
        f"dt = {fixed.dt:g} s) and run as golden-fixed-point, which Lava's fixed_pt models "
        "compute spike for spike",
        backends.get("golden-fixed-point", profile=chip, dt=fixed.dt),
        network,
        # measured: the steps beside the folder's (FolderRun.at_step, spll_hw.exporters.remedies);
        # no other bundled profile is: Lava's Dense holds only Loihi's 8-bit weight mantissas,
        # which loihi1 shares with loihi2, and fixed16's and spinnaker's weights are refused
        ["untried: --to lava-standard (Loihi's own LIF and Dense neurons; its export takes the "
         "coarsest step whose check passes, or says why none does)"],
    )  # fmt: skip
    return replace(run, step=fixed.dt, at_step=partial(_at_step, network, profile, chip))


def _folder_profile(folder: Path, named: str) -> tuple[str, object]:
    """The chip profile of a ``--to lava`` folder whose ``lava.json`` names it ``named``: its
    name, and what the backends and chips take for it (:func:`~.export.folder_profile`, the
    folder's ``profile.toml``): the bundled profile's name where the folder's definition is
    that profile's to the last figure (specs and labels as ever), else the loaded profile
    itself (a TOML file's, issue 62: not looked up by a name only its file knew)."""
    chip = folder_profile(folder, named)
    try:
        bundled = quantize.load_profile(chip.name) == chip
    except (ValueError, OSError):  # a name no bundled profile has
        bundled = False
    return chip.name, chip.name if bundled else chip


def _at_step(network: Network, profile: str, chip, dt: float) -> FolderRun:
    """:attr:`FolderRun.at_step` of ``--to lava``: the network's integers under the folder's
    profile ``chip`` (named ``profile``; :func:`_folder_profile`) at step ``dt`` [s], as
    golden-fixed-point runs them; ``ValueError`` where the export would be refused there (a
    time constant shorter than the step, a parameter that does not fit)."""
    refuse_saturating(network, dt, profile)
    backend = backends.get("golden-fixed-point", profile=chip, dt=dt)
    backend.prepare(network)
    return FolderRun.by_backend(f"golden-fixed-point at dt = {dt:g} s", backend, network)


def _same(stored, made, path: Path, profile: str) -> None:
    """``ValueError`` naming the first parameter of ``stored`` that differs from ``made``."""
    for group in ("tde", "cco", "fan_out", "feedback"):
        a, b = getattr(stored, group), getattr(made, group)
        for key in sorted(set(a) | set(b), key=str):
            if key not in a or key not in b or not np.array_equal(a[key], b[key]):
                raise ValueError(
                    f"{path}: {group}.{key} is not that of the network in params.toml under "
                    f"profile {profile} at dt = {made.dt:g} s; the check runs only what "
                    "spll-hw exports (export again)"
                )


def read_standard(folder: str | Path, network: Network) -> FolderRun:
    """The ``read_back`` of ``--to lava-standard`` (module docstring); ``network`` is not
    used to run it (the folder holds its integers), only to tell whether they are those of a
    backend's (``reads_as``)."""
    params = read_integers(folder)
    clocked = isinstance(params, ClockedStandard)
    options = {"levels": params.levels, "placement": params.gate.placement, "hold": params.hold,
               "current": params.current}  # fmt: skip
    if clocked:
        backend = backends.get("standard-fixed-point", clock="per-spll", holds=int(params.holds),
                      **options)  # fmt: skip
        at = f"with each sPLL at its own step ({len(params.parts)} clocks, R = {params.holds:g})"
    else:
        backend = backends.get("standard-fixed-point", dt=params.dt, **options)
        at = f"at dt = {params.dt:g} s"
    step = (
        f"another R than {params.holds:g} (each sPLL's refractory steps; 3 to 8 measured on the "
        "time-scaled presets, docs/backends.md)"
        if clocked
        else f"another --dt than {params.dt:g} s: Loihi's 12-bit decays round long time "
        "constants coarsely at small steps (10-25 % at 10 µs), the time grid is coarse at "
        "large ones; without --dt the export writes the coarsest of 50, 25 and 10 µs whose "
        "check passes, else a clock per sPLL"
    )
    return FolderRun(
        runs=f"`params.npz` read back and run by Loihi's LIF and Dense integer arithmetic in "
        f"spll-hw's Rust core (mappings/lava/loihi.py, which the folder's run.py on lava-nc "
        f"matches spike for spike) {at}",
        backend=backend,
        simulate=lambda trains, duration: run_integers(params, trains, duration, "lava-standard"),
        # the folder runs as standard-fixed-point runs the network where its integers are, to
        # the bit, those that backend builds for it (kept by the backend that built them)
        reads_as=lambda same_rules, net: params.difference(same_rules.prepared(net)) is None,
        remedies=(
            "another construction: --to lava (spll-hw's exact TDE and CCO processes) or "
            "--to nir-standard (docs/backends.md, the error per preset)",
            step,
            more_levels(params.levels, "mappings.lava.standard.lava_standard", EXPORT_LEVELS),
        ),
    )


def cost_exact(folder: str | Path, network: Network) -> FolderCost:
    """The ``cost_of`` of ``--to lava``: the two-compartment sPLL (spll-hw's TDE and CCO
    processes) on the integers of the folder's profile at its ``dt`` (``lava.json``)."""
    spec = load_export(folder, "fixed_pt")
    profile, chip = _folder_profile(Path(folder), str(spec.info["profile"]))
    if not isinstance(chip, str):  # costed on the folder's own definition, at its step
        chip = chip if math.isclose(chip.dt, spec.dt, rel_tol=1e-9) else at_step(chip, spec.dt)
    return FolderCost(
        f"the two-compartment sPLL (spll-hw's TDE and CCO processes, a neuron each) in "
        f"{profile}'s integers",
        float(spec.dt),
        profile,
        source=None if isinstance(chip, str) else chip,
    )


def cost_standard(folder: str | Path, network: Network) -> FolderCost:
    """The ``cost_of`` of ``--to lava-standard``: every LIF neuron and ``Dense`` synapse of
    ``params.npz`` (:func:`mappings.lava.neuron_graph.lava_graph`) at its step (or steps)."""
    graph = lava_graph(read_integers(folder))
    return FolderCost(
        f"every neuron and synapse of the standard construction in params.npz "
        f"({graph.description})",
        graph.dts[0] if len(graph.dts) == 1 else None,
        None,
        graph,
    )
