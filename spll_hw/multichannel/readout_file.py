"""A trained spiking readout in a file (``.npz``), and back: what ``spll-hw slide --readout``
saves and ``spll-hw export --network FILE --readout FILE`` exports with the network.

A file holds the :class:`~.readout.Readout` (``weights`` ``(k, d)`` [score x s], ``bias``
``(k,)`` [score], ``class_names``, ``bits``: ``0`` for float) and what it was trained on: the
multichannel network's ``channels`` (feature order: the ``d`` TDEs are those channels' sPLLs,
in order) and each channel's input ``levels`` [the channel's raw unit] (what its signal was
divided by before encoding; the readout's weights hold only with those levels).

A :class:`~.readout.StagedReadout` is saved with every stage's ``weights`` ``(stages, k, d)``
and ``bias`` ``(stages, k)`` and their switch-on times ``starts`` ``(stages,)``, and read back as
one (``export --to nir-standard`` writes its switching in standard nodes; ``--to nir``'s
continuous-time graph has one readout and refuses it).

An integer readout saved by ``slide`` also holds ``training_loss`` ``(2,)``: the accuracy points
it loses against its float weights on the training runs and when [s]
(:func:`~.anytime.training_loss`); ``export`` refuses one that loses more than
:data:`~.anytime.READOUT_LOSS_LIMIT` (:meth:`SavedReadout.check_loss`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..files import writing
from .anytime import READOUT_LOSS_LIMIT
from .readout import Readout, StagedReadout

#: Arrays of a readout file.
KEYS = ("weights", "bias", "class_names", "bits", "channels", "levels")


@dataclass(frozen=True)
class SavedReadout:
    """A readout and the network inputs it was trained on.

    Attributes:
        readout: the readout neurons.
        channels: channel names, in feature order.
        levels: input level of each channel [its raw unit], shape ``(len(channels),)``.
        training_loss: accuracy points [%] an integer readout loses against its float weights
            on the training runs, and the time [s] into the run of that loss; ``None``: not
            measured (a float readout, or a file from before it was saved).
    """

    readout: Readout | StagedReadout
    channels: tuple[str, ...]
    levels: np.ndarray
    training_loss: tuple[float, float] | None = None

    def check_loss(self, where: str) -> None:
        """``ValueError`` (``where`` names the file) when the readout's integer weights lose
        more than :data:`~.anytime.READOUT_LOSS_LIMIT` points against its float weights on
        the training runs: they would not make the decisions its figures were measured with."""
        if self.training_loss is None or self.training_loss[0] <= READOUT_LOSS_LIMIT:
            return
        loss, t = self.training_loss
        raise ValueError(
            f"{where}: its {self.readout.bits}-bit weights decide the training recordings "
            f"{loss:.1f} points below its float weights ({t:g} s into the run, from the rates so "
            f"far); the limit is {READOUT_LOSS_LIMIT:g} points: export the 8-bit or float "
            "readout spll-hw slide --readout saved beside it (--readout-bits 8), or "
            "--allow-error to export it anyway"
        )

    def check_network(self, channels: tuple[str, ...], n_tde: int, where: str) -> None:
        """``ValueError`` (``where`` names the network) unless the readout takes the ``n_tde``
        TDEs of exactly these ``channels``, in this order."""
        if tuple(channels) != self.channels:
            raise ValueError(
                f"{where} has channels {', '.join(channels)}; the readout was trained on "
                f"{', '.join(self.channels)} (export the network it was trained with)"
            )
        d = self.readout.weights.shape[-1]  # (k, d), staged (stages, k, d)
        if d != n_tde:
            raise ValueError(
                f"the readout takes {d} TDE features, {where} has {n_tde} TDEs (export the "
                "network it was trained with)"
            )


def save_readout(path: str | Path, saved: SavedReadout) -> Path:
    """Write ``saved`` to the ``.npz`` file ``path``; returns the path."""
    path = Path(path)
    r = saved.readout
    staged = {}
    if isinstance(r, StagedReadout):
        staged = {"starts": np.asarray(r.starts, float)}
        bias = np.stack([s.bias for s in r.stages])
    else:
        bias = r.bias
    if saved.training_loss is not None:
        staged["training_loss"] = np.asarray(saved.training_loss, float)
    with writing(path) as target, open(target, "wb") as stream:
        np.savez(
            stream,
            weights=np.asarray(r.weights, float),
            bias=np.asarray(bias, float),
            class_names=np.array(r.class_names, dtype=str),
            bits=np.int64(r.bits or 0),
            channels=np.array(saved.channels, dtype=str),
            levels=np.asarray(saved.levels, float),
            **staged,
        )
    return path


def load_readout(path: str | Path) -> SavedReadout:
    """The readout in the file ``path`` (:func:`save_readout`); ``FileNotFoundError`` or
    ``ValueError`` naming the file when it is missing or not a readout file."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(
            f"{path}: no such readout file (spll-hw slide --readout saves them)"
        )
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {key: data[key] for key in KEYS}
            starts = data["starts"] if "starts" in data.files else None
            loss = data["training_loss"] if "training_loss" in data.files else None
    except (OSError, ValueError, KeyError) as exc:
        raise ValueError(f"{path}: not a readout file ({', '.join(KEYS)}): {exc}") from None
    if loss is not None:
        loss = loss.astype(float).reshape(-1)
        if loss.shape != (2,) or not np.isfinite(loss).all():
            raise ValueError(f"{path}: training_loss must be 2 finite numbers (points, time "
                             f"[s]), got {loss.tolist()}")  # fmt: skip
        loss = (float(loss[0]), float(loss[1]))
    if starts is None:
        return replace(_checked(path, arrays), training_loss=loss)
    starts = starts.astype(float).reshape(-1)
    stages = [
        _checked(path, arrays | {"weights": w, "bias": b}, f" (stage {i + 1})").readout
        for i, (w, b) in enumerate(zip(arrays["weights"], arrays["bias"], strict=False))
    ]
    if len(stages) != starts.size or arrays["bias"].shape[0] != starts.size:
        raise ValueError(f"{path}: {starts.size} stage start times for weights "
                         f"{arrays['weights'].shape} and bias {arrays['bias'].shape}")  # fmt: skip
    saved = _checked(path, arrays | {"weights": arrays["weights"][0], "bias": arrays["bias"][0]})
    try:
        staged = StagedReadout(tuple(stages), tuple(starts))
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None
    return SavedReadout(staged, saved.channels, saved.levels, loss)


