"""Gesture planning: from timed words to beats, semantic gestures and annotation segments.

Rules (all times in seconds):

- A *phrase* is a run of words whose gaps are all shorter than :data:`PHRASE_GAP_S`.
- A keyword of :data:`beatlite.synth.transcripts.KEYWORDS` gets its scripted semantic gesture
  when the gesture's preparation (``PREP_S / speed`` before the word onset, longer for the
  far-travelling kinds of :data:`SLOW_KINDS`) starts at least
  ``0.15`` s after the previous semantic gesture ended; its stroke ends exactly at the word onset
  and it is held until ``max(word end, onset + MIN_HOLD_S)``.
- Every other word gets a *beat* on its first acoustic onset (the onset detected in the take's
  audio within the word, :func:`beatlite.synth.onsets.speech_onsets`; the word onset itself when
  no onsets are given), and a long word may get a second beat on a later onset (a stressed
  syllable), when the beat comes at least :data:`MIN_BEAT_GAP_S` after the previous beat,
  0.25 s after any semantic gesture and after 0.3 s; words of one or two letters only half of the
  time. Beats come ~1.5-2.5 per second of speech and every beat sits on an audio onset: the hand
  speed is zero there (:func:`beatlite.synth.motion.beat_lift`).

Part of the corpus generator :mod:`beatlite.synth`, which no notebook teaches (``data_samples/README.md`` describes its rules).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

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
MIN_BEAT_GAP_S = 0.35
"""Shortest time between two beats, seconds (at speaker tempo 1; divided by tempos below 1)."""
ONSET_SNAP_S = 0.03
"""An onset counts as a word's when it lies in ``[start - ONSET_SNAP_S, end - 0.05]``, seconds."""
ACCENT_GAP_S = 0.2
"""Shortest time between an accent and the neighbouring beat or accent, seconds (3 frames at 15 fps)."""
ACCENT_DEPTH = 0.15
"""Hand speed at an accent, as a fraction of the loop's peak speed profile."""
GESTURE_GAP_S = 1.0
"""Shortest time from a semantic gesture's end to the next one's preparation, seconds (room for beats)."""
LOOP_S = 1.2
"""Longest beat loop at gesture speed 1, seconds (``prep + stroke`` of a :class:`Beat`)."""
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
    """A beat: the hand stops at ``time`` s (an audio onset) at the end of its loop.

    ``amplitude`` is the loop's height in centimetres; ``prep + stroke`` (seconds) is the loop's
    duration (its rising and falling halves; shortened to the time since the previous beat when
    that is shorter, see :func:`beatlite.synth.motion.beat_lift`). ``accents`` are the times (s,
    increasing, inside the loop) of the further syllable onsets the loop passes: the hand slows
    there (a shallow speed minimum, :data:`ACCENT_DEPTH` of the peak) without stopping.
    """

    time: float
    amplitude: float
    stroke: float
    prep: float
    accents: tuple[float, ...] = ()


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
    accents : tuple of float
        Syllable onsets (s) inside the preparation or the retraction: the hand slows there.
    """

    kind: str
    onset: float
    hold_end: float
    ramp_in: float
    ramp_out: float
    word: str
    label: str
    amplitude: float
    accents: tuple[float, ...] = ()

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
    syllables : tuple of float
        Audio onsets at least :data:`ACCENT_GAP_S` apart, seconds: the torso bobs between them
        (:func:`beatlite.synth.motion.syllable_pulse`).
    """

    words: tuple[TimedWord, ...]
    phrases: tuple[tuple[float, float], ...]
    beats: tuple[Beat, ...]
    gestures: tuple[Gesture, ...]
    duration: float
    syllables: tuple[float, ...] = ()


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

    Examples
    --------
    A 0.1-s gap stays inside a phrase, a 1.5-s pause starts a new one:

    >>> find_phrases([TimedWord(0.0, 0.4, "we", 0), TimedWord(0.5, 1.0, "walked", 0),
    ...               TimedWord(2.5, 3.0, "home", 0)])
    [(0.0, 1.0), (2.5, 3.0)]
    """
    phrases: list[tuple[float, float]] = []
    for w in words:
        if phrases and w.start - phrases[-1][1] < gap:
            phrases[-1] = (phrases[-1][0], w.end)
        else:
            phrases.append((w.start, w.end))
    return phrases


@dataclass
class _PlanState:
    """What :func:`make_plan` has placed so far (mutated word by word)."""

    beats: list[Beat] = field(default_factory=list)
    gestures: list[Gesture] = field(default_factory=list)
    last_beat: float = -np.inf
    """Last zero-speed point of the hand: a beat or a gesture's retraction end, seconds."""
    busy_until: float = -np.inf
    """End of the last semantic gesture's retraction, seconds."""
    pending: list[float] = field(default_factory=list)
    """Onsets since the last beat: accents of the next beat's loop, seconds."""


