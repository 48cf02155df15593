"""Reading and writing BVH motion files (``.bvh`` or ``.bvh.gz``).

The HIERARCHY is parsed token by token (it is a few hundred lines); the
MOTION block, which holds almost all of the bytes (16 MB for one minute of
BEAT at 120 fps), is parsed in one vectorised call (:func:`numpy.loadtxt` on
the raw bytes, which also checks that every row has the same number of
values). Only when that fails does a slow per-line pass run, to name the line
and column that is wrong.

Frame rates: ``Frame Time`` is printed with few digits (BEAT writes
``0.008333``), so the reader snaps it to an integer frame rate when
``1/n`` agrees with the printed value to within one unit of its last digit
(``0.008333`` -> 120.0, ``0.0333333`` -> 30.0). Real BEAT files sometimes carry a
wrong Frame Time (docs/reference_code.md#bvh-header); pass ``fps=`` to override it.

Frame rates that lie: derived BEAT files keep the 120 fps header (``Frames: 7669``,
``Frame Time: 0.008333``) over rows written at 15 fps (957 rows). When ``Frames``
and the row count differ by a clean integer factor ``k`` (within 1 %),
:func:`read_bvh` reads the rows at ``header_fps / k`` (or ``* k``) so that the
header duration is kept, and says so in one :class:`BVHWarning` naming both
readings and the override (:func:`infer_row_rate`).

Units: beatlite works in centimetres. ``units="auto"`` warns when the rest pose
is under :data:`METRE_EXTENT` units tall (a skeleton in metres, e.g. SMPL-X
exports); ``units="m"`` or ``"mm"`` converts offsets and position channels to cm.

Taught in notebooks/01_beat_formats.ipynb, sections 2 (the BVH file) and 3 (reading the motion); writing in notebooks/08_visualisation_3d.ipynb, section 6 (export to Blender: BVH).
"""

from __future__ import annotations

import dataclasses
import io
import math
import os
import re
import warnings
from decimal import Decimal, InvalidOperation
from pathlib import Path
from typing import IO

import numpy as np

from beatlite.io.atomic import atomic_write
from beatlite.io.errors import BVHWarning, FormatError
from beatlite.io.motion import Motion
from beatlite.io.textfile import describe_bytes, open_binary
from beatlite.skeleton.core import POSITION_CHANNELS, ROTATION_CHANNELS, Skeleton

__all__ = [
    "read_bvh",
    "read_bvh_header",
    "write_bvh",
    "parse_frame_time",
    "format_frame_time",
    "infer_row_rate",
    "UNITS",
]

CHANNEL_NAMES = POSITION_CHANNELS + ROTATION_CHANNELS
_CHANNEL_LOOKUP = {c.lower(): c for c in CHANNEL_NAMES}
_FRAMES_RE = re.compile(r"^\s*Frames\s*:\s*(\S+)\s*$", re.IGNORECASE)
_FRAME_TIME_RE = re.compile(r"^\s*Frame\s+Time\s*:\s*(\S+)\s*$", re.IGNORECASE)
_MAX_HEADER_LINES = 200_000
#: Accepted ``Frame Time`` range in seconds (100 kHz .. 1 fps; resampling to 15 fps stays bounded).
FRAME_TIME_RANGE = (1e-5, 1.0)
#: The frame rates, frames per second, that :data:`FRAME_TIME_RANGE` allows (1 .. 100,000 fps).
FRAME_RATE_RANGE = (1.0 / FRAME_TIME_RANGE[1], 1.0 / FRAME_TIME_RANGE[0])
#: Largest integer factor between ``Frames`` and the row count that :func:`infer_row_rate` accepts.
MAX_RATE_FACTOR = 16
#: ``units=`` values of :func:`read_bvh` and their factor to centimetres.
UNITS = {"auto": 1.0, "cm": 1.0, "m": 100.0, "mm": 0.1}
#: A rest pose less tall than this (in file units) looks like metres to ``units="auto"``.
METRE_EXTENT = 5.0


# ----------------------------------------------------------------------------- frame time


