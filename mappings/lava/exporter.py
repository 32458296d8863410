"""The ``spll_hw.exporters`` entry points of ``spll-hw export --to lava`` and ``--to
lava-standard`` (light to import: Lava and the export module load only when one runs); both
write through :mod:`mappings.lava.export` and are read back for the export check by
:mod:`mappings.lava.check`."""

from __future__ import annotations

from pathlib import Path

from spll_hw.exporters import reads_back

from . import check


@reads_back(check.read_exact)
def export_folder(network, out: str | Path, *, profile=None, dt=None) -> list[Path]:
    """lava.json + lava_<tag>.npz: parameters of spll-hw's own TDE/CCO Lava processes (float
    and fixed point; running them needs spll-hw's mappings.lava), quantization.md

    The ``spll_hw.exporters`` entry point of ``spll-hw export --to lava``: :func:`export_lava`
    plus the quantization report of ``profile`` (default ``loihi2``) at ``dt``.
    """
    import quantize
    from mappings.folder import ExportFolder

    from .export import write_lava

    profile = profile or "loihi2"
    with ExportFolder(out) as folder:
        write_lava(folder, network, dt, profile)
        chosen = quantize.load_profile(profile)
        q = quantize.quantize(network, chosen if dt is None else chosen.with_dt(dt))
        folder.text("quantization.md", f"# The network under {q.profile.name}\n\n"
                    f"{q.report_markdown()}\n")  # fmt: skip
    return folder.files


@reads_back(check.read_standard)
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
