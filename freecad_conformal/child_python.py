"""One request answered in a child Python on the other core (`python -m MODULE`).

The child starts (interpreter, FreeCAD, the modules it preloads) when the `ChildPython` is
made, so that it is ready by the time the parent knows what to ask. The request and the
answer cross as pickles on the child's stdin and stdout; shapes travel inside them in OCC's
binary format (geometry/occ_binary.py: bit for bit, so the child computes on the very
solid the parent holds). A child is a fresh interpreter, not a fork: OCC's thread pool,
once started in the parent, deadlocks a forked child in its next Boolean (seen in
`generalFuse` under pytest). Used only outside FreeCAD's GUI and with two or more cores
(`can_start_child`); the caller computes in place otherwise, or when the child dies.
"""
from __future__ import annotations

import multiprocessing
import os
import pickle
import subprocess
import sys
import threading
from pathlib import Path
from typing import Callable

from freecad_conformal import ADDON_ROOT
from freecad_conformal.freecad_env import import_freecad


def can_start_child() -> bool:
    """Whether a child Python may compute here: not with one core, not in a process that is
    itself a worker of a pool (batch's already fills the cores, and stops a part's process
    without its children), not in FreeCAD's GUI or an embedded interpreter."""
    if (os.cpu_count() or 1) < 2:
        return False
    if multiprocessing.parent_process() is not None:
        return False
    if not Path(sys.executable).name.lower().startswith("python"):
        return False  # embedded (FreeCADCmd): no interpreter to start the child with
    App, _ = import_freecad()
    return not getattr(App, "GuiUp", False)


#: Bytes of the length that precedes each item `serve_items` sends.
FRAME_HEADER = 8

#: What unpickling an answer may raise besides the pickle module's own errors: a class the
#: parent cannot import (ImportError, AttributeError), or one whose pickle does not rebuild
#: it (TypeError: an exception with arguments of its own and no `__reduce__`). The caller
#: then computes in place, as when the child died.
UNREADABLE = (pickle.UnpicklingError, EOFError, AttributeError, ImportError, ValueError,
              TypeError)


def can_stream() -> bool:
    """Whether a child's items can be read without waiting (`ChildPython.received`): a pipe
    set non-blocking, which Windows' Python before 3.12 cannot do."""
    return os.name == "posix"


class ChildPython:
    """`python -m module` started now: `ask()` sends the one request (or its parts, for a
    child serving with `serve_prepared`), `answer()` waits for (ok, value), or `received()`
    collects the items a child serving with `serve_items` sends as it goes; `stop()` ends
    it (also unasked)."""

    def __init__(self, module: str) -> None:
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(
            [str(ADDON_ROOT)] + ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
        try:
            # In the addon's folder: `-m` puts the working folder first on the path, and
            # another copy of the package there (a user's checkout) would answer instead.
            self._process = subprocess.Popen([sys.executable, "-m", module],
                                             stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                             env=env, cwd=str(ADDON_ROOT))
        except OSError:
            self._process = None  # no interpreter to start: answer() says so
        self._buffer: bytearray | None = None  # what `received` has read, not yet whole
        self._writer: threading.Thread | None = None

    def ask(self, request, last: bool = True) -> None:
        """Send the request (picklable) and, when it is the `last` part, close the child's
        input. A thread writes it: a request larger than a pipe holds (the stacks of a
        plan's layers) would otherwise hold this process until the child, still starting,
        reads it. Parts go in the order asked."""
        if self._process is None:
            return
        data = pickle.dumps(request, protocol=pickle.HIGHEST_PROTOCOL)
        before = self._writer
        self._writer = threading.Thread(target=self._write, args=(data, last, before),
                                        daemon=True)
        self._writer.start()

    def _write(self, data: bytes, last: bool, before: threading.Thread | None) -> None:
        if before is not None:
            before.join()
        try:
            self._process.stdin.write(data)
            self._process.stdin.flush()
        except (OSError, ValueError):
            pass  # the child died or was stopped (BrokenPipe, or its pipe closed already):
            # answer() sees its exit code
        if not last:
            return
        try:
            self._process.stdin.close()
        except OSError:
            pass  # same: nothing left to flush to

    def answer(self) -> tuple[bool, object] | None:
        """(True, value) or (False, the error it raised); None when the child gave no
        answer (it did not start, or died): the caller then computes in place."""
        if self._process is None:
            return None
        data = self._process.stdout.read()
        self._process.stdout.close()
        code = self._process.wait()
        if code != 0 or not data:
            return None
        try:
            ok, value = pickle.loads(data)
        except UNREADABLE:
            return None
        return bool(ok), value

    def received(self) -> list:
        """The items a child serving with `serve_items` has sent since the last call, without
        waiting (an item still crossing the pipe comes with a later call)."""
        if self._process is None:
            return []
        fd = self._process.stdout.fileno()
        if self._buffer is None:
            self._buffer = bytearray()
            os.set_blocking(fd, False)
        while True:
            try:
                chunk = os.read(fd, 1 << 20)
            except BlockingIOError:
                break
            except OSError:
                chunk = b""
            if not chunk:
                break  # the child ended: what it sent is all there is
            self._buffer += chunk
        items = []
        while len(self._buffer) >= FRAME_HEADER:
            size = int.from_bytes(self._buffer[:FRAME_HEADER], "little")
            if len(self._buffer) < FRAME_HEADER + size:
                break
            try:
                items.append(pickle.loads(self._buffer[FRAME_HEADER:FRAME_HEADER + size]))
            except UNREADABLE:
                self._buffer.clear()  # garbled: nothing after it can be trusted
                break
            del self._buffer[:FRAME_HEADER + size]
        return items

    def stop(self) -> None:
        """End the child (its answer is not needed)."""
        if self._process is None:
            return
        if self._process.poll() is None:
            self._process.kill()
        self._process.wait()
        if self._writer is not None:
            self._writer.join()   # its write fails at once on the dead child's pipe
        for stream in (self._process.stdin, self._process.stdout):
            try:
                stream.close()
            except OSError:
                pass  # a pipe the killed child left unread


def _request(preload: Callable[[], None] | None):
    """Child side: (the parent's pipe for the answer, the request), or None when the parent
    closed its input unasked (not needed after all). Anything FreeCAD prints from here on
    goes to stderr, not into the answer; `preload()` runs while the parent decides."""
    out = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)
    if preload is not None:
        preload()
    try:
        return out, pickle.load(sys.stdin.buffer)
    except EOFError:
        return None


