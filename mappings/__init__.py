"""Mappings of spll-hw networks onto other simulators, exchange formats and hardware links.

Each subpackage (``brian2``, ``nir``, ``usb``, ...) expresses a :class:`spll_hw.network.Network`
in another framework or on another substrate; simulator backends return the golden engine's
:class:`spll_hw.result.SimulationResult` so their spikes compare directly with the exact model.
Subpackages import their framework lazily and need the extra of the same name
(``pip install -e .[brian2]``, ...).

``standard`` is not a target but a construction: the sPLL from standard neurons only, exported
as a variant of the ``nir`` and ``lava`` targets by their own writers. Every export writes its
folder through :class:`~mappings.folder.ExportFolder`.
"""
