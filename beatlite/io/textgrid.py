"""Praat TextGrid files (word/phone alignments from the Montreal Forced Aligner).

Both Praat text formats are read: the *long* one (``xmin = 1.45`` labels,
as MFA writes it) and the *short* one (bare values), in UTF-8 or UTF-16 with a
byte-order mark, plain or gzipped. The reader ignores labels and reads the
stream of values (quoted strings, numbers, ``<exists>``), which is the same
in both formats. Empty marks (``""``) are silence.

Word-to-frame alignment (:func:`words_to_frames`) implements three documented
rules, all vectorised with :func:`numpy.searchsorted`:

- ``"span"`` (beatlite's default): frame ``i`` at ``t = i / fps`` gets the word
  whose half-open ``[start, end)`` contains ``t``; PAD (0) in silence, UNK (3)
  for a word missing from the vocabulary.
- ``"onset"`` (HA2G / Trimodal, docs/reference_code.md#textgrid): only frame ``floor(start * fps)``
  of each word gets its id; every other frame is PAD.
- ``"beat"`` (BEAT/CaMN's loader, docs/reference_code.md#textgrid): the *first* interval with
  ``start <= t <= end`` (closed) wins, silence included. A mark equal to
  ``" "`` is PAD, but an empty mark ``""`` (MFA silence) is looked up in the
  vocabulary like a word (the reference's ``build_vocab`` indexes ``""``), so
  it gets ``vocab[""]`` if present and UNK otherwise. A frame outside every
  interval is UNK.

Taught in notebooks/01_beat_formats.ipynb, section 9 (the words: a Praat TextGrid); ``words_to_frames`` in notebooks/03_audio_and_text_features.ipynb, section 6 (words to frames: three rules).
"""

from __future__ import annotations

import math
import os
import re
import warnings
from bisect import bisect_right
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np

from beatlite.io.atomic import atomic_write
from beatlite.io.errors import FormatError, FormatWarning
from beatlite.io.textfile import read_text

__all__ = [
    "Interval",
    "WordIntervals",
    "read_textgrid",
    "read_textgrid_tiers",
    "read_words",
    "words_to_frames",
    "write_textgrid",
    "PAD",
    "UNK",
    "RULES",
]

PAD = 0
UNK = 3
RULES = ("span", "onset", "beat")
_EPS = 1e-9  # seconds: tolerance for touching intervals written with rounding


class Interval(NamedTuple):
    """One TextGrid interval: ``[start, end]`` in seconds with its mark (``""`` = silence).

    Points of a ``TextTier`` are read as zero-length intervals (``start == end``).

    Examples
    --------
    >>> Interval(0.0, 0.5, "hello")
    Interval(start=0.0, end=0.5, text='hello')
    """

    start: float
    end: float
    text: str


@dataclass(frozen=True, eq=False)
class WordIntervals:
    """The spoken words of a take (non-empty marks only), in time order.

    Attributes
    ----------
    starts, ends : (W,) float64, seconds
        Word boundaries, sorted and non-overlapping.
    words : tuple of str, length W
        The marks.
    xmax : float or None
        End of the tier (seconds); the tier covers ``[0, xmax]`` (silences included).

    Examples
    --------
    >>> words = WordIntervals(np.array([0.1, 0.6]), np.array([0.4, 0.9]), ("hello", "world"), xmax=1.0)
    >>> words.words, (words.ends - words.starts).round(6).tolist()
    (('hello', 'world'), [0.3, 0.3])
    """

    starts: np.ndarray
    ends: np.ndarray
    words: tuple[str, ...]
    xmax: float | None = None

    def __post_init__(self) -> None:
        starts = np.asarray(self.starts, dtype=np.float64).reshape(-1)
        ends = np.asarray(self.ends, dtype=np.float64).reshape(-1)
        if starts.shape != ends.shape or len(self.words) != starts.size:
            raise ValueError(
                f"WordIntervals: starts {starts.shape}, ends {ends.shape} and {len(self.words)} words differ"
            )
        object.__setattr__(self, "starts", starts)
        object.__setattr__(self, "ends", ends)
        object.__setattr__(self, "words", tuple(self.words))

    def __len__(self) -> int:
        return len(self.words)

    def __repr__(self) -> str:
        head = " ".join(self.words[:8]) + (" ..." if len(self.words) > 8 else "")
        return f"WordIntervals({len(self.words)} words: {head!r})"