def parse_frame_time(text: str) -> float:
    """Frames per second from a printed ``Frame Time`` value (seconds).

    If an integer ``n`` has ``1/n`` within one unit of the last printed digit
    of ``text``, the rate is exactly ``n`` (``"0.008333"`` -> ``120.0``,
    ``"0.066667"`` -> ``15.0``); otherwise it is ``1 / float(text)``, snapped
    to the shortest decimal (at most 9 decimals) within 4 ulps, so that
    ``1 / (1 / 29.97)`` reads as ``29.97``.

    Parameters
    ----------
    text : str
        The value as written, e.g. ``"0.008333"`` or ``"3.33333e-2"``.

    Returns
    -------
    float
        Frames per second (positive).

    Raises
    ------
    ValueError
        If ``text`` is not a positive finite number.

    Examples
    --------
    >>> parse_frame_time("0.008333"), parse_frame_time("0.066667")
    (120.0, 15.0)
    >>> parse_frame_time("0.0333667000333667")  # 1 / 29.97 as printed
    29.97
    """
    try:
        dec = Decimal(text.strip())
    except InvalidOperation:
        raise ValueError(f"frame time {text!r} is not a number") from None
    frame_time = float(dec)
    if not math.isfinite(frame_time) or frame_time <= 0:
        raise ValueError(f"frame time must be a positive number of seconds, got {text!r}")
    if not FRAME_TIME_RANGE[0] <= frame_time <= FRAME_TIME_RANGE[1]:
        raise ValueError(
            f"frame time {text!r} s is outside {FRAME_TIME_RANGE[0]:g}..{FRAME_TIME_RANGE[1]:g} s"
        )
    exponent = dec.as_tuple().exponent
    unit = 10.0 ** int(exponent) if isinstance(exponent, int) else 0.0
    n = round(1.0 / frame_time)
    if n >= 1 and abs(1.0 / n - frame_time) <= unit * (1 + 1e-9):
        return float(n)
    fps = 1.0 / frame_time
    # 1/(1/29.97) is 29.969999999999995: snap to the shortest decimal within 4 ulps
    tolerance = 4 * math.ulp(fps)
    for decimals in range(1, 10):
        snapped = round(fps, decimals)
        if abs(snapped - fps) <= tolerance:
            return snapped
    return fps


def format_frame_time(fps: float) -> str:
    """The shortest ``Frame Time`` text (at least 6 decimals) that :func:`parse_frame_time` reads as ``fps``.

    ``format_frame_time(120) == "0.008333"`` (as BEAT writes it),
    ``format_frame_time(15) == "0.066667"``. Exact for integer rates and for
    rates with at most 9 decimals (29.97, 23.976); any other rate reads back
    within a few ulps.

    Examples
    --------
    >>> format_frame_time(120), format_frame_time(15)
    ('0.008333', '0.066667')
    >>> parse_frame_time(format_frame_time(29.97))
    29.97
    """
    fps = float(fps)
    if not math.isfinite(fps) or fps <= 0:
        raise ValueError(f"fps must be positive and finite, got {fps}")
    for decimals in range(6, 18):
        text = f"{1.0 / fps:.{decimals}f}"
        if float(text) > 0 and parse_frame_time(text) == fps:
            return text
    # 1/(1/fps) may miss fps by an ulp (29.97): try the neighbouring doubles of 1/fps
    up = down = 1.0 / fps
    for _ in range(64):
        up, down = float(np.nextafter(up, np.inf)), float(np.nextafter(down, 0.0))
        for cand in (up, down):
            if parse_frame_time(repr(cand)) == fps:
                return repr(cand)
    return repr(1.0 / fps)


# ----------------------------------------------------------------------------- header


class _Tokens:
    """The hierarchy as a stream of ``(token, line, column)`` with helpful errors."""

    def __init__(self, lines: list[tuple[int, str]], path: Path | None) -> None:
        self.items: list[tuple[str, int, int]] = []
        for lineno, text in lines:
            for col, tok in enumerate(text.split(), start=1):
                self.items.append((tok, lineno, col))
        self.pos = 0
        self.path = path
        self.last_line = lines[-1][0] if lines else 1

    def peek(self) -> tuple[str, int, int] | None:
        return self.items[self.pos] if self.pos < len(self.items) else None

    def next(self, what: str) -> tuple[str, int, int]:
        item = self.peek()
        if item is None:
            raise FormatError(self.path, f"HIERARCHY ends early: expected {what}", line=self.last_line)
        self.pos += 1
        return item

    def expect(self, word: str) -> tuple[str, int, int]:
        tok, line, col = self.next(repr(word))
        if tok.upper() != word.upper():
            raise FormatError(self.path, f"expected {word!r}, found {tok!r}", line=line, column=col)
        return tok, line, col

    def number(self, what: str) -> float:
        tok, line, col = self.next(what)
        try:
            value = float(tok)
        except ValueError:
            raise FormatError(self.path, f"{what}: {tok!r} is not a number", line=line, column=col) from None
        if not math.isfinite(value):
            raise FormatError(self.path, f"{what}: {tok!r} is not finite", line=line, column=col)
        return value

    def rest_of_line(self, line: int) -> list[str]:
        out = []
        while (item := self.peek()) is not None and item[1] == line:
            out.append(item[0])
            self.pos += 1
        return out


class _Joints:
    """The joints parsed so far, in file (depth-first) order."""

    def __init__(self, path: Path | None) -> None:
        self.path = path
        self.names: list[str] = []
        self.parents: list[int] = []
        self.offsets: list[tuple[float, float, float] | None] = []
        self.channels: list[tuple[str, ...]] = []
        self.end_sites: dict[int, np.ndarray] = {}
        self.lines: dict[str, int] = {}

    def add(self, name: str, parent: int, line: int) -> int:
        if name in self.lines:
            raise FormatError(
                self.path, f"joint name {name!r} appears twice (first on line {self.lines[name]})", line=line
            )
        self.lines[name] = line
        self.names.append(name)
        self.parents.append(parent)
        self.offsets.append(None)
        self.channels.append(())
        return len(self.names) - 1

    def skeleton(self) -> Skeleton:
        return Skeleton(
            names=tuple(self.names),
            parents=np.array(self.parents, dtype=np.int64),
            offsets=np.array(self.offsets, dtype=np.float64),
            channels=tuple(self.channels),
            end_sites=self.end_sites,
        )


