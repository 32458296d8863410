"""The ``spll_hw.exporters`` entry point of ``spll-hw export --to lava`` (light to import: Lava
and the export module load only when it runs)."""

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
