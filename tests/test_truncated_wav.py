"""A WAV recording whose data chunk is cut short (a copy or a write that stopped) is refused by
name, as a broken header is: scipy only warns ("Reached EOF prematurely") and returns the
samples that are there, so the folder dataset dropped it as too short, or trained on a stub,
with scipy's warning and its source line as the only sign (issue 62's campaign: a corrupt WAV)."""

from __future__ import annotations

import warnings

import pytest

from spll_hw.cli.main import main
from spll_hw.datasets.vibtac import read_recording

from .test_bad_input_campaign import _wav


def test_a_wav_cut_short_in_its_data_is_refused_by_name(tmp_path):
    path = tmp_path / "cut.wav"
    _wav(path)
    path.write_bytes(path.read_bytes()[:1000])  # header whole, data chunk cut
    with pytest.raises(ValueError) as exc:
        read_recording(path)
    text = str(exc.value)
    assert text.startswith(f"{path}: not a readable WAV file (its data is cut short: "), text
    assert "Reached EOF prematurely" in text and "replace or remove the file" in text


def test_a_whole_wav_reads_without_a_warning(tmp_path):
    path = tmp_path / "whole.wav"
    _wav(path, seconds=0.5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        signal, fs = read_recording(path)
    assert fs == 8000 and signal.shape == (4000,)


def test_evaluate_names_a_cut_wav_instead_of_dropping_it(tmp_path, capsys):
    root = tmp_path / "wavs"
    for name in ("a", "b"):
        (root / name).mkdir(parents=True)
        for i in (1, 2, 3):
            _wav(root / name / f"r{i}.wav")
    cut = root / "a" / "r2.wav"
    cut.write_bytes(cut.read_bytes()[:1000])
    argv = ["evaluate", "--features", "spectrum", "--folds", "2", "--dataset", "folder",
            "--data", str(root), "--quiet", "--out", str(tmp_path / "out")]  # fmt: skip
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert f"{cut}: not a readable WAV file (its data is cut short" in err, err
    assert "WavFileWarning" not in err and not (tmp_path / "out").exists()
