"""What one tuning trial computes (thesis 2.8-2.9), with a cheap first look for pruning.

The samples are encoded once (outside); :class:`Objective` jitters every spike train ``repeats``
times with phase noise ``N(0, sigma^2)`` (the same draws for every trial, so trials differ only
by their parameters). A search space with encoder dimensions (``pacinian.model``, ...) re-encodes
the samples per trial from an :class:`Encoding` (same noise seeds). Per trial:

1. samples the parameters and builds the network (:mod:`spll_hw.tune.space`); with
   ``constraints="enforce"`` an infeasible one is pruned before any simulation;
2. step 0: simulates noise draw 0 of a stratified subset (``prune_fraction`` of every class) and
   reports its ridge CV accuracy to Optuna's pruner;
3. steps 1..R: simulates noise draw ``r - 1`` of every sample (the subset's draw-0 rates are
   reused) and reports the running mean CV accuracy; the pruner may stop after any step;
4. returns the mean over the ``R`` draws of the mean 5-fold CV accuracy (a fraction), as the
   thesis averages three classifiers.

A network the engine refuses (e.g. a neuron firing absurdly fast) is pruned with the reason in the
trial's ``error`` user attribute.
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
import os
import socket
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass

import numpy as np

from .. import backends
from ..classify import cross_validate
from ..config import NetworkConfig
from ..encoders import Encoder
from ..features.spll import spll_features
from ..network import DEFAULT_N_SPLL, DEFAULT_REFERENCE_FREQUENCY
from ..pipeline import jitter
from . import import_optuna
from .space import (
    CONSTRAINT_MODES,
    CONSTRAINTS,
    PROBE_SPLL,
    SearchSpace,
    constraint_values,
    encoder_settings,
    network_config,
)


@dataclass(frozen=True)
class ObjectiveSettings:
    """How a trial is scored.

    Attributes:
        layout: ``"vary-offset"``, ``"time-scaled"`` or ``"grouped:G"``.
        n_spll: sPLLs in the network (thesis: 50).
        reference_frequency: [Hz] where a time-scaled base sPLL runs unscaled.
        repeats: phase-noise draws per sample (thesis: 3).
        phase_noise: spike-time jitter sd [s] (thesis: 5e-4); 0 means one noiseless draw.
        folds: stratified CV folds (thesis: 5).
        alpha: ridge L2 penalty.
        seed: seed of the noise draws, the pruning subset and the CV folds.
        prune_fraction: fraction of every class simulated first (step 0); >= 1 skips step 0.
        constraints: ``"penalise"`` (TPE ranks infeasible trials last), ``"enforce"`` (prune
            them unsimulated) or ``"off"`` (the thesis's practice).
        backend: simulator of every trial's network (a spec of :mod:`spll_hw.backends`, e.g.
            ``golden-fixed-point:profile=loihi2`` to tune on a chip's own arithmetic).
    """

    layout: str = "vary-offset"
    n_spll: int = DEFAULT_N_SPLL
    reference_frequency: float = DEFAULT_REFERENCE_FREQUENCY
    repeats: int = 3
    phase_noise: float = 5e-4
    folds: int = 5
    alpha: float = 1.0
    seed: int = 0
    prune_fraction: float = 0.25
    constraints: str = "penalise"
    backend: str = "golden"

    def __post_init__(self) -> None:
        NetworkConfig(spll=PROBE_SPLL, layout=self.layout)  # raises on an unknown layout
        backends.get(self.backend)  # raises on an unknown or unavailable backend
        if self.n_spll < 1 or self.repeats < 1 or self.folds < 2:
            raise ValueError("n_spll and repeats must be >= 1 and folds >= 2")
        if not (math.isfinite(self.phase_noise) and self.phase_noise >= 0):
            raise ValueError(f"phase noise must be >= 0 s, got {self.phase_noise!r}")
        if not self.prune_fraction > 0:
            raise ValueError(f"prune fraction must be > 0, got {self.prune_fraction!r}")
        if self.constraints not in CONSTRAINT_MODES:
            raise ValueError(
                f"unknown constraints mode {self.constraints!r}; choose from {CONSTRAINT_MODES}"
            )

    @property
    def n_repeats(self) -> int:
        """Noise draws actually simulated (1 without noise: draws would be identical)."""
        return self.repeats if self.phase_noise > 0 else 1


@dataclass(frozen=True)
class Encoding:
    """What a study re-encodes when it tunes encoder parameters.

    Attributes:
        encoder: the study's encoder (with its fixed settings); a trial replaces the tuned fields.
        signals: the samples' normalised pressure, shape ``(n, L)``, in the objective's order.
        fs: sampling rate [Hz] of ``signals``.
    """

    encoder: Encoder
    signals: np.ndarray
    fs: float

    def trains(self, settings: dict) -> list[np.ndarray]:
        """Spike times [s] of every sample with the encoder's fields ``settings`` replaced."""
        encoder = dataclasses.replace(self.encoder, **settings)
        return encoder.encode(self.signals, self.fs, ids=np.arange(len(self.signals)))


def stratified_subset(labels: np.ndarray, fraction: float, minimum: int, seed: int) -> np.ndarray:
    """Sorted indices of ``ceil(fraction * count)`` (at least ``minimum``) samples per class."""
    rng = np.random.default_rng(seed)
    picks = []
    for k in np.unique(labels):
        members = np.flatnonzero(labels == k)
        take = min(members.size, max(minimum, math.ceil(fraction * members.size)))
        picks.append(rng.permutation(members)[:take])
    return np.sort(np.concatenate(picks))


def fingerprint(trains: Sequence[np.ndarray], labels: np.ndarray) -> str:
    """SHA-256 (16 hex digits) of the spike trains and labels: the data a study was tuned on."""
    digest = hashlib.sha256(np.asarray(labels, dtype=np.int64).tobytes())
    for t in trains:
        digest.update(np.int64(t.size).tobytes())
        digest.update(np.ascontiguousarray(t, dtype=np.float64).tobytes())
    return digest.hexdigest()[:16]


class Objective:
    """Callable Optuna objective (module docstring); picklable, so workers can receive it.

    Args:
        space: the search space.
        trains: encoded spike times [s] of every sample, ``n`` arrays.
        labels: class index of every sample, shape ``(n,)``.
        class_names: one name per class.
        duration: length [s] of the spike trains (:func:`~spll_hw.encoders.train_duration`).
        settings: :class:`ObjectiveSettings`.
        threads: engine threads per trial (None: all cores).
        encoding: the encoder and signals behind ``trains``; required when ``space`` tunes
            encoder parameters (they must be this encoder's).
    """

    def __init__(
        self,
        space: SearchSpace,
        trains: Sequence[np.ndarray],
        labels: np.ndarray,
        class_names: Sequence[str],
        duration: float,
        settings: ObjectiveSettings,
        threads: int | None = None,
        encoding: Encoding | None = None,
    ):
        tuned = space.encoders
        if tuned and (encoding is None or tuned != {encoding.encoder.name}):
            raise ValueError(
                f"the search space tunes parameters of encoder(s) {sorted(tuned)} but the study "
                f"encodes with {encoding.encoder.name if encoding else 'fixed spike trains'}; "
                "tune only the study's own encoder"
            )
        self.space = space
        self.encoding = encoding
        self.stop_requested = False
        self._encoded: tuple[tuple, list[list[np.ndarray]]] | None = None
        self.labels = np.asarray(labels, dtype=int)
        self.class_names = tuple(class_names)
        self.duration = float(duration)
        self.settings = settings
        self.threads = threads
        self.fingerprint = fingerprint(trains, self.labels)
        counts = np.bincount(self.labels)
        if counts.min() < settings.folds:
            raise ValueError(
                f"every class needs at least {settings.folds} samples for {settings.folds}-fold "
                f"CV; the smallest has {counts.min()}"
            )
        self.noisy = self._jitter(trains)
        self.first = None
        if settings.prune_fraction < 1:
            subset = stratified_subset(
                self.labels, settings.prune_fraction, settings.folds, settings.seed
            )
            self.first = subset if subset.size < self.labels.size else None

    def request_stop(self) -> None:
        """Make the running trial (or the next one) raise ``KeyboardInterrupt`` at its next
        chunk of samples: safe to call from a signal handler, unlike raising there."""
        self.stop_requested = True

    def _checkpoint(self, done: int = 0) -> None:
        if self.stop_requested:
            raise KeyboardInterrupt("stopped by a signal")

    def _jitter(self, trains: Sequence[np.ndarray]) -> list[list[np.ndarray]]:
        s = self.settings
        return [
            jitter(trains, s.phase_noise, self.duration, s.seed + r) for r in range(s.n_repeats)
        ]

    def draws(self, params: dict[str, float]) -> list[list[np.ndarray]]:
        """The noise draws of the spike trains a trial's ``params`` encode (:attr:`noisy`
        unless the space tunes the encoder; the last re-encoding is cached)."""
        settings = encoder_settings(self.space.complete(params))
        if not settings:
            return self.noisy
        key = tuple(sorted(settings[self.encoding.encoder.name].items()))
        if self._encoded is None or self._encoded[0] != key:
            trains = self.encoding.trains(dict(key))
            self._encoded = (key, self._jitter(trains))
        return self._encoded[1]

    def metadata(self) -> dict:
        """JSON-able description of what is scored, stored with the study."""
        return {
            "settings": asdict(self.settings),
            "n_samples": int(self.labels.size),
            "class_names": list(self.class_names),
            "duration_s": self.duration,
            "data_fingerprint": self.fingerprint,
        }

    def config(self, params: dict[str, float]) -> NetworkConfig:
        """The network of a trial's parameters (fixed dimensions filled in)."""
        s = self.settings
        full = self.space.complete(params)
        return network_config(full, s.layout, s.n_spll, s.reference_frequency, s.seed)

    def rates(
        self, config: NetworkConfig, draw: Sequence[np.ndarray], indices: np.ndarray
    ) -> np.ndarray:
        """TDE rates [Hz] of samples ``indices`` of one noise ``draw`` (of :meth:`draws`),
        shape ``(len(indices), n_spll)``."""
        trains = [draw[i] for i in indices]
        network = config.build()
        return spll_features(
            trains,
            self.duration,
            network,
            threads=self.threads,
            on_chunk=self._checkpoint,
            backend=self.settings.backend,
        )

    def score(self, features: np.ndarray, indices: np.ndarray) -> tuple[float, float]:
        """Mean and sd of the stratified CV accuracy (fractions) of ``features`` of ``indices``."""
        s = self.settings
        cv = cross_validate(
            features, self.labels[indices], self.class_names, s.folds, s.alpha, s.seed
        )
        return cv.accuracy, cv.accuracy_sd

    def __call__(self, trial) -> float:
        self._checkpoint()
        optuna = import_optuna()
        trial.set_user_attr("worker", f"{socket.gethostname()}:{os.getpid()}")
        params = self.space.suggest(trial)
        try:
            config = self.config(params)
            violations = constraint_values(config)
        except ValueError as exc:
            trial.set_user_attr("error", str(exc))
            raise optuna.TrialPruned(f"invalid network: {exc}") from None
        trial.set_user_attr("constraints", list(violations))
        if self.settings.constraints == "penalise":  # TPE ranks infeasible trials last
            for name, value in zip(CONSTRAINTS, violations, strict=True):
                trial.set_constraint(name, value)
        if self.settings.constraints == "enforce" and max(violations) > 0:
            trial.set_user_attr("error", "violates the sPLL constraints")
            raise optuna.TrialPruned("violates the sPLL constraints")
        start = time.perf_counter()
        everything = np.arange(self.labels.size)
        try:
            value = self._steps(trial, config, self.draws(params), everything, optuna)
        except ValueError as exc:  # the engine (or the encoder) refused the settings
            trial.set_user_attr("error", str(exc))
            raise optuna.TrialPruned(f"simulation failed: {exc}") from None
        finally:
            trial.set_user_attr("simulation_seconds", time.perf_counter() - start)
        return value

    def _steps(
        self, trial, config: NetworkConfig, draws: list, everything: np.ndarray, optuna
    ) -> float:
        first_rates = None
        if self.first is not None:
            first_rates = self.rates(config, draws[0], self.first)
            trial.report(self.score(first_rates, self.first)[0], 0)
            if trial.should_prune():
                raise optuna.TrialPruned("pruned on the first subset")
        accuracies, sds = [], []
        for r in range(self.settings.n_repeats):
            x = np.zeros((everything.size, config.n))
            todo = everything
            if r == 0 and first_rates is not None:
                x[self.first] = first_rates
                todo = np.setdiff1d(everything, self.first)
            x[todo] = self.rates(config, draws[r], todo)
            acc, sd = self.score(x, everything)
            accuracies.append(acc)
            sds.append(sd)
            trial.report(float(np.mean(accuracies)), r + 1)
            if r + 1 < self.settings.n_repeats and trial.should_prune():
                raise optuna.TrialPruned(f"pruned after noise draw {r + 1}")
        trial.set_user_attr("accuracy_sd", float(np.mean(sds)))
        trial.set_user_attr("repeat_accuracies", accuracies)
        return float(np.mean(accuracies))