# ----------------------------------------------------------------------------- reading

_TOKEN_RE = re.compile(r'"(?:[^"]|"")*"|!.*$|\S+', re.MULTILINE)
_STRING_RE = re.compile(r'"(?:[^"]|"")*"')
_NUMBER_RE = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


class _Values:
    """The value stream of a TextGrid (labels skipped), each value with its line."""

    def __init__(self, text: str, path: Path) -> None:
        self.path = path
        self.line_starts = [0] + [m.end() for m in re.finditer("\n", text)]
        self.last_line = self.line_of(max(len(text.rstrip()) - 1, 0))  # where a file that ends early ends
        self.items: list[tuple[str, str | float, int]] = []  # (kind, value, offset)
        for m in _TOKEN_RE.finditer(text):
            tok = m.group(0)
            if tok.startswith('"'):
                if len(tok) < 2 or not _STRING_RE.fullmatch(tok):
                    raise FormatError(path, f"unterminated string {tok[:40]!r}", line=self.line_of(m.start()))
                self.items.append(("str", tok[1:-1].replace('""', '"'), m.start()))
            elif tok.startswith("!"):
                continue  # short-format comment
            elif tok in ("<exists>", "<absent>"):
                self.items.append(("flag", tok, m.start()))
            elif _NUMBER_RE.fullmatch(tok):
                self.items.append(("num", float(tok), m.start()))
            # anything else is a label (xmin, =, intervals, [1]:, ...)
        self.pos = 0

    def line_of(self, offset: int) -> int:
        return bisect_right(self.line_starts, offset)

    def current_line(self) -> int:
        if self.pos < len(self.items):
            return self.line_of(self.items[self.pos][2])
        return self.last_line

    def take(self, kind: str, what: str) -> tuple[str | float, int]:
        if self.pos >= len(self.items):
            raise FormatError(self.path, f"file ends early: expected {what}", line=self.last_line)
        k, value, offset = self.items[self.pos]
        if k != kind:
            raise FormatError(
                self.path, f"expected {what}, found {value!r}", line=self.line_of(offset), field=what
            )
        self.pos += 1
        return value, self.line_of(offset)

    def number(self, what: str) -> tuple[float, int]:
        value, line = self.take("num", what)
        if not math.isfinite(float(value)):
            raise FormatError(self.path, f"{what} is not a finite number", line=line, field=what)
        return float(value), line

    def string(self, what: str) -> tuple[str, int]:
        value, line = self.take("str", what)
        return str(value), line

    def count(self, what: str) -> tuple[int, int]:
        value, line = self.number(what)
        if value < 0 or value != int(value):
            raise FormatError(self.path, f"{what} must be a whole number, got {value}", line=line)
        if value > len(self.items) - self.pos:  # each counted item needs at least one more value
            raise FormatError(self.path, f"{what} is {value:g}, more than the file holds", line=line)
        return int(value), line


def _extent(values: _Values, what: str) -> tuple[float, float]:
    """``xmin, xmax`` of the TextGrid or of a tier; ``xmin > xmax`` raises."""
    xmin, _ = values.number(f"xmin of {what}")
    xmax, line = values.number(f"xmax of {what}")
    if xmin > xmax:
        raise FormatError(values.path, f"{what}: xmin {xmin} is after xmax {xmax}", line=line, field="xmax")
    return xmin, xmax


def _read_tier(values: _Values, k: int) -> tuple[str, str, list[Interval], list[int]]:
    """Tier ``k`` (0-based): ``(name, class, intervals, line of each interval)``."""
    tier_class, class_line = values.string(f"class of tier {k + 1}")
    name, _ = values.string(f"name of tier {k + 1}")
    _extent(values, f"tier {name!r}")
    n, _ = values.count(f"size of tier {name!r}")
    intervals: list[Interval] = []
    lines: list[int] = []
    if tier_class not in ("IntervalTier", "TextTier"):
        raise FormatError(values.path, f"unknown tier class {tier_class!r}", line=class_line)
    for i in range(n):
        if tier_class == "IntervalTier":
            start, line = values.number(f"xmin of interval {i + 1} of tier {name!r}")
            end, _ = values.number(f"xmax of interval {i + 1} of tier {name!r}")
            mark, _ = values.string(f"text of interval {i + 1} of tier {name!r}")
        else:
            start, line = values.number(f"time of point {i + 1} of tier {name!r}")
            end = start
            mark, _ = values.string(f"mark of point {i + 1} of tier {name!r}")
        intervals.append(Interval(start, end, mark))
        lines.append(line)
    return name, tier_class, intervals, lines


