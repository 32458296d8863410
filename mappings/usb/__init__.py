"""Stream spikes to and from a USB-attached sPLL board (pyusb; the ``[usb]`` extra).

- :mod:`.wire`: the versioned AER wire format (framed, CRC-checked event packets).
- :mod:`.protocol`: the control protocol (GET_INFO, RESET, LOAD, START, STOP, COUNTERS).
- :mod:`.link`: :class:`UsbLink`, the host side on pyusb, with its errors.
- :mod:`.image`: the fixed-point image LOAD carries (``quantize``'s integer parameters) and the
  emulator's core on the Rust fixed-point reference.
- :mod:`.emulator`: a board emulator that plugs into pyusb as a backend (CI without hardware).
- :mod:`.backend`: :func:`simulate_usb`, the ``usb`` backend of ``spll-hw compare``.

Only :mod:`.link` and :mod:`.emulator` need pyusb, imported when a link opens; a missing pyusb is
reported with the extra to install.
"""

from . import link
from .backend import simulate_usb
from .link import *  # noqa: F403 - the link's public names, listed once in link.__all__
from .wire import VERSION, WireError

__all__ = [*link.__all__, "VERSION", "WireError", "simulate_usb"]