def _joint_name(tokens: _Tokens, keyword_line: int, keyword: str) -> str:
    """The rest of the ``ROOT``/``JOINT`` line (a name may hold spaces), leaving a trailing ``{``."""
    parts = tokens.rest_of_line(keyword_line)
    if parts and parts[-1] == "{":
        parts.pop()
        tokens.pos -= 1  # give the brace back
    if not parts:
        raise FormatError(tokens.path, f"{keyword} without a joint name", line=keyword_line)
    return " ".join(parts)


def _parse_end_site(tokens: _Tokens, joints: _Joints, j: int) -> None:
    site_tok, site_line, _ = tokens.next("'Site'")
    if site_tok.upper() != "SITE":
        raise FormatError(tokens.path, f"expected 'End Site', found 'End {site_tok}'", line=site_line)
    extra = tokens.rest_of_line(site_line)  # some exporters name End Sites; ignore the name
    if extra and extra[-1] == "{":
        tokens.pos -= 1
    tokens.expect("{")
    tokens.expect("OFFSET")
    what = f"End Site OFFSET of {joints.names[j]!r}"
    if j in joints.end_sites:  # a Skeleton holds one End Site per joint: a second would replace the first
        raise FormatError(tokens.path, f"joint {joints.names[j]!r} has a second End Site", line=site_line)
    joints.end_sites[j] = np.array([tokens.number(what) for _ in range(3)])
    tokens.expect("}")


def _parse_hierarchy(lines: list[tuple[int, str]], path: Path | None) -> Skeleton:
    """Build a :class:`Skeleton` from the numbered lines before ``MOTION`` (a loop, no recursion)."""
    tokens = _Tokens(lines, path)
    tokens.expect("HIERARCHY")
    joints = _Joints(path)
    tok, line, col = tokens.next("'ROOT'")
    if tok.upper() != "ROOT":
        raise FormatError(path, f"expected 'ROOT', found {tok!r}", line=line, column=col)
    stack = [joints.add(_joint_name(tokens, line, "ROOT"), -1, line)]
    tokens.expect("{")
    # (joint, OFFSET or CHANNELS) -> its line: a second one would replace the first
    declared: dict[tuple[int, str], int] = {}
    while stack:
        tok, line, col = tokens.next("'}'")
        key = tok.upper()
        j = stack[-1]
        if key in ("OFFSET", "CHANNELS"):
            if (j, key) in declared:
                raise FormatError(
                    path,
                    f"joint {joints.names[j]!r} has a second {key} (the first on line {declared[j, key]})",
                    line=line,
                    column=col,
                )
            declared[j, key] = line
        if key == "OFFSET":
            joints.offsets[j] = tuple(tokens.number(f"OFFSET of {joints.names[j]!r}") for _ in range(3))  # type: ignore[assignment]
        elif key == "CHANNELS":
            joints.channels[j] = _parse_channels(tokens, joints.names[j], line, col, path)
        elif key == "JOINT":
            if joints.offsets[j] is None:
                raise FormatError(
                    path, f"joint {joints.names[j]!r} has no OFFSET before its children", line=line
                )
            stack.append(joints.add(_joint_name(tokens, line, "JOINT"), j, line))
            tokens.expect("{")
        elif key == "END":
            _parse_end_site(tokens, joints, j)
        elif key == "}":
            if joints.offsets[j] is None:
                raise FormatError(path, f"joint {joints.names[j]!r} has no OFFSET", line=line)
            stack.pop()
        elif key == "ROOT":
            raise FormatError(path, "more than one ROOT is not supported", line=line, column=col)
        else:
            raise FormatError(
                path, f"unexpected {tok!r} inside joint {joints.names[j]!r}", line=line, column=col
            )
    extra = tokens.peek()
    if extra is not None:
        raise FormatError(
            path, f"unexpected {extra[0]!r} after the ROOT joint closed", line=extra[1], column=extra[2]
        )
    return joints.skeleton()