def make_plan(
    words: Sequence[TimedWord],
    speaker: SpeakerStyle,
    duration: float,
    rng: np.random.Generator,
    onsets: Sequence[float] | np.ndarray | None = None,
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
    onsets : (K,) float, optional
        Acoustic onsets of the take's audio, seconds (increasing). Beats are placed on them;
        without them, on the word onsets.

    Returns
    -------
    Plan

    Examples
    --------
    "idea" is a keyword: its gesture's stroke ends on the word (2.4 s), its preparation takes
    ``PREP_S x 1.3 = 0.585`` s (a far-travelling kind, :data:`SLOW_KINDS`) and its retraction
    ``RETRACT_S x 1.3 = 0.78`` s after the word's end (2.9 s); the beats before it sit on word
    onsets, and "works" (3.5 s) comes too soon after the retraction for one ("we", two letters,
    gets a beat only half of the time).

    >>> from beatlite.synth.styles import SPEAKERS
    >>> timing = [(0.5, 0.9, "we"), (1.0, 1.5, "walked"), (1.6, 2.0, "home"), (2.4, 2.9, "idea"),
    ...           (3.5, 4.0, "works")]
    >>> words = [TimedWord(start, end, word, 0) for start, end, word in timing]  # all neutral
    >>> plan = make_plan(words, SPEAKERS[2], 5.0, np.random.default_rng(0))
    >>> [b.time for b in plan.beats]
    [1.0, 1.6]
    >>> [(g.kind, g.onset, round(g.start, 3), round(g.end, 3)) for g in plan.gestures]
    [('idea', 2.4, 1.815, 3.68)]
    >>> plan.phrases
    ((0.5, 4.0),)

    Given the audio's onsets, the beats move onto them:

    >>> onsets = [0.52, 1.02, 1.62, 2.42, 3.52]
    >>> [b.time for b in make_plan(words, SPEAKERS[2], 5.0, np.random.default_rng(0), onsets=onsets).beats]
    [1.02, 1.62]
    """
    onset_arr = None if onsets is None else merge_onsets(onsets)
    state = _PlanState()
    min_gap = MIN_BEAT_GAP_S / min(speaker.tempo, 1.0)
    for w in words:
        candidates = _word_onsets(w, onset_arr)
        kw = KEYWORDS.get(w.word)
        if kw is not None and _add_gesture(state, w, kw, candidates, speaker, onset_arr, rng):
            continue
        _add_beats(state, w, candidates, speaker, min_gap, rng)
    return Plan(
        words=tuple(words),
        phrases=tuple(find_phrases(words)),
        beats=tuple(state.beats),
        gestures=tuple(state.gestures),
        duration=float(duration),
        syllables=_accents(onset_arr, 0.3 - ACCENT_GAP_S, float(duration) + ACCENT_GAP_S),
    )


def _word_onsets(w: TimedWord, onsets: np.ndarray | None) -> list[float]:
    """The onsets (s) that belong to word ``w`` (see :data:`ONSET_SNAP_S`); ``[w.start]`` without onsets."""
    if onsets is None:
        return [w.start]
    inside = (onsets >= w.start - ONSET_SNAP_S) & (onsets <= w.end - 0.05)
    return [float(x) for x in onsets[inside]]


def _add_gesture(
    state: _PlanState,
    w: TimedWord,
    kw: tuple[str, str],
    candidates: list[float],
    speaker: SpeakerStyle,
    onsets: np.ndarray | None,
    rng: np.random.Generator,
) -> bool:
    """Give keyword ``w`` its semantic gesture ``kw = (kind, label)`` when there is room.

    The gesture replaces the beats after its preparation start. Returns whether it was added.
    """
    emo = EMOTION_STYLES[w.emotion]
    speed = emo.speed * speaker.tempo
    slow = SLOW_KINDS.get(kw[0], 1.0)
    onset = candidates[0] if candidates else w.start
    ramp_in = _snap_ramp(onset, -PREP_S * slow / speed, onsets)
    start = onset - ramp_in
    accept = start >= state.busy_until + GESTURE_GAP_S and start >= 0.05
    if kw[0] == "chest":  # "I" is frequent: not every one gets the gesture
        accept = accept and rng.random() < 0.7
    if not accept:
        return False
    while state.beats and state.beats[-1].time > start:  # the preparation starts from the last beat
        state.beats.pop()
    hold_end = max(w.end, onset + MIN_HOLD_S)
    if kw[0] == "circle":
        hold_end = max(hold_end, onset + 0.9 / speed)
    hold_end = _snap_later(hold_end, onsets)
    ramp_out = _snap_ramp(hold_end, RETRACT_S * slow / speed, onsets)
    g = Gesture(
        kind=kw[0],
        onset=onset,
        hold_end=hold_end,
        ramp_in=ramp_in,
        ramp_out=ramp_out,
        word=w.word,
        label=kw[1],
        amplitude=float(np.clip(emo.amplitude * speaker.amplitude, 0.6, 1.3)),
        accents=_accents(onsets, start, onset) + _accents(onsets, hold_end, hold_end + ramp_out),
    )
    state.gestures.append(g)
    state.busy_until = state.last_beat = g.end
    state.pending = []
    return True


def _add_beats(
    state: _PlanState,
    w: TimedWord,
    candidates: list[float],
    speaker: SpeakerStyle,
    min_gap: float,
    rng: np.random.Generator,
) -> None:
    """Put a beat on each of word ``w``'s onsets that is far enough from the last beat and gesture.

    The other onsets become accents of the next beat's loop (``state.pending``).
    """
    emo = EMOTION_STYLES[w.emotion]
    speed = emo.speed * speaker.tempo
    short_ok = len(w.word) >= 3 or rng.random() < 0.5
    for k, time in enumerate(candidates):
        if (
            (k > 0 or short_ok)
            and time - state.last_beat >= min_gap
            and time >= state.busy_until + min_gap
            and time > 0.3
        ):
            amp = 5.0 * emo.amplitude * speaker.amplitude * rng.uniform(0.8, 1.2)
            state.beats.append(_beat(time, amp, speed, state.last_beat, state.pending))
            state.last_beat = time
            state.pending = []
        elif (
            time >= max([state.last_beat, *state.pending]) + ACCENT_GAP_S
            and time >= state.busy_until + ACCENT_GAP_S
        ):
            state.pending.append(time)


def _beat(time: float, amp: float, speed: float, last_beat: float, pending: list[float]) -> Beat:
    """The beat at ``time`` (s): its loop spans at most ``LOOP_S / speed`` s since ``last_beat``.

    After a pause the loop starts on one of the ``pending`` onsets; those inside the loop
    become its accents.
    """
    loop = min(LOOP_S / speed, time - last_beat)
    early = [a for a in pending if time - a <= 1.6 * LOOP_S / speed]
    if loop < time - last_beat and early and time - early[0] > loop:
        loop = time - early[0]  # after a pause the loop starts on an onset too
    accents = tuple(a for a in pending if time - loop + ACCENT_GAP_S <= a <= time - ACCENT_GAP_S)
    return Beat(time=time, amplitude=amp, stroke=0.5 * loop, prep=0.5 * loop, accents=accents)


def merge_onsets(onsets: Sequence[float] | np.ndarray, gap: float | None = None) -> np.ndarray:
    """Onsets with each run of neighbours closer than ``gap`` replaced by the run's mean time.

    Two onsets 0.13 s apart (a word onset and its first vowel) are one syllable for the motion;
    at 15 fps two speed minima need ~0.2 s between them.

    Parameters
    ----------
    onsets : (K,) float, seconds
    gap : float, optional
        Seconds; default :data:`ACCENT_GAP_S`.

    Returns
    -------
    (K',) float64 increasing, seconds.

    Examples
    --------
    Runs closer than 0.2 s become their mean: (1.0 + 1.1) / 2 and (2.0 + 2.12 + 2.24) / 3.

    >>> np.round(merge_onsets([1.0, 1.1, 1.5, 2.0, 2.12, 2.24], gap=0.2), 3).tolist()
    [1.05, 1.5, 2.12]
    """
    gap = ACCENT_GAP_S if gap is None else float(gap)
    x = np.sort(np.asarray(onsets, dtype=np.float64).reshape(-1))
    if x.size == 0:
        return x
    runs = np.split(x, np.flatnonzero(np.diff(x) >= gap) + 1)
    return np.array([float(r.mean()) for r in runs])


def _accents(onsets: np.ndarray | None, start: float, end: float) -> tuple[float, ...]:
    """Onsets inside ``(start, end)`` at least :data:`ACCENT_GAP_S` from both ends and from each other."""
    if onsets is None:
        return ()
    out: list[float] = []
    for x in onsets[(onsets >= start + ACCENT_GAP_S) & (onsets <= end - ACCENT_GAP_S)]:
        if not out or x - out[-1] >= ACCENT_GAP_S:
            out.append(float(x))
    return tuple(out)


def _snap_later(time: float, onsets: np.ndarray | None, within: float = 0.4) -> float:
    """The first onset in ``[time, time + within]`` (seconds), or ``time`` when there is none."""
    if onsets is None:
        return time
    later = onsets[(onsets >= time) & (onsets <= time + within)]
    return float(later[0]) if later.size else time


def _snap_ramp(anchor: float, ramp: float, onsets: np.ndarray | None) -> float:
    """A ramp duration (s) whose far end lies on an onset.

    ``ramp > 0`` ends ``ramp`` after ``anchor`` (a retraction), ``ramp < 0`` starts ``-ramp`` before
    it (a preparation); the far end moves to the onset nearest to it within 0.75-1.4 times the
    nominal duration. Returns the (positive) duration, the nominal one when no onset fits.
    """
    nominal = abs(ramp)
    if onsets is None:
        return nominal
    gaps = (onsets - anchor) * np.sign(ramp)
    ok = (gaps >= 0.75 * nominal) & (gaps <= 1.4 * nominal)
    if not np.any(ok):
        return nominal
    return float(gaps[ok][np.argmin(np.abs(gaps[ok] - nominal))])


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

    Examples
    --------
    A beat at 1 s (its 1-s loop from 0 s, annotated until 1.2 s) and an "idea" gesture from 2 to
    3.5 s in a 5-s take; scores from :data:`beatlite.synth.styles.SEMANTIC_SCORES`.

    >>> beat = Beat(time=1.0, amplitude=5.0, stroke=0.5, prep=0.5)
    >>> idea = Gesture(kind="idea", onset=2.5, hold_end=3.0, ramp_in=0.5, ramp_out=0.5, word="idea",
    ...                label="08_metaphoric_l", amplitude=1.0)
    >>> plan = Plan(words=(), phrases=(), beats=(beat,), gestures=(idea,), duration=5.0)
    >>> for segment in semantic_segments(plan):
    ...     print(segment)
    ('01_beat_align', 0.0, 1.2, 0.1, '')
    ('00_nogesture', 1.2, 2.0, 0.0, '')
    ('08_metaphoric_l', 2.0, 3.5, 0.8, 'idea')
    ('00_nogesture', 3.5, 5.0, 0.0, '')
    """
    marks = [(max(g.start, 0.0), min(g.end, plan.duration), g.label, g.word) for g in plan.gestures]
    for start, end in _beat_runs(plan.beats):
        marks.append((max(start, 0.0), min(end + 0.2, plan.duration), "01_beat_align", ""))
    marks.sort()
    out = _tile(marks, plan.duration)
    return [(lab, round(s, 3), round(e, 3), sc, kw) for lab, s, e, sc, kw in out]


def _beat_runs(beats: Sequence[Beat]) -> list[list[float]]:
    """Runs of consecutive beats closer than 1.2 s: ``[first loop start, last beat time]``, seconds."""
    runs: list[list[float]] = []
    for b in beats:
        if runs and b.time - runs[-1][1] < 1.2:
            runs[-1][1] = b.time
        else:
            runs.append([b.time - b.stroke - b.prep, b.time])
    return runs


def _tile(
    marks: Sequence[tuple[float, float, str, str]], duration: float
) -> list[tuple[str, float, float, float, str]]:
    """Sorted ``(start, end, label, word)`` marks cut into a tiling of ``[0, duration]`` seconds.

    A mark starts where the previous one ended at the earliest; marks shorter than 0.05 s are
    dropped; gaps of 0.01 s or more become ``00_nogesture``, shorter ones widen the next mark.
    """
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
    if duration - t >= 0.01:
        out.append(("00_nogesture", t, duration, 0.0, ""))
    return out
