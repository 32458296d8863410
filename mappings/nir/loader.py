"""Load this folder's ``network.nir`` in a NIR consumer at the step it is written for, and run it.

This file is copied as ``load_consumer.py`` into the folder ``spll-hw export --to nir-standard``
writes; it needs numpy, nir, torch and the consumer (Norse or snnTorch), not spll-hw::

    python load_consumer.py norse            # loads it at the file's dt, says so
    python load_consumer.py norse 5e-5       # refused (exit 2) unless 5e-5 s is the file's dt

    from load_consumer import load, run
    module, dt = load("norse")               # the step is the file's (standard.json "dt")
    out = run(module, counts, dt)            # counts (steps, batch) -> spikes (steps, batch, 2N)

The graph is a discrete construction written for one ``dt``; stepped by another it is another
network (its step guard then makes every output spike in every step: README.md). :func:`load`
passes the file's step to the consumer and refuses another; a consumer that ``standard.json``'s
table lists as unable to run the file (snnTorch, which steps by 100 µs only, for a file of
another step) is refused with the table's reason; :func:`run` raises :class:`StepGuardTripped`
where the output is the guard's (every output spiking in two successive steps), so that a
consumer that stepped it otherwise cannot hand back a plausible wrong answer.

Norse runs in float64 (:data:`PRECISION`): its NIR import builds float32 modules, and in float32
a slow sPLL's CCO current beside its refractory force keeps too few bits below 100 µs, which
moves its counts beyond ``check_consumer.py``'s tolerance (docs/backends.md, "Consumers").
"""

from __future__ import annotations

import contextlib
import io
import json
import logging
import sys
from collections.abc import Iterable, Iterator
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
#: Consumers this file loads, with the package each needs beside torch and nir.
CONSUMERS = {"norse": "norse", "snntorch": "snntorch"}
#: How far a requested step may be from the file's (relative) and still count as it: float
#: noise only (the graph's own guard lets 0.1 % pass).
SAME_STEP = 1e-9
#: The float type each consumer's module computes in (:func:`load_module` casts Norse's, its
#: neurons' parameters included; snnTorch runs only at 100 µs, where float32 holds).
PRECISION = {"norse": "float64", "snntorch": "float32"}


class StepGuardTripped(RuntimeError):
    """A consumer ran the graph at another step than the file's: every output spiked in two
    successive steps, the step guard's signature."""


def table(folder: Path = HERE) -> dict:
    """``standard.json``: the file's ``dt`` [s] and its consumer table (consumer -> one line,
    "runs it: ..." or "cannot run it: ...")."""
    return json.loads((Path(folder) / "standard.json").read_text())


def file_step(folder: Path = HERE) -> float:
    """The step [s] ``network.nir`` is written for (``standard.json``'s ``dt``)."""
    return float(table(folder)["dt"])


def checked_step(consumer: str, dt: float | None = None, folder: Path = HERE) -> float:
    """The step to run ``consumer`` at: the file's; ``ValueError`` naming the file's step when
    ``dt`` [s] is another, or the table's reason when the table says ``consumer`` cannot run
    the file."""
    info = table(folder)
    step = float(info["dt"])
    if consumer not in CONSUMERS:
        raise ValueError(f"unknown consumer {consumer!r}; this loader knows {', '.join(CONSUMERS)}")
    line = info["consumers"].get(consumer, "is not listed in standard.json")
    if not line.startswith("runs it"):
        raise ValueError(f"{consumer} {line}")
    if dt is not None and not abs(float(dt) / step - 1.0) <= SAME_STEP:
        raise ValueError(
            f"network.nir is written for dt = {step!r} s and runs only at that step (stepped by "
            f"another, every output spikes in every step); got dt = {float(dt)!r} s: load it "
            f"with dt = {step!r}, or export again with spll-hw export --to nir-standard "
            f"--dt {float(dt)!r}"
        )
    return step


def load(consumer: str, dt: float | None = None, folder: Path = HERE):
    """``(module, dt)``: ``consumer``'s torch module of ``network.nir``, loaded at the file's
    step ``dt`` [s] (:func:`checked_step` refuses another)."""
    step = checked_step(consumer, dt, folder)
    import nir

    return load_module(consumer, nir.read(Path(folder) / "network.nir"), step), step


def load_module(consumer: str, graph, dt: float):
    """The torch module of ``consumer``'s NIR import of ``graph`` (a ``nir.NIRGraph`` written
    for time step ``dt`` [s]; Norse gets ``dt``, snnTorch assumes 100 µs), in the consumer's
    :data:`PRECISION`; what the imports print and log is dropped."""
    with contextlib.redirect_stdout(io.StringIO()), _quiet_logging():
        if consumer == "snntorch":
            from snntorch.import_nir import import_from_nir

            return import_from_nir(graph)
        import norse.torch

        return _in_float64(norse.torch.from_nir(graph, dt=dt))


