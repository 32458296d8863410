"""``spll-hw export --to lava-standard``: a folder that runs on lava-nc alone."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np

from spll_hw.model import grid as model_grid

from .lava_params import DEFAULT_DT, LavaStandard, lava_standard

_README = """# sPLL network on Lava's own processes

{n} sPLLs as the standard-neuron construction ({k} gate levels) on `lava.proc.lif` LIF,
`lava.proc.dense` Dense and `lava.proc.io` ring buffers, with their bit-accurate fixed-point
models, dt = {dt:g} s. Needs numpy and lava-nc 0.10 only (`lava_compat.py` lets lava-nc 0.10
import on Python 3.11; install it with `pip install --ignore-requires-python lava-nc==0.10.0`):

    python run.py spikes.npy 1.0     # input spike times [s] (.npy), duration [s]

prints JSON with `tde_counts` and `cco_counts` per sPLL. `params.npz`: the integers
(`lif.POP.*`: du, dv, vth, bias_mant, bias_exp; `dense.NAME.weights` / `.meta`: source, target,
weight_exp, num_message_bits); `standard.json`: what they stand for; `spll_grid.py`: the step
each input spike counts in (spll-hw's grid rule).
"""


def export_lava_standard(network, out: str | Path, *, profile=None, dt=None) -> list[Path]:
    """params.npz, run.py (lava-nc and numpy only: python run.py spikes.npy 1.0 prints TDE and
    CCO counts as JSON), lava_compat.py: the standard sPLL on Lava's own LIF and Dense.

    The ``spll_hw.exporters`` entry point of ``spll-hw export --to lava-standard``. ``dt`` [s]
    defaults to 10 µs; the integers are Loihi's own formats, so ``profile`` does not apply and
    raises ``ValueError``. Writing needs no lava-nc.
    """
    if profile is not None:
        raise ValueError("lava-standard export uses Loihi's own number formats: drop --profile")
    return write_folder(lava_standard(network, dt=DEFAULT_DT if dt is None else float(dt)), out)


def write_folder(params: LavaStandard, out: str | Path) -> list[Path]:
    """Write the folder of :func:`export_lava_standard` for integers already made."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    npz = out / "params.npz"
    np.savez(npz, **params.arrays())
    here = Path(__file__).resolve().parent
    run = out / "run.py"
    shutil.copyfile(here / "lava_run.py", run)
    compat = out / "lava_compat.py"
    shutil.copyfile(here.parent / "lava" / "compat.py", compat)
    grid = out / "spll_grid.py"
    shutil.copyfile(model_grid.__file__, grid)
    meta = out / "standard.json"
    meta.write_text(
        json.dumps(
            {
                "dt": params.dt,
                "n_spll": params.n_spll,
                "gate_levels": params.levels,
                "gate_placement": params.gate.placement,
                "thresholds_A": params.gate.thresholds.tolist(),
                "increments_A": params.gate.increments.tolist(),
                "populations": {
                    k: {"du": int(v["du"]), "dv": int(v["dv"]), "vth": int(v["vth"])}
                    for k, v in params.lif.items()
                },
            },
            indent=1,
        )  # fmt: skip
    )
    readme = out / "README.md"
    readme.write_text(_README.format(n=params.n_spll, k=params.levels, dt=params.dt))
    return [npz, run, compat, grid, meta, readme]
