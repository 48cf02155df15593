"""Atomic file writing: a reader never sees a half-written file.

Usage (skipped by the doctests: it writes ``out.txt`` in the current folder):

>>> with atomic_write("out.txt") as f:  # doctest: +SKIP
...     f.write("hello\\n")

Not taught in a notebook: every writer of :mod:`beatlite.io` uses it (``docs/architecture.md``, Conventions).
"""

from __future__ import annotations

import contextlib
import gzip
import io
import os
import re
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

_MODES = ("w", "wb")


@contextlib.contextmanager
def atomic_write(
    path: str | os.PathLike[str], mode: str = "w", *, encoding: str = "utf-8", newline: str | None = "\n"
) -> Iterator[IO[Any]]:
    r"""Open ``path`` for writing so that it appears complete or not at all.

    Data go to a temporary file ``.{name}.{pid}.*.tmp`` in the same folder, which
    is flushed, ``fsync``-ed and renamed over ``path`` with :func:`os.replace` when
    the ``with`` block ends normally. If the block raises, the temporary file is
    removed and an existing ``path`` is left untouched. Temporary files of ``path``
    left by a process that was killed mid-write are removed first
    (:func:`remove_stale_temps`).

    Parameters
    ----------
    path : str or PathLike
        Destination. A ``.gz`` suffix gzips the content (deterministic: the
        gzip header stores no name and mtime 0).
    mode : {"w", "wb"}
        Text (``"w"``) or binary (``"wb"``).
    encoding : str
        Text encoding (text mode only).
    newline : str or None
        Newline translation for text mode; ``"\n"`` (default) writes LF on
        every platform.

    Yields
    ------
    file object
        Text or binary file to write to.

    Examples
    --------
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "notes.txt"
    >>> with atomic_write(path) as f:
    ...     _ = f.write("complete or not at all\n")
    >>> path.read_text()
    'complete or not at all\n'
    >>> try:
    ...     with atomic_write(path) as f:
    ...         _ = f.write("half a line")
    ...         raise RuntimeError("killed mid-write")
    ... except RuntimeError:
    ...     pass
    >>> path.read_text(), sorted(p.name for p in Path(tmp.name).iterdir())  # old content, no temp file left
    ('complete or not at all\n', ['notes.txt'])
    >>> tmp.cleanup()
    """
    if mode not in _MODES:
        raise ValueError(f"atomic_write: mode must be one of {_MODES}, got {mode!r}")
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise FileNotFoundError(f"atomic_write: folder {folder} does not exist (writing {target})")
    remove_stale_temps(target)
    fd, tmp_name = tempfile.mkstemp(dir=folder, prefix=f".{target.name}.{os.getpid()}.", suffix=".tmp")
    tmp = Path(tmp_name)
    raw = os.fdopen(fd, "wb")
    gz: gzip.GzipFile | None = None
    text: io.TextIOWrapper | None = None
    try:
        binary: IO[bytes] = raw
        if target.name.endswith(".gz"):
            gz = gzip.GzipFile(filename="", mode="wb", fileobj=raw, mtime=0)
            binary = gz  # type: ignore[assignment]
        if mode == "w":
            text = io.TextIOWrapper(binary, encoding=encoding, newline=newline)  # type: ignore[arg-type]
            yield text
            text.flush()
            text.detach()  # keep the binary stream open: it is closed below
            text = None
        else:
            yield binary
        if gz is not None:
            gz.close()  # writes the gzip trailer; leaves raw open
            gz = None
        raw.flush()
        os.fsync(raw.fileno())
        raw.close()
        _copy_mode(target, tmp)
        os.replace(tmp, target)
        _fsync_dir(folder)
    except BaseException:
        # close wrappers first so that their finalizers do not write to a closed file later
        for stream in (text, gz, raw):
            if stream is not None:
                with contextlib.suppress(Exception):
                    stream.close()
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise


def write_json(path: str | os.PathLike[str], data: Any, *, indent: int = 1) -> Path:
    """Write ``data`` as JSON text (a newline at the end) to ``path`` with :func:`atomic_write`, creating its
    folders: the benchmarks' records, rewritten after every row, so a run stopped mid-write keeps its last whole one.

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    >>> import json, tempfile
    >>> out = write_json(Path(tempfile.mkdtemp()) / "records" / "r.json", {"rows": [1, 2]})
    >>> json.loads(out.read_text()), out.read_text().endswith("\\n")
    ({'rows': [1, 2]}, True)
    """
    import json

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_write(path) as f:
        f.write(json.dumps(data, indent=indent) + "\n")
    return path


def _umask() -> int:
    """The process's umask, read without changing it where the system tells it (Linux ``/proc``)."""
    with contextlib.suppress(OSError, ValueError):
        with open("/proc/self/status", encoding="ascii", errors="replace") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    mask = os.umask(0o022)  # elsewhere: set and restore (briefly process-wide)
    os.umask(mask)
    return mask


