"""Dataset loaders: BioTac CSVs, folder-per-class recordings, synthetic textures, bad input."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.io import wavfile

from spll_hw.datasets import (
    THESIS_11,
    SampleSet,
    load_biotac,
    load_folder_dataset,
    make_synthetic,
    read_biotac_csv,
    split_recording,
)
from spll_hw.datasets.biotac import resolve_classes

from .pipeline_data import BIOTAC_DIR, needs_biotac

HEADER = "timestamp,tdc,tac,pdc," + ",".join(f"pac{i}" for i in range(1, 23)) + ",ele1"


def _row(t: float, values) -> str:
    return f"{t:.6f},1,2,3," + ",".join(str(v) for v in values) + ",7,"


def write_biotac(root, folder="mat1", n=1, rows=210, dt=0.01, value=None):
    """A fake ``raw_data/<folder>/<folder>_<n>_bio.csv`` with ``rows`` frames ``dt`` s apart."""
    d = root / "raw_data" / folder
    d.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(n)
    lines = [HEADER]
    for r in range(rows):
        values = rng.integers(0, 1000, 22) if value is None else [value] * 22
        lines.append(_row(100.0 + r * dt, values))
    path = d / f"{folder}_{n}_bio.csv"
    path.write_text("\n".join(lines) + "\n")
    return path


# ------------------------------------------------------------------------------- BioTac


@needs_biotac
def test_real_biotac_file_parses_pac_columns_in_order():
    path = BIOTAC_DIR / "raw_data" / "mat1" / "mat1_1_bio.csv"
    lines = path.read_text().splitlines()
    pac = read_biotac_csv(path)
    assert pac.size == 22 * (len(lines) - 1)
    first = [float(v) for v in lines[1].split(",")[4:26]]
    np.testing.assert_array_equal(pac[:22], first)


@needs_biotac
def test_real_biotac_subset_gives_2s_samples_at_2200hz():
    s = load_biotac(BIOTAC_DIR, classes=["mat1", "metal"], recordings=[1, 2])
    assert s.fs == 2200.0 and s.signals.shape[1] == 4400 and s.duration == 2.0
    assert s.class_names == ("carpet net", "metal")
    # whole 2-s samples per recording: 200 rows of 22 PAC values each (mat1: 6 s, mat20: ~8 s)
    expected = {}
    for folder, name in (("mat1", "carpet net"), ("mat20", "metal")):
        rows = [
            len((BIOTAC_DIR / "raw_data" / folder / f"{folder}_{n}_bio.csv").read_text().split())
            - 1
            for n in (1, 2)
        ]
        expected[name] = sum(r // 200 for r in rows)
    assert s.class_counts() == expected and expected["carpet net"] == 6
    assert "mat20_2_bio.csv [" in s.sources[-1]
    # the mean of each recording is removed before splitting
    assert abs(s.signals[s.labels == 1][:4].mean()) < 1e-9


def test_thesis_subset_and_class_names_resolve():
    assert len(THESIS_11) == 11 and "mat12" not in THESIS_11
    assert resolve_classes("all")[-1] == "mat20"
    assert resolve_classes(["BT", "3", "bath towel", "mat20"]) == ("mat3", "mat20")
    with pytest.raises(ValueError, match="unknown BioTac material"):
        resolve_classes(["velvet"])


def test_fake_biotac_loads_and_reports_tail(tmp_path):
    for folder in ("mat1", "mat2"):
        write_biotac(tmp_path, folder, n=1, rows=210)  # 4620 samples: 1 sample + 0.1 s tail
    s = load_biotac(tmp_path, classes="mat1,mat2")
    assert len(s) == 2 and s.signals.shape == (2, 4400)
    assert any("tails" in note for note in s.skipped)


def test_biotac_short_row_names_file_and_row(tmp_path):
    path = write_biotac(tmp_path)
    lines = path.read_text().splitlines()
    original = list(lines)
    lines[3] = ",".join(lines[3].split(",")[:10])
    path.write_text("\n".join(lines))
    with pytest.raises(ValueError, match=r"mat1_1_bio\.csv, row 4: 10 fields where the header"):
        read_biotac_csv(path)
    # One field missing after the PAC columns would shift nothing we read, but one missing in
    # front of them shifts pac1..pac22 by one column: refused, never read shifted.
    fields = original[4].split(",")
    lines = list(original)
    lines[4] = ",".join(fields[:1] + fields[2:])
    path.write_text("\n".join(lines))
    with pytest.raises(ValueError, match=r"row 5: .* a field is missing, which would shift"):
        read_biotac_csv(path)
    lines[4] = ",".join([*fields, "7"])
    path.write_text("\n".join(lines))
    with pytest.raises(ValueError, match=r"row 5: .* a field is extra"):
        read_biotac_csv(path)


def test_biotac_non_numeric_and_nan_values_name_row_and_column(tmp_path):
    path = write_biotac(tmp_path)
    lines = path.read_text().splitlines()
    fields = lines[5].split(",")
    fields[4 + 6] = "12x"
    lines[5] = ",".join(fields)
    path.write_text("\n".join(lines))
    with pytest.raises(ValueError, match=r"row 6, column pac7: not a number: '12x'"):
        read_biotac_csv(path)
    fields[4 + 6] = "nan"
    lines[5] = ",".join(fields)
    path.write_text("\n".join(lines))
    with pytest.raises(ValueError, match=r"row 6, column pac7: value is NaN"):
        read_biotac_csv(path)


def test_biotac_wrong_sampling_rate_and_missing_columns(tmp_path):
    slow = write_biotac(tmp_path, n=1, dt=0.02)  # 22 samples per 20 ms = 1.1 kHz
    with pytest.raises(ValueError, match="sampling rate of 1100 Hz"):
        read_biotac_csv(slow)
    bad = tmp_path / "bad.csv"
    bad.write_text("timestamp,pac1,pac2\n1,2,3\n")
    with pytest.raises(ValueError, match=r"bad\.csv, row 1: header lacks column"):
        read_biotac_csv(bad)


def test_biotac_missing_and_empty_classes(tmp_path):
    write_biotac(tmp_path, "mat1")
    (tmp_path / "raw_data" / "mat2").mkdir()
    with pytest.raises(ValueError, match="mat2: no mat2_N_bio.csv recordings"):
        load_biotac(tmp_path, classes="mat1,mat2")
    with pytest.raises(ValueError, match="mat3: material folder not found"):
        load_biotac(tmp_path, classes="mat1,mat3")
    with pytest.raises(ValueError, match=r"recording\(s\) 2 missing"):
        load_biotac(tmp_path, classes="mat1", recordings=[1, 2])
    with pytest.raises(ValueError, match="not a BioTac_slide_20_50 folder"):
        load_biotac(tmp_path / "nowhere")


# ------------------------------------------------------------------------------- folders


def _folder_dataset(root, fs=1000):
    t = np.arange(int(4.5 * fs)) / fs
    (root / "alu").mkdir(parents=True)
    (root / "felt").mkdir()
    wavfile.write(root / "alu" / "a.wav", fs, (1e4 * np.sin(2 * np.pi * 50 * t)).astype(np.int16))
    np.save(root / "felt" / "b.npy", np.stack([np.sin(2 * np.pi * 90 * t), t], axis=1))
    (root / "felt" / "c.csv").write_text("value\n" + "\n".join(f"{v:.6f}" for v in np.cos(t)))
    return root


def test_folder_dataset_reads_wav_npy_csv(tmp_path):
    s = load_folder_dataset(_folder_dataset(tmp_path / "vib"), fs=1000)
    assert s.class_names == ("alu", "felt") and s.fs == 1000
    assert s.class_counts() == {"alu": 2, "felt": 4} and s.signals.shape[1] == 2000
    assert any("tails" in n for n in s.skipped)  # 0.5 s left over per recording


def test_folder_dataset_sampling_rate_errors(tmp_path):
    root = _folder_dataset(tmp_path / "vib")
    with pytest.raises(ValueError, match=r"a\.wav: WAV sampling rate is 1000 Hz but 8000"):
        load_folder_dataset(root, fs=8000)
    with pytest.raises(ValueError, match=r"files carry no sampling rate: give it \(--fs HZ"):
        load_folder_dataset(root)


def test_folder_dataset_bad_rows_nan_and_empty_class(tmp_path):
    root = _folder_dataset(tmp_path / "vib")
    (root / "felt" / "c.csv").write_text("1.0\n2.0\nabc\n")
    with pytest.raises(ValueError, match=r"c\.csv, row 3: not a number: 'abc'"):
        load_folder_dataset(root, fs=1000)
    (root / "felt" / "c.csv").write_text("1.0\nnan\n")
    with pytest.raises(ValueError, match=r"c\.csv, row 2: value is NaN"):
        load_folder_dataset(root, fs=1000)
    (root / "felt" / "c.csv").unlink()
    (root / "cork").mkdir()
    with pytest.raises(ValueError, match="cork: no recordings.*empty class"):
        load_folder_dataset(root, fs=1000)


# ------------------------------------------------------------------------------- samples


def test_split_recording_counts_tail():
    chunks, tail = split_recording(np.arange(21.0), fs=2.0, duration=2.0)
    assert chunks.shape == (5, 4) and tail == pytest.approx(0.5)
    np.testing.assert_array_equal(chunks[1], [4, 5, 6, 7])


def test_sample_set_rejects_nan_and_empty_classes():
    x = np.zeros((2, 10))
    x[1, 3] = np.nan
    with pytest.raises(ValueError, match="rec-b: sample contains NaN"):
        SampleSet(x, 100.0, np.array([0, 1]), ("a", "b"), ("rec-a", "rec-b"))
    with pytest.raises(ValueError, match=r"\['c'\] have no samples"):
        SampleSet(np.zeros((2, 10)), 100.0, np.array([0, 1]), ("a", "b", "c"), ("p", "q"))


def test_sample_set_subsets_and_normalisation():
    s = make_synthetic(n_classes=3, samples_per_class=8)
    sub = s.per_class(3, seed=1)
    assert sub.class_counts() == dict.fromkeys(s.class_names, 3)
    only = s.subset(np.flatnonzero(s.labels == 2))
    assert only.class_names == (s.class_names[2],) and set(only.labels) == {0}
    norm = s.normalized()
    assert norm.reference_level() == pytest.approx(1.0)
    assert "median sample RMS" in norm.unit


# ------------------------------------------------------------------------------- synthetic


def test_synthetic_is_deterministic_per_seed():
    a, b, c = make_synthetic(seed=3), make_synthetic(seed=3), make_synthetic(seed=4)
    np.testing.assert_array_equal(a.signals, b.signals)
    assert not np.allclose(a.signals, c.signals)
    assert a.n_classes == 8 and len(a) == 8 * 350 and a.fs == 2200.0 and a.duration == 1.0


def _cli_duration(dataset: str, duration: float | None, **extra) -> float:
    """The sample length [s] the CLI's loader gives ``--dataset dataset --duration duration``."""
    from argparse import Namespace

    from spll_hw.cli.inputs import load_samples

    extra = {"recordings": None} | extra
    args = Namespace(dataset=dataset, duration=duration, synthetic_classes=2, synthetic_samples=3,
                     seed=0, quiet=True, per_class=None, **extra)  # fmt: skip
    return load_samples(args).duration


