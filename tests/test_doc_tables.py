"""The numbers docs/backends.md states that the code states: the generated tables are what
``scripts/doc_tables.py`` writes now, every ``declared`` / ``default limit`` cell of a table
with a ``spec`` column is that backend's declared tolerance, the measured errors of the Rust
backends are what the conformance suite measures, and the prose's figures of the check and
the suite are the constants'. Also: every link into or out of the reference pages and the
notes resolves, anchors included.
"""

from __future__ import annotations

import importlib.util
import math
import re
from pathlib import Path

import pytest

from spll_hw import backends
from spll_hw.backends import conformance
from spll_hw.exporters import check

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "backends.md"
#: Backends whose measured column the test reruns: the Rust engine's, seconds for the whole set.
FAST = {"golden", "golden-fixed-point", "standard-exact", "usb-emulator"}


def _script():
    spec = importlib.util.spec_from_file_location("doc_tables", ROOT / "scripts" / "doc_tables.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _tables(text: str) -> list[list[dict[str, str]]]:
    """Every Markdown table of ``text`` as a list of rows, each ``{header: cell}``."""
    tables, lines = [], text.splitlines()
    for i in range(len(lines) - 1):
        if lines[i].startswith("|") and re.fullmatch(r"\|(\s*:?-+:?\s*\|)+", lines[i + 1]):
            header = [c.strip() for c in lines[i].strip("|").split("|")]
            rows = []
            for line in lines[i + 2 :]:
                if not line.startswith("|"):
                    break
                cells = [c.strip() for c in line.strip("|").split("|")]
                rows.append(dict(zip(header, cells, strict=True)))
            tables.append(rows)
    return tables


def _spec_rows(column: str) -> list[dict[str, str]]:
    """The rows of every table of the page with a ``spec`` column and ``column``."""
    rows = [r for t in _tables(DOC.read_text()) for r in t if "spec" in r and column in r]
    assert rows, f"no table with columns 'spec' and {column!r} in {DOC}"
    return rows


def _backend(cell: str):
    spec = re.fullmatch(r"`([^`]+)`", cell)
    assert spec, f"the spec cell {cell!r} is not one `spec`"
    name, options = backends.parse_spec(spec.group(1))
    return spec.group(1), backends.backend_class(name)(**options)


def test_the_generated_tables_are_up_to_date():
    text = DOC.read_text()
    assert _script().rewrite(text) == text, "stale: run python scripts/doc_tables.py"


def test_the_generated_backend_table_lists_every_registered_backend():
    rows = _tables(_script().backends_table())[0]
    assert [r["backend"] for r in rows] == [f"`{n}`" for n in backends.names()]
    listed = {r["backend"].strip("`"): r["declared tolerance"] for r in rows}
    assert listed["nir-numpy"] == "11 %" and listed["standard-fixed-point"] == "7 %"


@pytest.mark.parametrize("column", ["declared", "default limit"])
def test_every_declared_tolerance_is_the_backends(column):
    percent = _script().percent
    for row in _spec_rows(column):
        spec, backend = _backend(row["spec"])
        want = percent(backend.capabilities.rate_tolerance)
        assert row[column] == want, f"{spec}: the page says {row[column]}, the code {want}"


def test_the_rust_backends_measured_errors_are_the_suites():
    checked = 0
    for row in _spec_rows("reference set"):
        spec, _ = _backend(row["spec"])
        if backends.parse_spec(spec)[0] not in FAST:
            continue
        errors = conformance.rate_errors(conformance.configure(spec))
        mean = float(sum(e for e in errors.values() if not math.isnan(e)))
        mean /= sum(not math.isnan(e) for e in errors.values())
        cell = row["reference set"]
        if cell == "0":
            assert mean == 0, f"{spec}: measured {mean}, the page says 0"
        else:
            shown = re.fullmatch(r"([\d.]+) %", cell)
            assert shown, f"{spec}: {cell!r} is not a percentage"
            digits = len(shown.group(1).partition(".")[2])
            assert f"{100 * mean:.{digits}f}" == shown.group(1), (
                f"{spec}: measured {100 * mean:.3f} %, the page says {cell}"
            )
        checked += 1
    assert checked >= 5


def test_the_prose_figures_are_the_constants():
    text = " ".join(DOC.read_text().split())
    shift = re.search(r"runs golden on every input (\S+) ms later", text)
    assert shift and float(shift.group(1)) == 1e3 * check.RESOLUTION_SHIFT
    longer = re.search(r"golden's variation on (\S+) s of each input", text)
    assert longer and float(longer.group(1)) == check.LONGER
    trains = re.search(r"periodic trains of (\S+) s at", text)
    assert trains and float(trains.group(1)) == conformance.REFERENCE_DURATION


def _slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation but ``-`` and ``_`` dropped,
    spaces to ``-``."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def _outside_code(path: Path) -> str:
    return re.sub(r"```.*?```", "", path.read_text(), flags=re.S)


def _anchors(path: Path) -> set[str]:
    out: set[str] = set()
    for heading in re.findall(r"^#{1,6} (.*)$", _outside_code(path), re.M):
        slug, n = _slug(heading), 1
        while slug in out:
            slug, n = f"{_slug(heading)}-{n}", n + 1
        out.add(slug)
    return out


def test_links_into_and_out_of_the_reference_pages_and_notes_resolve():
    docs = ROOT / "docs"
    owned = {docs / "backends.md", docs / "speed.md", *(docs / "notes").glob("*.md")}
    pages = [ROOT / "README.md", *docs.rglob("*.md")]
    broken, seen = [], 0
    for page in pages:
        for link in re.findall(r"\]\(([^)\s]+)\)", _outside_code(page)):
            if re.match(r"[a-z]+:", link):
                continue
            path, _, fragment = link.partition("#")
            target = (page.parent / path).resolve() if path else page
            if page not in owned and target not in owned:
                continue
            seen += 1
            if not target.exists():
                broken.append(f"{page.relative_to(ROOT)}: {link} (no such file)")
            elif fragment and target.suffix == ".md" and fragment not in _anchors(target):
                broken.append(f"{page.relative_to(ROOT)}: {link} (no such heading)")
    assert seen > 50 and not broken, "\n".join(broken)


def test_every_note_is_dated_and_says_what_it_measured():
    notes = sorted((ROOT / "docs" / "notes").glob("2*.md"))
    index = (ROOT / "docs" / "notes" / "README.md").read_text()
    assert len(notes) >= 30
    for note in notes:
        date = re.match(r"(\d{4}-\d{2}-\d{2})-[a-z0-9-]+\.md$", note.name)
        assert date, f"{note.name}: not YYYY-MM-DD-topic.md"
        assert note.read_text().startswith(f"# {date.group(1)}: "), f"{note.name}: no dated title"
        assert f"]({note.name})" in index, f"{note.name} is not in docs/notes/README.md"


#: Longest reference page [lines] (issue 61: reference says what is; studies go to docs/notes/).
REFERENCE_LINES = {"backends.md": 500, "multichannel.md": 400}


@pytest.mark.parametrize("page", sorted(REFERENCE_LINES))
def test_reference_pages_stay_reference(page):
    """A reference page has no dated section (a dated study is a note) and stays short."""
    text = (ROOT / "docs" / page).read_text()
    dated = [h for h in re.findall(r"^#+ .*$", text, re.M) if re.search(r"\d{4}-\d{2}-\d{2}", h)]
    assert not dated, f"docs/{page}: dated sections belong in docs/notes/: {dated}"
    lines = text.count("\n")
    assert lines <= REFERENCE_LINES[page], f"docs/{page}: {lines} lines"