def _copy_mode(target: Path, tmp: Path) -> None:
    """Give the temp file the permissions of the file it replaces; a new file gets ``0o666 & ~umask`` (what
    ``open`` would give it: ``0o644`` under the usual umask 022, ``0o600`` under 077)."""
    try:
        mode = target.stat().st_mode & 0o7777
    except FileNotFoundError:
        mode = 0o666 & ~_umask()
    with contextlib.suppress(OSError):
        os.chmod(tmp, mode)


def _fsync_dir(folder: Path) -> None:
    """Best-effort fsync of the folder so the rename itself is durable (POSIX only)."""
    if os.name != "posix":
        return
    with contextlib.suppress(OSError):
        dfd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(dfd)
        finally:
            os.close(dfd)


STALE_AGE_S = 24 * 3600.0  # where process ids cannot be checked, a temp file this old is stale


def _process_alive(pid: int) -> bool:
    """Whether process ``pid`` exists on this machine (POSIX); elsewhere assume it does."""
    if os.name != "posix":
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # PermissionError: it exists, owned by someone else
        return True
    return True


def remove_stale_temps(path: str | os.PathLike[str]) -> list[Path]:
    """Remove the temporary files of ``path`` that a killed writer left behind.

    A temp file ``.{name}.{pid}.{random}.tmp`` (exactly: not a sibling ``{name}.{digits}``'s) is stale when process ``pid`` no longer exists
    (or, where that cannot be checked, when it is older than a day). Temp files of live
    writers are left alone.

    Returns
    -------
    list of Path
        The files removed.

    Examples
    --------
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "notes.txt"
    >>> stale = Path(tmp.name) / ".notes.txt.999999999.abc.tmp"  # left by a process that no longer exists
    >>> _ = stale.write_text("partial")
    >>> [p.name for p in remove_stale_temps(path)], stale.exists()
    (['.notes.txt.999999999.abc.tmp'], False)
    >>> tmp.cleanup()
    """
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    removed = []
    # exactly what atomic_write names its temp files (mkstemp's random part has no dot): the temp file of a
    # sibling target named "<name>.<digits>" (".<name>.<digits>.<pid>.<random>.tmp") is not this target's
    own = re.compile(rf"\.{re.escape(target.name)}\.([0-9]+)\.[A-Za-z0-9_]+\.tmp", re.ASCII)
    with contextlib.suppress(OSError):
        for cand in folder.iterdir():
            match = own.fullmatch(cand.name)
            if match is None or int(match.group(1)) == os.getpid():
                continue
            pid_text = match.group(1)
            try:
                age = time.time() - cand.stat().st_mtime
            except OSError:
                continue
            if not _process_alive(int(pid_text)) or (os.name != "posix" and age > STALE_AGE_S):
                with contextlib.suppress(OSError):
                    cand.unlink()
                    removed.append(cand)
    return removed


@contextlib.contextmanager
def exclusive_lock(path: str | os.PathLike[str], *, wait: bool = True) -> Iterator[None]:
    """Hold an exclusive advisory lock (``flock``) on ``path`` (created if needed) for the ``with`` block.

    Processes that prepare the same thing (``retrain-all --jobs 2`` and ``torchrun`` start several,
    each building the same window store or FGD extractor) take turns: the first does the work, the
    others wait, then find it done. Waiting has no time limit and happens outside any collective of
    ``torch.distributed`` (whose barriers time out after 30 minutes). The lock is released when the
    block ends or the process dies. POSIX only; elsewhere (Windows) the block runs unlocked.

    With ``wait=False`` a lock that another holder has raises ``BlockingIOError`` at once instead (what
    ``fit`` does when another run trains the same recipe into the same ``--out``). An existing lock file in a
    folder that cannot be written (read-only media) is opened read-only: ``flock`` needs no write access.

    Examples
    --------
    >>> tmp = tempfile.TemporaryDirectory()
    >>> lock = Path(tmp.name) / "store.lock"
    >>> with exclusive_lock(lock):  # other processes taking this lock wait here
    ...     lock.exists()
    True
    >>> tmp.cleanup()
    """
    try:
        import fcntl
    except ImportError:  # Windows: no advisory locks in the standard library
        yield
        return
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    try:
        f = open(path, "a+b")
    except OSError:  # a read-only folder (a store on read-only media): an existing lock is taken read-only
        if not Path(path).is_file():
            raise
        f = open(path, "rb")
    with f:
        fcntl.flock(f.fileno(), fcntl.LOCK_EX if wait else fcntl.LOCK_EX | fcntl.LOCK_NB)
        try:
            yield
        finally:
            fcntl.flock(f.fileno(), fcntl.LOCK_UN)
