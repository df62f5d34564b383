"""Serial ports through pyserial, imported only when a port is opened.

pyserial is optional: FreeCAD's Addon Manager does not install it, so importing this module
never fails; opening a port without pyserial raises a StreamError that says how to install it.
Every failure of the port (missing, no permission, device gone) becomes a StreamError that
names the port; a device that vanishes mid-job raises PortLost so the job can save its state.
"""
from __future__ import annotations

import contextlib
import errno
import time
from typing import Any, Protocol

from freecad_conformal.errors import StreamError

#: How long one blocking read may wait (s): short, so pause/abort requests from another
#: thread are seen within a tenth of a second, long enough not to spin the CPU.
READ_SLICE = 0.05


class PortLost(StreamError):
    """The device disappeared or the connection dropped while a job was running."""


class Link(Protocol):
    """What a protocol needs from a connection: whole lines in, bytes out."""

    name: str

    def readline(self, timeout: float) -> str | None:
        """The next line without its end, or None when nothing complete came in `timeout` s."""

    def write(self, data: bytes) -> None:
        """Send all of `data`."""

    def close(self) -> None:
        """Release the port."""


def import_pyserial() -> Any:
    """The `serial` module, or a StreamError saying how to install it."""
    try:
        import serial
    except ImportError:
        raise StreamError(
            "streaming needs the Python package 'pyserial', which FreeCAD does not include: "
            "install it into FreeCAD's Python with `pip install pyserial` "
            "(e.g. `python3 -m pip install --user pyserial`)"
        ) from None
    return serial


def _open_error(port: str, exc: BaseException) -> StreamError:
    """Turn an exception from opening `port` into a message a user can act on."""
    code = getattr(exc, "errno", None)
    text = str(exc)
    if code == errno.ENOENT or "[Errno 2]" in text:
        return StreamError(f"serial port {port} does not exist (is the machine plugged in and switched on?)")
    if code in (errno.EACCES, errno.EPERM) or "[Errno 13]" in text:
        return StreamError(
            f"no permission to open serial port {port}: add your user to the group that owns it "
            "(usually 'dialout': `sudo usermod -aG dialout $USER`, then log in again)"
        )
    if code == errno.EBUSY or "[Errno 16]" in text:
        return StreamError(f"serial port {port} is busy: another program (a printer host?) holds it")
    return StreamError(f"serial port {port} cannot be opened: {text}")


class SerialLink:
    """A pyserial port read in whole lines, with port failures turned into StreamErrors."""

    def __init__(self, port: str, baud: int = 115200) -> None:
        serial = import_pyserial()
        self.name = port
        self._serial_exception = serial.SerialException
        self._buffer = bytearray()
        try:
            self._port = serial.Serial(port, baud, timeout=READ_SLICE, write_timeout=10)
        except (serial.SerialException, OSError) as exc:
            raise _open_error(port, exc) from None

    def _lost(self, exc: BaseException) -> PortLost:
        return PortLost(f"connection to {self.name} lost: {exc}")

    def readline(self, timeout: float) -> str | None:
        deadline = time.monotonic() + timeout
        while True:
            end = self._buffer.find(b"\n")
            if end >= 0:
                raw = bytes(self._buffer[:end])
                del self._buffer[:end + 1]
                return raw.decode("ascii", errors="replace").strip("\r\x00 ")
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return None
            try:
                self._port.timeout = min(READ_SLICE, remaining)
                chunk = self._port.read(max(1, self._port.in_waiting))
            except (self._serial_exception, OSError) as exc:
                raise self._lost(exc) from None
            self._buffer.extend(chunk)

    def write(self, data: bytes) -> None:
        try:
            self._port.write(data)
        except (self._serial_exception, OSError) as exc:
            raise self._lost(exc) from None

    def close(self) -> None:
        # A device that is already gone has nothing left to release.
        with contextlib.suppress(self._serial_exception, OSError):
            self._port.close()