def _warn_outside(path: Path, xmin: float, xmax: float, tiers: list) -> None:
    """One :class:`FormatWarning` for the first interval outside ``[xmin, xmax]``."""
    for name, _, intervals in tiers:
        for i, iv in enumerate(intervals):
            if iv.start < xmin - _EPS or iv.end > xmax + _EPS:
                warnings.warn(
                    f"{path}: tier {name!r}, interval {i + 1} [{iv.start}, {iv.end}] lies outside the "
                    f"TextGrid's [{xmin}, {xmax}]",
                    FormatWarning,
                    stacklevel=3,
                )
                return


def read_textgrid_tiers(
    path: str | os.PathLike[str],
) -> tuple[float, float, list[tuple[str, str, list[Interval]]]]:
    """Read every tier of a TextGrid with its class.

    Returns
    -------
    xmin, xmax : float, seconds
        Extent of the TextGrid.
    tiers : list of (name, class, intervals)
        ``class`` is ``"IntervalTier"`` or ``"TextTier"``, in file order
        (duplicate names are kept).

    Raises
    ------
    FormatError
        Malformed file, infinite times, ``xmin > xmax``, unsorted or overlapping
        intervals. An interval outside ``[xmin, xmax]`` gives a :class:`FormatWarning`.

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "take.TextGrid"
    >>> write_textgrid(path, {"words": [Interval(0.2, 0.5, "hi")]}, 1.0)
    >>> xmin, xmax, tiers = read_textgrid_tiers(path)
    >>> xmin, xmax, [(name, cls, len(intervals)) for name, cls, intervals in tiers]  # gaps filled with ""
    (0.0, 1.0, [('words', 'IntervalTier', 3)])
    >>> tmp.cleanup()
    """
    p = Path(path)
    text = read_text(p, encoding="auto")
    if not text.strip():
        raise FormatError(p, "empty file: expected a Praat TextGrid")
    if "ooBinaryFile" in text[:64]:
        raise FormatError(p, "binary TextGrids are not supported: save as text from Praat", line=1)
    values = _Values(text, p)
    file_type, _ = values.string("File type")
    if file_type != "ooTextFile":
        raise FormatError(p, f"File type is {file_type!r}, expected 'ooTextFile'", line=1)
    object_class, line = values.string("Object class")
    if object_class != "TextGrid":
        raise FormatError(p, f"Object class is {object_class!r}, expected 'TextGrid'", line=line)
    xmin, xmax = _extent(values, "the TextGrid")
    flag, line = values.take("flag", "tiers? <exists>")
    if flag == "<absent>":
        return xmin, xmax, []
    n_tiers, _ = values.count("size (number of tiers)")
    tiers: list[tuple[str, str, list[Interval]]] = []
    for k in range(n_tiers):
        name, tier_class, intervals, lines = _read_tier(values, k)
        _validate_tier(p, name, intervals, lines)
        tiers.append((name, tier_class, intervals))
    if values.pos < len(values.items):
        raise FormatError(
            p, f"unexpected content after the {n_tiers} declared tiers", line=values.current_line()
        )
    _warn_outside(p, xmin, xmax, tiers)
    return xmin, xmax, tiers


def _validate_tier(path: Path, name: str, intervals: list[Interval], lines: list[int]) -> None:
    """Sorted, non-overlapping, start <= end; errors name the tier, the 1-based interval index and line."""
    if not intervals:
        return
    starts = np.array([iv.start for iv in intervals])
    ends = np.array([iv.end for iv in intervals])
    bad = np.flatnonzero(ends < starts)
    if bad.size:
        i = int(bad[0])
        raise FormatError(
            path,
            f"tier {name!r}, interval {i + 1}: end {ends[i]} is before start {starts[i]}",
            line=lines[i],
        )
    bad = np.flatnonzero(starts[1:] < ends[:-1] - _EPS)
    if bad.size:
        i = int(bad[0]) + 1
        raise FormatError(
            path,
            f"tier {name!r}, interval {i + 1} [{starts[i]}, {ends[i]}] overlaps or precedes "
            f"interval {i} [{starts[i - 1]}, {ends[i - 1]}] (intervals must be sorted and not overlap)",
            line=lines[i],
        )


