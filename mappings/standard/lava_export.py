"""Former module path of the ``lava-standard`` export entry point, kept for installs whose
entry-point metadata still names it: the exporter is
:func:`mappings.lava.exporter.export_standard`."""

from mappings.lava.exporter import export_standard as export_lava_standard

__all__ = ["export_lava_standard"]
