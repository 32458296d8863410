"""`spll-hw chips --network MULTICHANNEL` shows progress while it places and costs every sample,
not only while it encodes and simulates the channels (issue 62: "progress on every command that
can run past ~10 s"; the costing of 20 samples of the BioTac preset took 30-40 s in silence)."""

from __future__ import annotations

from spll_hw.datasets.biotac_channels import load_biotac_channels
from spll_hw.multichannel.chips import classification_cost
from spll_hw.multichannel.config import MultichannelConfig
from spll_hw.multichannel.features import input_levels

from .test_multichannel_data import write_recording


def test_placing_and_costing_every_sample_has_a_progress_bar(tmp_path, capsys):
    for material in ("mat1", "mat2"):
        write_recording(tmp_path, material, 1, rows=60)
    config = MultichannelConfig.single("pac", "biotac-tuned-time-scaled-lif")
    samples = load_biotac_channels(tmp_path, ["pac"], ["mat1", "mat2"], duration=0.5)
    levels = input_levels(config, samples)
    capsys.readouterr()
    cost = classification_cost(config, "loihi2", samples, levels, 0.5, classes=2, progress=True)
    err = capsys.readouterr().err
    assert "loihi2: encoding + sPLLs" in err
    assert "loihi2: placing and costing" in err and "/4 [" in err, err  # 2 samples x (net, readout)
    assert len(cost.costs) == len(cost.readout) == 2
    classification_cost(config, "loihi2", samples, levels, 0.5)  # quiet by default
    assert capsys.readouterr().err == ""
