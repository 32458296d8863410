"""The one Lava folder writer, for the exact processes and for the standard construction.

* Exact (``spll-hw export --to lava``): :func:`export_lava` writes, for each tag
  (``floating_pt`` and ``fixed_pt``), the :class:`~mappings.lava.run.LavaSpec`: the variables
  of spll-hw's TDE and CCO processes, the ``Dense`` weights per weight exponent and the
  fixed-point word widths, in ``lava_<tag>.npz``, a ``lava.json`` manifest listing
  processes, ports, connections, time step and profile, and the chip profile itself, whole, in
  ``profile.toml`` (a bundled one's or a TOML file's: the folder is checked again anywhere,
  :func:`folder_profile`). :func:`load_export` reads one tag back into a ``LavaSpec``, which
  :func:`~mappings.lava.run.simulate_lava` (or :func:`~mappings.lava.run.build`, to wire the
  processes into a larger Lava application) accepts in place of a network.
* Standard (``--to lava-standard``): :func:`write_standard` writes the integers of
  :mod:`mappings.lava.standard` (Lava's own LIF and Dense) as ``params.npz`` with a
  self-contained ``run.py`` (:mod:`mappings.lava.standalone_run`), ``lava_compat.py``,
  ``spll_grid.py``, ``standard.json`` and ``README.md``: a folder that runs on lava-nc alone
  (with a clock per set of sPLLs, :mod:`mappings.lava.clocks`, each clock's integers);
  :func:`read_standard` reads the integers back (for :func:`~mappings.lava.loihi.simulate_fixed`).

Both write through :class:`mappings.folder.ExportFolder`.
"""

import json
import zipfile
from pathlib import Path

import numpy as np

import quantize
from mappings.folder import ExportFolder
from mappings.lava.clocks import ClockedStandard, ClockPart
from mappings.lava.run import DEFAULT_PROFILE, TAGS, LavaSpec, make_spec
from mappings.lava.standalone_run import load_clocks, load_params
from mappings.lava.standard import HOLDS, LavaStandard
from quantize.analog import TAU_NAMES
from spll_hw.construction.gate import Gate
from spll_hw.network import Network

HERE = Path(__file__).resolve().parent

#: Version of the folder layout.
FORMAT = "spll-hw Lava export v1"
#: The file that holds the folder's chip profile, whole (:func:`quantize.profiles.profile_toml`).
PROFILE_FILE = "profile.toml"

#: Processes and connections, as the manifest states them (``mappings/lava/processes/process.py``).
PROCESSES = {
    "source": "lava.proc.io.source.RingBuffer: input spike counts per step (one step early)",
    "fan_out_<e>": "lava.proc.dense.process.Dense (N, 1), weight_exp e, graded input",
    "tde": "mappings.lava.processes.process.TDE: ports fac_in, trg_in, s_out",
    "cco": "mappings.lava.processes.process.CCO: ports fb_in, s_out",
    "feedback_<e>": "lava.proc.dense.process.Dense diagonal (N, N), weight_exp e",
}
CONNECTIONS = [
    ["source.s_out", "fan_out_<e>.s_in"],
    ["fan_out_<e>.a_out", "tde.fac_in"],
    ["cco.s_out", "tde.trg_in"],
    ["tde.s_out", "feedback_<e>.s_in"],
    ["feedback_<e>.a_out", "cco.fb_in"],
]


def export_lava(network, out: str | Path, dt=None, profile=None) -> list[Path]:
    """Write the Lava processes' parameters of ``network`` for both tags into folder ``out``.

    ``dt`` [s] and ``profile`` (a ``quantize`` fixed-point profile, default ``"loihi2"``) as in
    :func:`~mappings.lava.run.simulate_lava`; the fixed-point profile's time step is used for
    both tags unless ``dt`` is given. Raises ``ValueError`` when the network does not fit the
    profile. Returns the written files.
    """
    with ExportFolder(out) as folder:
        write_lava(folder, network, dt, profile)
    return folder.files


