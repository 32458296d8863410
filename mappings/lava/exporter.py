"""The ``spll_hw.exporters`` entry points of ``spll-hw export --to lava`` and ``--to
lava-standard`` (light to import: Lava and the export module load only when one runs); both
write through :mod:`mappings.lava.export`."""

from __future__ import annotations

from pathlib import Path


def export_folder(network, out: str | Path, *, profile=None, dt=None) -> list[Path]:
    """lava.json + lava_<tag>.npz: parameters of spll-hw's own TDE/CCO Lava processes (float
    and fixed point; running them needs spll-hw's mappings.lava), quantization.md

    The ``spll_hw.exporters`` entry point of ``spll-hw export --to lava``: :func:`export_lava`
    plus the quantization report of ``profile`` (default ``loihi2``) at ``dt``.
    """
    import quantize

    from .export import export_lava

    profile = profile or "loihi2"
    files = export_lava(network, out, dt=dt, profile=profile)
    chosen = quantize.load_profile(profile)
    q = quantize.quantize(network, chosen if dt is None else chosen.with_dt(dt))
    report = Path(out) / "quantization.md"
    report.write_text(f"# The network under {q.profile.name}\n\n{q.report_markdown()}\n")
    return [*files, report]


def export_standard(network, out: str | Path, *, profile=None, dt=None) -> list[Path]:
    """params.npz, run.py (lava-nc and numpy only: python run.py spikes.npy 1.0 prints TDE and
    CCO counts as JSON), lava_compat.py: the standard sPLL on Lava's own LIF and Dense.

    The ``spll_hw.exporters`` entry point of ``spll-hw export --to lava-standard``. ``dt`` [s]
    defaults to 10 µs; the integers are Loihi's own formats, so ``profile`` does not apply and
    raises ``ValueError``. Writing needs no lava-nc.
    """
    if profile is not None:
        raise ValueError("lava-standard export uses Loihi's own number formats: drop --profile")
    from .export import write_standard
    from .standard import DEFAULT_DT, lava_standard

    return write_standard(lava_standard(network, dt=DEFAULT_DT if dt is None else float(dt)), out)
