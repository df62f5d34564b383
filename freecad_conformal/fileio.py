"""Safe output: a file appears whole or not at all, several files of one result appear together
or not at all, an output never replaces an input, and nothing is written into folders that do
not exist (a typo in `-o` must not create directory trees)."""
from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path
from typing import IO, Iterable, Iterator, Mapping

from freecad_conformal.errors import OutputError

#: Temporary files are `.NAME.<pid>.<random>.part` beside their target; the pid lets a later
#: run remove what a killed one left behind.
TEMP_SUFFIX = ".part"


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def clean_stale_temporaries(target: Path) -> list[Path]:
    """Remove temporary files of `target` left by runs that were killed (their pid is gone)."""
    removed = []
    for leftover in target.parent.glob(f".{target.name}.*{TEMP_SUFFIX}"):
        parts = leftover.name[len(target.name) + 2:].split(".")
        if parts and parts[0].isdigit() and not _pid_alive(int(parts[0])):
            with contextlib.suppress(OSError):
                leftover.unlink()
                removed.append(leftover)
    return removed


def check_output_path(path: str | os.PathLike, what: str = "output") -> Path:
    """The output path, refused with an OutputError when it cannot be a file we may write."""
    target = Path(path)
    if str(path) == "":
        raise OutputError(f"{what}: no file name given")
    if target.is_dir():
        raise OutputError(f"{what} {target} is a folder; give a file name")
    parent = target.parent if str(target.parent) else Path(".")
    if not parent.is_dir():
        raise OutputError(f"{what} {target}: folder {parent} does not exist")
    if not os.access(parent, os.W_OK):
        raise OutputError(f"{what} {target}: folder {parent} is not writable")
    if target.exists() and not os.access(target, os.W_OK):
        raise OutputError(f"{what} {target} exists and is not writable")
    return target


def make_output_folder(folder: str | os.PathLike) -> Path:
    """An output folder, made if missing, but only one level: a typo in `-o` must not
    create a directory tree."""
    out = Path(folder)
    if out.exists() and not out.is_dir():
        raise OutputError(f"output folder {out} is a file")
    if not out.parent.is_dir():
        raise OutputError(f"output folder {out}: its parent {out.parent} does not exist")
    try:
        out.mkdir(exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot make output folder {out}: {exc.strerror or exc}") from exc
    return out


def _same_file(a: Path, b: Path) -> bool:
    with contextlib.suppress(OSError):
        if a.exists() and b.exists():
            return os.path.samefile(a, b)
    return a.resolve() == b.resolve()


def guard_outputs(inputs: Iterable[str | os.PathLike], outputs: Mapping[str, str | os.PathLike]) -> None:
    """Refuse outputs that would replace an input or each other, or cannot be written.
    `outputs` maps a name for messages (e.g. "--png") to its path; None entries are skipped."""
    given = {name: Path(path) for name, path in outputs.items() if path is not None}
    sources = [Path(p) for p in inputs if p is not None]
    for name, path in given.items():
        check_output_path(path, name)
        for source in sources:
            if _same_file(path, source):
                raise OutputError(f"{name} {path} is the input file {source}; it would be "
                                  "overwritten. Choose another output name")
    names = list(given)
    for i, first in enumerate(names):
        for second in names[i + 1:]:
            if _same_file(given[first], given[second]):
                raise OutputError(f"{first} and {second} are the same file {given[first]}")


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike, mode: str = "w", encoding: str | None = "utf-8") -> Iterator[IO]:
    """Open a temporary file beside `path`; rename it onto `path` only if the block succeeds.
    The folder must exist; OS errors become an OutputError naming the file."""
    target = check_output_path(path)
    clean_stale_temporaries(target)
    binary = "b" in mode
    try:
        fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name}.{os.getpid()}.",
                                        suffix=TEMP_SUFFIX, dir=target.parent)
    except OSError as exc:
        raise OutputError(f"cannot write {target}: {exc.strerror or exc}") from exc
    # mkstemp creates 0600 files; give the result the permissions a plain open() would.
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp_name, 0o666 & ~umask)
    try:
        with os.fdopen(fd, mode, encoding=None if binary else encoding) as handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(tmp_name, target)
    except BaseException as exc:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp_name)
        if isinstance(exc, OSError):
            raise OutputError(f"cannot write {target}: {exc.strerror or exc}") from exc
        raise


def write_text_atomic(path: str | os.PathLike, text: str) -> None:
    with atomic_write(path, "w") as handle:
        handle.write(text)


def write_all(contents: Mapping[str | os.PathLike, str | bytes]) -> list[Path]:
    """Write several files as one result: every file goes to a temporary beside its target
    first, and only when all are written are they renamed into place; on any failure none of
    the targets is touched. Returns the paths written, in the order given."""
    staged: list[tuple[str, Path]] = []
    try:
        for path, content in contents.items():
            target = check_output_path(path)
            clean_stale_temporaries(target)
            fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name}.{os.getpid()}.",
                                            suffix=TEMP_SUFFIX, dir=target.parent)
            staged.append((tmp_name, target))
            data = content.encode("utf-8") if isinstance(content, str) else content
            with os.fdopen(fd, "wb") as handle:
                handle.write(data)
                handle.flush()
                os.fsync(handle.fileno())
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp_name, 0o666 & ~umask)
    except BaseException as exc:
        for tmp_name, _ in staged:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp_name)
        if isinstance(exc, OSError) and not isinstance(exc, OutputError):
            raise OutputError(f"cannot write {target}: {exc.strerror or exc}") from exc
        raise
    for tmp_name, target in staged:
        os.replace(tmp_name, target)
    return [target for _, target in staged]
