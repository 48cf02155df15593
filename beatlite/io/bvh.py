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

Taught in notebooks/01_beat_formats.ipynb, sections 2 (the BVH file) and 3 (reading the motion); writing in notebooks/08_visualisation_3d.ipynb, section 6 (export to Blender: BVH).
"""

from __future__ import annotations

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

__all__ = ["read_bvh", "read_bvh_header", "write_bvh", "parse_frame_time", "format_frame_time"]

CHANNEL_NAMES = POSITION_CHANNELS + ROTATION_CHANNELS
_CHANNEL_LOOKUP = {c.lower(): c for c in CHANNEL_NAMES}
_FRAMES_RE = re.compile(r"^\s*Frames\s*:\s*(\S+)\s*$", re.IGNORECASE)
_FRAME_TIME_RE = re.compile(r"^\s*Frame\s+Time\s*:\s*(\S+)\s*$", re.IGNORECASE)
_MAX_HEADER_LINES = 200_000


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
    """
    try:
        dec = Decimal(text.strip())
    except InvalidOperation:
        raise ValueError(f"frame time {text!r} is not a number") from None
    frame_time = float(dec)
    if not math.isfinite(frame_time) or frame_time <= 0:
        raise ValueError(f"frame time must be a positive number of seconds, got {text!r}")
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


def _parse_hierarchy(lines: list[tuple[int, str]], path: Path | None) -> Skeleton:
    """Build a :class:`Skeleton` from the numbered lines before ``MOTION``."""
    tokens = _Tokens(lines, path)
    tokens.expect("HIERARCHY")
    names: list[str] = []
    parents: list[int] = []
    offsets: list[tuple[float, float, float] | None] = []
    channels: list[tuple[str, ...]] = []
    end_sites: dict[int, np.ndarray] = {}

    tok, line, col = tokens.next("'ROOT'")
    if tok.upper() != "ROOT":
        raise FormatError(path, f"expected 'ROOT', found {tok!r}", line=line, column=col)

    def joint_name(keyword_line: int, keyword: str) -> str:
        parts = tokens.rest_of_line(keyword_line)
        if parts and parts[-1] == "{":
            parts.pop()
            tokens.pos -= 1  # give the brace back
        if not parts:
            raise FormatError(path, f"{keyword} without a joint name", line=keyword_line)
        return " ".join(parts)

    stack: list[int] = []
    names.append(joint_name(line, "ROOT"))
    parents.append(-1)
    offsets.append(None)
    channels.append(())
    tokens.expect("{")
    stack.append(0)
    while stack:
        tok, line, col = tokens.next("'}'")
        key = tok.upper()
        j = stack[-1]
        if key == "OFFSET":
            offsets[j] = (
                tokens.number(f"OFFSET of {names[j]!r}"),
                tokens.number(f"OFFSET of {names[j]!r}"),
                tokens.number(f"OFFSET of {names[j]!r}"),
            )
        elif key == "CHANNELS":
            channels[j] = _parse_channels(tokens, names[j], line, col, path)
        elif key == "JOINT":
            if offsets[j] is None:
                raise FormatError(path, f"joint {names[j]!r} has no OFFSET before its children", line=line)
            names.append(joint_name(line, "JOINT"))
            parents.append(j)
            offsets.append(None)
            channels.append(())
            tokens.expect("{")
            stack.append(len(names) - 1)
        elif key == "END":
            site_tok, site_line, site_col = tokens.next("'Site'")
            if site_tok.upper() != "SITE":
                raise FormatError(path, f"expected 'End Site', found 'End {site_tok}'", line=site_line)
            extra = tokens.rest_of_line(site_line)  # some exporters name End Sites; ignore the name
            if extra and extra[-1] == "{":
                tokens.pos -= 1
            tokens.expect("{")
            tokens.expect("OFFSET")
            end_sites[j] = np.array([tokens.number(f"End Site OFFSET of {names[j]!r}") for _ in range(3)])
            tokens.expect("}")
        elif key == "}":
            if offsets[j] is None:
                raise FormatError(path, f"joint {names[j]!r} has no OFFSET", line=line)
            stack.pop()
        elif key == "ROOT":
            raise FormatError(path, "more than one ROOT is not supported", line=line, column=col)
        else:
            raise FormatError(path, f"unexpected {tok!r} inside joint {names[j]!r}", line=line, column=col)
    extra = tokens.peek()
    if extra is not None:
        raise FormatError(
            path, f"unexpected {extra[0]!r} after the ROOT joint closed", line=extra[1], column=extra[2]
        )
    return Skeleton(
        names=tuple(names),
        parents=np.array(parents, dtype=np.int64),
        offsets=np.array(offsets, dtype=np.float64),
        channels=tuple(channels),
        end_sites=end_sites,
    )


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
    return tuple(names)


def _decode(raw: bytes, path: Path, lineno: int) -> str:
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        raise FormatError(path, f"not a text BVH file: {describe_bytes(raw[:64])}", line=lineno) from None


