"""Atomic output paths for the viz writers (figures, GIF/MP4, PNG, BVH helpers)."""

from __future__ import annotations

import contextlib
import os
import secrets
from collections.abc import Iterator
from pathlib import Path


@contextlib.contextmanager
def atomic_target(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` (same extension); move it onto ``path`` on success.

    The temporary file keeps the final suffix because writers such as pillow,
    ffmpeg and imageio choose the format from it. On any exception the
    temporary file is removed and ``path`` is left untouched. The parent folder
    is created when missing.

    Parameters
    ----------
    path : str or Path
        The final file.

    Yields
    ------
    Path
        Where the caller must write, e.g. ``out/.clip.1234.a1b2c3d4.tmp.gif``.
    """
    final = Path(path)
    final.parent.mkdir(parents=True, exist_ok=True)
    tmp = final.parent / f".{final.stem}.{os.getpid()}.{secrets.token_hex(4)}.tmp{final.suffix}"
    try:
        yield tmp
        if not tmp.exists():
            raise FileNotFoundError(f"the writer produced no file for {final}")
        os.replace(tmp, final)
    finally:
        with contextlib.suppress(OSError):
            tmp.unlink()