def read_textgrid(path: str | os.PathLike[str]) -> dict[str, list[Interval]]:
    """Read a Praat TextGrid (long or short text format, UTF-8/UTF-16, ``.gz`` transparent).

    Parameters
    ----------
    path : str or PathLike
        The ``.TextGrid`` file.

    Returns
    -------
    dict str -> list of Interval
        Tier name -> intervals in time order (seconds; ``""`` marks are
        silence). A repeated tier name gets a suffix ``" (2)"``, ``" (3)"``.

    Raises
    ------
    FormatError
        Malformed file, or intervals that are unsorted/overlapping (naming the
        tier, the 1-based interval index and the line).

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "take.TextGrid"
    >>> write_textgrid(path, {"words": [Interval(0.2, 0.5, "hi")]}, 1.0)
    >>> for interval in read_textgrid(path)["words"]:  # gaps filled with "" (silence)
    ...     print(interval)
    Interval(start=0.0, end=0.2, text='')
    Interval(start=0.2, end=0.5, text='hi')
    Interval(start=0.5, end=1.0, text='')
    >>> tmp.cleanup()
    """
    _, _, tiers = read_textgrid_tiers(path)
    out: dict[str, list[Interval]] = {}
    for name, _, intervals in tiers:
        key, k = name, 1
        while key in out:
            k += 1
            key = f"{name} ({k})"
        out[key] = intervals
    return out


def read_words(path: str | os.PathLike[str], tier: str | int = "words") -> WordIntervals:
    """The non-empty words of one tier.

    Parameters
    ----------
    path : str or PathLike
        The TextGrid.
    tier : str or int
        Tier name (MFA: ``"words"``) or 0-based position (BEAT's loader uses tier 0).

    Returns
    -------
    WordIntervals
        Marks that are not blank, with their start/end seconds and the tier's ``xmax``.

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "take.TextGrid"
    >>> write_textgrid(path, {"words": [Interval(0.2, 0.5, "hi"), Interval(0.6, 0.9, "there")]}, 1.0)
    >>> words = read_words(path)  # silences dropped
    >>> words.words, words.starts.tolist(), words.xmax
    (('hi', 'there'), [0.2, 0.6], 1.0)
    >>> tmp.cleanup()
    """
    p = Path(path)
    _, xmax, tiers = read_textgrid_tiers(p)
    names = [t[0] for t in tiers]
    if isinstance(tier, int):
        if not -len(tiers) <= tier < len(tiers):
            raise FormatError(p, f"no tier {tier}: the file has {len(tiers)} tiers {names}", field="tier")
        chosen = tiers[tier][2]
    else:
        if tier not in names:
            raise FormatError(p, f"no tier named {tier!r}; tiers are {names}", field=tier)
        chosen = tiers[names.index(tier)][2]
    kept = [iv for iv in chosen if iv.text.strip()]
    return WordIntervals(
        starts=np.array([iv.start for iv in kept], dtype=np.float64),
        ends=np.array([iv.end for iv in kept], dtype=np.float64),
        words=tuple(iv.text for iv in kept),
        xmax=float(xmax),
    )


# ----------------------------------------------------------------------------- alignment


def _lookup(vocab: Mapping[str, int], words: Sequence[str], unk: int) -> np.ndarray:
    get = getattr(vocab, "get", None)
    ids = np.empty(len(words), dtype=np.int64)
    for k, w in enumerate(words):
        if get is not None:
            value = get(w, unk)
        else:
            try:
                value = vocab[w]
            except KeyError:
                value = unk
        ids[k] = unk if value is None else int(value)
    return ids


def _as_arrays(
    words: WordIntervals | Sequence[Interval],
) -> tuple[np.ndarray, np.ndarray, list[str], float | None]:
    if isinstance(words, WordIntervals):
        return words.starts, words.ends, list(words.words), words.xmax
    if isinstance(words, str | bytes) or not isinstance(words, Sequence):
        raise TypeError(f"words must be WordIntervals or a sequence of Interval, got {type(words).__name__}")
    starts = np.array([float(iv[0]) for iv in words], dtype=np.float64)
    ends = np.array([float(iv[1]) for iv in words], dtype=np.float64)
    marks = [str(iv[2]) for iv in words]
    return starts, ends, marks, (float(ends[-1]) if len(marks) else None)


