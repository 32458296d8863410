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

Tuning for a chip (:mod:`spll_hw.tune.chip`; the backend simulates a chip profile): a network that
does not fit the chip is pruned before any simulation (``error`` and ``fit`` user attributes);
on an analog profile every noise draw is simulated on each of ``chip_draws`` mismatch draws and
the accuracy is their mean; with a profile that models energy, the mean dynamic energy per sample
[J] (event counts × per-event costs) of a few samples per class (noise draw 0, every chip draw)
is stored as the ``energy_j`` user attribute, static power apart as ``static_energy_j``, and
with ``objectives`` such as ``("accuracy", "energy")`` the trial returns one value per objective
(a multi-objective study: no pruning, Optuna's pruners need one value).
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
from ..network import DEFAULT_N_SPLL, DEFAULT_REFERENCE_FREQUENCY
from ..pipeline import jitter
from . import import_optuna
from .chip import (
    Fit,
    backend_profile,
    check_fit,
    check_objectives,
    check_time_step,
    chip_tables,
    draw_specs,
    has_mismatch,
    parse_objectives,
    profile_kind,
    sample_energy,
)
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
            ``golden:profile=loihi2`` to tune the network as the chip realises it, or
            ``golden-fixed-point:profile=loihi2`` on the chip's own arithmetic); a backend that
            simulates a chip profile makes the study a chip study (:mod:`spll_hw.tune.chip`).
        chip_draws: mismatch draws (``chip_seed`` 0..K-1) every trial is scored on; > 1 only
            for an analog profile.
        objectives: what the study optimises, ``("accuracy",)`` or accuracy and chip costs
            (``"energy"`` [J per sample], ``"cores"``): :data:`spll_hw.tune.chip.OBJECTIVES`.
        energy_per_class: samples of every class (of noise draw 0) whose chip energy is
            averaged into a trial's energy.
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
    chip_draws: int = 1
    objectives: tuple[str, ...] = ("accuracy",)
    energy_per_class: int = 2

    def __post_init__(self) -> None:
        NetworkConfig(spll=PROBE_SPLL, layout=self.layout)  # raises on an unknown layout
        backends.get(self.backend)  # raises on an unknown or unavailable backend
        check_time_step(self.backend)
        object.__setattr__(self, "objectives", parse_objectives(self.objectives))
        check_objectives(self.objectives, self.profile)
        draw_specs(self.backend, self.chip_draws)  # raises on a bad number of chip draws
        if isinstance(self.energy_per_class, bool) or not (
            isinstance(self.energy_per_class, int) and self.energy_per_class >= 1
        ):
            raise ValueError(f"energy samples per class must be >= 1, got {self.energy_per_class}")
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

    @property
    def profile(self) -> str | None:
        """The chip profile the backend simulates (``None``: the network as given)."""
        return backend_profile(self.backend)

    @property
    def specs(self) -> tuple[str, ...]:
        """One backend spec per chip draw (:func:`spll_hw.tune.chip.draw_specs`)."""
        return draw_specs(self.backend, self.chip_draws)

    @property
    def chip_seeds(self) -> tuple[int | None, ...]:
        """The mismatch seed of every chip draw (``None``: a fixed-point profile or none)."""
        if not has_mismatch(self.profile):
            return (None,)
        return tuple(range(self.chip_draws))

    @property
    def multi_objective(self) -> bool:
        return len(self.objectives) > 1

    def stored(self) -> dict:
        """The settings as a study stores them: the fields added for chip studies only when
        they differ from their defaults, so studies from before them resume unchanged."""
        out = asdict(self)
        out["objectives"] = list(self.objectives)
        for f in dataclasses.fields(self):
            if f.name in CHIP_FIELDS and getattr(self, f.name) == f.default:
                del out[f.name]
        return out


#: Settings added for chip studies (stored only when not at their defaults).
CHIP_FIELDS = ("chip_draws", "objectives", "energy_per_class")


@dataclass(frozen=True)
class Encoding:
    """What a study re-encodes when it tunes encoder parameters.

    Attributes:
        encoder: the study's encoder (with its fixed settings); a trial replaces the tuned fields.
        signals: the samples' normalised pressure, shape ``(n, L)``, in the objective's order.
        fs: sampling rate [Hz] of ``signals``.
        ids: every sample's noise id, shape ``(n,)`` (:attr:`SampleSet.noise_ids
            <spll_hw.datasets.samples.SampleSet.noise_ids>`): a trial's noisy encoder draws
            what the study's first encoding drew.
    """

    encoder: Encoder
    signals: np.ndarray
    fs: float
    ids: np.ndarray

    def trains(self, settings: dict) -> list[np.ndarray]:
        """Spike times [s] of every sample with the encoder's fields ``settings`` replaced."""
        encoder = dataclasses.replace(self.encoder, **settings)
        return encoder.encode(self.signals, self.fs, ids=self.ids)


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
        input_level: what the signals behind ``trains`` were divided by [the dataset's raw
            unit], the level the encoder is tuned at (written into ``best.toml``).
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
        input_level: float | None = None,
    ):
        tuned = space.encoders
        if tuned and (encoding is None or tuned != {encoding.encoder.name}):
            raise ValueError(
                f"the search space tunes parameters of encoder(s) {sorted(tuned)} but the study "
                f"encodes with {encoding.encoder.name if encoding else 'fixed spike trains'}; "
                "tune only the study's own encoder"
            )
        self.encoding = encoding
        self.input_level = input_level
        self._encoded: tuple[tuple, list[list[np.ndarray]]] | None = None
        self._score_on(
            space, labels, class_names, duration, settings, threads, fingerprint(trains, labels)
        )
        self.noisy = self._jitter(trains)

    def _score_on(
        self,
        space: SearchSpace,
        labels: np.ndarray,
        class_names: Sequence[str],
        duration: float,
        settings: ObjectiveSettings,
        threads: int | None,
        data_fingerprint: str,
    ) -> None:
        """Set what every objective scores with (the arguments of :class:`Objective` apart
        from the spike trains, and the fingerprint of those): the checks, the pruning subset
        and the samples costed on a chip."""
        self.space = space
        self.stop_requested = False
        self.labels = np.asarray(labels, dtype=int)
        self.class_names = tuple(class_names)
        self.duration = float(duration)
        self.settings = settings
        self.threads = threads
        self.fingerprint = data_fingerprint
        counts = np.bincount(self.labels)
        if counts.min() < settings.folds:
            raise ValueError(
                f"every class needs at least {settings.folds} samples for {settings.folds}-fold "
                f"CV; the smallest has {counts.min()}"
            )
        self.specs = settings.specs
        self.seeds = settings.chip_seeds  # one per spec
        self.profile = settings.profile
        self.first = None
        if settings.prune_fraction < 1 and not settings.multi_objective:
            subset = stratified_subset(
                self.labels, settings.prune_fraction, settings.folds, settings.seed
            )
            self.first = subset if subset.size < self.labels.size else None
        self.costed = np.empty(0, dtype=int)
        if self.profile is not None and "energy" in chip_tables(self.profile):
            # costed on noise draw 0 (within the first subset when there is one)
            pool = self.first if self.first is not None else np.arange(self.labels.size)
            self.costed = np.sort(np.concatenate([
                pool[self.labels[pool] == k][: settings.energy_per_class]
                for k in np.unique(self.labels)
            ]))  # fmt: skip

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
        """JSON-able description of what is scored, stored with the study (a chip study adds
        its profile and the mismatch seeds of its chip draws)."""
        out = {
            "settings": self.settings.stored(),
            "n_samples": int(self.labels.size),
            "class_names": list(self.class_names),
            "duration_s": self.duration,
            "data_fingerprint": self.fingerprint,
        }
        if self.profile is not None:
            out["chip"] = {
                "profile": self.profile,
                "kind": profile_kind(self.profile),
                "chip_seeds": list(self.seeds),
                "backends": list(self.specs),
            }
        return out

    def describe_network(self) -> str:
        """What a trial's network is, for the report (layout and size)."""
        return f"{self.settings.layout}, {self.settings.n_spll} sPLLs"

    def features_per_sample(self, config: NetworkConfig) -> int:
        """Features (TDE rates) :meth:`simulate` gives a sample of ``config``'s network."""
        return config.n

    def constraints(self, config: NetworkConfig) -> tuple[float, ...]:
        """The :data:`~spll_hw.tune.space.CONSTRAINTS` of a trial's network (ratio - 1,
        feasible when <= 0; :func:`~spll_hw.tune.space.constraint_values`)."""
        return constraint_values(config)

    def config(self, params: dict[str, float]) -> NetworkConfig:
        """The network of a trial's parameters (fixed dimensions filled in)."""
        s = self.settings
        full = self.space.complete(params)
        return network_config(full, s.layout, s.n_spll, s.reference_frequency, s.seed)

    def simulate(
        self,
        config: NetworkConfig,
        draw: Sequence[np.ndarray],
        indices: np.ndarray,
        spec: str | None = None,
        keep: np.ndarray | None = None,
        duration: float | None = None,
    ) -> tuple[np.ndarray, list]:
        """TDE rates [Hz] of samples ``indices`` of one noise ``draw`` (of :meth:`draws`) on
        backend ``spec`` (default: the first chip draw's), shape ``(len(indices), n_spll)``,
        and the :class:`~spll_hw.result.SimulationResult` of every sample of ``keep`` (a
        subset of ``indices``, in the order of ``indices``). ``duration``: the spike trains'
        length [s] (default :attr:`duration`)."""
        sim = backends.get(spec or self.specs[0])
        duration = self.duration if duration is None else duration
        network = config.build()
        wanted = set() if keep is None else set(np.asarray(keep).tolist())
        out = np.zeros((len(indices), network.n_spll))
        kept = []
        for start in range(0, len(indices), sim.batch_size):
            batch = np.asarray(indices[start : start + sim.batch_size])
            trains = [np.ascontiguousarray(draw[i], dtype=float) for i in batch]
            results = sim.simulate_batch(network, trains, duration, threads=self.threads)
            out[start : start + batch.size] = [r.tde_rates for r in results]
            kept += [r for i, r in zip(batch.tolist(), results, strict=True) if i in wanted]
            self._checkpoint(batch.size)
        return out, kept

    def rates(
        self,
        config: NetworkConfig,
        draw: Sequence[np.ndarray],
        indices: np.ndarray,
        spec: str | None = None,
    ) -> np.ndarray:
        """TDE rates [Hz] of samples ``indices`` of one noise ``draw`` (of :meth:`draws`) on
        backend ``spec`` (default: the first chip draw's), shape ``(len(indices), n_spll)``."""
        return self.simulate(config, draw, indices, spec)[0]

    def score(self, features: np.ndarray, indices: np.ndarray) -> tuple[float, float]:
        """Mean and sd of the stratified CV accuracy (fractions) of ``features`` of ``indices``."""
        s = self.settings
        cv = cross_validate(
            features, self.labels[indices], self.class_names, s.folds, s.alpha, s.seed
        )
        return cv.accuracy, cv.accuracy_sd

    def fit(self, config: NetworkConfig) -> Fit:
        """Whether the network of ``config`` fits the study's chip on every chip draw
        (:func:`spll_hw.tune.chip.check_fit`; always, without a chip profile)."""
        if self.profile is None:
            return Fit((), None)
        return check_fit(config.build(), self.profile, self.seeds)

    def __call__(self, trial) -> float | tuple[float, ...]:
        self._checkpoint()
        optuna = import_optuna()
        trial.set_user_attr("worker", f"{socket.gethostname()}:{os.getpid()}")
        params = self.space.suggest(trial)
        try:
            config = self.config(params)
            violations = self.constraints(config)
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
        fit = self.fit(config)
        if not fit.fits:
            why = "; ".join(fit.problems)
            trial.set_user_attr("fit", why)
            trial.set_user_attr("error", f"does not fit {self.profile}: {why}")
            raise optuna.TrialPruned(f"does not fit {self.profile}: {why}")
        if fit.cores is not None:
            trial.set_user_attr("cores", fit.cores)
        start = time.perf_counter()
        everything = np.arange(self.labels.size)

        def step(value: float, k: int) -> None:
            if self.settings.multi_objective:
                return  # Optuna's pruners take one value: a multi-objective trial runs on
            trial.report(value, k)
            if k < self.settings.n_repeats and trial.should_prune():  # not after the last
                where = "on the first subset" if k == 0 else f"after noise draw {k}"
                raise optuna.TrialPruned(f"pruned {where}")

        try:
            scores = self.evaluate(config, self.draws(params), everything, step, trial)
        except ValueError as exc:  # the engine (or the encoder) refused the settings
            trial.set_user_attr("error", str(exc))
            raise optuna.TrialPruned(f"simulation failed: {exc}") from None
        finally:
            trial.set_user_attr("simulation_seconds", time.perf_counter() - start)
        values = scores.values(self.settings.objectives, fit)
        return values if self.settings.multi_objective else values[0]

    def evaluate(
        self,
        config: NetworkConfig,
        draws: list,
        everything: np.ndarray | None = None,
        step=None,
        trial=None,
    ) -> Scores:
        """Score the network of ``config`` on noise ``draws`` (:meth:`draws`), every chip
        draw: what a trial computes (module docstring), also for a network that is not a
        trial (a reference to compare with). ``step(value, k)`` is called with the running
        accuracy after the first subset (``k = 0``) and after every noise draw (``k = 1..R``)
        and may raise to stop; ``trial`` gets the user attributes as they are known."""
        s = self.settings
        everything = np.arange(self.labels.size) if everything is None else everything
        step = step or (lambda value, k: None)
        note = trial.set_user_attr if trial is not None else (lambda key, value: None)
        first_rates, costed = None, []
        if self.first is not None:
            first_rates, costed = self.simulate(
                config, draws[0], self.first, self.specs[0], self.costed
            )
            step(self.score(first_rates, self.first)[0], 0)
        per_draw = np.zeros((s.n_repeats, len(self.specs)))
        sds = []
        for r in range(s.n_repeats):
            for k, spec in enumerate(self.specs):
                x = np.zeros((everything.size, self.features_per_sample(config)))
                todo = everything
                if r == 0 and k == 0 and first_rates is not None:  # costed with the subset
                    x[self.first] = first_rates
                    todo = np.setdiff1d(everything, self.first)
                    x[todo] = self.rates(config, draws[r], todo, spec)
                else:
                    keep = self.costed if r == 0 else None
                    x[todo], kept = self.simulate(config, draws[r], todo, spec, keep)
                    costed += kept
                per_draw[r, k], sd = self.score(x, everything)
                sds.append(sd)
            step(float(per_draw[: r + 1].mean()), r + 1)
        energy = None
        if costed:
            seeds = [seed for seed in self.seeds for _ in range(self.costed.size)]
            energy = sample_energy(config.build(), self.profile, costed, seeds[: len(costed)])
        scores = Scores(
            accuracy=float(per_draw.mean()),
            accuracy_sd=float(np.mean(sds)),
            repeat_accuracies=tuple(float(a) for a in per_draw.mean(axis=1)),
            chip_accuracies=tuple(float(a) for a in per_draw.mean(axis=0)),
            energy=energy.dynamic if energy else None,
            static_energy=energy.static if energy else None,
        )
        for key, value in scores.user_attrs().items():
            note(key, value)
        return scores


