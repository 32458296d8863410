"""PNG figures of the golden model: one sPLL's spikes, currents and CCO rate (thesis Figure 7),
a network's TDE rates, and frequency responses (thesis Figures 8-9)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..files import save_figure
from ..result import SimulationResult
from ..simulate import Trace
from .plots import _pyplot


def plot_spll_activity(
    result: SimulationResult, inputs: np.ndarray, index: int, path: Path, window=None
) -> None:
    """Input/TDE/CCO spikes, synapse currents and potentials, and the CCO's instantaneous rate of
    sPLL ``index``. ``result`` must come from ``simulate(..., probe_times=...)`` (it carries a
    :class:`Trace`); ``window`` = (start, end) [s] limits the time axis."""
    trace: Trace = result.info["trace"]
    plt = _pyplot()
    t0, t1 = window if window is not None else (trace.times[0], trace.times[-1])
    fig, axes = plt.subplots(4, 1, figsize=(8, 8), sharex=True)
    rows = [
        (inputs, "input"),
        (result.tde_spikes[index], "TDE"),
        (result.cco_spikes[index], "CCO"),
    ]
    for k, (spikes, _) in enumerate(rows):
        axes[0].eventplot(spikes[(spikes >= t0) & (spikes <= t1)], lineoffsets=k, linelengths=0.8)
    axes[0].set_yticks(range(len(rows)), [name for _, name in rows])
    axes[0].set_title(f"sPLL {index}: spikes")
    for name, label in (("i_fac", "facilitatory"), ("i_trg", "trigger"), ("i_cco", "CCO syn.")):
        axes[1].plot(trace.times, trace[name][index], label=label)
    axes[1].set_ylabel("current [A]")
    axes[1].set_yscale("symlog", linthresh=1e-3)
    axes[1].legend(loc="upper right", fontsize=8)
    for name, label in (("v_tde", "TDE"), ("v_cco", "CCO")):
        axes[2].plot(trace.times, trace[name][index], label=label)
    axes[2].set_ylabel("potential [V]")
    axes[2].legend(loc="upper right", fontsize=8)
    cco = result.cco_spikes[index]
    if len(cco) > 1:
        axes[3].step(cco[1:], 1.0 / np.diff(cco), where="post")
    axes[3].set_ylabel("CCO rate [Hz]")
    axes[3].set_xlabel("time [s]")
    axes[3].set_xlim(t0, t1)
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    plt.close(fig)


def plot_network_rates(result: SimulationResult, frequencies: np.ndarray, path: Path) -> None:
    """TDE and CCO rate of every sPLL against its free-running frequency."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(frequencies, result.tde_rates, "o-", ms=3, label="TDE rate (feature)")
    ax.plot(frequencies, result.cco_rates, "s-", ms=3, label="CCO rate")
    ax.plot(frequencies, frequencies, "k:", lw=1, label="free-running frequency")
    ax.set_xlabel("free-running frequency of the sPLL [Hz]")
    ax.set_ylabel("rate [Hz]")
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    plt.close(fig)


def plot_frequency_response(
    input_freqs: np.ndarray, rates: np.ndarray, free_freq: float, path: Path, title: str = ""
) -> None:
    """TDE rate [Hz] against the frequency of a periodic input [Hz] (thesis Figures 8-9)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(input_freqs, rates, lw=1)
    ax.axvline(free_freq, color="k", ls=":", lw=1, label=f"free-running {free_freq:g} Hz")
    ax.set_xlabel("input frequency [Hz]")
    ax.set_ylabel("TDE rate [Hz]")
    ax.set_title(title)
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    plt.close(fig)
