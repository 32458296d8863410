"""The time step of a clocked chip as a design axis: a profile at another step, and whether the
network can be written at it.

A clocked (fixed-point) profile runs at its ``dt``; ``NAME@STEP`` (``loihi2@80us``) is the same
chip stepped every ``STEP``, accepted wherever a profile is (:func:`quantize.load_profile`). A
coarser step costs fewer neuron updates and step overheads per second of input; it is bounded by
what the chip's integers can still write:

* a **time constant** is a decay ``delta = round(2^D (1 - e^{-dt/tau}))`` of ``2^D``
  (:func:`spll_hw.model.discrete.decay_constant`): ``delta = 0`` is no decay at all (``tau`` too
  long for the step, fine steps), ``delta = 2^D`` loses the whole state every step (``tau`` too
  short, coarse steps). The chip would clamp either to another time constant;
* a **refractory period** holds ``round(t_refr / dt)`` whole steps
  (:func:`spll_hw.model.grid.refractory_steps`): 0 steps (shorter than half a step) drops it,
  more than the counter holds (``2^refractory_bits - 1``) cuts it short.

:func:`step_problems` names each of these, sPLL by sPLL; a step with any is refused by the step
ladders of ``report``, ``chips`` and ``fit`` (:func:`ladder`), which name the steps that work.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from spll_hw.model.discrete import decay_constant
from spll_hw.model.grid import refractory_steps
from spll_hw.network import Network
from spll_hw.timestep import DEFAULT_LADDER, step_label

from .analog import TAU_NAMES
from .profiles import at_step

_REFRACTORY = ("t_cco_refr", "t_tde_refr")


@dataclass(frozen=True)
class StepCheck:
    """Whether a network can be written at one step of a profile.

    Attributes:
        profile: the profile's name at that step (``loihi2@80us``).
        dt: the step [s].
        problems: one line per parameter that cannot be written, naming the sPLLs (empty: it
            can).
    """

    profile: str
    dt: float
    problems: tuple[str, ...]

    @property
    def works(self) -> bool:
        return not self.problems


def _spll_list(indices: Sequence[int]) -> str:
    shown = ", ".join(str(i) for i in indices[:6])
    return f"sPLL {shown}" + (f" and {len(indices) - 6} more" if len(indices) > 6 else "")


def step_problems(network: Network, dt: float, decay_bits: int, refractory_bits: int) -> list[str]:
    """What ``network`` loses at step ``dt`` [s] on a chip of ``decay_bits``-bit decays and a
    ``refractory_bits``-bit refractory counter (module docstring), one line per parameter and
    way it fails, naming the sPLLs; empty when every parameter can be written."""
    out = []
    for name in TAU_NAMES:
        tau = np.array([getattr(p, name) for p in network.spll], dtype=np.float64)
        delta = np.asarray(decay_constant(tau, dt, decay_bits))
        for bad, what in ((delta <= 0, "rounds to no decay (too long for the step)"),
                          (delta >= 2**decay_bits, "decays completely each step (too short "
                           "for the step)")):  # fmt: skip
            idx = np.flatnonzero(bad).tolist()
            if idx:
                out.append(
                    f"{name} = {_seconds(tau[idx[0]])} {what} on {_spll_list(idx)}: a "
                    f"{decay_bits}-bit decay at dt = {step_label(dt)}"
                )
    top = 2**refractory_bits - 1
    for name in _REFRACTORY:
        t = np.array([getattr(p, name) for p in network.spll], dtype=np.float64)
        steps = refractory_steps(t, dt)
        for bad, what in ((np.logical_and(t > 0, steps == 0), "is shorter than half a step"),
                          (steps > top, f"needs more than the {refractory_bits}-bit counter's "
                           f"{top} steps")):  # fmt: skip
            idx = np.flatnonzero(bad).tolist()
            if idx:
                out.append(
                    f"{name} = {_seconds(t[idx[0]])} {what} on {_spll_list(idx)} at "
                    f"dt = {step_label(dt)}"
                )
    return out


def _seconds(x: float) -> str:
    for unit, scale in (("s", 1.0), ("ms", 1e-3), ("us", 1e-6)):
        if x >= scale:
            return f"{x / scale:.3g} {unit}"
    return f"{x / 1e-9:.3g} ns"


def ladder(network: Network, profile, steps: Sequence[float]) -> list[StepCheck]:
    """:class:`StepCheck` of ``network`` at every step of ``steps`` [s] on the clocked
    ``profile`` (a :class:`quantize.profiles.FixedPointProfile`)."""
    return [
        StepCheck(
            at_step(profile, dt).name,
            dt,
            tuple(step_problems(network, dt, profile.decay_bits, profile.refractory_bits)),
        )  # fmt: skip
        for dt in steps
    ]


def is_stepped(profile) -> bool:
    """The profile was named at a step (``NAME@STEP``): it refuses what it cannot write."""
    return "@" in profile.name


def check_step(network: Network, profile, ladder_steps: Sequence[float] = DEFAULT_LADDER) -> None:
    """``ValueError`` when the stepped ``profile`` cannot write ``network`` at its step: the
    reasons, and which steps of ``ladder_steps`` (and its own) would."""
    problems = step_problems(network, profile.dt, profile.decay_bits, profile.refractory_bits)
    if problems:
        others = ladder(network, profile, sorted(set(ladder_steps) | {profile.dt}))
        works = [step_label(c.dt) for c in others if c.works]
        raise ValueError(
            f"{profile.name} cannot write this network: " + "; ".join(problems) + ". Steps "
            "that can: " + (", ".join(works) if works else "none of " + ", ".join(
                step_label(c.dt) for c in others)) + "."
        )  # fmt: skip
