"""Every BioTac channel: the column reader, the multichannel loader and MultiChannelSet."""

from __future__ import annotations

import numpy as np
import pytest

from spll_hw.datasets import load_biotac
from spll_hw.datasets.biotac_channels import (
    CHANNELS,
    ELECTRODES,
    ROW_FS,
    channel_fs,
    load_biotac_channels,
    read_channels,
)
from spll_hw.datasets.multichannel import MultiChannelSet
from spll_hw.datasets.recordings import split_recordings

from .pipeline_data import BIOTAC_DIR, needs_biotac

#: The thesis's BioTac base sPLL (SI units), the body of a ``[spll]`` table.
ROW_SPLL = """
tau_cco_syn = 0.0539
tau_cco = 0.0636
tau_tde_trg = 0.00115
tau_tde_fac = 0.0199
tau_tde = 0.0209
g_cco = 9.83
g_tde_trg = 0.348
g_tde_fac = 3450.0
"""
#: A ``[[channel]]`` table's tables below its ``channels``: four time-scaled sPLLs of
#: :data:`ROW_SPLL` over 2-45 Hz through a LIF encoder.
ROW_TABLE = f"""
[channel.spll]
{ROW_SPLL}[channel.network]
layout = "time-scaled"
f_start = 2.0
f_end = 45.0
n = 4
[channel.encoder]
name = "lif"
tau = 0.05
t_ref = 0.01
gain = 300.0
"""

HEADER = "timestamp,tdc,tac,pdc," + ",".join(f"pac{i}" for i in range(1, 23)) + ","
HEADER += ",".join(ELECTRODES)


def write_recording(root, folder: str, n: int, rows: int = 450) -> None:
    """A fake ``<folder>_<n>_bio.csv``: row r has pac ``r*22 .. r*22+21``, ele_k ``k*1000+r``,
    tdc ``r``, tac ``2r``, pdc ``3r`` (plus the recordings' trailing comma)."""
    d = root / "raw_data" / folder
    d.mkdir(parents=True, exist_ok=True)
    lines = [HEADER]
    for r in range(rows):
        pac = [r * 22 + i for i in range(22)]
        ele = [k * 1000 + r for k in range(1, 20)]
        values = [r, 2 * r, 3 * r, *pac, *ele]
        lines.append(f"{100 + 0.01 * r:.6f}," + ",".join(map(str, values)) + ",")
    (d / f"{folder}_{n}_bio.csv").write_text("\n".join(lines) + "\n")


@pytest.fixture
def fake_root(tmp_path):
    for folder in ("mat1", "mat20"):
        for n in (1, 2, 3):
            write_recording(tmp_path, folder, n, rows=450 + 10 * n)
    return tmp_path


def test_read_channels_gives_pac_at_2200_and_row_channels_at_100hz(fake_root):
    path = fake_root / "raw_data" / "mat1" / "mat1_1_bio.csv"
    x = read_channels(path, ["ele3", "pac", "pdc", "tdc", "tac"])
    np.testing.assert_array_equal(x["pac"], np.arange(22 * 460))
    np.testing.assert_array_equal(x["ele3"], 3000 + np.arange(460))
    np.testing.assert_array_equal(x["pdc"], 3 * np.arange(460))
    np.testing.assert_array_equal(x["tac"], 2 * np.arange(460))
    assert channel_fs("pac") == 2200.0 and channel_fs("ele19") == ROW_FS == 100.0
    assert len(CHANNELS) == 23
    with pytest.raises(ValueError, match="unknown BioTac channel 'ele20'"):
        read_channels(path, ["ele20"])


def test_bad_value_names_file_row_and_column(tmp_path):
    write_recording(tmp_path, "mat1", 1, rows=20)
    path = tmp_path / "raw_data" / "mat1" / "mat1_1_bio.csv"
    lines = path.read_text().splitlines()
    fields = lines[5].split(",")
    fields[HEADER.split(",").index("ele7")] = "x7"
    lines[5] = ",".join(fields)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=r"mat1_1_bio\.csv, row 6, column ele7: not a number"):
        read_channels(path, ["ele7"])


def test_loader_cuts_the_same_samples_in_every_channel(fake_root):
    m = load_biotac_channels(fake_root, ["pac", "ele1", "pdc"], ["mat1", "mat20"], duration=2.0)
    assert m.names == ("pac", "ele1", "pdc") and len(m) == 12  # 4.5-4.8 s: two 2-s samples each
    assert m.channel("pac").signals.shape == (12, 4400)
    assert m.channel("ele1").signals.shape == (12, 200) and m.channel("ele1").fs == 100.0
    assert m.channel("pac").sources == m.channel("ele1").sources
    # the single-channel loader's samples, bit for bit
    single = load_biotac(fake_root, ["mat1", "mat20"], duration=2.0)
    np.testing.assert_array_equal(m.channel("pac").signals, single.signals)
    assert m.channel("pac").sources == single.sources
    with pytest.raises(ValueError, match="whole number of 10 ms"):
        load_biotac_channels(fake_root, ["pac"], ["mat1"], duration=0.005)
    with pytest.raises(ValueError, match="no channel 'ele2' loaded"):
        m.channel("ele2")


def test_openings_first_window_and_hold_out(fake_root):
    m = load_biotac_channels(fake_root, ["pac", "ele2"], ["mat1", "mat20"], duration=2.0)
    opening = m.openings()
    assert len(opening) == 6 and all("[0-2 s]" in s for s in opening.first_set.sources)
    early = opening.first(0.25)
    assert early.channel("pac").signals.shape == (6, 550)
    assert early.channel("ele2").signals.shape == (6, 25)
    assert early.first_set.sources[0].endswith("[0-0.25 s]") and early.duration == 0.25
    np.testing.assert_array_equal(
        early.channel("ele2").signals, opening.channel("ele2").signals[:, :25]
    )
    train, test = split_recordings(opening, [3], "--test-recordings 3")
    assert (len(train), len(test)) == (4, 2) and test.names == ("pac", "ele2")
    with pytest.raises(ValueError, match="not within the 2 s samples"):
        opening.first(2.5)


def test_multichannel_set_refuses_channels_of_other_samples(fake_root):
    a = load_biotac_channels(fake_root, ["pac"], ["mat1", "mat20"], recordings=[1, 2])
    b = load_biotac_channels(fake_root, ["ele1"], ["mat1", "mat20"], recordings=[1, 3])
    with pytest.raises(ValueError, match="channel 'ele1': its samples are not those"):
        MultiChannelSet({"pac": a.channel("pac"), "ele1": b.channel("ele1")})


@needs_biotac
def test_real_recording_has_every_channel():
    m = load_biotac_channels(BIOTAC_DIR, CHANNELS, ["mat1", "metal"], [1], duration=4.0)
    assert m.names == CHANNELS and len(m.openings()) == 2
    single = load_biotac(BIOTAC_DIR, ["mat1", "metal"], [1], duration=4.0)
    np.testing.assert_array_equal(m.channel("pac").signals, single.signals)
    assert m.openings().channel("ele1").signals.shape == (2, 400)