def write_lava(folder: ExportFolder, network, dt=None, profile=None) -> None:
    """Write :func:`export_lava`'s files into an open ``folder``."""
    specs = {"fixed_pt": make_spec(network, "fixed_pt", dt, profile)}
    specs["floating_pt"] = make_spec(network, "floating_pt", specs["fixed_pt"].dt)
    chosen = (network.profile if isinstance(network, quantize.QuantizedNetwork)
              else quantize.load_profile(profile or DEFAULT_PROFILE))  # fmt: skip
    folder.text(PROFILE_FILE, quantize.profile_toml(chosen, PROFILE_COMMENT))
    for tag, spec in specs.items():
        arrays = {f"tde.{k}": np.asarray(v) for k, v in spec.tde.items()}
        arrays |= {f"cco.{k}": np.asarray(v) for k, v in spec.cco.items()}
        arrays |= {f"fan_out.{e}": np.asarray(w) for e, w in spec.fan_out.items()}
        arrays |= {f"feedback.{e}": np.asarray(w) for e, w in spec.feedback.items()}
        folder.arrays(f"lava_{tag}.npz", arrays)
    manifest = {
        "format": FORMAT,
        "n_spll": specs["fixed_pt"].n_spll,
        "dt": specs["fixed_pt"].dt,
        "tags": {
            tag: {"file": f"lava_{tag}.npz", "formats": spec.formats, "info": spec.info}
            for tag, spec in specs.items()
        },  # fmt: skip
        "profile_file": PROFILE_FILE,
        "processes": PROCESSES,
        "connections": CONNECTIONS,
        "delays": "every connection delays one time step (see mappings/lava/parameters.py)",
    }
    folder.json("lava.json", manifest, indent=2, newline=True)


#: The comment atop :data:`PROFILE_FILE`.
PROFILE_COMMENT = (
    "The chip profile whose integers lava_fixed_pt.npz holds (spll-hw export --to lava), whole:\n"
    "spll-hw export --check reads it from here, wherever the folder goes. Its time step is\n"
    "the profile's own; the folder's is lava.json's dt. Units: SI (seconds, joules, watts)."
)


def folder_profile(folder: str | Path, named: str) -> quantize.FixedPointProfile:
    """The chip profile of a folder written by :func:`export_lava`, which ``lava.json`` names
    ``named``: its :data:`PROFILE_FILE`. A folder written before it had one (issue 62) is
    read by that name, which must then be a bundled profile's (or one at a step,
    ``loihi2@80us``). ``ValueError`` naming the file and what to do otherwise (export
    again)."""
    path = Path(folder) / PROFILE_FILE
    if path.is_file():
        try:
            chip = quantize.load_profile(path)
        except ValueError as exc:  # ProfileError names the file, the table and the key
            raise ValueError(f"{exc} (the folder's chip profile; export again)") from exc
        if not isinstance(chip, quantize.FixedPointProfile):
            raise ValueError(
                f"{path}: profile {chip.name!r} is {chip.kind}, not fixed point: a --to lava "
                "folder holds a fixed-point chip's integers (export again)"
            )
        return chip
    try:
        return quantize.load_profile(named)
    except ValueError:
        raise ValueError(
            f"{path}: no such file, and lava.json's profile {named!r} is not a bundled one "
            f"({', '.join(quantize.available_profiles())}): the folder does not say which chip "
            "its integers are for; export it again (spll-hw export --to lava now writes the "
            "profile into the folder)"
        ) from None


def write_standard(
    params: LavaStandard | ClockedStandard, out: str | Path, readme: str | None = None
) -> list[Path]:
    """Write the standard construction's folder for integers already made
    (:func:`~mappings.lava.standard.lava_standard`, or with a clock per set of sPLLs
    :func:`~mappings.lava.clocks.clocked_standard`): ``params.npz``, ``run.py`` (lava-nc and
    numpy only; ``run.py --check`` compares Lava's counts with ``check.json``), ``lava_compat.py``,
    ``spll_grid.py``, ``check_counts.py``, ``standard.json``, ``README.md`` (``readme``,
    default the integers' ``readme()``)."""
    with ExportFolder(out) as folder:
        folder.arrays("params.npz", params.arrays())
        folder.copy("run.py", HERE / "standalone_run.py")
        folder.copy("lava_compat.py", HERE / "compat.py")
        folder.grid()
        folder.counts()
        folder.json("standard.json", params.info())
        folder.text("README.md", params.readme() if readme is None else readme)
    return folder.files


