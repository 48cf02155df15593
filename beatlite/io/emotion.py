"""BEAT emotion annotations (``.csv``, comma-separated, no header; docs/reference_code.md#emotion-annotations).

Each line is ``name,start,end,duration,class`` with ``class`` in 0..7
(neutral, happiness, anger, sadness, contempt, surprise, fear, disgust).

Taught in notebooks/01_beat_formats.ipynb, section 10 (semantic relevance and emotion annotations).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import NamedTuple

import numpy as np

from beatlite.io.atomic import atomic_write
from beatlite.io.errors import FormatError
from beatlite.io.semantic import check_times, parse_number, segments_to_frames, warn_durations
from beatlite.io.textfile import read_text

__all__ = ["EmotionSegment", "read_emotion", "write_emotion", "emotion_to_frames", "N_EMOTIONS"]

N_EMOTIONS = 8


class EmotionSegment(NamedTuple):
    """One emotion span: a label ``name``, times in seconds and the class ``emotion`` in 0..7.

    Examples
    --------
    >>> seg = EmotionSegment("happiness", 0.0, 2.5, 2.5, 1)
    >>> seg.name, seg.end - seg.start, seg.emotion
    ('happiness', 2.5, 1)
    """

    name: str
    start: float
    end: float
    duration: float
    emotion: int


def read_emotion(path: str | os.PathLike[str]) -> list[EmotionSegment]:
    r"""Read a BEAT emotion ``.csv`` file (``.gz`` transparent).

    Returns
    -------
    list of EmotionSegment
        In file order.

    Raises
    ------
    FormatError
        An empty file (no row: not "neutral"), not 5 fields, a non-numeric field, a
        negative time, ``start > end`` or a class that is not a whole number in 0..7,
        naming the line and the field. Rows whose ``duration`` is not
        ``end - start`` give one :class:`FormatWarning`.

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "take.csv"
    >>> _ = path.write_text("neutral,0.0,14.8,14.8,0\n")
    >>> read_emotion(path)
    [EmotionSegment(name='neutral', start=0.0, end=14.8, duration=14.8, emotion=0)]
    >>> tmp.cleanup()
    """
    p = Path(path)
    out: list[EmotionSegment] = []
    notes: list[str] = []
    for lineno, raw in enumerate(read_text(p).split("\n"), start=1):
        if not raw.strip():
            continue
        parts = [x.strip() for x in raw.split(",")]
        if len(parts) != 5:
            raise FormatError(
                p,
                f"expected 5 comma-separated fields (name,start,end,duration,class), found {len(parts)}",
                line=lineno,
            )
        start = parse_number(p, parts[1], lineno, "start")
        end = parse_number(p, parts[2], lineno, "end")
        duration = parse_number(p, parts[3], lineno, "duration")
        value = parse_number(p, parts[4], lineno, "class")
        if (note := check_times(p, lineno, start, end, duration)) is not None:
            notes.append(note)
        if value != int(value) or not 0 <= value < N_EMOTIONS:
            raise FormatError(
                p,
                f"emotion class {parts[4]!r} is not an integer in 0..{N_EMOTIONS - 1}",
                line=lineno,
                field="class",
            )
        out.append(EmotionSegment(parts[0], start, end, duration, int(value)))
    if not out:
        raise FormatError(p, "no emotion rows (an empty file is not 'neutral'; delete it instead)")
    warn_durations(p, notes)
    return out


def emotion_to_frames(
    segments: Sequence[EmotionSegment], n_frames: int, fps: float, default: int = 0
) -> np.ndarray:
    """Emotion class of every frame: the class of the segment whose ``[start, end]`` holds ``t = i / fps``.

    Parameters
    ----------
    segments : sequence of EmotionSegment
        From :func:`read_emotion`.
    n_frames : int
        T.
    fps : float
        Frame rate.
    default : int
        Class of frames outside every segment (BEAT: 0, neutral).

    Returns
    -------
    (T,) int64

    Examples
    --------
    >>> segments = [EmotionSegment("happiness", 0.2, 0.4, 0.2, 1)]
    >>> emotion_to_frames(segments, n_frames=6, fps=10)  # frames at 0.0, 0.1, ..., 0.5 s
    array([0, 0, 1, 1, 1, 0])
    """
    starts = np.array([s.start for s in segments], dtype=np.float64)
    ends = np.array([s.end for s in segments], dtype=np.float64)
    classes = np.array([s.emotion for s in segments], dtype=np.int64)
    return segments_to_frames(starts, ends, classes, n_frames, fps, default, np.int64)


def write_emotion(path: str | os.PathLike[str], segments: Sequence[EmotionSegment]) -> None:
    """Write segments as a BEAT emotion ``.csv`` (atomic).

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "take.csv"
    >>> segments = [EmotionSegment("neutral", 0.0, 1.5, 1.5, 0), EmotionSegment("anger", 1.5, 3.0, 1.5, 3)]
    >>> write_emotion(path, segments)
    >>> read_emotion(path) == segments
    True
    >>> tmp.cleanup()
    """
    lines = []
    for i, s in enumerate(segments):
        seg = EmotionSegment(*s)
        if "," in seg.name or "\n" in seg.name:
            raise ValueError(f"write_emotion: segment {i} name {seg.name!r} contains a comma or newline")
        if not 0 <= int(seg.emotion) < N_EMOTIONS or seg.start > seg.end:
            raise ValueError(
                f"write_emotion: segment {i} has class {seg.emotion} / times {seg.start}-{seg.end}"
            )
        lines.append(
            f"{seg.name},{float(seg.start)!r},{float(seg.end)!r},{float(seg.duration)!r},{int(seg.emotion)}"
        )
    with atomic_write(path, "w") as f:
        f.write("".join(line + "\n" for line in lines))