def _parse_channels(tokens: _Tokens, joint: str, line: int, col: int, path: Path | None) -> tuple[str, ...]:
    count_tok, count_line, count_col = tokens.next(f"channel count of {joint!r}")
    try:
        count = int(count_tok)
    except ValueError:
        raise FormatError(
            path, f"CHANNELS count {count_tok!r} of joint {joint!r} is not an integer", line=count_line
        ) from None
    if count not in (0, 3, 6):
        raise FormatError(
            path,
            f"joint {joint!r} declares {count} channels; BVH joints have 3 or 6",
            line=count_line,
            column=count_col,
        )
    names: list[str] = []
    for k in range(count):
        item = tokens.peek()
        if item is None or item[0].lower() not in _CHANNEL_LOOKUP:
            found = "end of HIERARCHY" if item is None else repr(item[0])
            raise FormatError(
                path,
                f"CHANNELS of joint {joint!r} declares {count} channels but lists {k} (then {found})",
                line=line,
                column=col,
            )
        tokens.pos += 1
        names.append(_CHANNEL_LOOKUP[item[0].lower()])
    if len(set(names)) != len(names):
        raise FormatError(path, f"CHANNELS of joint {joint!r} repeats a channel: {names}", line=line)
    n_rot = sum(c.endswith("rotation") for c in names)
    if n_rot not in (0, 3) or count - n_rot not in (0, 3):
        raise FormatError(
            path,
            f"CHANNELS of joint {joint!r} lists {n_rot} rotation and {count - n_rot} position channels "
            f"({' '.join(names)}); a joint needs all three of a kind (X, Y and Z)",
            line=line,
        )
    return tuple(names)


def _decode(raw: bytes, path: Path, lineno: int) -> str:
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        raise FormatError(path, f"not a text BVH file: {describe_bytes(raw[:64])}", line=lineno) from None


def _open_bvh(path: Path) -> tuple[IO[bytes], bytes]:
    """The file as a byte stream (gzip by content) and its first bytes.

    A file with CR-only line endings (classic Mac) is read whole and its CRs turned into LFs.
    """
    f = open_binary(path)
    head = f.peek(65536)[:65536]  # type: ignore[attr-defined]
    if b"\r" in head and b"\n" not in head:
        try:
            data = f.read()
        except (OSError, EOFError) as exc:
            f.close()
            raise FormatError(path, f"cannot decompress gzip data: {exc}") from None
        f.close()
        return io.BytesIO(data.replace(b"\r", b"\n")), head
    return f, head


def _hierarchy_lines(f: IO[bytes], path: Path, head: bytes) -> tuple[list[tuple[int, str]], int]:
    """The numbered lines before ``MOTION`` and the line number of ``MOTION``."""
    lines: list[tuple[int, str]] = []
    lineno = 0
    first_seen = False
    while True:
        raw = f.readline()
        if not raw:
            if lineno == 0:
                raise FormatError(path, "empty file: expected a BVH HIERARCHY")
            raise FormatError(path, "no MOTION section (the file ends inside the HIERARCHY)", line=lineno)
        lineno += 1
        text = _decode(raw, path, lineno).lstrip("\ufeff")
        stripped = text.strip()
        if not first_seen and stripped:
            first_seen = True
            if stripped.split()[0].upper() != "HIERARCHY":
                raise FormatError(
                    path, f"not a BVH file: expected 'HIERARCHY', found {describe_bytes(head)}", line=lineno
                )
        if stripped.upper() == "MOTION":
            return lines, lineno
        lines.append((lineno, text))
        if lineno > _MAX_HEADER_LINES:
            raise FormatError(path, f"no MOTION line in the first {_MAX_HEADER_LINES} lines", line=lineno)


def _next_nonblank(f: IO[bytes], path: Path, lineno: int, what: str) -> tuple[int, str]:
    """The next non-blank line after line ``lineno``: ``(its number, its text)``."""
    while True:
        raw = f.readline()
        if not raw:
            raise FormatError(path, f"file ends after MOTION: expected {what}", line=lineno)
        lineno += 1
        text = _decode(raw, path, lineno)
        if text.strip():
            return lineno, text


def _read_header(f: IO[bytes], path: Path, head: bytes = b"") -> tuple[Skeleton, int, str, int, int]:
    """Read up to and including ``Frame Time``.

    Returns
    -------
    skeleton, n_frames_declared, frame_time_text, frame_time_line, header_line_count
    """
    lines, lineno = _hierarchy_lines(f, path, head)
    skeleton = _parse_hierarchy(lines, path)
    frames_line, text = _next_nonblank(f, path, lineno, "'Frames: N'")
    m = _FRAMES_RE.match(text)
    if m is None:
        raise FormatError(
            path, f"expected 'Frames: N' after MOTION, found {text.strip()!r}", line=frames_line
        )
    try:
        frames_value = float(m.group(1))
    except ValueError:
        frames_value = math.nan
    if not (math.isfinite(frames_value) and 0 <= frames_value <= 2**53 and frames_value == int(frames_value)):
        raise FormatError(path, f"Frames: {m.group(1)!r} is not a whole number", line=frames_line)
    time_line, text = _next_nonblank(f, path, frames_line, "'Frame Time: dt'")
    m = _FRAME_TIME_RE.match(text)
    if m is None:
        raise FormatError(path, f"expected 'Frame Time: dt', found {text.strip()!r}", line=time_line)
    return skeleton, int(frames_value), m.group(1), time_line, time_line