def load_export(folder: str | Path, tag: str = "fixed_pt") -> LavaSpec:
    """The :class:`~mappings.lava.run.LavaSpec` of ``tag`` from a folder written by
    :func:`export_lava`; ``ValueError`` naming the file when it is not one."""
    folder = Path(folder)
    if tag not in TAGS:
        raise ValueError(f"unknown Lava tag {tag!r}; choose from {TAGS}")
    manifest_path = folder / "lava.json"
    if not manifest_path.is_file():
        raise FileNotFoundError(f"{manifest_path}: no Lava export here (spll-hw export --to lava)")
    manifest = json.loads(manifest_path.read_text())
    if manifest.get("format") != FORMAT:
        raise ValueError(f"{manifest_path}: format {manifest.get('format')!r}, expected {FORMAT!r}")
    entry = manifest["tags"][tag]
    with np.load(folder / entry["file"]) as data:
        groups: dict[str, dict] = {"tde": {}, "cco": {}, "fan_out": {}, "feedback": {}}
        for key in data.files:
            group, _, name = key.partition(".")
            groups[group][int(name) if group in ("fan_out", "feedback") else name] = data[key]
    return LavaSpec(tag, float(manifest["dt"]), groups["tde"], groups["cco"], groups["fan_out"],
                    groups["feedback"], entry["formats"], entry["info"])  # fmt: skip


def read_standard(folder: str | Path) -> LavaStandard | ClockedStandard:
    """The integers of a folder written by :func:`write_standard` (``params.npz``, read as the
    folder's ``run.py`` reads them, and the gate of ``standard.json``): a
    :class:`~mappings.lava.clocks.ClockedStandard` where each set of sPLLs has its own clock;
    ``FileNotFoundError`` or ``ValueError`` naming the file when it is not such a folder."""
    folder = Path(folder)
    for name in ("params.npz", "standard.json"):
        if not (folder / name).is_file():
            raise FileNotFoundError(
                f"{folder / name}: no lava-standard export here (spll-hw export --to lava-standard)"
            )
    try:
        info = json.loads((folder / "standard.json").read_text())
        gate = Gate(np.array(info["thresholds_A"]), np.array(info["increments_A"]),
                    info["gate_placement"])  # fmt: skip
        if info.get("clock") == "per-spll":
            return _read_clocked(folder, info, gate)
        raw = load_params(folder / "params.npz")
        return _integers(raw, info, gate, raw["members"], tuple(info.get("notes", ())))
    except (OSError, KeyError, IndexError, ValueError, zipfile.BadZipFile) as exc:
        raise ValueError(f"{folder}: not a readable lava-standard export: {exc}") from exc


def _integers(raw: dict, info: dict, gate: Gate, members: dict, notes) -> LavaStandard:
    """One clock's integers (:func:`~mappings.lava.standalone_run.load_params`' ``raw``) with
    ``standard.json``'s ``info``, the ``gate`` (its rows) and ``members`` of its sPLLs."""
    return LavaStandard(raw["dt"], gate.thresholds.shape[0], int(info["gate_levels"]),
                        raw["lif"], raw["dense"], gate, members, tuple(notes),
                        info.get("refractory_hold", HOLDS[0]))  # fmt: skip


def _read_clocked(folder: Path, info: dict, gate: Gate) -> ClockedStandard:
    """:func:`read_standard` of a folder with a clock per set of sPLLs: each clock's integers
    with its sPLLs numbered among its own again, as :func:`~mappings.lava.clocks.clocked_standard`
    makes them."""
    parts = []
    for raw, clock in zip(load_clocks(folder / "params.npz"), info["clocks"], strict=True):
        spll = np.asarray(clock["spll"], dtype=np.int64)
        members = {}
        for pop, idx in raw["members"].items():
            if not np.isin(idx, spll).all():
                raise ValueError(f"members.{pop} names sPLLs outside its clock's {spll.tolist()}")
            members[pop] = np.searchsorted(spll, idx)
        rows = Gate(gate.thresholds[spll], gate.increments[spll], gate.placement)
        parts.append(ClockPart(spll, _integers(raw, info, rows, members, clock["notes"])))
    return ClockedStandard(tuple(parts), int(info["n_spll"]), float(info["holds"]), gate)


def refuse_saturating(network, dt: float, profile: str) -> None:
    """``ValueError`` naming the parameter where a time constant of ``network`` is shorter
    than the step ``dt`` [s]: its decay would clamp to the fastest and the export run wrong
    (quantize only warns). Anything but a Network is left to quantize to refuse."""
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
