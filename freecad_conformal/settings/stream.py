"""Settings of streaming a program to a machine (`stream` command, the GUI's Stream panel).
They belong to a connection, not a document: flags and panel fields only (prop "")."""
from __future__ import annotations

from freecad_conformal.settings.schema import Setting

PROTOCOLS = ("marlin", "grbl")
#: Serial speeds the panel offers first (any positive whole number is accepted).
COMMON_BAUDS = (115200, 250000, 57600, 9600)

STREAM_SETTINGS: tuple[Setting, ...] = (
    Setting("port", "text", "/dev/ttyUSB0", "port", "serial port, e.g. /dev/ttyUSB0 or COM3",
            group="connection", prop="", required=True),
    Setting("baud", "int", COMMON_BAUDS[0], "speed (baud)", "serial speed",
            group="connection", prop="", minimum=1),
    Setting("protocol", "choice", PROTOCOLS[0], "protocol",
            "marlin: line numbers, checksums, ok/resend (RepRap firmwares); grbl: character "
            "counting (grbl, grblHAL)", group="connection", prop="", choices=PROTOCOLS),
)
