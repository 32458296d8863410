"""Recordings, not chunks: numbered recordings of folder datasets and BioTac, held-out recordings
and folds of whole recordings (``--recordings``, ``--holdout-recordings``, ``--cv recordings``)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from spll_hw.classify import fold_indices
from spll_hw.cli.main import build_parser, main
from spll_hw.datasets import load_biotac, load_folder_dataset, make_synthetic
from spll_hw.datasets.recordings import format_numbers, recording_numbers, split_recordings

from .pipeline_data import BIOTAC_DIR, needs_biotac

FS = 1500.0


def leaky_folder(root, per_class=6, chunks=3, seed=0):
    """Two classes of ``per_class`` .npy recordings, each ``chunks`` 2-s samples of one sine
    whose frequency [Hz] is drawn per recording, unrelated to its class: chunks of one recording
    look alike, so folds of samples leak the label and folds of recordings cannot."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(chunks * 2 * FS)) / FS
    for name in ("a", "b"):
        (root / name).mkdir(parents=True)
        for i in range(per_class):
            f = rng.uniform(20, 200)
            np.save(root / name / f"rec{i:02d}.npy", np.sin(2 * np.pi * f * t))
    return root


def test_folder_recordings_are_numbered_by_position_in_their_class_folder(tmp_path):
    root = leaky_folder(tmp_path / "vib", per_class=4, chunks=2)
    s = load_folder_dataset(root, fs=FS)
    assert recording_numbers(s).tolist() == [1, 1, 2, 2, 3, 3, 4, 4] * 2
    picked = load_folder_dataset(root, fs=FS, recordings=[2, 4])
    assert sorted(set(picked.recordings.tolist())) == [
        "vib/a/rec01.npy", "vib/a/rec03.npy", "vib/b/rec01.npy", "vib/b/rec03.npy",
    ]  # fmt: skip
    assert picked.numbers.tolist() == [2, 2, 4, 4] * 2
    with pytest.raises(ValueError, match=r"vib/a: no recording\(s\) 5: the class folder has 4"):
        load_folder_dataset(root, fs=FS, recordings=[4, 5])


def test_split_recordings_holds_out_whole_recordings_and_names_the_flag(tmp_path):
    s = load_folder_dataset(leaky_folder(tmp_path / "vib", per_class=4, chunks=2), fs=FS)
    train, test = split_recordings(s, [3, 4], "--holdout-recordings 3-4")
    assert set(train.numbers.tolist()) == {1, 2} and set(test.numbers.tolist()) == {3, 4}
    assert not set(train.recordings) & set(test.recordings)
    assert len(train) + len(test) == len(s) and test.class_names == s.class_names
    with pytest.raises(ValueError, match=r"--holdout-recordings 3-9: recording\(s\) 5-9 are not "
                       r"loaded \(loaded: 1-4"):  # fmt: skip
        split_recordings(s, range(3, 10), "--holdout-recordings 3-9")
    with pytest.raises(ValueError, match="--x needs numbered recordings"):
        split_recordings(make_synthetic(2, 4), [1], "--x")
    assert format_numbers([9, 1, 2, 3, 7, 10]) == "1-3, 7, 9-10"


def test_numbers_survive_subsets_and_joins(tmp_path):
    s = load_folder_dataset(leaky_folder(tmp_path / "vib", per_class=3, chunks=2), fs=FS)
    part = s.subset([5, 0, 11])
    assert part.numbers.tolist() == [s.numbers[5], s.numbers[0], s.numbers[11]]
    assert s.joined(s).numbers.tolist() == s.numbers.tolist() * 2
    assert make_synthetic(2, 3).joined(make_synthetic(2, 3)).numbers is None


def run_evaluate(*argv):
    args = build_parser().parse_args(["evaluate", *argv])
    return args.func(args)


def test_folds_of_recordings_stop_the_leak_that_folds_of_samples_have(tmp_path):
    """Chunks of one recording share its sine: folds of samples score it nearly perfectly from
    a sibling chunk; folds of whole recordings cannot (the frequency is not the class)."""
    root = leaky_folder(tmp_path / "vib", per_class=10, chunks=4)
    common = ["--dataset", "folder", "--data", str(root), "--fs", str(FS),
              "--features", "spectrum", "--folds", "5", "--quiet", "--jobs", "1"]  # fmt: skip
    accuracy = {}
    for cv in ("samples", "recordings"):
        out = tmp_path / cv
        assert run_evaluate(*common, "--cv", cv, "--out", str(out)) == 0
        accuracy[cv] = json.loads((out / "results.json").read_text())["results"][0]["accuracy"]
    assert accuracy["samples"] > 0.7  # 76 % here
    assert accuracy["recordings"] < 0.5  # 35 %: chance, the leak is gone
    assert (
        "5-fold CV of recordings (every recording in one fold)"
        in (tmp_path / "recordings" / "summary.md").read_text()
    )
    s = load_folder_dataset(root, fs=FS)
    for train, test in fold_indices(s.labels, 5, 0, groups=s.recordings):
        assert not set(s.recordings[train]) & set(s.recordings[test])


def test_folder_holdout_and_bad_recording_flags_name_flag_and_what_exists(tmp_path, capsys):
    root = leaky_folder(tmp_path / "vib", per_class=4, chunks=2)
    common = ["evaluate", "--dataset", "folder", "--data", str(root), "--fs", str(FS),
              "--features", "spectrum", "--quiet", "--jobs", "1"]  # fmt: skip
    out = tmp_path / "held"
    assert main([*common, "--holdout-recordings", "4", "--out", str(out)]) == 0
    result = json.loads((out / "results.json").read_text())["results"][0]
    assert result["test_recordings"] == 2 and np.shape(result["correct"]) == (1, 4)
    assert main([*common, "--holdout-recordings", "4-6", "--out", str(out)]) == 2
    assert "--holdout-recordings 4-6: recording(s) 5-6 are not loaded (loaded: 1-4" in (
        capsys.readouterr().err
    )
    assert main([*common, "--recordings", "1-5", "--out", str(out)]) == 2
    assert "--recordings 1-5:" in capsys.readouterr().err
    assert main([*common, "--cv", "recordings", "--folds", "5", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "--cv recordings --folds 5: class(es) {'a': 4, 'b': 4} have fewer recordings" in err
    assert main(["evaluate", "--recordings", "1-2", "--quiet", "--out", str(out)]) == 2
    assert "--recordings needs --dataset biotac or folder" in capsys.readouterr().err


@needs_biotac
def test_biotac_samples_carry_their_recording_numbers():
    s = load_biotac(BIOTAC_DIR, "mat1,mat2", [3, 7], 2.0, False)
    numbers = recording_numbers(s)
    assert set(numbers.tolist()) == {3, 7}
    for source, n in zip(s.sources, numbers, strict=True):
        assert f"_{n}_bio.csv" in source
