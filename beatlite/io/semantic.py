"""BEAT semantic-relevance annotations (``.txt``, tab-separated, no header; docs/reference_code.md#semantic-annotations).

Each line is ``type  start  end  duration  score  [keywords]``, e.g.
``08_metaphoric_l\\t31.931\\t34.035\\t2.104\\t0.8\\tlove``: a gesture type, its
time span in seconds and a relevance score in [0, 1].

Taught in notebooks/01_beat_formats.ipynb, section 10 (semantic relevance and emotion annotations).
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import NamedTuple

import numpy as np

from beatlite.io.atomic import atomic_write
from beatlite.io.errors import FormatError, FormatWarning
from beatlite.io.textfile import read_text

__all__ = ["SemanticSegment", "read_semantic", "write_semantic", "semantic_to_frames", "segments_to_frames"]

_FIELDS = ("type", "start", "end", "duration", "score")


class SemanticSegment(NamedTuple):
    """One annotated gesture: ``type`` (e.g. ``"01_beat_align"``), times in seconds, score in [0, 1].

    Examples
    --------
    >>> seg = SemanticSegment("02_deictic_l", 0.734, 2.315, 1.581, 0.3, "my")
    >>> seg.type, seg.score, seg.keywords
    ('02_deictic_l', 0.3, 'my')
    """

    type: str
    start: float
    end: float
    duration: float
    score: float
    keywords: str = ""


def parse_number(path: Path, token: str, line: int, field: str) -> float:
    """``float(token)``, or a :class:`FormatError` naming ``line`` and ``field`` (also for NaN/inf).

    Examples
    --------
    >>> parse_number(Path("take.txt"), "0.75", 3, "score")
    0.75
    >>> parse_number(Path("take.txt"), "abc", 3, "score")
    Traceback (most recent call last):
        ...
    beatlite.io.errors.FormatError: take.txt, line 3, field 'score': 'abc' is not a number
    """
    try:
        value = float(token)
    except ValueError:
        raise FormatError(path, f"{token!r} is not a number", line=line, field=field) from None
    if not math.isfinite(value):
        raise FormatError(path, f"{token!r} is not a finite number", line=line, field=field)
    return value


#: Largest ``|duration - (end - start)|`` accepted without a warning, seconds (BEAT prints 3 decimals).
DURATION_TOLERANCE = 0.01


def check_times(path: Path, line: int, start: float, end: float, duration: float) -> str | None:
    """Raise for negative or reversed times; return a note when ``duration != end - start``.

    Examples
    --------
    >>> check_times(Path("take.txt"), 2, 1.0, 2.0, 1.0) is None  # consistent: no note
    True
    >>> check_times(Path("take.txt"), 2, 1.0, 2.0, 1.5) is not None  # duration disagrees: a note for warn_durations
    True
    """
    if start < 0 or end < 0:
        raise FormatError(path, f"negative time: start {start}, end {end}", line=line, field="start")
    if start > end:
        raise FormatError(path, f"start {start} is after end {end}", line=line, field="start")
    if abs(duration - (end - start)) > DURATION_TOLERANCE:
        return f"line {line}: duration {duration} but end - start = {end - start:.6g}"
    return None


def warn_durations(path: Path, notes: list[str]) -> None:
    """One :class:`FormatWarning` for the rows whose duration disagrees with their times.

    Examples
    --------
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     warn_durations(Path("take.txt"), ["line 2: duration 1.5 != end - start 1.0"])
    >>> len(caught), caught[0].category.__name__
    (1, 'FormatWarning')
    """
    if notes:
        warnings.warn(
            f"{path}: {len(notes)} rows have a duration that is not end - start, e.g. {notes[0]}; "
            "the start and end times are used",
            FormatWarning,
            stacklevel=3,
        )


def read_semantic(path: str | os.PathLike[str]) -> list[SemanticSegment]:
    r"""Read a BEAT semantic ``.txt`` file (``.gz`` transparent).

    Parameters
    ----------
    path : str or PathLike
        The file. Fields are separated by TABs (lines without a TAB are split on
        whitespace). Blank lines are skipped.

    Returns
    -------
    list of SemanticSegment
        In file order.

    Raises
    ------
    FormatError
        Fewer than 5 fields, a non-numeric time/score, a negative time, ``start > end``
        or a score outside [0, 1], naming the line and the field. Rows whose
        ``duration`` is not ``end - start`` give one :class:`FormatWarning`.

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "take.txt"
    >>> _ = path.write_text("00_nogesture\t0.0\t0.734\t0.734\t0.0\n"
    ...                     "02_deictic_l\t0.734\t2.315\t1.581\t0.3\tmy\n")
    >>> [(s.type, s.start, s.score, s.keywords) for s in read_semantic(path)]
    [('00_nogesture', 0.0, 0.0, ''), ('02_deictic_l', 0.734, 0.3, 'my')]
    >>> tmp.cleanup()
    """
    p = Path(path)
    out: list[SemanticSegment] = []
    notes: list[str] = []
    for lineno, raw in enumerate(read_text(p).split("\n"), start=1):
        if not raw.strip():
            continue
        parts = raw.rstrip().split("\t") if "\t" in raw else raw.split(maxsplit=5)
        parts = [x.strip() for x in parts]
        if len(parts) < 5:
            raise FormatError(
                p, f"expected at least 5 fields {_FIELDS}, found {len(parts)}: {raw.strip()!r}", line=lineno
            )
        start = parse_number(p, parts[1], lineno, "start")
        end = parse_number(p, parts[2], lineno, "end")
        duration = parse_number(p, parts[3], lineno, "duration")
        score = parse_number(p, parts[4], lineno, "score")
        if not parts[0]:
            raise FormatError(p, "empty gesture type", line=lineno, field="type")
        if (note := check_times(p, lineno, start, end, duration)) is not None:
            notes.append(note)
        if not 0.0 <= score <= 1.0:
            raise FormatError(p, f"score {score} is outside [0, 1]", line=lineno, field="score")
        keywords = " ".join(x for x in parts[5:] if x)
        out.append(SemanticSegment(parts[0], start, end, duration, score, keywords))
    warn_durations(p, notes)
    return out


def segments_to_frames(
    starts: np.ndarray,
    ends: np.ndarray,
    values: np.ndarray,
    n_frames: int,
    fps: float,
    default: float,
    dtype: type,
) -> np.ndarray:
    """Per-frame value of the first segment (in the given order) whose closed ``[start, end]`` holds ``t = i / fps``.

    Parameters
    ----------
    starts, ends, values : (S,) arrays
        Segment times (seconds) and values.
    n_frames : int
        T.
    fps : float
        Frame rate.
    default : float
        Value of frames outside every segment.
    dtype : numpy dtype
        Output dtype.

    Returns
    -------
    (T,) array of ``dtype``

    Examples
    --------
    >>> segments_to_frames(np.array([0.1, 0.25]), np.array([0.3, 0.5]), np.array([1.0, 2.0]),
    ...                    n_frames=6, fps=10, default=0.0, dtype=np.float32)  # the first segment wins at 0.3 s
    array([0., 1., 1., 1., 2., 2.], dtype=float32)
    """
    if isinstance(n_frames, bool) or not isinstance(n_frames, int | np.integer) or n_frames < 0:
        raise ValueError(f"n_frames must be a non-negative integer, got {n_frames!r}")
    if not np.isfinite(fps) or fps <= 0:
        raise ValueError(f"fps must be positive, got {fps!r}")
    t = np.arange(int(n_frames), dtype=np.float64) / float(fps)
    out = np.full(int(n_frames), default, dtype=dtype)
    lo = np.searchsorted(t, np.asarray(starts, dtype=np.float64), side="left")
    hi = np.searchsorted(t, np.asarray(ends, dtype=np.float64), side="right")
    for a, b, v in zip(lo[::-1].tolist(), hi[::-1].tolist(), np.asarray(values)[::-1].tolist()):
        out[a:b] = v  # reversed, so the first segment of the file wins where segments overlap
    return out


def semantic_to_frames(segments: Sequence[SemanticSegment], n_frames: int, fps: float) -> np.ndarray:
    """Semantic score of every frame: the score of the segment containing ``t = i / fps``, else 0.

    Parameters
    ----------
    segments : sequence of SemanticSegment
        From :func:`read_semantic`.
    n_frames : int
        T.
    fps : float
        Frame rate.

    Returns
    -------
    (T,) float32
        Scores in [0, 1] (closed intervals; the first segment wins on overlap, as BEAT's loop does).

    Examples
    --------
    >>> segments = [SemanticSegment("02_deictic_l", 0.1, 0.3, 0.2, 0.5)]
    >>> semantic_to_frames(segments, n_frames=5, fps=10)  # frames at 0.0 .. 0.4 s
    array([0. , 0.5, 0.5, 0.5, 0. ], dtype=float32)
    """
    starts = np.array([s.start for s in segments], dtype=np.float64)
    ends = np.array([s.end for s in segments], dtype=np.float64)
    scores = np.array([s.score for s in segments], dtype=np.float32)
    return segments_to_frames(starts, ends, scores, n_frames, fps, 0.0, np.float32)


def _fmt(value: float) -> str:
    return repr(float(value))


def write_semantic(path: str | os.PathLike[str], segments: Sequence[SemanticSegment]) -> None:
    """Write segments as a BEAT semantic ``.txt`` (TAB-separated, atomic; keywords omitted when empty).

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "take.txt"
    >>> segments = [SemanticSegment("00_nogesture", 0.0, 0.5, 0.5, 0.0),
    ...             SemanticSegment("02_deictic_l", 0.5, 1.0, 0.5, 0.3, "my")]
    >>> write_semantic(path, segments)
    >>> read_semantic(path) == segments
    True
    >>> tmp.cleanup()
    """
    lines = []
    for i, s in enumerate(segments):
        seg = SemanticSegment(*s)
        if not seg.type or any(c in seg.type for c in "\t\n"):
            raise ValueError(f"write_semantic: segment {i} has an invalid type {seg.type!r}")
        if not 0.0 <= seg.score <= 1.0 or seg.start > seg.end:
            raise ValueError(
                f"write_semantic: segment {i} has score {seg.score} / times {seg.start}-{seg.end}"
            )
        fields = [seg.type, _fmt(seg.start), _fmt(seg.end), _fmt(seg.duration), _fmt(seg.score)]
        if seg.keywords:
            fields.append(seg.keywords.replace("\t", " ").replace("\n", " "))
        lines.append("\t".join(fields))
    with atomic_write(path, "w") as f:
        f.write("".join(line + "\n" for line in lines))