# ----------------------------------------------------------------------------- motion block


def _parse_motion(data: bytes, n_channels: int, first_line: int, path: Path) -> np.ndarray:
    """Parse the rows after ``Frame Time`` into a ``(T, C) float64`` array (vectorised)."""
    if not data.strip():
        return np.zeros((0, n_channels), dtype=np.float64)
    try:
        values = np.loadtxt(io.BytesIO(data), dtype=np.float64, ndmin=2, comments=None)
    except ValueError as exc:
        _diagnose_motion(data, n_channels, first_line, path)
        raise FormatError(path, f"cannot parse the MOTION rows: {exc}", line=first_line) from None
    if values.shape[1] != n_channels:
        line = first_line + _line_index_of_row(data, 0)
        raise FormatError(
            path,
            f"motion rows have {values.shape[1]} values but the HIERARCHY declares {n_channels} channels",
            line=line,
        )
    finite = np.isfinite(values)
    if not finite.all():
        row, col = (int(v) for v in np.argwhere(~finite)[0])
        raise FormatError(
            path,
            f"motion value {values[row, col]} is not finite",
            line=first_line + _line_index_of_row(data, row),
            column=col + 1,
        )
    return values


def _line_index_of_row(data: bytes, row: int) -> int:
    """0-based line offset (within ``data``) of the ``row``-th non-blank line (error path only)."""
    seen = -1
    for i, line in enumerate(data.split(b"\n")):
        if line.strip():
            seen += 1
            if seen == row:
                return i
    return 0


def _diagnose_motion(data: bytes, n_channels: int, first_line: int, path: Path) -> None:
    """Slow per-line pass that raises a :class:`FormatError` at the first bad row or token."""
    row = -1
    for i, raw in enumerate(data.split(b"\n")):
        tokens = raw.split()
        if not tokens:
            continue
        row += 1
        line = first_line + i
        for col, tok in enumerate(tokens, start=1):
            try:
                if b"_" in tok:
                    raise ValueError
                float(tok)
            except ValueError:
                shown = tok.decode("utf-8", "replace")
                raise FormatError(
                    path, f"motion frame {row}: {shown!r} is not a number", line=line, column=col
                ) from None
        if len(tokens) != n_channels:
            raise FormatError(
                path,
                f"motion frame {row} has {len(tokens)} values but the HIERARCHY declares "
                f"{n_channels} channels" + (" (truncated row?)" if len(tokens) < n_channels else ""),
                line=line,
            )


# ----------------------------------------------------------------------------- public API


def read_bvh_header(path: str | os.PathLike[str]) -> tuple[Skeleton, int, float]:
    """Read only the HIERARCHY and the ``Frames`` / ``Frame Time`` lines of a BVH file.

    Parameters
    ----------
    path : str or PathLike
        ``.bvh`` or ``.bvh.gz`` file.

    Returns
    -------
    skeleton : Skeleton
        Joint names, parents, offsets (file units, normally centimetres), channels, End Sites.
    n_frames_declared : int
        The ``Frames:`` value (the rows are not counted).
    frame_time : float
        The ``Frame Time:`` value in seconds, as written (positive).

    Raises
    ------
    FormatError
        If the header is malformed (naming the line), a ``Frame Time`` of zero or less included.

    Examples
    --------
    >>> import tempfile
    >>> from beatlite.skeleton.beat import beat_skeleton
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "take.bvh"
    >>> write_bvh(path, Motion(beat_skeleton(), np.zeros((4, 228)), fps=120))
    >>> skeleton, n_frames, frame_time = read_bvh_header(path)
    >>> skeleton.n_joints, n_frames, frame_time
    (75, 4, 0.008333)
    >>> tmp.cleanup()
    """
    p = Path(path)
    f, head = _open_bvh(p)
    with f:
        skeleton, n_frames, time_text, time_line, _ = _read_header(f, p, head)
    try:
        frame_time = float(time_text)
    except ValueError:
        raise FormatError(p, f"Frame Time {time_text!r} is not a number", line=time_line) from None
    if not math.isfinite(frame_time):
        raise FormatError(p, f"Frame Time {time_text!r} is not finite", line=time_line)
    if frame_time <= 0:
        raise FormatError(p, f"Frame Time {time_text!r} is not a positive number of seconds", line=time_line)
    return skeleton, n_frames, frame_time


def infer_row_rate(n_declared: int, header_fps: float, n_rows: int) -> float | None:
    """The frame rate of the rows when ``Frames`` and the row count differ by a clean integer factor.

    The header duration ``n_declared / header_fps`` is trusted: with ``k = round(n_declared /
    n_rows)`` (or its inverse) in ``2..MAX_RATE_FACTOR`` and ``|n_declared - k * n_rows|`` within
    1 % of the larger count, the rows are at ``header_fps / k`` (``header_fps * k`` when there are
    more rows than declared). Otherwise ``None`` (e.g. a truncated file).

    Examples
    --------
    >>> infer_row_rate(7669, 120.0, 957)  # a 120 fps header over 15 fps rows
    15.0
    >>> infer_row_rate(100, 120.0, 99) is None
    True
    """
    if min(n_declared, n_rows) < 2 or n_declared == n_rows:
        return None
    big, small = max(n_declared, n_rows), min(n_declared, n_rows)
    k = round(big / small)
    if not 2 <= k <= MAX_RATE_FACTOR or abs(big - k * small) > 0.01 * big:
        return None
    rate = header_fps / k if n_declared > n_rows else header_fps * k
    return rate if rate >= 1.0 else None