def serve(compute: Callable[[object], object], preload: Callable[[], None]) -> None:
    """Child side: `preload()` while the parent decides, then read the request on stdin and
    write (True, compute(request)) or (False, the error) on stdout. An error that is not the
    package's own travels as a GeometryError naming it."""
    asked = _request(preload)
    if asked is None:
        return
    out, request = asked
    _answer(out, compute, request)


def _answer(out, compute: Callable[[object], object], request) -> None:
    """Write (True, compute(request)) or (False, the error) on the parent's pipe `out`."""
    try:
        answer = (True, compute(request))
    except Exception as exc:  # sent to the parent, which raises it
        from freecad_conformal.errors import ConformalError, GeometryError

        error = exc if isinstance(exc, ConformalError) else GeometryError(
            f"{compute.__name__} failed in the child: {type(exc).__name__}: {exc}")
        answer = (False, error)
    pickle.dump(answer, out)
    out.close()


def serve_prepared(prepare: Callable[[object], object], compute: Callable[[object, object], object],
                   preload: Callable[[], None]) -> None:
    """Child side of a request sent in two parts (`ChildPython.ask(first, last=False)`, then
    `ask(second)`): `prepare(first)` runs while the parent decides the second part, then
    (True, compute(prepared, second)) or (False, the error) is written, as `serve` does.
    The child just stops when the parent closes its input after the first part."""
    asked = _request(preload)
    if asked is None:
        return
    out, first = asked
    try:
        prepared = (True, prepare(first))
    except Exception as exc:  # noqa: BLE001 - answered once the second part has come
        prepared = (False, exc)
    try:
        second = pickle.load(sys.stdin.buffer)
    except EOFError:
        return   # not needed after all

    def computed(request):
        ok, value = prepared
        if not ok:
            raise value
        return compute(value, request)

    computed.__name__ = compute.__name__
    _answer(out, computed, second)


def serve_items(compute: Callable[[object, Callable[[object], None]], None],
                preload: Callable[[], None] | None = None) -> None:
    """Child side of `ChildPython.received`: read the request on stdin, then
    `compute(request, send)`, each `send(item)` written at once. The child just stops on
    an error: its parent does the work it did not send (and meets the error there), and
    stops it when it no longer needs it (a closed pipe)."""
    asked = _request(preload)
    if asked is None:
        return
    out, request = asked

    def send(item) -> None:
        data = pickle.dumps(item, protocol=pickle.HIGHEST_PROTOCOL)
        out.write(len(data).to_bytes(FRAME_HEADER, "little") + data)
        out.flush()

    try:
        compute(request, send)
    except Exception:  # noqa: BLE001 - the parent does what is left (see above)
        return
