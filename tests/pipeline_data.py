"""Where the pipeline tests find the shared real data (never copied into the repo).

``SPLL_HW_BIOTAC_DIR`` / ``SPLL_HW_TOUCHSIM_REF`` override the defaults, which are
``../shared/datasets/biotac_slide_20_50`` and ``../shared/reference/touchsim_pc`` relative to the
repository root. Tests that need them skip with the reason below when they are absent.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
BIOTAC_DIR = Path(
    os.environ.get("SPLL_HW_BIOTAC_DIR", REPO.parent / "shared" / "datasets" / "biotac_slide_20_50")
)
TOUCHSIM_REF = Path(
    os.environ.get("SPLL_HW_TOUCHSIM_REF", REPO.parent / "shared" / "reference" / "touchsim_pc")
)

needs_biotac = pytest.mark.skipif(
    not (BIOTAC_DIR / "raw_data").is_dir(),
    reason=f"BioTac_slide_20_50 not found at {BIOTAC_DIR} (set SPLL_HW_BIOTAC_DIR)",
)
needs_touchsim_ref = pytest.mark.skipif(
    not (TOUCHSIM_REF / "pc_vectors.npz").is_file(),
    reason=f"TouchSim reference spikes not found at {TOUCHSIM_REF} (set SPLL_HW_TOUCHSIM_REF)",
)