def _settle_rate(
    p: Path, n_declared: int, file_fps: float | None, n_rows: int, override: float | None
) -> float:
    """The rate to read the rows at, with the one warning that names both readings and the override.

    ``file_fps`` is the ``Frame Time`` rate (None when unreadable, then ``override`` is set).
    An override equal to the inferred rate is silent: the mismatch was already resolved.
    """
    inferred = None if file_fps is None else infer_row_rate(n_declared, file_fps, n_rows)
    if n_rows == n_declared or (override is not None and override == inferred):
        return float(override if override is not None else file_fps)  # type: ignore[arg-type]
    message = f"'Frames: {n_declared}' but the MOTION block has {n_rows} rows"
    if override is not None or inferred is None or file_fps is None:
        rate = float(override if override is not None else file_fps)  # type: ignore[arg-type]
        hint = (
            ""
            if override is not None
            else " (pass fps= to read_bvh, bvh_fps= to load_take/index_folder if the rate is wrong)"
        )
        warnings.warn(
            f"{p}: {message}; using the {n_rows} rows at {rate:g} fps{hint}", BVHWarning, stacklevel=3
        )
        return rate
    warnings.warn(
        f"{p}: {message}: the header says {n_declared / file_fps:.2f} s at {file_fps:g} fps, so the rows "
        f"are read at {inferred:g} fps ({n_rows / inferred:.2f} s), not at the header's {file_fps:g} fps "
        f"({n_rows / file_fps:.2f} s); pass fps={file_fps:g} to read_bvh (bvh_fps= to load_take/"
        "index_folder) to keep the header rate",
        BVHWarning,
        stacklevel=3,
    )
    return inferred


def convert_units(skeleton: Skeleton, channels: np.ndarray, factor: float) -> tuple[Skeleton, np.ndarray]:
    """Scale offsets, End Sites and position channels by ``factor`` (e.g. 100 for metres -> cm).

    Examples
    --------
    >>> from beatlite.skeleton.core import Skeleton
    >>> arm = Skeleton(("Root", "Hand"), [-1, 0], [[0, 0, 0], [0.3, 0, 0]],
    ...                (("Xposition", "Yposition", "Zposition"), ()))
    >>> cm, channels = convert_units(arm, np.array([[1.0, 0.5, 0.0]]), 100)  # metres -> cm
    >>> cm.offsets[1], channels
    (array([30.,  0.,  0.]), array([[100.,  50.,   0.]]))
    """
    if factor == 1.0:
        return skeleton, channels
    cols = [
        int(start) + k
        for start, chans in zip(skeleton.channel_starts, skeleton.channels)
        for k, c in enumerate(chans)
        if c.endswith("position")
    ]
    channels = channels.copy()
    channels[:, cols] *= factor
    scaled = dataclasses.replace(
        skeleton,
        offsets=skeleton.offsets * factor,
        end_sites={j: v * factor for j, v in skeleton.end_sites.items()},
    )
    return scaled, channels


def _check_units(p: Path, skeleton: Skeleton, units: str) -> float:
    """Factor to centimetres for ``units``; ``"auto"`` warns when the skeleton looks like metres."""
    if units == "auto":
        from beatlite.skeleton.kinematics import skeleton_extent

        extent = skeleton_extent(skeleton)
        if 0 < extent < METRE_EXTENT:
            warnings.warn(
                f"{p}: the rest pose is only {extent:.3g} units tall, so the file is probably in metres "
                "(beatlite works in centimetres); pass units='m' to convert or units='cm' to keep the values",
                BVHWarning,
                stacklevel=3,
            )
    return UNITS[units]