def words_to_frames(
    words: WordIntervals | Sequence[Interval],
    n_frames: int,
    fps: float,
    vocab: Mapping[str, int],
    *,
    rule: str = "span",
    unk: int = UNK,
    pad: int = PAD,
    offset: float = 0.0,
) -> np.ndarray:
    """Word id of every frame, by one of the documented rules (see the module docstring).

    Parameters
    ----------
    words : WordIntervals or sequence of Interval
        The words (from :func:`read_words`) or a whole tier with its ``""``
        silences (from :func:`read_textgrid`); both must be sorted and not overlap.
        For ``"span"`` and ``"onset"`` blank marks are silence. For ``"beat"``
        a :class:`WordIntervals` is completed with ``""`` silence intervals
        over ``[0, xmax]`` (as MFA writes them) before applying the rule.
    n_frames : int
        Number of frames T.
    fps : float
        Frame rate; frame ``i`` is at ``t = i / fps + offset`` seconds.
    vocab : Mapping[str, int]
        Word -> id; looked up with the raw mark (no case folding).
    rule : {"span", "onset", "beat"}
        Alignment rule.
    unk, pad : int
        Ids of unknown words and of silence.
    offset : float
        Seconds added to every frame time (BEAT's ``_b`` halves use 30 s or 300 s).

    Returns
    -------
    (T,) int64
        Word ids.

    Examples
    --------
    >>> words = WordIntervals(np.array([0.1]), np.array([0.3]), ("hi",), xmax=0.5)
    >>> words_to_frames(words, n_frames=5, fps=10, vocab={"hi": 7})  # frames at 0.0 .. 0.4 s; end excluded
    array([0, 7, 7, 0, 0])
    """
    if rule not in RULES:
        raise ValueError(f"words_to_frames: rule must be one of {RULES}, got {rule!r}")
    if isinstance(n_frames, bool) or not isinstance(n_frames, int | np.integer) or n_frames < 0:
        raise ValueError(f"words_to_frames: n_frames must be a non-negative integer, got {n_frames!r}")
    if not np.isfinite(fps) or fps <= 0:
        raise ValueError(f"words_to_frames: fps must be positive, got {fps!r}")
    starts, ends, marks, xmax = _as_arrays(words)
    t = np.arange(int(n_frames), dtype=np.float64) / float(fps) + float(offset)
    out = np.full(int(n_frames), pad, dtype=np.int64)
    if rule == "beat":
        return _beat_rule(starts, ends, marks, xmax, isinstance(words, WordIntervals), t, vocab, unk, pad)
    keep = np.array([bool(m.strip()) for m in marks], dtype=bool)
    starts, ends = starts[keep], ends[keep]
    marks = [m for m, k in zip(marks, keep) if k]
    if not marks:
        return out
    ids = _lookup(vocab, marks, unk)
    if rule == "span":
        k = np.searchsorted(starts, t, side="right") - 1
        inside = (k >= 0) & (t < ends[np.maximum(k, 0)])
        out[inside] = ids[k[inside]]
        return out
    # onset: frame floor((start - offset) * fps); a later word on the same frame wins
    frames = np.floor((starts - float(offset)) * float(fps) + 1e-9).astype(np.int64)
    valid = (frames >= 0) & (frames < n_frames)
    frames, ids = frames[valid], ids[valid]
    last = np.unique(frames[::-1], return_index=True)[1]  # first in reversed order = last word
    out[frames[::-1][last]] = ids[::-1][last]
    return out


def _beat_rule(
    starts: np.ndarray,
    ends: np.ndarray,
    marks: list[str],
    xmax: float | None,
    fill_gaps: bool,
    t: np.ndarray,
    vocab: Mapping[str, int],
    unk: int,
    pad: int,
) -> np.ndarray:
    if fill_gaps:  # rebuild the MFA tier: "" silences between words and up to xmax
        s, e, m = [], [], []
        cursor = 0.0
        for a, b, w in zip(starts.tolist(), ends.tolist(), marks):
            if a > cursor:
                s.append(cursor), e.append(a), m.append("")
            s.append(a), e.append(b), m.append(w)
            cursor = b
        if xmax is not None and xmax > cursor:
            s.append(cursor), e.append(xmax), m.append("")
        starts, ends, marks = np.array(s, dtype=np.float64), np.array(e, dtype=np.float64), m
    out = np.full(t.shape, unk, dtype=np.int64)
    if not marks:
        return out
    ids = _lookup(vocab, marks, unk)
    ids[np.array([m == " " for m in marks], dtype=bool)] = pad
    # first interval (lowest index) with start <= t <= end: ends are sorted, so it is the first end >= t
    k = np.searchsorted(ends, t, side="left")
    kk = np.minimum(k, len(marks) - 1)
    inside = (k < len(marks)) & (starts[kk] <= t)
    out[inside] = ids[kk[inside]]
    return out


