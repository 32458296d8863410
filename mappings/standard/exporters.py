"""``spll-hw export --to nir-standard``: the standard sPLL as a NIR file that consumers run."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np

from spll_hw.model import grid as model_grid

from .nir_graph import DEFAULT_DT, NODE_NAMES, to_standard_nir

_README = """# sPLL network from standard NIR nodes

`network.nir` holds {n} sPLLs built from CubaLIF, LIF, Linear and Affine nodes only (no
metadata semantics), with a {k}-level gate ({placement} levels); written for a time step of
dt = {dt:g} s, a spike counting 1 in its step. Output: one vector of {n2} spikes per step, the
{n} TDEs first, then the {n} CCOs. Feed it the number of input spikes in each step, binned by
`spll_grid.py` (spll-hw's grid rule: a spike at `t` counts in step `max(1, ceil(t/dt))`, one on
a step's end in that step; numpy only):

```python
import nir, numpy as np, torch
from spll_grid import arrival_counts, n_steps
graph = nir.read("network.nir")
counts = arrival_counts(spike_times, n_steps(duration, {dt!r}), {dt!r})   # (steps,)
input_counts_per_step = torch.tensor(counts, dtype=torch.float32)[:, None, None]

from snntorch.import_nir import import_from_nir      # snnTorch (its import assumes dt = 1e-4)
module = import_from_nir(graph)
import norse.torch                                   # Norse
module = norse.torch.from_nir(graph, dt={dt!r})

state, counts = None, 0
for x in input_counts_per_step:                      # torch tensors of shape (batch, 1)
    out, state = module(x) if state is None else module(x, state)
    counts = counts + out                            # (batch, {n2}) spike counts
```

(`mappings/standard/consumers.py` in spll-hw runs both, batch and all.) Gate levels and the
construction: `standard.json`.
"""


def export_nir_standard(network, out: str | Path, *, profile=None, dt=None) -> list[Path]:
    """network.nir from standard NIR nodes only (CubaLIF, LIF, Linear, Affine) that snnTorch,
    Norse and other NIR consumers run; standard.json: gate levels and the graph's conventions.

    The ``spll_hw.exporters`` entry point of ``spll-hw export --to nir-standard``. ``dt`` [s]
    (default 100 µs, snnTorch's fixed step) is written into the graph; ``profile`` does not
    apply (the graph is in floating point) and raises ``ValueError``.
    """
    if profile is not None:
        raise ValueError("nir-standard export is a floating-point graph: drop --profile")
    built = to_standard_nir(network, dt=DEFAULT_DT if dt is None else float(dt))
    import nir

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "network.nir"
    nir.write(path, built.graph)
    info = {
        "format": built.graph.metadata["format"],
        "dt": built.dt,
        "n_spll": network.n_spll,
        "outputs": built.graph.metadata["outputs"],
        "spike_size": built.graph.metadata["spike_size"],
        "refractory": built.refractory,
        "nodes": NODE_NAMES,
        "gate": {
            "levels": built.gate.n_levels,
            "placement": built.gate.placement,
            "input_rate_hz": built.gate.input_rate,
            "thresholds_A": np.asarray(built.gate.thresholds).tolist(),
            "increments_A": np.asarray(built.gate.increments).tolist(),
        },
    }
    meta = out / "standard.json"
    meta.write_text(json.dumps(info, indent=1))
    readme = out / "README.md"
    readme.write_text(
        _README.format(
            n=network.n_spll,
            n2=2 * network.n_spll,
            k=built.gate.n_levels,
            placement=built.gate.placement,
            dt=built.dt,
        )  # fmt: skip
    )
    grid = out / "spll_grid.py"
    shutil.copyfile(model_grid.__file__, grid)
    return [path, meta, readme, grid]