def _read_header(f: IO[bytes], path: Path) -> tuple[Skeleton, int, str, int, int]:
    """Read up to and including ``Frame Time``.

    Returns
    -------
    skeleton, n_frames_declared, frame_time_text, frame_time_line, header_line_count
    """
    head = f.peek(256)[:256] if hasattr(f, "peek") else b""  # type: ignore[attr-defined]
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
            break
        lines.append((lineno, text))
        if lineno > _MAX_HEADER_LINES:
            raise FormatError(path, f"no MOTION line in the first {_MAX_HEADER_LINES} lines", line=lineno)
    skeleton = _parse_hierarchy(lines, path)

    def next_nonblank(what: str) -> tuple[int, str]:
        nonlocal lineno
        while True:
            raw = f.readline()
            if not raw:
                raise FormatError(path, f"file ends after MOTION: expected {what}", line=lineno)
            lineno += 1
            text = _decode(raw, path, lineno)
            if text.strip():
                return lineno, text

    frames_line, text = next_nonblank("'Frames: N'")
    m = _FRAMES_RE.match(text)
    if m is None:
        raise FormatError(
            path, f"expected 'Frames: N' after MOTION, found {text.strip()!r}", line=frames_line
        )
    try:
        frames_value = float(m.group(1))
    except ValueError:
        frames_value = math.nan
    if not (math.isfinite(frames_value) and frames_value >= 0 and frames_value == int(frames_value)):
        raise FormatError(path, f"Frames: {m.group(1)!r} is not a whole number", line=frames_line)
    time_line, text = next_nonblank("'Frame Time: dt'")
    m = _FRAME_TIME_RE.match(text)
    if m is None:
        raise FormatError(path, f"expected 'Frame Time: dt', found {text.strip()!r}", line=time_line)
    return skeleton, int(frames_value), m.group(1), time_line, lineno


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
        Joint names, parents, offsets (centimetres), channels, End Sites.
    n_frames_declared : int
        The ``Frames:`` value (the rows are not counted).
    frame_time : float
        The ``Frame Time:`` value in seconds, as written.

    Raises
    ------
    FormatError
        If the header is malformed (naming the line).
    """
    p = Path(path)
    with open_binary(p) as f:
        skeleton, n_frames, time_text, time_line, _ = _read_header(f, p)
    try:
        frame_time = float(time_text)
    except ValueError:
        raise FormatError(p, f"Frame Time {time_text!r} is not a number", line=time_line) from None
    return skeleton, n_frames, frame_time


def read_bvh(path: str | os.PathLike[str], *, fps: float | None = None, strict: bool = False) -> Motion:
    """Read a BVH file (``.bvh`` or ``.bvh.gz``) into a :class:`Motion`.

    Parameters
    ----------
    path : str or PathLike
        The file. Gzip is detected from the content.
    fps : float, optional
        Frame rate to use instead of the file's ``Frame Time`` (some real BEAT
        files have a wrong one, docs/reference_code.md#bvh-header). By default the rate comes from
        :func:`parse_frame_time`, which snaps e.g. ``0.008333`` to 120.
    strict : bool
        If True, a ``Frames:`` value that differs from the number of rows
        raises :class:`FormatError`; otherwise a :class:`BVHWarning` naming
        both numbers is issued and the rows are used.

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
    if fps is not None:
        fps = float(fps)
        if not math.isfinite(fps) or fps <= 0:
            raise ValueError(f"read_bvh: fps must be a positive number, got {fps}")
    with open_binary(p) as f:
        skeleton, n_declared, time_text, time_line, n_header = _read_header(f, p)
        try:
            data = f.read()
        except (OSError, EOFError) as exc:
            raise FormatError(p, f"cannot decompress gzip data: {exc}") from None
    if fps is None:
        try:
            fps = parse_frame_time(time_text)
        except ValueError as exc:
            raise FormatError(p, f"{exc} (pass fps= to override)", line=time_line) from None
    channels = _parse_motion(data, skeleton.n_channels, n_header + 1, p)
    n_rows = channels.shape[0]
    if n_rows != n_declared:
        message = f"'Frames: {n_declared}' but the MOTION block has {n_rows} rows"
        if strict:
            raise FormatError(p, message, field="Frames")
        warnings.warn(f"{p}: {message}; using the {n_rows} rows", BVHWarning, stacklevel=2)
    return Motion(skeleton=skeleton, channels=channels, fps=fps)


def _fmt_offset(value: float) -> str:
    text = f"{value:.6f}"
    return text if float(text) == value else repr(float(value))


def _header_text(skeleton: Skeleton) -> list[str]:
    lines = ["HIERARCHY"]
    children: list[list[int]] = [[] for _ in range(skeleton.n_joints)]
    for j, p in enumerate(skeleton.parents[1:], start=1):
        children[int(p)].append(j)

    def emit(j: int, depth: int) -> None:
        pad = "\t" * depth
        keyword = "ROOT" if j == 0 else "JOINT"
        lines.append(f"{pad}{keyword} {skeleton.names[j]}")
        lines.append(f"{pad}{{")
        lines.append(pad + "\tOFFSET " + " ".join(_fmt_offset(float(v)) for v in skeleton.offsets[j]))
        if skeleton.channels[j]:
            lines.append(f"{pad}\tCHANNELS {len(skeleton.channels[j])} " + " ".join(skeleton.channels[j]))
        for c in children[j]:
            emit(c, depth + 1)
        if j in skeleton.end_sites:
            lines.append(f"{pad}\tEnd Site")
            lines.append(f"{pad}\t{{")
            lines.append(pad + "\t\tOFFSET " + " ".join(_fmt_offset(float(v)) for v in skeleton.end_sites[j]))
            lines.append(f"{pad}\t}}")
        lines.append(f"{pad}}}")

    # file order must be depth-first: check that recursion reproduces it
    emit(0, 0)
    return lines


def write_bvh(path: str | os.PathLike[str], motion: Motion, *, precision: int = 6) -> None:
    """Write ``motion`` as a BVH file, atomically (``.gz`` suffix gzips).

    Parameters
    ----------
    path : str or PathLike
        Destination.
    motion : Motion
        Skeleton and ``(T, C)`` channels; non-finite values are rejected.
    precision : int
        Decimals printed for each channel value (0..17). Values already
        rounded to ``precision`` decimals read back bit-identical.
        ``Frame Time`` is written with :func:`format_frame_time`, so
        ``read_bvh`` recovers ``motion.fps`` exactly.
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