# ----------------------------------------------------------------------------- writing


def _fmt(value: float | int) -> str:
    if isinstance(value, int | np.integer) and not isinstance(value, bool):
        return str(int(value))
    return repr(float(value))


def _quote(text: str) -> str:
    return '"' + text.replace('"', '""') + '"'


def write_textgrid(
    path: str | os.PathLike[str],
    tiers: Mapping[str, Sequence[Interval]],
    xmax: float,
    *,
    xmin: float = 0.0,
) -> None:
    """Write interval tiers as a long-format TextGrid, laid out as MFA writes it (atomic).

    Parameters
    ----------
    path : str or PathLike
        Destination (``.gz`` suffix gzips).
    tiers : Mapping[str, sequence of Interval]
        Tier name -> sorted, non-overlapping intervals (seconds). Gaps are filled
        with ``""`` intervals so that each tier covers ``[xmin, xmax]``, as Praat requires.
    xmax : float
        End of the TextGrid in seconds (an ``int`` is written without decimals, like MFA's ``62``).
    xmin : float
        Start, default 0.

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "take.TextGrid"
    >>> write_textgrid(path, {"words": [Interval(0.25, 0.5, "hi")]}, 1)
    >>> print(path.read_text()[:60])
    File type = "ooTextFile"
    Object class = "TextGrid"
    <BLANKLINE>
    xmin = 0
    >>> read_words(path).words
    ('hi',)
    >>> tmp.cleanup()
    """
    if not np.isfinite(xmax) or xmax < xmin:
        raise ValueError(f"write_textgrid: xmax must be >= xmin ({xmin}), got {xmax!r}")
    lines = [
        'File type = "ooTextFile"',
        'Object class = "TextGrid"',
        "",
        f"xmin = {_fmt(xmin)}",
        f"xmax = {_fmt(xmax)}",
        "tiers? <exists>",
        f"size = {len(tiers)}",
        "item []:",
    ]
    for k, (name, intervals) in enumerate(tiers.items(), start=1):
        filled = _fill_gaps(str(name), [Interval(*iv) for iv in intervals], xmin, xmax)
        lines += [
            f"\titem [{k}]:",
            '\t\tclass = "IntervalTier"',
            f"\t\tname = {_quote(str(name))}",
            f"\t\txmin = {_fmt(xmin)}",
            f"\t\txmax = {_fmt(xmax)}",
            f"\t\tintervals: size = {len(filled)}",
        ]
        for i, iv in enumerate(filled, start=1):
            lines += [
                f"\t\t\tintervals [{i}]:",
                f"\t\t\t\txmin = {_fmt(iv.start)}",
                f"\t\t\t\txmax = {_fmt(iv.end)}",
                f"\t\t\t\ttext = {_quote(iv.text)}",
            ]
    with atomic_write(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def _fill_gaps(name: str, intervals: list[Interval], xmin: float, xmax: float) -> list[Interval]:
    out: list[Interval] = []
    cursor: float = xmin
    for i, iv in enumerate(intervals):
        if not (np.isfinite(iv.start) and np.isfinite(iv.end)) or iv.end < iv.start:
            raise ValueError(f"write_textgrid: tier {name!r} interval {i} has invalid times {iv[:2]}")
        if iv.start < cursor - _EPS:
            raise ValueError(
                f"write_textgrid: tier {name!r} interval {i} starts at {iv.start} before {cursor} "
                "(intervals must be sorted, non-overlapping and within [xmin, xmax])"
            )
        if iv.start > cursor + _EPS:
            out.append(Interval(cursor, iv.start, ""))
        out.append(iv)
        cursor = iv.end
    if cursor > xmax + _EPS:
        raise ValueError(f"write_textgrid: tier {name!r} ends at {cursor} after xmax {xmax}")
    if cursor < xmax - _EPS:
        out.append(Interval(cursor, xmax, ""))
    return out
