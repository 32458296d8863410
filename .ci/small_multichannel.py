"""Write a small multichannel network (tests/test_multichannel_standard_export.py's: 7 sPLLs of
BioTac channels ele1, ele2 and tdc) and a readout for it into folder ARGV[1], for CI's third
environment to export with --to nir-standard and run in Norse (``.ci/run``)."""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from spll_hw.multichannel.readout_file import save_readout  # noqa: E402
from tests.test_multichannel_standard_export import CONFIG, readout, small_config  # noqa: E402

out = Path(sys.argv[1])
out.mkdir(parents=True, exist_ok=True)
(out / "small.toml").write_text(CONFIG)
save_readout(out / "readout.npz", readout(small_config(), np.random.default_rng(1), 2))
print(f"wrote {out / 'small.toml'} and {out / 'readout.npz'} (a 2-stage readout)")