def test_the_cli_samples_last_1_s_on_synthetic_data_unless_told():
    assert _cli_duration("synthetic", None) == 1.0
    assert _cli_duration("synthetic", 0.5) == 0.5


@needs_biotac
def test_the_cli_samples_last_2_s_on_biotac_unless_told():
    biotac = {"data": str(BIOTAC_DIR), "classes": "mat1,mat2", "recordings": "1-2"}
    assert _cli_duration("biotac", None, **biotac) == 2.0
    assert _cli_duration("biotac", 1.5, **biotac) == 1.5


def test_synthetic_drift_glides_the_peaks_at_an_unchanged_mean_speed():
    """A pure tone warped by a drift d reads at rate 1 - d/2 at the start and 1 + d/2 at the
    end: its instantaneous frequency glides by d of itself, its mean stays."""
    from spll_hw.datasets.synthetic import _drifted

    fs, f, n = 2200.0, 200.0, 4400
    tone = np.sin(2 * np.pi * f * np.arange(n) / fs)[None, :]
    warped = _drifted(tone, np.array([0.1]))[0]
    crossings = np.flatnonzero((warped[:-1] < 0) & (warped[1:] >= 0))
    rate = fs / np.diff(crossings)  # instantaneous frequency [Hz]
    assert rate[:5].mean() == pytest.approx(f * 0.95, rel=0.01)
    assert rate[-5:].mean() == pytest.approx(f * 1.05, rel=0.01)
    assert len(crossings) == pytest.approx(f * n / fs, abs=2)


def test_synthetic_classes_have_distinct_dominant_frequencies():
    s = make_synthetic(n_classes=5, samples_per_class=20, seed=0)
    spectra = np.abs(np.fft.rfft(s.signals, axis=1))
    freqs = np.fft.rfftfreq(s.signals.shape[1], 1 / s.fs)
    nominal = [float(name.split("(")[1].split(" Hz")[0]) for name in s.class_names]
    for k, f0 in enumerate(nominal):
        mean = spectra[s.labels == k].mean(axis=0)
        near = (freqs > 0.9 * f0) & (freqs < 1.1 * f0)
        # the fundamental stands far above the class's typical level (harmonics and the
        # inharmonic mode may be as strong: a texture has several peaks)
        assert mean[near].max() > 4 * np.median(mean[freqs > 20]), (k, f0)
    # within-class variability: individual samples' peaks spread around the class value
    spread = np.std([freqs[np.argmax(x)] for x in spectra[s.labels == 4]])
    assert spread > 1.0