@dataclass(frozen=True)
class Scores:
    """What a network scored (:meth:`Objective.evaluate`).

    Attributes:
        accuracy: mean CV accuracy over noise and chip draws (fraction).
        accuracy_sd: mean over draws of the sd of the fold accuracies (fraction).
        repeat_accuracies: mean over chip draws, per noise draw, shape ``(R,)``.
        chip_accuracies: mean over noise draws, per chip draw, shape ``(K,)``.
        energy: mean dynamic energy per sample on the chip [J]: event counts × per-event
            costs, no static power (``None``: no energy model).
        static_energy: mean static and core power × the window per sample [J] (the sample's
            duration, or the time on chip where the chip cannot keep up), apart (``None``: not
            modelled).
    """

    accuracy: float
    accuracy_sd: float
    repeat_accuracies: tuple[float, ...]
    chip_accuracies: tuple[float, ...]
    energy: float | None = None
    static_energy: float | None = None

    def values(self, objectives: Sequence[str], fit: Fit) -> tuple[float, ...]:
        """The value of every objective (accuracy fraction, energy [J], cores)."""
        known = {"accuracy": self.accuracy, "energy": self.energy, "cores": fit.cores}
        missing = [n for n in objectives if known[n] is None]
        if missing:
            raise RuntimeError(f"objective(s) {missing} were not computed")
        return tuple(float(known[n]) for n in objectives)

    def user_attrs(self) -> dict:
        """The trial's user attributes: ``accuracy_sd``, ``repeat_accuracies``, and
        ``chip_accuracies`` (several chip draws), ``energy_j`` (dynamic) and
        ``static_energy_j`` (an energy model)."""
        out = {"accuracy_sd": self.accuracy_sd, "repeat_accuracies": list(self.repeat_accuracies)}
        if len(self.chip_accuracies) > 1:
            out["chip_accuracies"] = list(self.chip_accuracies)
        if self.energy is not None:
            out["energy_j"] = self.energy
            out["static_energy_j"] = self.static_energy
        return out
