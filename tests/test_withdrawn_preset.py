"""A preset kept although what it was tuned for is withdrawn is offered with a note saying so
(issue 62: "the withdrawn Pacinian preset is offered without a note"; the README and
docs/tuning.md said it, `--network`'s list of presets did not)."""

from __future__ import annotations

import pytest

from spll_hw import presets
from spll_hw.cli.main import main

PACINIAN = "biotac-tuned-vary-offset-pacinian"


def test_every_withdrawn_preset_exists_and_its_file_says_so():
    assert PACINIAN in presets.WITHDRAWN
    for name, note in presets.WITHDRAWN.items():
        assert name in presets.names() and "withdrawn" in note
        assert "WITHDRAWN" in presets.path(name).read_text()  # the file's own header


def test_the_listing_notes_the_withdrawn_preset_only():
    listing = presets.listing()
    assert f"{PACINIAN} ({presets.WITHDRAWN[PACINIAN]})" in listing
    assert listing.count("withdrawn") == len(presets.WITHDRAWN)
    assert listing.replace(f" ({presets.WITHDRAWN[PACINIAN]})", "") == ", ".join(presets.names())


@pytest.mark.parametrize("command", ["fit", "simulate", "export", "evaluate", "report"])
def test_network_help_says_the_pacinian_gain_is_withdrawn(command, capsys):
    assert main([command, "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "tuned-vary-offset-pacinian (its tuned gain is withdrawn" in text