def read_bvh(
    path: str | os.PathLike[str], *, fps: float | None = None, strict: bool = False, units: str = "auto"
) -> Motion:
    """Read a BVH file (``.bvh`` or ``.bvh.gz``) into a :class:`Motion`.

    Parameters
    ----------
    path : str or PathLike
        The file. Gzip is detected from the content; LF, CRLF or CR-only line endings.
    fps : float, optional
        Frame rate of the rows, instead of the file's ``Frame Time`` (some real BEAT
        files have a wrong one, docs/reference_code.md#bvh-header). By default the rate comes from
        :func:`parse_frame_time`, which snaps e.g. ``0.008333`` to 120; when
        ``Frames`` and the row count differ by a clean integer factor the rows are
        read at the rate that keeps the header duration (:func:`infer_row_rate`).
    strict : bool
        If True, a ``Frames:`` value that differs from the number of rows
        raises :class:`FormatError`; otherwise a :class:`BVHWarning` naming
        both numbers (and both readings of the rate) is issued and the rows are used.
    units : {"auto", "cm", "m", "mm"}
        Length unit of the file. ``"m"``/``"mm"`` convert to centimetres; ``"auto"``
        (default) keeps the values and warns when the skeleton looks like metres.

    Returns
    -------
    Motion
        ``channels`` is ``(T, C) float64`` (positions in cm, rotations in degrees,
        columns in ``skeleton.channels`` order).

    Raises
    ------
    FormatError
        For any malformed content, naming the file and line (and column for a
        bad number).

    Examples
    --------
    A two-joint BVH file: a root with 6 channels and a child 10 cm above it with 3.

    >>> import pathlib, tempfile
    >>> from beatlite.io.bvh import read_bvh
    >>> text = '''HIERARCHY
    ... ROOT Hips
    ... {
    ...   OFFSET 0 0 0
    ...   CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
    ...   JOINT Spine
    ...   {
    ...     OFFSET 0 10 0
    ...     CHANNELS 3 Zrotation Xrotation Yrotation
    ...     End Site
    ...     {
    ...       OFFSET 0 5 0
    ...     }
    ...   }
    ... }
    ... MOTION
    ... Frames: 2
    ... Frame Time: 0.008333
    ... 0 95 0 0 0 0 0 0 0
    ... 4 95 0 0 0 0 0 0 0
    ... '''
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = pathlib.Path(folder) / "tiny.bvh"
    ...     _ = path.write_text(text)
    ...     motion = read_bvh(path)
    >>> motion
    Motion(2 frames @ 120 fps = 0.02 s, 2 joints, 9 channels)
    >>> motion.skeleton.names, motion.skeleton.channels[1]
    (('Hips', 'Spine'), ('Zrotation', 'Xrotation', 'Yrotation'))
    >>> motion.channels.shape  # (T, C): positions in cm, rotations in degrees
    (2, 9)
    >>> motion.positions()[1]  # frame 1: the root moved 4 cm along x; Spine sits 10 cm above
    array([[  4.,  95.,   0.],
           [  4., 105.,   0.]])
    """
    p = Path(path)
    if units not in UNITS:
        raise ValueError(f"read_bvh: units must be one of {sorted(UNITS)}, got {units!r}")
    if fps is not None:
        fps = float(fps)
        if not math.isfinite(fps) or fps <= 0:
            raise ValueError(f"read_bvh: fps must be a positive number, got {fps}")
    f, head = _open_bvh(p)
    with f:
        skeleton, n_declared, time_text, time_line, n_header = _read_header(f, p, head)
        try:
            data = f.read()
        except (OSError, EOFError) as exc:
            raise FormatError(p, f"cannot decompress gzip data: {exc}") from None
    factor = _check_units(p, skeleton, units)
    try:
        file_fps: float | None = parse_frame_time(time_text)
    except ValueError as exc:
        if fps is None:
            raise FormatError(p, f"{exc} (pass fps= to override)", line=time_line) from None
        file_fps = None
    channels = _parse_motion(data, skeleton.n_channels, n_header + 1, p)
    n_rows = channels.shape[0]
    if n_rows == 0:
        raise FormatError(
            p, f"no motion: the MOTION block has no rows ('Frames: {n_declared}')", field="Frames"
        )
    if strict and n_rows != n_declared:
        raise FormatError(p, f"'Frames: {n_declared}' but the MOTION block has {n_rows} rows", field="Frames")
    rate = _settle_rate(p, n_declared, file_fps, n_rows, fps)
    skeleton, channels = convert_units(skeleton, channels, factor)
    return Motion(skeleton=skeleton, channels=channels, fps=rate)


def _fmt_offset(value: float) -> str:
    text = f"{value:.6f}"
    return text if float(text) == value else repr(float(value))


def _check_names(skeleton: Skeleton) -> None:
    """Joint names that :func:`read_bvh` could not read back raise ``ValueError``."""
    seen: set[str] = set()
    for j, name in enumerate(skeleton.names):
        if not isinstance(name, str) or not name.strip() or " ".join(name.split()) != name:
            raise ValueError(
                f"write_bvh: joint {j} name {name!r} is empty, has leading/trailing or repeated "
                "whitespace, a tab or a newline, so it cannot be read back"
            )
        if "{" in name or "}" in name:
            raise ValueError(
                f"write_bvh: joint {j} name {name!r} contains a brace, so it cannot be read back"
            )
        if name in seen:
            raise ValueError(f"write_bvh: joint name {name!r} appears twice")
        seen.add(name)


