"""BioTac_slide_20_50 (Gao et al., IROS 2020): a BioTac finger sliding over 20 materials.

Layout: ``<root>/raw_data/matX/matX_N_bio.csv`` for material X (1-20) and recording N. Each CSV row
is one ~100 Hz BioTac frame; columns ``pac1 ... pac22`` are 22 consecutive samples of the dynamic
pressure (AC) channel, so concatenating the rows gives one 2.2 kHz signal (the only channel the
thesis uses). Values are raw ADC counts; each recording's mean is removed before it is cut into
2-s samples (:mod:`spll_hw.datasets.samples`).

When the file has a ``timestamp`` column, the PAC sampling rate implied by it
(``22 * (rows - 1) / (t_last - t_first)``) must be within 5 % of 2.2 kHz, else the file is refused.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from pathlib import Path

import numpy as np
from tqdm.auto import tqdm

from .recordings import format_numbers
from .samples import DEFAULT_SAMPLE_DURATION, SampleSet, build_sample_set, text_lines

#: The environment variable that names a BioTac_slide_20_50 folder (the default of the command
#: line's ``--data``, and of the export check's recordings).
BIOTAC_ENV = "SPLL_HW_BIOTAC_DIR"
#: PAC sampling rate [Hz] (22 samples per ~10 ms frame).
BIOTAC_FS = 2200.0
#: Number of PAC samples per CSV row.
PAC_PER_ROW = 22
_PAC_COLUMNS = tuple(f"pac{i}" for i in range(1, PAC_PER_ROW + 1))
_FS_TOLERANCE = 0.05

#: ``(folder, name, code, in the thesis's 11-class subset)`` for materials 1-20.
MATERIALS: tuple[tuple[str, str, str, bool], ...] = (
    ("mat1", "carpet net", "CP", True),
    ("mat2", "cotton", "CT", True),
    ("mat3", "bath towel", "BT", True),
    ("mat4", "fake leather", "LF", False),
    ("mat5", "polypropylene", "PP", True),
    ("mat6", "felt", "FL", False),
    ("mat7", "soft material 2", "S2", True),
    ("mat8", "paper 2", "P2", False),
    ("mat9", "polypropylene smooth", "PS", False),
    ("mat10", "polypropylene thin", "PT", True),
    ("mat11", "soft material 1", "S1", True),
    ("mat12", "cork", "CK", False),
    ("mat13", "ethylene-vinyl acetate", "EV", True),
    ("mat14", "paper 1", "P1", False),
    ("mat15", "fiber board", "FB", False),
    ("mat16", "wood hard", "WH", False),
    ("mat17", "styrofoam", "SF", True),
    ("mat18", "sponge soft", "SS", False),
    ("mat19", "foam", "FM", True),
    ("mat20", "metal", "MT", True),
)
#: Folders of the thesis's 11 classes (it dropped cork, felt, fiber board, fake leather, both
#: papers, smooth polypropylene, soft sponge and hard wood).
THESIS_11 = tuple(m[0] for m in MATERIALS if m[3])
ALL_20 = tuple(m[0] for m in MATERIALS)
_FILE_RE = re.compile(r"^(mat\d+)_(\d+)_bio\.csv$")


def read_biotac_csv(path: str | Path) -> np.ndarray:
    """The PAC signal of one ``*_bio.csv`` file: rows' ``pac1..pac22`` concatenated, raw counts.

    Raises ``ValueError`` as :func:`read_biotac_columns` does.
    """
    return read_biotac_columns(path, _PAC_COLUMNS).reshape(-1)


def read_biotac_columns(path: str | Path, columns: Sequence[str]) -> np.ndarray:
    """The named ``columns`` of one ``*_bio.csv`` file, raw counts, shape ``(rows, len(columns))``.

    Raises ``ValueError`` naming the file and row (1-based line number) for a missing header
    column, a row whose field count is not the header's (a missing or extra field would shift
    every later column; one empty trailing field, as the recordings end their rows with a comma,
    is allowed), a non-numeric or non-finite value in ``columns``, or timestamps that imply a PAC
    sampling rate other than 2.2 kHz (a row rate other than ~100 Hz).
    """
    path = Path(path)
    lines = text_lines(path, "BioTac recording")
    if not lines:
        raise ValueError(f"{path}: empty file (expected a header with {', '.join(columns)})")
    header = [h.strip() for h in lines[0].split(",")]
    missing = [c for c in columns if c not in header]
    if missing:
        raise ValueError(f"{path}, row 1: header lacks column(s) {missing}")
    col_idx = [header.index(c) for c in columns]
    ts_idx = header.index("timestamp") if "timestamp" in header else None
    rows: list[list[str]] = []
    stamps: list[str] = []
    line_numbers: list[int] = []
    for lineno, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        fields = line.split(",")
        if not fields[-1].strip():
            fields.pop()  # the trailing comma of every recorded row
        if len(fields) != len(header):
            what = "missing" if len(fields) < len(header) else "extra"
            raise ValueError(
                f"{path}, row {lineno}: {len(fields)} fields where the header has "
                f"{len(header)} columns: a field is {what}, which would shift the columns after it"
            )
        rows.append([fields[i] for i in col_idx])
        if ts_idx is not None:
            stamps.append(fields[ts_idx])
        line_numbers.append(lineno)
    if not rows:
        raise ValueError(f"{path}: no data rows after the header")
    values = _to_float(rows, path, line_numbers, columns)
    bad = np.flatnonzero(~np.isfinite(values).all(axis=1))
    if bad.size:
        col = columns[int(np.flatnonzero(~np.isfinite(values[bad[0]]))[0])]
        raise ValueError(
            f"{path}, row {line_numbers[bad[0]]}, column {col}: value is NaN or infinite"
        )
    if ts_idx is not None and len(stamps) > 1:
        t = _to_float([[s] for s in stamps], path, line_numbers, ("timestamp",))[:, 0]
        span = t[-1] - t[0]
        fs = PAC_PER_ROW * (len(t) - 1) / span if span > 0 else np.inf
        if not abs(fs / BIOTAC_FS - 1.0) <= _FS_TOLERANCE:
            raise ValueError(
                f"{path}: timestamps imply a PAC sampling rate of {fs:.6g} Hz, expected "
                f"{BIOTAC_FS:g} Hz ({PAC_PER_ROW} samples per ~10 ms row)"
            )
    return values


def _to_float(
    rows: list[list[str]], path: Path, line_numbers: list[int], columns: Sequence[str]
) -> np.ndarray:
    try:
        return np.array(rows, dtype=float)
    except ValueError:
        for lineno, row in zip(line_numbers, rows, strict=True):
            for col, text in zip(columns, row, strict=True):
                try:
                    float(text)
                except ValueError:
                    raise ValueError(
                        f"{path}, row {lineno}, column {col}: not a number: {text!r}"
                    ) from None
        raise


def resolve_classes(classes: str | Iterable[str | int]) -> tuple[str, ...]:
    """Material folders for ``"thesis11"``, ``"all"`` or a list of folders/indices/codes/names."""
    if isinstance(classes, str):
        if classes == "thesis11":
            return THESIS_11
        if classes == "all":
            return ALL_20
        classes = [c.strip() for c in classes.split(",") if c.strip()]
    lookup: dict[str, str] = {}
    for i, (folder, name, code, _) in enumerate(MATERIALS, start=1):
        for key in (folder, name, code, str(i)):
            lookup[key.lower()] = folder
    out = []
    for c in classes:
        key = str(c).strip().lower()
        if key not in lookup:
            raise ValueError(
                f"unknown BioTac material {c!r}: use 'thesis11', 'all', or folders (mat1..mat20), "
                "indices (1..20), codes (e.g. BT) or names (e.g. 'bath towel')"
            )
        out.append(lookup[key])
    if not out:
        raise ValueError("no BioTac material selected")
    return tuple(dict.fromkeys(out))


def material_name(folder: str) -> str:
    return next(m[1] for m in MATERIALS if m[0] == folder)


def recording_files(
    root: str | Path, folder: str, recordings: Iterable[int] | None = None
) -> list[Path]:
    """The ``matX_N_bio.csv`` files of one material, sorted by recording number N."""
    raw = _raw_dir(root)
    directory = raw / folder
    if not directory.is_dir():
        raise ValueError(f"{directory}: material folder not found (expected {raw}/matX folders)")
    found: dict[int, Path] = {}
    for p in directory.iterdir():
        m = _FILE_RE.match(p.name)
        if m and m.group(1) == folder:
            found[int(m.group(2))] = p
    if recordings is None:
        files = [found[n] for n in sorted(found)]
    else:
        wanted = sorted(set(int(n) for n in recordings))
        absent = [n for n in wanted if n not in found]
        if absent:
            raise ValueError(
                f"{directory}: recording(s) {format_numbers(absent)} missing "
                f"({folder}_N_bio.csv; it has {format_numbers(found) or 'none'})"
            )
        files = [found[n] for n in wanted]
    if not files:
        raise ValueError(f"{directory}: no {folder}_N_bio.csv recordings (empty class)")
    return files


def recording_jobs(
    root: str | Path, classes, recordings: Sequence[int] | None
) -> tuple[list[str], list[tuple[int, Path]]]:
    """``(the class folders of classes, (label, file) of every recording to read)``: the files of
    ``recordings`` (default: every one present) in each folder, class by class."""
    folders = resolve_classes(classes)
    jobs = [
        (label, path)
        for label, folder in enumerate(folders)
        for path in recording_files(root, folder, recordings)
    ]
    return folders, jobs


def recording_number(path: Path) -> int:
    """N of a BioTac recording file ``matX_N_bio.csv``; ``ValueError`` naming the file for
    another name."""
    match = _FILE_RE.match(Path(path).name)
    if match is None:
        raise ValueError(f"{path}: not a BioTac recording file (matX_N_bio.csv)")
    return int(match.group(2))


def _raw_dir(root: str | Path) -> Path:
    root = Path(root)
    if (root / "raw_data").is_dir():
        return root / "raw_data"
    if root.is_dir() and any(root.glob("mat*")):
        return root
    raise ValueError(f"{root}: not a BioTac_slide_20_50 folder (no raw_data/matX subfolders)")


def load_biotac(
    root: str | Path,
    classes: str | Iterable[str | int] = "thesis11",
    recordings: Iterable[int] | None = None,
    duration: float = DEFAULT_SAMPLE_DURATION,
    progress: bool = False,
) -> SampleSet:
    """Load BioTac PAC recordings as 2-s samples.

    Args:
        root: dataset folder (containing ``raw_data/``) or the ``raw_data`` folder itself.
        classes: ``"thesis11"`` (default), ``"all"``, or materials (see :func:`resolve_classes`).
        recordings: recording numbers N to use (default: all present); each sample keeps its
            recording's N (:attr:`SampleSet.numbers`).
        duration: sample length [s].
        progress: show a progress bar over files.
    """
    folders, jobs = recording_jobs(root, classes, recordings)
    raw = _raw_dir(root)
    # closed before an unreadable file's error is said, so that the error is the last line
    with tqdm(jobs, desc="reading BioTac", unit="file", disable=not progress) as bar:
        recs = []
        for label, path in bar:
            source = str(path.relative_to(raw.parent))
            recs.append((label, source, read_biotac_csv(path), recording_number(path)))
    names = [material_name(f) for f in folders]
    return build_sample_set(recs, BIOTAC_FS, names, name="biotac", duration=duration)
