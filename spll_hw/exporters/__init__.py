"""Exports of a network for other toolchains, reached through a registry: the core never
imports the package that writes them.

An exporter is a function ``export(network, out, *, profile=None, dt=None) -> list[Path]``
that writes its files into folder ``out`` and returns them (``profile``: a chip profile for
exports with integer parameters; ``dt`` [s]: a time step for clocked exports; an exporter that
has no use for one raises ``ValueError`` when it is given). Exporters register in the
``spll_hw.exporters`` entry-point group (spll-hw's own in its ``pyproject.toml``); the first
paragraph of the function's docstring is its description in ``spll-hw export --help``.

An exporter whose folders can be simulated again declares how with :func:`reads_back`: a
function ``read_back(folder, network) -> FolderRun`` that reads the folder's files and runs
them by the rules its target runs (:class:`FolderRun`). :mod:`.check` checks every export
against the golden model that way (``spll-hw export`` does after writing, ``spll-hw export
--check FOLDER`` again later), and :mod:`.conformance` checks an exporter's protocol.

Every export folder states what it costs on a chip (:mod:`.cost`: ``cost.json`` beside
``check.json``): an exporter declares with :func:`costs_as` how a chip sees its folders, a
function ``cost_of(folder, network) -> FolderCost``: the two-compartment sPLL of the network
(at the folder's step, on the folder's profile where it has them) or the graph of standard
neurons the folder writes (:class:`~spll_hw.neuron_graph.NeuronGraph`).

An exporter that checks what it writes from memory before writing it (``--to nir-standard``
without ``dt`` checks each step it tries) hands that check on instead of having it run twice:
it declares :func:`hands_on_check` and takes a keyword ``checked``, which it calls once with a
:class:`MemoryCheck` of what it wrote (the :meth:`FolderRun.by_backend` run and its
:func:`~.check.check_run` report). :func:`export_checked` calls an exporter that way, and
:func:`~.folder_check.check_folder` given that check takes its report as the folder's where it is
the same check (the same rules, inputs and network, and the folder reads back as that network:
:meth:`FolderRun.runs_as`), and simulates the folder otherwise.

An exporter whose choices depend on that check (``--to nir-standard`` and ``--to
lava-standard`` without ``dt`` write the coarsest step whose check passes) judges them by the
user's limit and on the user's inputs, not its own: it declares :func:`takes_check_limit`
and takes the keywords ``max_error`` (the check's limit, a fraction; ``None`` for the declared
tolerance), ``allow_error`` (the export is kept although its check fails) and ``duration``
(the check's reference inputs' length [s]), which :func:`export_checked` passes on from
``spll-hw export --max-error``, ``--allow-error`` and ``--check-duration``. Any other
target's ``--max-error`` below golden's own resolution on the check's inputs is refused before
any work, as a ladder refuses it (:func:`.checked_folder.export_into`), but for one whose
folders run golden itself (``--to nir``, :func:`runs_golden`), whose check judges any limit.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from fnmatch import fnmatchcase
from functools import cache
from importlib.metadata import entry_points
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..timestep import checked_step

if TYPE_CHECKING:
    from ..backends.base import Backend
    from ..network import Network
    from ..neuron_graph import NeuronGraph
    from ..result import SimulationResult
    from .check import CheckReport

#: Entry-point group exporters register in.
GROUP = "spll_hw.exporters"
#: The names of every file an export folder holds (``fnmatch`` patterns): each target's own
#: (:class:`mappings.folder.ExportFolder` writes no other), those ``spll-hw export`` adds (the
#: network, the check and the cost) and the ``__pycache__`` a run of its scripts leaves. An
#: export replaces a folder that holds these only, as a whole, and refuses one that holds
#: anything else (:func:`foreign_files`), so that a folder never mixes two exports.
EXPORT_FILES = (
    "README.md", "params.toml", "check.json", "check_inputs.npz", "cost.json",
    "network.nir", "standard.json", "multichannel.toml", "spll_grid.py", "check_consumer.py",
    "check_counts.py", "load_consumer.py", "lava.json", "lava_*.npz", "quantization.md",
    "profile.toml", "params.npz", "run.py", "lava_compat.py", "__pycache__", "channels",
    "readout", "multichannel.json", "decisions.json", "run_multichannel.py",
)  # fmt: skip
#: Sane lengths [s] of the check's reference inputs (``spll-hw export --check-duration``):
#: below 0.1 s the network's slowest sPLLs see few periods; above 100 s one check of a
#: clocked export runs for hours and its inputs need gigabytes.
CHECK_DURATION_RANGE = (0.1, 100.0)

Exporter = Callable[..., list[Path]]


@dataclass(frozen=True)
class FolderRun:
    """An export folder read back, ready to simulate by its target's rules.

    Attributes:
        runs: one sentence on what simulates the folder and by which rules (the README and
            ``check.json`` quote it).
        backend: the backend that runs the same network from memory by the same rules: its
            declared ``capabilities.rate_tolerance`` is the export's default limit, and the
            folder's simulation equals its own spike for spike (the round trip).
        simulate: ``simulate(trains, duration) -> list[SimulationResult]``: every train
            (sorted spike times [s]) through the folder's files for ``duration`` [s].
        remedies: what would bring the export closer to golden, most useful first (the
            message of a failed check lists them).
        reads_as: ``reads_as(backend, network)``: whether the folder's files, read back, are
            exactly what ``backend`` (one of the same rules as :attr:`backend`) runs for
            ``network``, so that simulating the folder is ``backend.simulate_batch(network,
            ...)`` spike for spike; ``None`` where the reader cannot tell (never the same).
        step: the folder's one time step [s] where ``--dt`` chose it; ``None`` elsewhere.
        at_step: ``at_step(dt)``: the run of the same network exported at step ``dt`` [s]
            (``ValueError`` where it cannot be written there), so that a failed check measures
            the steps either side before it advises one (:mod:`.remedies`); ``None`` where the
            step is no remedy.
    """

    runs: str
    backend: Backend
    simulate: Callable[[Sequence[np.ndarray], float], list[SimulationResult]]
    remedies: tuple[str, ...] = ()
    reads_as: Callable[[Backend, Network], bool] | None = None
    step: float | None = None
    at_step: Callable[[float], FolderRun] | None = None

    @classmethod
    def by_backend(
        cls, runs: str, backend: Backend, network: Network, remedies: Sequence[str] = ()
    ) -> FolderRun:
        """A folder whose contents, read back as ``network``, run in ``backend`` itself."""
        return cls(runs, backend, lambda trains, t: backend.simulate_batch(network, trains, t),
                   tuple(remedies), lambda _, other: same_network(network, other))  # fmt: skip

    def runs_as(self, other: FolderRun, network: Network) -> bool:
        """Whether this run and ``other`` both simulate ``network`` by the same rules (their
        backends of one class with equal options, and each :attr:`reads_as` ``network`` in
        ``other``'s backend): then they compute the same spikes, and a check of one is a
        check of the other."""
        mine, theirs = self.backend, other.backend
        same_rules = type(mine) is type(theirs) and mine.options == theirs.options
        return bool(
            same_rules
            and self.reads_as is not None
            and other.reads_as is not None
            and other.reads_as(theirs, network)
            and self.reads_as(theirs, network)
        )


def same_network(a: Network, b: Network) -> bool:
    """Whether ``a`` and ``b`` have the same sPLLs, parameter for parameter, bit for bit."""
    return a is b or np.array_equal(a.matrix(), b.matrix())


@dataclass(frozen=True)
class MemoryCheck:
    """A check an exporter ran from memory on what it then wrote (module docstring).

    Attributes:
        run: what it simulated (a :meth:`FolderRun.by_backend` of the network it wrote).
        report: :func:`~.check.check_run`'s report of ``run`` on the reference inputs.
    """

    run: FolderRun
    report: CheckReport


@dataclass(frozen=True)
class FolderCost:
    """How a chip costs what an export folder runs (:func:`costs_as`).

    Attributes:
        what: one line on what is costed (``cost.json``'s and the README's ``costed``).
        dt: the folder's time step [s] (``None``: it has none, as the continuous-time NIR
            graph, or one per set of sPLLs, which ``graph`` states).
        profile: the chip profile whose integers the folder holds (``--to lava``'s), ``None``
            where it holds none: its name.
        graph: the graph of standard neurons the folder writes; ``None``: the folder runs the
            two-compartment sPLL of the network (TDE and CCO per sPLL).
        source: the folder's own definition of ``profile`` at the folder's step ``dt``, the
            provider's loaded profile (``--to lava``'s ``profile.toml``), where ``profile`` names
            none a provider bundles (a TOML file's): what the folder is costed on in its place;
            ``None``: ``profile`` is costed by its name (issue 62).
    """

    what: str
    dt: float | None = None
    profile: str | None = None
    graph: NeuronGraph | None = None
    source: object | None = None


CostOf = Callable[[Path, "Network"], FolderCost]


def costs_as(cost_of: CostOf) -> Callable[[Exporter], Exporter]:
    """Decorator of an exporter whose folders ``cost_of(folder, network)`` says how a chip
    costs (:class:`FolderCost`; ``network``: the network the folder was exported from)."""

    def mark(export: Exporter) -> Exporter:
        export.cost_of = cost_of
        return export

    return mark


ReadBack = Callable[[Path, "Network"], FolderRun]


def reads_back(read_back: ReadBack) -> Callable[[Exporter], Exporter]:
    """Decorator of an exporter whose folders ``read_back(folder, network)`` reads back
    (:class:`FolderRun`; ``network`` is the network the folder was exported from)."""

    def mark(export: Exporter) -> Exporter:
        export.read_back = read_back
        return export

    return mark


def hands_on_check(export: Exporter) -> Exporter:
    """Decorator of an exporter that takes the keyword ``checked`` and calls it with the
    :class:`MemoryCheck` of what it wrote, where it checked that from memory (module
    docstring)."""
    export.hands_on_check = True
    return export


#: ``write(config, out, saved, threshold, *, data, options) -> list[Path]``: a multichannel
#: network (:class:`~spll_hw.multichannel.config.MultichannelConfig`) and, where ``saved`` is
#: not ``None``, its trained spiking readout (:mod:`spll_hw.multichannel.readout_file`) decided
#: at ``threshold`` [score x s], written into folder ``out`` (:func:`exports_multichannel`);
#: ``data`` (a BioTac_slide_20_50 folder or ``None``) and ``options``
#: (:class:`~.checked_folder.ExportOptions`: ``--dt``, ``--max-error``, ...) for a writer that
#: checks what it writes (:mod:`.multichannel`: one checked export per channel group).
MultichannelWriter = Callable[..., list[Path]]


def exports_multichannel(write: MultichannelWriter) -> Callable[[Exporter], Exporter]:
    """Decorator of an exporter whose target also takes a multichannel network, written by
    ``write`` (:data:`MultichannelWriter`): ``spll-hw export --network MULTICHANNEL --to
    NAME`` reaches it through the registry (:func:`multichannel_writer`)."""

    def mark(export: Exporter) -> Exporter:
        export.multichannel = write
        return export

    return mark


def lists_consumers(consumers: Callable[[Path], str]) -> Callable[[Exporter], Exporter]:
    """Decorator of an exporter whose folders name the programs that run them:
    ``consumers(folder)`` is the text ``spll-hw export`` prints after writing (lines ending
    in a newline; ``""`` where the folder names none)."""

    def mark(export: Exporter) -> Exporter:
        export.consumers = consumers
        return export

    return mark


def runs_golden(export: Exporter) -> Exporter:
    """Decorator of an exporter whose folders run the golden model itself (``--to nir``: the
    exact sPLL, read back): its check measures the round trip, 0 where it holds, so it judges
    any ``--max-error``, 0 included. Any other target's ``--max-error`` below golden's own
    resolution on the check's inputs is refused before any work
    (:func:`.checked_folder.export_into`), as a step ladder refuses it."""
    export.runs_golden = True
    return export


def takes_check_limit(export: Exporter) -> Exporter:
    """Decorator of an exporter that takes the keywords ``max_error`` (the export check's limit
    of the total TDE-rate error, a fraction; ``None``: the declared tolerance),
    ``allow_error`` (keep an export whose check fails) and ``duration`` (the check's reference
    inputs' length [s]) and judges its own choices by them (module docstring)."""
    export.takes_check_limit = True
    return export


def chooses_by_check(cost_of: CostOf, read_back: ReadBack) -> Callable[[Exporter], Exporter]:
    """Decorator of an exporter that chooses what it writes by its own export check (``--to
    nir-standard`` and ``--to lava-standard``): :func:`hands_on_check`,
    :func:`takes_check_limit`, :func:`costs_as` ``cost_of`` and :func:`reads_back`
    ``read_back`` at once."""

    def mark(export: Exporter) -> Exporter:
        return hands_on_check(takes_check_limit(costs_as(cost_of)(reads_back(read_back)(export))))

    return mark


def export_checked(
    export: Exporter,
    network: Network,
    out: Path,
    *,
    profile=None,
    dt=None,
    max_error: float | None = None,
    allow_error: bool = False,
    duration: float | None = None,
) -> tuple[list[Path], MemoryCheck | None]:
    """``export(network, out, profile=..., dt=...)``, with ``max_error``, ``allow_error`` and
    ``duration`` (``None``: the exporter's choice) where it takes them
    (:func:`takes_check_limit`): its files, and the check it ran from
    memory on what it wrote (:func:`hands_on_check`), or ``None``. ``ValueError`` naming
    ``--max-error`` before anything runs when it is not a fraction >= 0, and
    ``--check-duration`` when ``duration`` lies outside :data:`CHECK_DURATION_RANGE`."""
    keywords: dict = {"profile": profile, "dt": dt}
    duration = check_duration(duration)
    if getattr(export, "takes_check_limit", False):
        keywords |= {"max_error": check_limit(max_error), "allow_error": allow_error,
                     "duration": duration}  # fmt: skip
    handed: list[MemoryCheck] = []
    if getattr(export, "hands_on_check", False):
        keywords["checked"] = handed.append
    files = export(network, out, **keywords)
    return files, (handed[-1] if handed else None)


def time_step(dt: object, target: str) -> float | None:
    """An exporter's ``dt`` [s] as a float (``None`` stays ``None``); ``ValueError`` naming
    ``dt`` and ``target`` when it is not a finite time within
    :data:`spll_hw.timestep.STEP_RANGE`."""
    if dt is None:
        return None
    return checked_step(_number(dt), f"{target}: dt (--dt) = {dt!r}")


def is_export_file(name: str) -> bool:
    """Whether an export writes a file called ``name`` (:data:`EXPORT_FILES`)."""
    return any(fnmatchcase(name, pattern) for pattern in EXPORT_FILES)


def foreign_files(folder: str | Path) -> list[str]:
    """The entries of ``folder`` that no export writes (:data:`EXPORT_FILES`), sorted; none
    where it does not exist or holds an export only."""
    folder = Path(folder)
    if not folder.is_dir():
        return []
    return sorted(p.name for p in folder.iterdir() if not is_export_file(p.name))


def check_out_folder(out: str | Path, flag: str = "--out") -> None:
    """``ValueError`` naming ``flag``, ``out`` and what it holds where ``out`` holds anything
    an export does not write (:func:`foreign_files`): an export replaces a folder whole, and
    only one that holds an export (or nothing)."""
    foreign = foreign_files(out)
    if foreign:
        shown = ", ".join(foreign[:5]) + (
            f" and {len(foreign) - 5} more" if len(foreign) > 5 else ""
        )
        raise ValueError(
            f"{flag} {out} holds {shown}, which no export writes: an export replaces its folder "
            "as a whole (an earlier export in it too), so it writes only into a new or empty "
            "folder or one that holds an export; choose another folder or move those files"
        )


def check_duration(duration: object) -> float | None:
    """The check's reference inputs' length [s] as a float (``None`` stays ``None``);
    ``ValueError`` naming ``--check-duration`` and :data:`CHECK_DURATION_RANGE` outside it."""
    low, high = CHECK_DURATION_RANGE
    value = None if duration is None else _number(duration)
    if value is None or (math.isfinite(value) and low <= value <= high):
        return value
    raise ValueError(f"--check-duration = {duration!r}: the check's inputs last {low:g} to "
                     f"{high:g} s")  # fmt: skip


def check_limit(max_error: object) -> float | None:
    """The export check's limit ``max_error`` (a fraction of the total TDE-rate error) as a
    float (``None``, none given, stays ``None``); ``ValueError`` naming ``--max-error`` when it
    is not a fraction >= 0."""
    if max_error is None:
        return None
    limit = _number(max_error)
    if not (math.isfinite(limit) and limit >= 0):
        raise ValueError(f"--max-error must be a fraction >= 0 (0.1 is 10 %), got {max_error!r}")
    return limit


def _number(x: object) -> float:
    """``x`` as a float, NaN where it is not a number."""
    try:
        return float(x)
    except (TypeError, ValueError):
        return math.nan


@cache
def _entry_points() -> dict:
    return {ep.name: ep for ep in entry_points(group=GROUP)}


def names() -> list[str]:
    """Registered export targets, sorted."""
    return sorted(_entry_points())


def get(name: str) -> Exporter:
    """The exporter registered as ``name``; ``ValueError`` for an unknown one or one that does
    not load (a missing extra, say)."""
    eps = _entry_points()
    if name not in eps:
        raise ValueError(f"unknown export target {name!r}; known: {', '.join(names()) or 'none'}")
    try:
        return eps[name].load()
    except Exception as exc:  # a missing optional dependency is a message, not a traceback
        raise ValueError(
            f"export target {name!r} ({eps[name].value}) does not load: {type(exc).__name__}: {exc}"
        ) from exc


def reader(name: str) -> ReadBack:
    """The ``read_back`` of target ``name`` (:func:`reads_back`); ``ValueError`` when its
    folders cannot be read back."""
    read_back = getattr(get(name), "read_back", None)
    if read_back is None:
        raise ValueError(f"export target {name!r} declares no read_back: its folders cannot be "
                         "simulated again, so they cannot be checked")  # fmt: skip
    return read_back


def multichannel_writer(name: str | None) -> MultichannelWriter:
    """The multichannel writer of target ``name`` (:func:`exports_multichannel`);
    ``ValueError`` naming the targets that have one where ``name`` has none (or is ``None``)."""
    write = None if name is None else getattr(get(name), "multichannel", None)
    if write is None:  # every target loaded, only to name those that have one
        able = [n for n in names() if _loads_with(n, "multichannel")]
        told = "needs --to" if name is None else f"--to {name} exports one sPLL network;"
        raise ValueError(f"a multichannel --network {told} give --to {' or '.join(able)}")
    return write


def _loads_with(name: str, attribute: str) -> bool:
    """Whether target ``name`` loads and its exporter carries ``attribute``."""
    try:
        return hasattr(get(name), attribute)
    except ValueError:
        return False


def cost_reader(name: str) -> CostOf:
    """The ``cost_of`` of target ``name`` (:func:`costs_as`); ``ValueError`` where it declares
    none."""
    cost_of = getattr(get(name), "cost_of", None)
    if cost_of is None:
        raise ValueError(f"export target {name!r} declares no cost_of: its folders cannot be "
                         "costed on a chip")  # fmt: skip
    return cost_of


def describe(name: str) -> str:
    """One line on what target ``name`` writes (its exporter's docstring; this loads the
    exporter's module, so the command line asks only for ``spll-hw export --help``)."""
    try:
        doc = get(name).__doc__ or ""
    except ValueError as exc:
        return str(exc)
    first = doc.strip().split("\n\n")[0]
    return " ".join(first.split()) or name