def _in_float64(module):
    """``module`` computing in float64: its weights (``.double()``) and every neuron's
    parameters (Norse keeps them in a named tuple ``p`` that ``.double()`` does not reach)."""
    module = module.double()
    for cell in module.modules():
        p = getattr(cell, "p", None)
        if hasattr(p, "_replace"):
            fields = p._asdict().items()
            cell.p = p._replace(**{k: v.double() for k, v in fields if _is_float_tensor(v)})
    return module


def _is_float_tensor(value) -> bool:
    return hasattr(value, "is_floating_point") and value.is_floating_point()


def _dtype(module):
    """The float type ``module``'s weights hold (float32 where it has none)."""
    import torch

    return next((p.dtype for p in module.parameters()), torch.float32)


def run(module, steps: np.ndarray, dt: float) -> np.ndarray:
    """:func:`step_module`'s outputs, shape ``(T, B, n_out)``, checked by :func:`guarded`:
    :class:`StepGuardTripped`, naming ``dt`` [s] (the step it was loaded at), where every
    output spiked in two successive steps."""
    return np.array(list(guarded(each_step(module, steps), dt)))


def step_module(module, steps: np.ndarray) -> np.ndarray:
    """:func:`each_step`'s outputs, shape ``(T, B, n_out)``."""
    return np.array(list(each_step(module, steps)))


def each_step(module, steps: Iterable[np.ndarray]) -> Iterator[np.ndarray]:
    """Step ``module`` once per row of ``steps`` (input spike counts, shape ``(T, B)``, or
    ``(T, B, n_in)`` for a graph of ``n_in`` inputs; or any iterable of such rows, taken one at a
    time as the steps run) from its initial state, yielding each step's outputs, shape
    ``(B, n_out)`` (1 where a neuron spiked), in the module's float type: memory for the state,
    not the steps. Torch runs each step on one thread: the graph's small products are fastest
    so (3 ms a step against 70-110 ms with two threads on a busy 2-core machine)."""
    import torch

    state, dtype = None, _dtype(module)
    for row in steps:
        x = torch.as_tensor(np.asarray(row), dtype=dtype)
        x = x[:, None] if x.ndim == 1 else x  # (B, n_in)
        with _one_thread(torch), torch.no_grad(), contextlib.redirect_stdout(io.StringIO()):
            result = module(x) if state is None else module(x, state)
        y, state = result[0], result[-1]
        yield y.reshape(x.shape[0], -1).numpy()


@contextlib.contextmanager
def _one_thread(torch):
    """Torch on one thread inside, as it was after: set and restored around each step, so that
    nothing global is held while :func:`each_step` waits between its steps."""
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        yield
    finally:
        torch.set_num_threads(threads)


def guard_check(out: np.ndarray, dt: float) -> None:
    """:func:`guarded` over a whole run's outputs ``out``, shape ``(T, B, n_out)``."""
    for _ in guarded(iter(out), dt):
        pass


def guarded(outputs: Iterator[np.ndarray], dt: float) -> Iterator[np.ndarray]:
    """``outputs`` (each ``(B, n_out)``) passed on, raising :class:`StepGuardTripped`, naming
    ``dt`` [s] (the step it ran at), where every output of a sample spiked in two successive
    steps."""
    before = None
    for out in outputs:
        every = np.all(out > 0, axis=1)  # (B,)
        if before is not None and np.any(every & before):
            tripped = np.flatnonzero(every & before).tolist()
            raise StepGuardTripped(
                f"every output spiked, in two successive steps and more, in sample(s) "
                f"{tripped}: the graph's step guard fired, so it was stepped by another dt than "
                f"the one it is written for (run at {dt!r} s; standard.json's dt is the file's)"
            )
        before = every
        yield out


@contextlib.contextmanager
def _quiet_logging():
    """Norse logs a warning per node it reads approximately; the counts say how it ran."""
    previous = logging.root.manager.disable
    logging.disable(logging.WARNING)
    try:
        yield
    finally:
        logging.disable(previous)


def main(argv: list[str], folder: Path = HERE) -> int:
    """``python load_consumer.py CONSUMER [DT]``: load ``network.nir`` in CONSUMER (at DT [s],
    which must be the file's); 0 and a line saying so, 2 and why where it is refused."""
    if not 1 <= len(argv) <= 2 or argv[0] not in CONSUMERS:
        print(f"usage: python load_consumer.py {{{'|'.join(CONSUMERS)}}} [DT]", file=sys.stderr)
        return 2
    try:
        dt = float(argv[1]) if len(argv) == 2 else None
        _, step = load(argv[0], dt, folder)
    except ValueError as exc:
        print(exc, file=sys.stderr)
        return 2
    except ImportError as exc:
        print(f"{argv[0]} needs torch, nir and {CONSUMERS[argv[0]]}: {exc}", file=sys.stderr)
        return 2
    print(f"{argv[0]} loaded network.nir at dt = {step!r} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
