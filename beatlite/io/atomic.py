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
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

_MODES = ("w", "wb")


@contextlib.contextmanager
def atomic_write(
    path: str | os.PathLike[str], mode: str = "w", *, encoding: str = "utf-8", newline: str | None = "\n"
) -> Iterator[IO[Any]]:
    """Open ``path`` for writing so that it appears complete or not at all.

    Data go to a temporary file in the same folder, which is flushed,
    ``fsync``-ed and renamed over ``path`` with :func:`os.replace` when the
    ``with`` block ends normally. If the block raises, the temporary file is
    removed and an existing ``path`` is left untouched.

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
        Newline translation for text mode; ``"\\n"`` (default) writes LF on
        every platform.

    Yields
    ------
    file object
        Text or binary file to write to.
    """
    if mode not in _MODES:
        raise ValueError(f"atomic_write: mode must be one of {_MODES}, got {mode!r}")
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise FileNotFoundError(f"atomic_write: folder {folder} does not exist (writing {target})")
    fd, tmp_name = tempfile.mkstemp(dir=folder, prefix=f".{target.name}.", suffix=".tmp")
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


def _copy_mode(target: Path, tmp: Path) -> None:
    """Give the temp file the permissions of the file it replaces (``0o644`` for a new file)."""
    try:
        mode = target.stat().st_mode & 0o7777
    except FileNotFoundError:
        mode = 0o644
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
