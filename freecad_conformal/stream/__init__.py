"""Streaming G-code to a machine over a serial port (Marlin or grbl), resumably.

Pure Python; pyserial is imported only when a port is opened (it is optional: FreeCAD does
not ship it). Entry point: `Streamer(load_program(path), port, ...).run()`.
"""
from freecad_conformal.stream.port import PortLost
from freecad_conformal.stream.program import Program, load_program, program_from_text
from freecad_conformal.stream.state import StreamState, load_state
from freecad_conformal.stream.streamer import StreamProgress, Streamer

__all__ = ["PortLost", "Program", "StreamProgress", "StreamState", "Streamer",
           "load_program", "load_state", "program_from_text"]