def _checked(path: Path, a: dict, where: str = "") -> SavedReadout:
    """The :class:`SavedReadout` of a file's arrays (one readout's: a staged file's stage);
    ``ValueError`` naming ``path`` (and ``where`` in it) when their shapes disagree or a number
    is not finite."""
    weights, bias = a["weights"].astype(float), a["bias"].astype(float)
    names = tuple(str(c) for c in a["class_names"].reshape(-1))
    channels = tuple(str(c) for c in a["channels"].reshape(-1))
    levels = a["levels"].astype(float).reshape(-1)
    k = len(names)
    problems = []
    if weights.ndim != 2 or weights.shape[0] != k:
        problems.append(f"weights have shape {weights.shape}, expected ({k} classes, TDEs)")
    if bias.shape != (k,):
        problems.append(f"bias has shape {bias.shape}, expected ({k},) (one per class)")
    if levels.shape != (len(channels),):
        problems.append(f"{levels.size} levels for {len(channels)} channels")
    if not all(np.isfinite(x).all() for x in (weights, bias, levels)):
        problems.append("weights, bias and levels must be finite")
    if problems:
        raise ValueError(f"{path}{where}: " + "; ".join(problems))
    bits = int(a["bits"])
    return SavedReadout(Readout(weights, bias, names, bits or None), channels, levels)
