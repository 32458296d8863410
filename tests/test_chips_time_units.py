"""`spll-hw chips` writes a step latency as `report` and the exports write a time, in µs,
beside its energies in µJ (issue 62: "one unit style per quantity"; it said "us"). Step names
such as ``loihi2@10us`` stay ASCII: they are typed."""

from __future__ import annotations

import re

from spll_hw.cli.main import main
from spll_hw.config import NetworkConfig

#: A time in ASCII micro-seconds after a number, as prose would write it (not ``@10us``).
ASCII_MICRO = re.compile(r"\d us\b")


def test_chips_writes_step_latencies_in_microseconds(tmp_path, capsys):
    network = tmp_path / "small.toml"
    network.write_text(NetworkConfig.preset("vibtac-time-scaled-lif").with_n(3).to_toml())
    out = tmp_path / "chips"
    argv = ["chips", "--network", str(network), "--profiles", "loihi2,loihi1,fixed16",
            "--duration", "0.2", "--out", str(out)]  # fmt: skip
    assert main(argv) == 0
    printed = capsys.readouterr().out
    summary = (out / "summary.md").read_text()
    for text in (printed, summary):
        assert "step latency " in text and re.search(r"step latency [\d.]+ µs", text), text
        assert not ASCII_MICRO.search(text), ASCII_MICRO.search(text)
        assert re.search(r"\| [\d.]+ µs \* \|", text)  # the table's latency column
