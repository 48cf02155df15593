"""Writing a take's TextGrid, semantic ``.txt`` and emotion ``.csv`` through :mod:`beatlite.io`."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence

from beatlite.io import EmotionSegment, Interval, SemanticSegment
from beatlite.io import write_emotion as _write_emotion
from beatlite.io import write_semantic as _write_semantic
from beatlite.io import write_textgrid as _write_textgrid


def write_textgrid(
    path: str | os.PathLike[str], tiers: Mapping[str, Sequence[tuple[float, float, str]]], xmax: float
) -> None:
    """Long-format MFA-style TextGrid; ``tiers`` maps tier name -> (start s, end s, text), words tier first."""
    _write_textgrid(path, {k: [Interval(*iv) for iv in v] for k, v in tiers.items()}, xmax)


def write_semantic(
    path: str | os.PathLike[str], rows: Sequence[tuple[str, float, float, float, str]]
) -> None:
    """BEAT semantic ``.txt`` from rows ``(type, start s, end s, score, keyword or "")``."""
    _write_semantic(path, [SemanticSegment(t, s, e, round(e - s, 3), sc, kw) for t, s, e, sc, kw in rows])


def write_emotion(path: str | os.PathLike[str], rows: Sequence[tuple[str, float, float, int]]) -> None:
    """BEAT emotion ``.csv`` from rows ``(name, start s, end s, emotion id 0..7)``."""
    _write_emotion(path, [EmotionSegment(n, s, e, round(e - s, 3), int(emo)) for n, s, e, emo in rows])
