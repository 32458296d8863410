"""Former module path of the ``nir-standard`` export entry point, kept for installs whose
entry-point metadata still names it: the exporter is :func:`mappings.nir.export_standard`."""

from mappings.nir import export_standard as export_nir_standard

__all__ = ["export_nir_standard"]
