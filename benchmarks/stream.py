"""Streaming speed: lines per second into OctoPrint's virtual printer, ours against Printrun's.

Both senders stream the same generated program (short G1 moves with line numbers and
checksums, one line in flight: the Marlin way both use) into a fresh virtual printer on a
pseudo-terminal, in the same run. The printer's dispatch log is checked, so a fast but
wrong sender would fail rather than win. Prints the ratio ours/Printrun (> 1: ours faster).

    .venv/bin/python benchmarks/stream.py [--lines 3000] [--repeats 3]
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from freecad_conformal.stream import Streamer, program_from_text  # noqa: E402
from tests.unit.streamsupport.virtual_printer import PtyPrinter  # noqa: E402

#: How long Printrun may take to see the printer online (it polls with M105).
ONLINE_TIMEOUT = 10.0


def make_program(count: int):
    # Absolute, tiny, fast moves: the virtual printer then spends almost no simulated
    # motion time per line, so the senders' own overhead is what is measured.
    lines = ["G90"] + [f"G1 X{i * 0.001:.3f} Y{(i % 17) * 0.001:.3f} F60000" for i in range(count - 1)]
    return program_from_text("\n".join(lines) + "\n", "bench.gcode")


def time_ours(program) -> float:
    printer = PtyPrinter()
    try:
        started = time.perf_counter()
        Streamer(program, printer.port).run()
        elapsed = time.perf_counter() - started
        assert printer.executed == list(program.commands), "ours: printer log differs"
        return elapsed
    finally:
        printer.close()


def printrun_sender():
    """Printrun's printcore, numbering lines from N1 instead of N0.

    printcore resets the count with `N-1 M110 N-1`, which Marlin accepts but OctoPrint's
    virtual printer cannot parse (its thread dies on the minus sign). Shifting every line
    number by one sends `N0 M110 N0` instead and changes nothing else per line.
    """
    from printrun.printcore import printcore

    class ShiftedPrintcore(printcore):
        def _send(self, command, lineno=0, calcchecksum=False):
            if calcchecksum:
                command = command.replace("M110 N-1", "M110 N0")
                lineno += 1
            super()._send(command, lineno, calcchecksum)

    return ShiftedPrintcore()


def time_printrun(program) -> float:
    from printrun import gcoder

    printer = PtyPrinter()
    core = printrun_sender()
    try:
        core.connect(printer.port, 115200)
        deadline = time.monotonic() + ONLINE_TIMEOUT
        while not core.online:
            if time.monotonic() > deadline:
                raise RuntimeError("Printrun never saw the virtual printer online")
            time.sleep(0.01)
        gcode = gcoder.LightGCode(list(program.commands))
        count_before = len(printer.executed)  # Printrun's M105 polls while connecting
        started = time.perf_counter()
        core.startprint(gcode)
        while core.printing:
            time.sleep(0.001)
        elapsed = time.perf_counter() - started
        executed = [line for line in printer.executed[count_before:] if line != "M105"]
        assert executed == list(program.commands), "Printrun: printer log differs"
        return elapsed
    finally:
        core.disconnect()
        printer.close()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lines", type=int, default=3000)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    program = make_program(args.lines)
    ours = [time_ours(program) for _ in range(args.repeats)]
    peer = [time_printrun(program) for _ in range(args.repeats)]
    ours_rate = args.lines / statistics.median(ours)
    peer_rate = args.lines / statistics.median(peer)
    print(f"virtual printer (OctoPrint {__import__('octoprint').__version__}), {args.lines} lines, "
          f"median of {args.repeats}")
    print(f"  conformal stream : {ours_rate:8.0f} lines/s")
    print(f"  Printrun printcore: {peer_rate:8.0f} lines/s")
    print(f"  ratio ours/Printrun: {ours_rate / peer_rate:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