def _joint_lines(skeleton: Skeleton, j: int, pad: str) -> list[str]:
    """The opening lines of joint ``j``: keyword and name, brace, OFFSET, CHANNELS."""
    keyword = "ROOT" if j == 0 else "JOINT"
    lines = [f"{pad}{keyword} {skeleton.names[j]}", f"{pad}{{"]
    lines.append(pad + "\tOFFSET " + " ".join(_fmt_offset(float(v)) for v in skeleton.offsets[j]))
    if skeleton.channels[j]:
        lines.append(f"{pad}\tCHANNELS {len(skeleton.channels[j])} " + " ".join(skeleton.channels[j]))
    return lines


def _closing_lines(skeleton: Skeleton, j: int, pad: str) -> list[str]:
    """The End Site of joint ``j`` (if any) and its closing brace."""
    lines = []
    if j in skeleton.end_sites:
        offset = " ".join(_fmt_offset(float(v)) for v in skeleton.end_sites[j])
        lines += [f"{pad}\tEnd Site", f"{pad}\t{{", f"{pad}\t\tOFFSET {offset}", f"{pad}\t}}"]
    lines.append(f"{pad}}}")
    return lines


def _header_text(skeleton: Skeleton) -> list[str]:
    """HIERARCHY lines, written with an explicit stack (no recursion limit on deep chains)."""
    children: list[list[int]] = [[] for _ in range(skeleton.n_joints)]
    for j, p in enumerate(skeleton.parents[1:], start=1):
        children[int(p)].append(j)
    lines = ["HIERARCHY"]
    stack: list[tuple[int, int, bool]] = [(0, 0, False)]  # (joint, depth, children done)
    while stack:
        j, depth, done = stack.pop()
        pad = "\t" * depth
        if done:
            lines += _closing_lines(skeleton, j, pad)
            continue
        lines += _joint_lines(skeleton, j, pad)
        stack.append((j, depth, True))
        stack.extend((c, depth + 1, False) for c in reversed(children[j]))
    return lines


def write_bvh(path: str | os.PathLike[str], motion: Motion, *, precision: int = 6) -> None:
    """Write ``motion`` as a BVH file, atomically (``.gz`` suffix gzips).

    Parameters
    ----------
    path : str or PathLike
        Destination.
    motion : Motion
        Skeleton and ``(T, C)`` channels; non-finite values are rejected, and so are
        joint names the reader could not read back (braces, newlines, tabs, repeated or
        edge whitespace, duplicates). Any depth of hierarchy is written (no recursion).
    precision : int
        Decimals printed for each channel value (0..17). Values already
        rounded to ``precision`` decimals read back bit-identical.
        ``Frame Time`` is written with :func:`format_frame_time`, so
        ``read_bvh`` recovers ``motion.fps`` exactly.

    Examples
    --------
    >>> import tempfile
    >>> from beatlite.skeleton.beat import beat_skeleton
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "take.bvh.gz"
    >>> channels = np.round(np.random.default_rng(0).uniform(-90, 90, (3, 228)), 6)
    >>> write_bvh(path, Motion(beat_skeleton(), channels, fps=15))
    >>> back = read_bvh(path)
    >>> back.fps, bool(np.array_equal(back.channels, channels))  # values rounded to 6 decimals read back exactly
    (15.0, True)
    >>> tmp.cleanup()
    """
    if not isinstance(motion, Motion):
        raise TypeError(f"write_bvh: motion must be a Motion, got {type(motion).__name__}")
    if not isinstance(precision, int | np.integer) or not 0 <= int(precision) <= 17:
        raise ValueError(f"write_bvh: precision must be an integer in 0..17, got {precision!r}")
    values = motion.channels
    if not np.isfinite(values).all():
        row, col = np.argwhere(~np.isfinite(values))[0]
        raise ValueError(f"write_bvh: motion.channels[{row}, {col}] is {values[row, col]} (not finite)")
    skeleton = motion.skeleton
    _check_names(skeleton)
    order = _depth_first_order(skeleton)
    if not np.array_equal(order, np.arange(skeleton.n_joints)):
        raise ValueError("write_bvh: skeleton joints are not in depth-first (file) order")
    header = _header_text(skeleton)
    header += ["MOTION", f"Frames: {motion.n_frames}", f"Frame Time: {format_frame_time(motion.fps)}"]
    n_channels = values.shape[1]
    row_format = " ".join([f"%.{int(precision)}f"] * n_channels)
    with atomic_write(path, "w") as f:
        f.write("\n".join(header) + "\n")
        block = 512
        for start in range(0, motion.n_frames, block):
            chunk = values[start : start + block].tolist()
            f.write("\n".join(row_format % tuple(r) for r in chunk) + "\n")


def _depth_first_order(skeleton: Skeleton) -> np.ndarray:
    """Joint indices in the order a depth-first walk (children by index) visits them."""
    children: list[list[int]] = [[] for _ in range(skeleton.n_joints)]
    for j, p in enumerate(skeleton.parents[1:], start=1):
        children[int(p)].append(j)
    out: list[int] = []
    stack = [0]
    while stack:
        j = stack.pop()
        out.append(j)
        stack.extend(reversed(children[j]))
    return np.array(out, dtype=np.int64)
