"""Network files say what they mean: an explicit list of free-running frequencies, a band that
runs upwards, and no silent default network."""

from __future__ import annotations

import numpy as np
import pytest

from spll_hw.cli.main import main
from spll_hw.config import NetworkConfig
from spll_hw.presets import path as preset_path

#: The [spll] table of the VibTac vary-offset preset (Table 6).
SPLL = preset_path("vibtac-vary-offset-lif").read_text().split("[network]")[0]


def write(tmp_path, network: str | None, name: str = "net.toml"):
    path = tmp_path / name
    path.write_text(SPLL + ("" if network is None else "[network]\n" + network + "\n"))
    return path


def test_an_explicit_list_of_frequencies_is_the_networks_frequencies(tmp_path):
    path = write(tmp_path, 'layout = "time-scaled"\nfrequencies = [40.0, 80, 160.5]')
    config = NetworkConfig.from_toml(path)
    assert (config.n, config.f_start, config.f_end) == (3, 40.0, 160.5)
    np.testing.assert_allclose(config.build().free_frequencies(), [40.0, 80.0, 160.5], rtol=1e-12)
    # written back as the list, without the spacing it replaces, and read back equal
    text = config.to_toml()
    assert "frequencies = [40.0, 80.0, 160.5]" in text and "f_start" not in text
    again = write(tmp_path, text.split("[network]\n")[1], "again.toml")
    assert NetworkConfig.from_toml(again) == config
    assert config.with_layout("vary-offset").build().n_spll == 3
    with pytest.raises(ValueError, match="cannot be re-spaced to 5 sPLLs"):
        config.with_n(5)
    assert main(["simulate", "--network", str(path), "--rate", "100", "--duration", "0.1",
                 "--out", str(tmp_path / "sim")]) == 0  # fmt: skip


@pytest.mark.parametrize(
    ("network", "message"),
    [
        ("frequencies = [40.0, 30.0]", "must rise strictly"),
        ("frequencies = []", "must be a list of Hz"),
        ("frequencies = [40.0, -1.0]", "finite numbers of Hz > 0"),
        ("frequencies = [40.0, 80.0]\nn = 3", r"not both \(found \['n'\]"),
        ("f_start = 500.0\nf_end = 60.0", "f_start = 500 Hz is above f_end = 60 Hz"),
    ],
)
def test_a_network_table_that_cannot_mean_one_network_is_refused_by_name(
    tmp_path, network, message
):
    path = write(tmp_path, network)
    with pytest.raises(ValueError, match=message) as exc:
        NetworkConfig.from_toml(path)
    assert str(path) in str(exc.value) and "[network]" in str(exc.value)


def test_a_file_without_a_network_table_says_which_defaults_it_gets(tmp_path):
    path = write(tmp_path, None)
    with pytest.warns(UserWarning, match=r"no \[network\] table.*50 vary-offset sPLLs over 56"):
        config = NetworkConfig.from_toml(path)
    assert config == NetworkConfig(config.spll)
