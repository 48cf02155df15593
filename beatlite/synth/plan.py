"""Gesture planning: from timed words to beats, semantic gestures and annotation segments.

Rules (all times in seconds):

- A *phrase* is a run of words whose gaps are all shorter than :data:`PHRASE_GAP_S`.
- A keyword of :data:`beatlite.synth.transcripts.KEYWORDS` gets its scripted semantic gesture
  when the gesture's preparation (``PREP_S / speed`` before the word onset, longer for the
  far-travelling kinds of :data:`SLOW_KINDS`) starts at least
  ``0.15`` s after the previous semantic gesture ended; its stroke ends exactly at the word onset
  and it is held until ``max(word end, onset + MIN_HOLD_S)``.
- Every other word starting at least ``0.3 / tempo`` s after the previous beat (and after any
  semantic gesture) gets a *beat*: the stroke ends (hand speed minimum) exactly at the word onset.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from beatlite.synth.styles import EMOTION_STYLES, SEMANTIC_SCORES, SpeakerStyle
from beatlite.synth.transcripts import KEYWORDS

PHRASE_GAP_S = 0.9
"""Pauses longer than this end a gesture phrase (hands return towards rest)."""
PREP_S = 0.45
"""Preparation time of a semantic gesture at speed 1, seconds."""
MIN_HOLD_S = 0.35
"""Shortest hold of a semantic gesture, seconds."""
RETRACT_S = 0.6
"""Retraction time of a semantic gesture at speed 1, seconds."""
SLOW_KINDS = {"up": 1.6, "big": 1.3, "everything": 1.3, "idea": 1.3}
"""Gestures whose hands travel far: preparation and retraction take this much longer."""


@dataclass(frozen=True)
class TimedWord:
    """A spoken word: ``start``/``end`` in seconds, its text and the emotion id it was spoken in."""

    start: float
    end: float
    word: str
    emotion: int


@dataclass(frozen=True)
class Beat:
    """A beat stroke ending (speed minimum) at ``time`` s.

    ``amplitude`` is in centimetres; ``stroke`` and ``prep`` are durations in seconds.
    """

    time: float
    amplitude: float
    stroke: float
    prep: float


@dataclass(frozen=True)
class Gesture:
    """A scripted semantic gesture.

    Attributes
    ----------
    kind : str
        One of :data:`beatlite.synth.transcripts.GESTURE_KINDS`.
    onset : float
        Word onset = end of the stroke, seconds.
    hold_end : float
        End of the hold, seconds.
    ramp_in, ramp_out : float
        Preparation and retraction durations, seconds.
    word : str
        The keyword.
    label : str
        BEAT semantic type, e.g. ``"07_iconic_h"``.
    amplitude : float
        Emotion x speaker excursion multiplier.
    """

    kind: str
    onset: float
    hold_end: float
    ramp_in: float
    ramp_out: float
    word: str
    label: str
    amplitude: float

    @property
    def start(self) -> float:
        """Start of the preparation, seconds."""
        return self.onset - self.ramp_in

    @property
    def end(self) -> float:
        """End of the retraction, seconds."""
        return self.hold_end + self.ramp_out


@dataclass(frozen=True)
class Plan:
    """Everything the motion and the annotations are generated from.

    Attributes
    ----------
    words : tuple of TimedWord
    phrases : tuple of (start, end)
        Speech phrases, seconds.
    beats : tuple of Beat
    gestures : tuple of Gesture
    duration : float
        Take length, seconds.
    """

    words: tuple[TimedWord, ...]
    phrases: tuple[tuple[float, float], ...]
    beats: tuple[Beat, ...]
    gestures: tuple[Gesture, ...]
    duration: float


def find_phrases(words: Sequence[TimedWord], gap: float = PHRASE_GAP_S) -> list[tuple[float, float]]:
    """Group words into phrases separated by pauses longer than ``gap`` seconds.

    Parameters
    ----------
    words : sequence of TimedWord
        In time order.
    gap : float
        Pause length that ends a phrase, seconds.

    Returns
    -------
    list of (start, end) in seconds.
    """
    phrases: list[tuple[float, float]] = []
    for w in words:
        if phrases and w.start - phrases[-1][1] < gap:
            phrases[-1] = (phrases[-1][0], w.end)
        else:
            phrases.append((w.start, w.end))
    return phrases


def make_plan(
    words: Sequence[TimedWord], speaker: SpeakerStyle, duration: float, rng: np.random.Generator
) -> Plan:
    """Choose the beats and semantic gestures of a take.

    Parameters
    ----------
    words : sequence of TimedWord
        The spoken words in time order.
    speaker : SpeakerStyle
    duration : float
        Take length, seconds.
    rng : numpy.random.Generator

    Returns
    -------
    Plan
    """
    beats: list[Beat] = []
    gestures: list[Gesture] = []
    last_beat = -np.inf
    busy_until = -np.inf  # end of the last semantic gesture's retraction
    min_gap = 0.3 / speaker.tempo
    for w in words:
        emo = EMOTION_STYLES[w.emotion]
        speed = emo.speed * speaker.tempo
        kw = KEYWORDS.get(w.word)
        if kw is not None:
            ramp_in = PREP_S * SLOW_KINDS.get(kw[0], 1.0) / speed
            accept = w.start - ramp_in >= busy_until + 0.15 and w.start - ramp_in >= 0.05
            if kw[0] == "chest":  # "I" is frequent: not every one gets the gesture
                accept = accept and rng.random() < 0.7
            if accept:
                hold_end = max(w.end, w.start + MIN_HOLD_S)
                if kw[0] == "circle":
                    hold_end = max(hold_end, w.start + 0.9 / speed)
                g = Gesture(
                    kind=kw[0],
                    onset=w.start,
                    hold_end=hold_end,
                    ramp_in=ramp_in,
                    ramp_out=RETRACT_S * SLOW_KINDS.get(kw[0], 1.0) / speed,
                    word=w.word,
                    label=kw[1],
                    amplitude=float(np.clip(emo.amplitude * speaker.amplitude, 0.6, 1.3)),
                )
                gestures.append(g)
                busy_until = g.end
                continue
        if w.start - last_beat >= min_gap and w.start - 0.25 >= busy_until and w.start > 0.3:
            if len(w.word) >= 3 or rng.random() < 0.5:
                amp = 5.0 * emo.amplitude * speaker.amplitude * rng.uniform(0.8, 1.2)
                beats.append(Beat(time=w.start, amplitude=amp, stroke=0.2 / speed, prep=0.3 / speed))
                last_beat = w.start
    return Plan(
        words=tuple(words),
        phrases=tuple(find_phrases(words)),
        beats=tuple(beats),
        gestures=tuple(gestures),
        duration=float(duration),
    )


def semantic_segments(plan: Plan) -> list[tuple[str, float, float, float, str]]:
    """The BEAT semantic annotation of a plan, tiling ``[0, duration]``.

    Semantic gestures span preparation to retraction; runs of beats span from the first
    beat's preparation to 0.2 s after the last beat (label ``01_beat_align``); everything else
    is ``00_nogesture``.

    Parameters
    ----------
    plan : Plan

    Returns
    -------
    list of (label, start, end, score, keyword)
        Contiguous, non-overlapping, rounded to milliseconds.
    """
    marks: list[tuple[float, float, str, str]] = []
    for g in plan.gestures:
        marks.append((max(g.start, 0.0), min(g.end, plan.duration), g.label, g.word))
    # beat runs: consecutive beats closer than 1.2 s, cut by semantic gestures
    runs: list[list[float]] = []
    for b in plan.beats:
        if runs and b.time - runs[-1][1] < 1.2:
            runs[-1][1] = b.time
        else:
            runs.append([b.time - b.stroke - b.prep, b.time])
    for start, end in runs:
        marks.append((max(start, 0.0), min(end + 0.2, plan.duration), "01_beat_align", ""))
    marks.sort()
    out: list[tuple[str, float, float, float, str]] = []
    t = 0.0
    for start, end, label, word in marks:
        start = max(start, t)
        if end - start < 0.05:
            continue
        if start - t >= 0.01:
            out.append(("00_nogesture", t, start, 0.0, ""))
        else:
            start = t
        out.append((label, start, end, SEMANTIC_SCORES[label], word))
        t = end
    if plan.duration - t >= 0.01:
        out.append(("00_nogesture", t, plan.duration, 0.0, ""))
    return [(lab, round(s, 3), round(e, 3), sc, kw) for lab, s, e, sc, kw in out]
