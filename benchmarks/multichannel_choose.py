"""How the low-frequency channels of ``biotac-multichannel-lif`` were chosen (issue 35), on
training recordings 1-32 only: each row channel's spectrum, then the LIF gain and the sPLL
frequency range of the 22 row channels (ele1-19, pdc, tac, tdc) by 5-fold cross-validation
grouped by recording (20 materials, first 2 s of each recording, ridge on the TDE rates).

Run from the repository root (about 3 min on 2 shared cores)::

    nice -n 15 python benchmarks/multichannel_choose.py ../shared/datasets/biotac_slide_20_50
"""

from __future__ import annotations

import sys
from dataclasses import replace

import numpy as np

from spll_hw.classify import cross_validate
from spll_hw.datasets.biotac_channels import load_biotac_channels
from spll_hw.multichannel.config import MultichannelConfig
from spll_hw.multichannel.features import channel_features, input_levels

GAINS = (30.0, 100.0, 300.0, 1000.0, 3000.0)
RANGES = ((2.0, 45.0), (0.5, 20.0))


def spectra(samples) -> None:
    """Frequencies [Hz] below which 50 % and 90 % of each row channel's power lies (DC out)."""
    for name in samples.names[1:]:
        s = samples.channel(name)
        power = (np.abs(np.fft.rfft(s.signals, axis=1)) ** 2).mean(axis=0)[1:]
        f = np.fft.rfftfreq(s.signals.shape[1], 1 / s.fs)[1:]
        cum = np.cumsum(power) / power.sum()
        f50, f90 = f[np.searchsorted(cum, 0.5)], f[np.searchsorted(cum, 0.9)]
        print(f"{name}: median RMS {s.reference_level():.3g} counts, 50 % of power below "
              f"{f50:.2f} Hz, 90 % below {f90:.2f} Hz")  # fmt: skip


def main(root: str) -> None:
    samples = load_biotac_channels(root, classes="all", recordings=range(1, 33), duration=4.0)
    samples = samples.openings()
    spectra(samples)
    samples = samples.first(2.0)
    config = MultichannelConfig.load("biotac-multichannel-lif")
    low = config.groups[1]
    levels = input_levels(config, samples)
    for f_start, f_end in RANGES:
        for gain in GAINS:
            group = replace(
                low,
                encoder=("lif", low.encoder[1] | {"gain": gain}),
                network=replace(low.network, f_start=f_start, f_end=f_end),
            )
            encoder = group.make_encoder()
            rate = np.mean([
                np.mean([t.size for t in encoder.encode(
                    samples.channel(c).signals / levels[c], samples.channel(c).fs)]) / 2.0
                for c in group.channels
            ])  # fmt: skip
            x = np.concatenate(
                [channel_features(samples, c, group, levels[c], jobs=2) for c in group.channels],
                axis=1,
            )
            cv = cross_validate(x, samples.labels, samples.class_names, 5, 1.0, 0,
                                groups=samples.recordings)  # fmt: skip
            print(f"{f_start:g}-{f_end:g} Hz, gain {gain:g}: encoder {rate:.1f} spikes/s, "
                  f"CV accuracy {100 * cv.accuracy:.1f} %", flush=True)  # fmt: skip


if __name__ == "__main__":
    main(sys.argv[1])
