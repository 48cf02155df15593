"""Procedural body motion on the BEAT skeleton: wrist paths, two-bone IK, fingers, spine and head.

The wrists follow targets written in the chest frame (the ``Spine3`` joint's frame, centimetres,
Y up, +Z forward, the character's right at -X):

``wrist = rest + a(t) reach (centre - rest) - lift(t) d + loop(t) n``, then blended towards
``target_g`` with weight ``w_g(t)`` for each semantic gesture, plus a slow, small drift (and
tremor in fear)

- ``a(t)`` is the phrase envelope (1 while talking, 0 in long pauses; minimum-jerk ramps);
- between consecutive beats the hand traces one closed loop (a circle in the plane of the stroke
  direction ``d`` and ``n``: up, over and down into the beat point) with the phase
  ``phi(s) = 2 pi (s - sin(2 pi s) / (2 pi))`` of the inter-beat time ``s in [0, 1]``, so its speed
  is ``prop. to 1 - cos(2 pi s)``: zero only at the beats (audio onsets), largest mid-way, with no
  turnaround stop at the top (:func:`beat_lift`). The head nod, shoulder shrug, spine emphasis
  and wrist flexion follow the same loop with two components each, so none of them stops
  between beats either;
- each semantic gesture ``g`` blends the wrist towards its scripted target with weight ``w_g``
  (minimum-jerk preparation that completes at the word onset, hold, retraction).

Arm joint angles come from an analytic two-bone IK (the elbow swivels towards a fixed pole
below, behind and outside the shoulder), fingers from blended hand shapes (open, relaxed, fist,
point, pinch), and the spine, neck and head from small sinusoids (breathing, sway), beat nods and
the emotion's head pitch. Everything is a smooth function of time evaluated at the frame times.

Part of the corpus generator :mod:`beatlite.synth`, which no notebook teaches (``data_samples/README.md`` describes its rules).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from beatlite.skeleton.core import Skeleton
from beatlite.skeleton.rotations import (
    axis_angle_to_matrix,
    euler_to_matrix,
    matrix_to_euler,
    nearest_euler,
    unwrap_degrees,
)
from beatlite.synth.plan import Gesture, Plan
from beatlite.synth.styles import EMOTION_STYLES, SpeakerStyle

HAND_SHAPES: dict[str, tuple[float, float, float, float, float]] = {
    # curl of (index, middle, ring, pinky, thumb), 0 = straight, 1 = fully flexed
    "open": (0.02, 0.02, 0.04, 0.06, 0.0),
    "relaxed": (0.25, 0.32, 0.38, 0.45, 0.2),
    "fist": (0.95, 0.95, 0.95, 0.95, 0.75),
    "point": (0.0, 0.92, 0.95, 0.95, 0.6),
    "pinch": (0.55, 0.3, 0.35, 0.42, 0.55),
}
"""Hand shape -> finger curls."""

# Maximum flexion (degrees) of the knuckle, middle and distal joints, and the carpal joint.
_CURL_DEG = (75.0, 95.0, 65.0)
_CARPAL_DEG = 6.0
_THUMB_DEG = (30.0, 35.0, 45.0)

# Scripted semantic gestures: right-wrist target (chest frame, cm), hands used, hand shape, wrist roll.
# hands: "dominant" or "both".
GESTURE_TARGETS: dict[str, tuple[tuple[float, float, float], str, str, float]] = {
    "chest": ((-4.0, -8.0, 17.0), "dominant", "open", 0.0),
    "point_forward": ((-14.0, -2.0, 46.0), "dominant", "point", 0.0),
    "point_down": ((-14.0, -26.0, 34.0), "dominant", "point", -20.0),
    "big": ((-50.0, -12.0, 24.0), "both", "open", 30.0),
    "small": ((-3.5, -22.0, 30.0), "both", "pinch", 20.0),
    "circle": ((-16.0, -14.0, 32.0), "dominant", "point", 0.0),
    "up": ((-30.0, 18.0, 24.0), "both", "open", 40.0),
    "idea": ((-22.0, 16.0, 26.0), "dominant", "point", 0.0),
    "future": ((-14.0, -8.0, 50.0), "dominant", "open", 60.0),
    "everything": ((-40.0, -16.0, 32.0), "both", "open", 0.0),
    "love": ((-5.0, -6.0, 16.0), "both", "open", 0.0),
}
"""Gesture kind -> (right-wrist target cm, hands, hand shape, wrist roll degrees)."""

MAX_ELBOW_FLEX_DEG = 145.0
"""Largest elbow flexion the IK produces (human range is about 0-150 degrees)."""

LOOP = 1.0
"""Width of a beat loop across the stroke direction, as a fraction of its height (1 = a circle)."""

FULL_LOOP_S = 0.9
"""Beat loops shorter than this (seconds) are smaller: amplitude times ``sqrt(duration / FULL_LOOP_S)``."""

DRIFT_CM = 0.3
"""Amplitude of each of the three slow idle-drift sinusoids of a wrist, per axis, centimetres."""

CIRCLE_RADIUS_CM = 12.0
"""Radius of the ``circle`` gesture's path (frontal plane)."""

_FAVOURITE_SHAPE = {"palm_up": "open", "chop": "open", "flick": "relaxed", "pinch": "pinch"}
_FAVOURITE_ROLL = {"palm_up": 70.0, "chop": 85.0, "flick": 20.0, "pinch": 10.0}
_FAVOURITE_FLEX = {"palm_up": 6.0, "chop": 4.0, "flick": 30.0, "pinch": 8.0}
_ELBOW_POLE = np.array([-0.45, -1.0, -0.35])


# ----------------------------------------------------------------------------- time profiles
def min_jerk(x: np.ndarray) -> np.ndarray:
    """Minimum-jerk ramp ``10x^3 - 15x^4 + 6x^5`` of ``x`` clipped to [0, 1] (zero speed at both ends).

    Parameters
    ----------
    x : (...) float, normalised time (0 = start, 1 = end of the ramp)

    Returns
    -------
    (...) float64 in [0, 1]

    Examples
    --------
    0 before the ramp, 1 after it, half-way at its middle (10/8 - 15/16 + 6/32 = 0.5):

    >>> min_jerk(np.array([-1.0, 0.0, 0.5, 1.0, 2.0])).tolist()
    [0.0, 0.0, 0.5, 1.0, 1.0]
    """
    x = np.clip(x, 0.0, 1.0)
    return x**3 * (10.0 - 15.0 * x + 6.0 * x**2)


def smooth_box(t: np.ndarray, start: float, end: float, ramp_in: float, ramp_out: float) -> np.ndarray:
    """1 on ``[start, end]``, minimum-jerk ramps on ``[start - ramp_in, start]`` and ``[end, end + ramp_out]``.

    Parameters
    ----------
    t : (T,) float, seconds
    start, end : float, seconds
    ramp_in, ramp_out : float, seconds (> 0)

    Returns
    -------
    (T,) float64 in [0, 1]

    Examples
    --------
    1 on [1, 3] s, half-way up 0.5 s before (the ramp's middle) and half-way down 0.5 s after:

    >>> smooth_box(np.array([0.0, 0.5, 1.0, 2.0, 3.0, 3.5, 4.0]), 1.0, 3.0, 1.0, 1.0).tolist()
    [0.0, 0.5, 1.0, 1.0, 1.0, 0.5, 0.0]
    """
    rise = min_jerk((t - (start - ramp_in)) / ramp_in)
    fall = 1.0 - min_jerk((t - end) / ramp_out)
    return rise * fall


def beat_phase(s: np.ndarray) -> np.ndarray:
    """Loop phase ``phi(s) = 2 pi s - sin(2 pi s)`` of the inter-beat time ``s`` (clipped to [0, 1]).

    ``dphi/ds = 2 pi (1 - cos 2 pi s)``: zero only at ``s = 0`` and ``s = 1`` (the beats), largest
    at ``s = 0.5``; ``phi`` rises monotonically from 0 to ``2 pi``.

    Parameters
    ----------
    s : (T,) float

    Returns
    -------
    (T,) float64, radians

    Examples
    --------
    ``phi(1/4) = pi/2 - sin(pi/2) = 0.5708``: a quarter of the time covers less than a quarter of
    the loop (slow start); the middle is at ``pi``, the end at ``2 pi``.

    >>> np.round(beat_phase(np.array([0.0, 0.25, 0.5, 1.0])), 4).tolist()
    [0.0, 0.5708, 3.1416, 6.2832]
    """
    s = np.clip(np.asarray(s, dtype=np.float64), 0.0, 1.0)
    return 2.0 * np.pi * s - np.sin(2.0 * np.pi * s)


def loop_phase(t: np.ndarray, start: float, end: float, accents: tuple[float, ...] = ()) -> np.ndarray:
    """Phase ``phi(t)`` of a beat loop on ``[start, end]``, from 0 to ``2 pi``, radians.

    Without accents ``phi = beat_phase((t - start) / (end - start))``: the phase rate is
    ``prop. to 1 - cos(2 pi s)``, zero only at both ends. With accents (times inside the loop) the
    rate profile is, on each piece between consecutive boundaries ``u_i < u_{i+1}``,
    ``r(s) = e(s) + (1 - e(s)) (1 - cos 2 pi s) / 2`` with ``e`` rising by a minimum-jerk step from
    the depth at ``u_i`` to that at ``u_{i+1}`` (0 at the loop's ends, ``ACCENT_DEPTH`` at an
    accent): a stop at the beats, a shallow minimum at each accent, one maximum per piece.
    ``phi`` is ``2 pi`` times the normalised integral of ``r`` (a fixed 1-ms grid, so the value
    does not depend on the frame rate).

    Parameters
    ----------
    t : (T,) float64, seconds
    start, end : float, seconds (start < end)
    accents : tuple of float
        Increasing times in ``(start, end)``, seconds.

    Returns
    -------
    (T,) float64, radians: 0 before ``start``, ``2 pi`` after ``end``.

    Examples
    --------
    Without accents, a loop on [0, 2] s is half done at 1 s (:func:`beat_phase` of 1/2); an accent
    at 0.5 s changes the path in between, not the ends.

    >>> np.round(loop_phase(np.array([-1.0, 0.0, 1.0, 2.0, 3.0]), 0.0, 2.0), 4).tolist()
    [0.0, 0.0, 3.1416, 6.2832, 6.2832]
    >>> phi = loop_phase(np.linspace(0.0, 2.0, 41), 0.0, 2.0, accents=(0.5,))
    >>> float(round(phi[0], 4)), float(round(phi[-1], 4)), bool(np.all(np.diff(phi) > 0))
    (0.0, 6.2832, True)
    """
    t = np.asarray(t, dtype=np.float64)
    if not accents:
        return beat_phase((t - start) / (end - start))
    from beatlite.synth.plan import ACCENT_DEPTH

    bounds = np.array([start, *accents, end], dtype=np.float64)
    depth = np.array([0.0] + [ACCENT_DEPTH] * len(accents) + [0.0])
    grid = np.linspace(start, end, max(int(np.ceil((end - start) / 1e-3)), 8) + 1)
    piece = np.clip(np.searchsorted(bounds, grid, side="right") - 1, 0, len(bounds) - 2)
    s = (grid - bounds[piece]) / (bounds[piece + 1] - bounds[piece])
    e = depth[piece] + (depth[piece + 1] - depth[piece]) * min_jerk(s)
    rate = e + (1.0 - e) * 0.5 * (1.0 - np.cos(2.0 * np.pi * s))
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(grid))])
    return np.interp(t, grid, 2.0 * np.pi * cum / cum[-1])


def beat_lift(t: np.ndarray, plan: Plan) -> tuple[np.ndarray, np.ndarray]:
    """Beat loops: displacement against the stroke direction and across it, centimetres.

    Beat ``k`` at ``t_k`` owns the loop on ``[t_k - D_k, t_k]`` with
    ``D_k = min(t_k - t_{k-1}, prep_k + stroke_k)``. With ``phi = loop_phase(t, t_k - D_k, t_k,
    accents_k)`` the hand traces a circle of diameter ``A_k`` (times ``LOOP`` across):

        lift = A_k (1 - cos phi) / 2,    loop = LOOP A_k sin(phi) / 2,

    so it rises to ``A_k`` mid-way while moving across (no stop at the top) and its speed
    ``A_k / 2 * dphi/dt`` is zero only at the loop's ends, the beats (with a shallow dip at each
    accent). ``A_k`` shrinks as ``sqrt(D_k / FULL_LOOP_S)`` for shorter loops. Outside the
    loops both are 0.

    Parameters
    ----------
    t : (T,) float64, seconds
    plan : Plan

    Returns
    -------
    lift : (T,) float64
        Height of the loop (0 at every beat time, ``A_k`` at its middle).
    loop : (T,) float64
        Sideways displacement of the loop (0 at the beat times and the middles).

    Examples
    --------
    A 5-cm beat at 1 s whose loop lasts 1 s (longer than :data:`FULL_LOOP_S`, so full size): the hand
    is 5 cm up half-way (``phi = pi``), back at the beat; a quarter of the way in ``phi = 0.5708``
    (:func:`beat_phase`), so ``lift = 2.5 (1 - cos phi)`` and ``loop = 2.5 sin phi``.

    >>> from beatlite.synth.plan import Beat, Gesture, Plan, TimedWord
    >>> plan = Plan(words=(), phrases=(), beats=(Beat(time=1.0, amplitude=5.0, stroke=0.5, prep=0.5),),
    ...             gestures=(), duration=2.0)
    >>> lift, loop = beat_lift(np.array([0.25, 0.5, 1.0, 1.5]), plan)
    >>> np.round(lift, 3).tolist(), np.round(loop, 3).tolist()
    ([0.396, 5.0, 0.0, 0.0], [1.351, 0.0, 0.0, 0.0])
    """
    t = np.asarray(t, dtype=np.float64)
    lift = np.zeros_like(t)
    loop = np.zeros_like(t)
    previous = -np.inf
    for b in plan.beats:
        dur = min(b.time - previous, b.prep + b.stroke)
        previous = b.time
        if dur < 0.1:
            continue
        amp = b.amplitude * np.sqrt(min(dur / FULL_LOOP_S, 1.0))
        on = (t > b.time - dur) & (t < b.time)
        accents = tuple(a for a in b.accents if b.time - dur < a < b.time)
        phi = loop_phase(t[on], b.time - dur, b.time, accents)
        lift[on] += 0.5 * amp * (1.0 - np.cos(phi))
        loop[on] += 0.5 * LOOP * amp * np.sin(phi)
    return lift, loop


SYLLABLE_LOOP_S = 1.0
"""Longest torso bob between two syllable onsets, seconds (longer gaps: still until the last 1.0 s)."""


def syllable_pulse(t: np.ndarray, plan: Plan) -> tuple[np.ndarray, np.ndarray]:
    """A small two-component bob of the torso between consecutive syllable onsets.

    Between onsets ``o_{i-1} < o_i`` of ``plan.syllables`` (the last ``SYLLABLE_LOOP_S`` s of the
    gap at most) ``phi = beat_phase(s)`` and the pulse is ``((1 - cos phi) / 2, sin(phi) / 2)``: a
    circle traversed once, at rest only at the onsets. Scaled into the shoulders and spine it makes
    their speed minima fall on the audio onsets (speech rhythm in the body).

    Parameters
    ----------
    t : (T,) float64, seconds
    plan : Plan

    Returns
    -------
    up, side : (T,) float64, unitless in [0, 1] and [-0.5, 0.5]

    Examples
    --------
    Onsets at 1 and 2 s: the bob is at the top (``up = 1``, ``side = 0``) half-way between them and
    at rest on them.

    >>> from beatlite.synth.plan import Beat, Gesture, Plan, TimedWord
    >>> plan = Plan(words=(), phrases=(), beats=(), gestures=(), duration=3.0, syllables=(1.0, 2.0))
    >>> up, side = syllable_pulse(np.array([0.5, 1.0, 1.5, 2.0, 2.5]), plan)
    >>> np.round(up, 3).tolist(), np.round(np.abs(side), 3).tolist()
    ([1.0, 0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0])
    """
    t = np.asarray(t, dtype=np.float64)
    up = np.zeros_like(t)
    side = np.zeros_like(t)
    previous = -np.inf
    for onset in plan.syllables:
        dur = min(onset - previous, SYLLABLE_LOOP_S)
        previous = onset
        on = (t > onset - dur) & (t < onset)
        phi = beat_phase((t[on] - (onset - dur)) / dur)
        up[on] = 0.5 * (1.0 - np.cos(phi))
        side[on] = 0.5 * np.sin(phi)
    return up, side


def gesture_weight(t: np.ndarray, g: Gesture) -> np.ndarray:
    """Blend weight of a semantic gesture: 0 -> 1 over the preparation, 1 in the hold, 1 -> 0 after.

    The ramps follow :func:`loop_phase` (zero speed at both ends, a shallow slow-down at each of
    the gesture's accents), so the hand stops only at the phase boundaries (audio onsets).

    Parameters
    ----------
    t : (T,) float64, seconds
    g : Gesture

    Returns
    -------
    (T,) float64 in [0, 1]

    Examples
    --------
    Preparation 0.5-1 s, hold 1-2 s, retraction 2-2.5 s; each ramp is half-way at its middle.

    >>> from beatlite.synth.plan import Beat, Gesture, Plan, TimedWord
    >>> g = Gesture(kind="idea", onset=1.0, hold_end=2.0, ramp_in=0.5, ramp_out=0.5, word="idea",
    ...             label="08_metaphoric_l", amplitude=1.0)
    >>> g.start, g.end
    (0.5, 2.5)
    >>> np.round(gesture_weight(np.array([0.5, 0.75, 1.0, 1.5, 2.0, 2.25, 2.5]), g), 4).tolist()
    [0.0, 0.5, 1.0, 1.0, 1.0, 0.5, 0.0]
    """
    t = np.asarray(t, dtype=np.float64)
    rise_acc = tuple(a for a in g.accents if g.start < a < g.onset)
    fall_acc = tuple(a for a in g.accents if g.hold_end < a < g.end)
    rise = loop_phase(t, g.start, g.onset, rise_acc) / (2.0 * np.pi)
    fall = loop_phase(t, g.hold_end, g.end, fall_acc) / (2.0 * np.pi)
    return rise * (1.0 - fall)


def phrase_envelope(t: np.ndarray, plan: Plan) -> np.ndarray:
    """Phrase envelope ``a(t)``: 1 from each phrase's first word onset to 0.25 s after its last word.

    Minimum-jerk ramps of 0.6 s before and 0.8 s after; phrases whose ramps would overlap are
    merged (the hands stay in the gesture space), so the envelope never has a kink.

    Parameters
    ----------
    t : (T,) float64, seconds
    plan : Plan

    Returns
    -------
    (T,) float64 in [0, 1]

    Examples
    --------
    One phrase from 1 to 2 s: 1 on [1, 2.25] s, half-way 0.3 s before (the 0.6-s ramp's middle) and
    0.4 s after (the 0.8-s ramp's), 0 outside.

    >>> from beatlite.synth.plan import Beat, Gesture, Plan, TimedWord
    >>> plan = Plan(words=(), phrases=((1.0, 2.0),), beats=(), gestures=(), duration=4.0)
    >>> np.round(phrase_envelope(np.array([0.3, 0.7, 1.0, 2.25, 2.65, 3.1]), plan), 4).tolist()
    [0.0, 0.5, 1.0, 1.0, 0.5, 0.0]
    """
    rise, fall, after = 0.6, 0.8, 0.25
    merged: list[list[float]] = []
    for start, end in plan.phrases:
        if merged and start - rise <= merged[-1][1] + after + fall:
            merged[-1][1] = max(merged[-1][1], end)
        else:
            merged.append([start, end])
    env = np.zeros_like(t)
    for start, end in merged:
        env = np.maximum(env, smooth_box(t, start, end + after, rise, fall))
    return env


def emotion_track(t: np.ndarray, plan: Plan, field: str) -> np.ndarray:
    """Per-frame value of an :class:`EmotionStyle` field, following the words' emotions.

    Each word's emotion holds from its start until the next word; before the first word the
    first emotion holds. Changes are smoothed over 0.5 s.

    Parameters
    ----------
    t : (T,) float64, seconds, evenly spaced
    plan : Plan
    field : str
        A field of :class:`beatlite.synth.styles.EmotionStyle` (``"amplitude"``, ``"head_pitch"``, ...).

    Returns
    -------
    (T,) float64, in the field's unit

    Examples
    --------
    A neutral word, then an angry one at 1 s: the beat amplitude multiplier rises smoothly from
    neutral's 1.0 to anger's 1.5 (:data:`beatlite.synth.styles.EMOTION_STYLES`).

    >>> from beatlite.synth.plan import Beat, Gesture, Plan, TimedWord
    >>> plan = Plan(words=(TimedWord(0.0, 0.9, "well", 0), TimedWord(1.0, 1.5, "no", 2)), phrases=(),
    ...             beats=(), gestures=(), duration=3.0)
    >>> amp = emotion_track(np.arange(30) / 10, plan, "amplitude")
    >>> float(amp[0]), float(amp[-1]), bool(np.all(np.diff(amp) >= 0))
    (1.0, 1.5, True)
    """
    if not plan.words:
        return np.full_like(t, getattr(EMOTION_STYLES[0], field))
    starts = np.array([w.start for w in plan.words])
    values = np.array([getattr(EMOTION_STYLES[w.emotion], field) for w in plan.words], dtype=np.float64)
    idx = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(values) - 1)
    return _smooth_track(t, values[idx])


def emotion_ids(t: np.ndarray, plan: Plan) -> np.ndarray:
    """Emotion id of each time: that of the last word started (the first word's before it).

    Parameters
    ----------
    t : (T,) float, seconds
    plan : Plan

    Returns
    -------
    (T,) int64

    Examples
    --------
    >>> from beatlite.synth.plan import Beat, Gesture, Plan, TimedWord
    >>> plan = Plan(words=(TimedWord(0.5, 0.9, "well", 0), TimedWord(1.0, 1.5, "no", 2)), phrases=(),
    ...             beats=(), gestures=(), duration=3.0)
    >>> emotion_ids(np.array([0.0, 0.99, 1.0, 2.5]), plan).tolist()
    [0, 0, 2, 2]
    """
    t = np.asarray(t, dtype=np.float64)
    if not plan.words:
        return np.zeros(t.shape, dtype=np.int64)
    starts = np.array([w.start for w in plan.words])
    values = np.array([w.emotion for w in plan.words], dtype=np.int64)
    idx = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(values) - 1)
    return values[idx]


def _smooth_track(t: np.ndarray, raw: np.ndarray) -> np.ndarray:
    """``raw`` (T,) smoothed with a 0.5-s Hann window (edges held)."""
    dt = float(t[1] - t[0]) if t.size > 1 else 1.0
    half = max(int(round(0.25 / dt)), 1)
    kernel = np.hanning(2 * half + 1)
    kernel /= kernel.sum()
    padded = np.pad(raw, half, mode="edge")
    return np.convolve(padded, kernel, mode="valid")


# ----------------------------------------------------------------------------- wrists
def _mirror(v: np.ndarray, side: str) -> np.ndarray:
    v = np.array(v, dtype=np.float64)
    if side == "left":
        v[..., 0] = -v[..., 0]
    return v


def _hand_role(speaker: SpeakerStyle, side: str) -> float:
    """Share of beats and gesture-space excursion of this hand (1 = dominant)."""
    if speaker.handedness == "both" or speaker.handedness == side:
        return 1.0
    return 0.35


class _HandDrive(NamedTuple):
    """Per-frame signals shared by both hands, each (T,) float64 (see :func:`wrist_paths`)."""

    amp_e: np.ndarray
    """Emotion amplitude."""
    tremor_e: np.ndarray
    """Emotion tremor, centimetres."""
    env: np.ndarray
    """Phrase envelope in [0, 1]."""
    lift: np.ndarray
    """Beat-loop height, centimetres."""
    loop: np.ndarray
    """Beat-loop width, centimetres."""
    angry: np.ndarray
    """Smoothed share of anger in [0, 1]."""


def wrist_paths(
    t: np.ndarray, plan: Plan, speaker: SpeakerStyle, rng: np.random.Generator
) -> dict[str, dict[str, np.ndarray]]:
    """Wrist targets, hand shapes and wrist roll of both hands.

    Parameters
    ----------
    t : (T,) float64, seconds
    plan : Plan
    speaker : SpeakerStyle
    rng : numpy.random.Generator

    Returns
    -------
    dict side -> {"wrist": (T, 3) cm chest frame, "curl": (T, 5) in [0, 1], "roll": (T,) degrees,
    "flex": (T,) degrees}, sides ``"right"``, ``"left"``.

    Examples
    --------
    With nothing said (no phrase, beat or gesture) both wrists rest at the speaker's ``rest`` (the left
    one mirrored in x), moved only by the three slow drift sinusoids of :data:`DRIFT_CM` each.

    >>> from beatlite.synth.plan import Plan
    >>> from beatlite.synth.styles import SPEAKERS
    >>> speaker = SPEAKERS[2]
    >>> silent = Plan(words=(), phrases=(), beats=(), gestures=(), duration=2.0)
    >>> paths = wrist_paths(np.arange(30) / 15, silent, speaker, np.random.default_rng(0))
    >>> {k: v.shape for k, v in paths["right"].items()}
    {'wrist': (30, 3), 'curl': (30, 5), 'roll': (30,), 'flex': (30,)}
    >>> rest = np.array(speaker.rest)
    >>> bool(np.abs(paths["right"]["wrist"] - rest).max() <= 3 * DRIFT_CM)
    True
    >>> bool(np.abs(paths["left"]["wrist"] - rest * [-1, 1, 1]).max() <= 3 * DRIFT_CM)
    True
    """
    lift, loop = beat_lift(t, plan)
    drive = _HandDrive(
        amp_e=emotion_track(t, plan, "amplitude"),
        tremor_e=emotion_track(t, plan, "tremor"),
        env=phrase_envelope(t, plan),
        lift=lift,
        loop=loop,
        angry=_smooth_track(t, (emotion_ids(t, plan) == 2).astype(np.float64)),
    )
    return {side: _hand_path(t, plan, speaker, side, drive, rng) for side in ("right", "left")}


def _hand_path(
    t: np.ndarray,
    plan: Plan,
    speaker: SpeakerStyle,
    side: str,
    drive: _HandDrive,
    rng: np.random.Generator,
) -> dict[str, np.ndarray]:
    """One hand of :func:`wrist_paths`: beat loops and drift, blended into the semantic gestures."""
    role = _hand_role(speaker, side)
    wrist = _beat_wrist(t, speaker, side, role, drive, rng)
    shape_fav = np.array(HAND_SHAPES[_FAVOURITE_SHAPE[speaker.favourite]])
    env = drive.env
    curl = (1 - env * role)[:, None] * np.array(HAND_SHAPES["relaxed"]) + (env * role)[:, None] * shape_fav
    # anger clenches the gesturing hand towards a fist
    fist = (0.6 * env * role * drive.angry)[:, None]
    curl = (1 - fist) * curl + fist * np.array(HAND_SHAPES["fist"])
    # the wrist pulses with the beat loop in two components (flexion ~ height, roll ~ across)
    # so the hand's rotation, too, is still only at the beats
    pulse = _FAVOURITE_FLEX[speaker.favourite] * role / 5.0
    roll = env * role * _FAVOURITE_ROLL[speaker.favourite] + 0.5 * pulse * drive.loop
    flex = 8.0 + pulse * drive.lift
    wrist, curl, roll = _blend_gestures(t, plan, speaker, side, role, wrist, curl, roll)
    if np.any(drive.tremor_e > 0):
        for axis in range(3):
            f = rng.uniform(8.0, 11.0)
            wrist[:, axis] += drive.tremor_e * np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi))
    return {"wrist": wrist, "curl": np.clip(curl, 0.0, 1.0), "roll": roll, "flex": flex}


def _beat_wrist(
    t: np.ndarray, speaker: SpeakerStyle, side: str, role: float, drive: _HandDrive, rng: np.random.Generator
) -> np.ndarray:
    """Wrist (T, 3) cm, chest frame: rest to gesture space by the envelope, beat loops, slow drift."""
    rest = _mirror(speaker.rest, side)
    centre = _mirror(speaker.gesture_center, side)
    # gesture space follows the emotion amplitude: sad speakers stay low and near the body
    reach = role * np.clip(0.4 + 0.6 * drive.amp_e, 0.5, 1.4)
    wrist = rest[None, :] + (drive.env * reach)[:, None] * (centre - rest)[None, :]
    direction = _mirror(speaker.beat_direction, side)
    direction = direction / np.linalg.norm(direction)
    # the loop's second axis: outwards and forwards (the elbow then loops too, it does not
    # stop and turn back mid-way); right is -x
    outward = _mirror(np.array([-1.0, 0.0, 0.6]), side)
    across = outward - np.dot(outward, direction) * direction
    across = across / max(float(np.linalg.norm(across)), 1e-9)
    wrist = (
        wrist
        - (role * drive.lift)[:, None] * direction[None, :]
        + (role * drive.loop)[:, None] * across[None, :]
    )
    # slow, small drift (no sharp speed minima between beats) and the favourite movement
    for _ in range(3):
        f = rng.uniform(0.05, 0.15)
        phase = rng.uniform(0, 2 * np.pi, size=3)
        wrist += DRIFT_CM * np.sin(2 * np.pi * f * t[:, None] + phase[None, :])
    return wrist


def _blend_gestures(
    t: np.ndarray,
    plan: Plan,
    speaker: SpeakerStyle,
    side: str,
    role: float,
    wrist: np.ndarray,
    curl: np.ndarray,
    roll: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Blend one hand's ``wrist`` (T, 3), ``curl`` (T, 5) and ``roll`` (T,) into the plan's gestures.

    Each gesture this hand takes part in pulls towards its target with weight
    :func:`gesture_weight`; overlapping gestures share by weight.
    """
    centre = _mirror(speaker.gesture_center, side)
    weight_sum = np.zeros_like(t)
    g_wrist = np.zeros_like(wrist)
    g_curl = np.zeros_like(curl)
    g_roll = np.zeros_like(roll)
    for g in plan.gestures:
        target, hands, shape, g_roll_deg = GESTURE_TARGETS[g.kind]
        if hands == "dominant" and (role < 1.0 or (speaker.handedness == "both" and side == "left")):
            continue
        w = gesture_weight(t, g)
        weight_sum += w
        g_wrist += w[:, None] * _gesture_path(t, g, side, centre, target, wrist.shape)
        g_curl += w[:, None] * np.array(HAND_SHAPES[shape])
        g_roll += w * g_roll_deg
    norm = np.maximum(weight_sum, 1.0)
    ws = np.clip(weight_sum, 0.0, 1.0)
    wrist = (1 - ws)[:, None] * wrist + g_wrist / norm[:, None]
    curl = (1 - ws)[:, None] * curl + g_curl / norm[:, None]
    roll = (1 - ws) * roll + g_roll / norm
    return wrist, curl, roll


def _gesture_path(
    t: np.ndarray,
    g: Gesture,
    side: str,
    centre: np.ndarray,
    target: tuple[float, float, float],
    shape: tuple[int, ...],
) -> np.ndarray:
    """Wrist path (T, 3) cm of gesture ``g``: its scaled target, circling during the hold for ``circle``."""
    tgt = centre + g.amplitude * (_mirror(target, side) - centre)
    path = np.broadcast_to(tgt, shape).copy()
    if g.kind == "circle":
        dur = g.hold_end - g.onset
        phi = loop_phase(t, g.onset, g.onset + dur)
        sign = -1.0 if side == "left" else 1.0
        path[:, 0] += sign * CIRCLE_RADIUS_CM * np.sin(phi)
        path[:, 1] += CIRCLE_RADIUS_CM * (np.cos(phi) - 1.0)
    return path


# ----------------------------------------------------------------------------- IK
def _normalize(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)


def _elbow_side(pole: np.ndarray, towards: np.ndarray) -> np.ndarray:
    """Unit directions (T, 3) perpendicular to ``towards`` (T, 3, unit) on the side of ``pole`` (T, 3).

    Where ``pole`` lies along ``towards`` (or is zero) every elbow plane is as good: the
    coordinate axis least aligned with ``towards`` gives one.
    """
    perp = pole - np.sum(pole * towards, axis=1, keepdims=True) * towards
    free = np.linalg.norm(perp, axis=1) <= 1e-9 * np.linalg.norm(pole, axis=1)
    if np.any(free):
        axis = np.eye(3)[np.argmin(np.abs(towards[free]), axis=1)]
        perp[free] = axis - np.sum(axis * towards[free], axis=1, keepdims=True) * towards[free]
    return _normalize(perp)


def two_bone_ik(
    target: np.ndarray,
    root: np.ndarray,
    upper: np.ndarray,
    lower: np.ndarray,
    pole: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Analytic two-bone IK (shoulder-elbow-wrist) in the parent's frame.

    Parameters
    ----------
    target : (T, 3) float, centimetres
        Wrist targets in the frame of the shoulder joint's parent (the clavicle).
    root : (3,) float
        The shoulder joint's offset in that frame.
    upper, lower : (3,) float
        Elbow offset (in the shoulder's frame) and wrist offset (in the elbow's frame) at rest.
    pole : (T, 3) or (3,) float
        Direction the elbow should point to, same frame as ``target``. Where it lies along the
        shoulder-target line (or is zero) any elbow plane reaches the target and one is chosen.

    Returns
    -------
    shoulder : (T, 3, 3) float64
        Local rotation of the shoulder joint.
    elbow : (T, 3, 3) float64
        Local rotation of the elbow joint (a pure rotation about the flexion axis).

    Notes
    -----
    The shoulder-wrist distance saturates smoothly (``tanh``): beyond ``0.85 (l1 + l2)``
    towards ``0.97 (l1 + l2)`` (the elbow keeps ~28 degrees of flexion and never snaps straight)
    and below the distance of :data:`MAX_ELBOW_FLEX_DEG` flexion (+ 4 cm) towards that distance.

    Examples
    --------
    A 30-cm upper arm and a 25-cm forearm hanging down; a target 35 cm from the shoulder is reached
    exactly (forward kinematics ``root + S (upper + E lower)``); one 100 cm away is not, and the
    wrist stops short of 0.97 x 55 cm.

    >>> upper, lower, root = np.array([0.0, -30.0, 0.0]), np.array([0.0, -25.0, 0.0]), np.zeros(3)
    >>> target = np.array([[0.0, -28.0, 21.0], [60.0, 0.0, 80.0]])  # 35 cm and 100 cm away
    >>> s, e = two_bone_ik(target, root, upper, lower, pole=np.array([0.0, 0.0, -1.0]))
    >>> wrist = root + np.einsum("tij,tj->ti", s, upper + np.einsum("tij,j->ti", e, lower))
    >>> bool(np.allclose(wrist[0], target[0])), bool(52.0 < np.linalg.norm(wrist[1]) < 0.97 * 55.0)
    (True, True)
    """
    target = np.asarray(target, dtype=np.float64)
    if target.ndim != 2 or target.shape[1] != 3:
        raise ValueError(f"two_bone_ik: target must be (T, 3), got {target.shape}")
    l1, l2 = float(np.linalg.norm(upper)), float(np.linalg.norm(lower))
    u1, u2 = _normalize(np.asarray(upper, float)), _normalize(np.asarray(lower, float))
    v = target - root[None, :]
    d = np.linalg.norm(v, axis=1)
    # soft limits (smooth, C1): the elbow flexion stays within about [28, 145] degrees
    d0, dmax = 0.85 * (l1 + l2), 0.97 * (l1 + l2)
    far = d > d0
    d[far] = d0 + (dmax - d0) * np.tanh((d[far] - d0) / (dmax - d0))
    dmin = np.sqrt(l1**2 + l2**2 - 2 * l1 * l2 * np.cos(np.deg2rad(180.0 - MAX_ELBOW_FLEX_DEG)))
    d1 = dmin + 4.0
    near = d < d1
    d[near] = d1 - 4.0 * np.tanh((d1 - d[near]) / 4.0)
    vh = _normalize(v)
    cos_a = np.clip((l1**2 + d**2 - l2**2) / (2 * l1 * d), -1.0, 1.0)
    sin_a = np.sqrt(1.0 - cos_a**2)
    pole = np.broadcast_to(np.asarray(pole, dtype=np.float64), v.shape)
    n = _elbow_side(pole, vh)
    a_dir = cos_a[:, None] * vh + sin_a[:, None] * n
    wrist = d[:, None] * vh
    f_dir = _normalize(wrist - l1 * a_dir)
    b_world = _normalize(np.cross(a_dir, f_dir))
    b_local = _normalize(np.cross(u1, np.array([0.0, 0.0, 1.0])))
    local = np.stack([u1, b_local, np.cross(u1, b_local)], axis=1)  # columns
    world = np.stack([a_dir, b_world, np.cross(a_dir, b_world)], axis=2)
    shoulder = world @ local.T[None, :, :]
    f_local = np.einsum("tji,tj->ti", shoulder, f_dir)
    cross = np.cross(u2[None, :], f_local)
    beta = np.arctan2(np.sum(cross * b_local[None, :], axis=1), f_local @ u2)
    elbow = axis_angle_to_matrix(beta[:, None] * b_local[None, :])
    return shoulder, elbow


# ----------------------------------------------------------------------------- whole body
def continuous_euler(angles: np.ndarray) -> np.ndarray:
    """Make an Euler-angle track continuous across the middle angle's ±90° (gimbal) boundary.

    ``(a, b, c)`` and ``(a + 180, 180 - b, c + 180)`` give the same rotation for every
    Tait-Bryan order; frame by frame the one closer to the previous frame is kept, then 360°
    jumps are unwrapped. Only needed when a joint passes through ``|b| = 90°`` (e.g. an elbow
    flexing beyond 90° about its middle axis).

    Parameters
    ----------
    angles : (T, 3) float, degrees

    Returns
    -------
    (T, 3) float64, degrees

    Examples
    --------
    An XYZ rotation passing from 89 to 91 degrees about Y: the second frame, given as the equivalent
    (180, 89, 180), is rewritten as the (0, 91, 0) next to the first.

    >>> continuous_euler(np.array([[0.0, 89.0, 0.0], [180.0, 89.0, 180.0]])).tolist()
    [[0.0, 89.0, 0.0], [0.0, 91.0, 0.0]]
    """
    out = unwrap_degrees(np.asarray(angles, dtype=np.float64))
    if out.shape[0] < 2 or np.abs(np.diff(out, axis=0)).max() < 90.0:
        return out
    fixed = out.copy()
    for i in range(1, fixed.shape[0]):
        fixed[i] = nearest_euler(out[i], fixed[i - 1])
    return fixed


def _put(channels: np.ndarray, skeleton: Skeleton, name: str, rot: np.ndarray) -> None:
    j = skeleton.index(name)
    angles = matrix_to_euler(rot, skeleton.rotation_order(j))
    channels[:, skeleton.rotation_channel_indices(j)] = continuous_euler(angles)


def _euler(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    return euler_to_matrix(np.stack([x, y, z], axis=-1), "XYZ")


def _sines(
    t: np.ndarray, rng: np.random.Generator, amp: float, fmin: float, fmax: float, n: int = 2
) -> np.ndarray:
    out = np.zeros_like(t)
    for _ in range(n):
        out += amp / n * np.sin(2 * np.pi * rng.uniform(fmin, fmax) * t + rng.uniform(0, 2 * np.pi))
    return out


class _BodyDrive(NamedTuple):
    """Per-frame signals shared by the trunk, head and arms, each (T,) float64 (see :func:`body_channels`)."""

    t: np.ndarray
    """Frame times, seconds."""
    head_pitch: np.ndarray
    """Emotion head pitch, degrees."""
    amp_e: np.ndarray
    """Emotion amplitude."""
    nod: np.ndarray
    """Beat-loop height / 5 (~1 at the top of a typical loop)."""
    side_nod: np.ndarray
    """Its quadrature component: nod and side_nod never stop together between beats."""
    bob_up: np.ndarray
    """Speech-rhythm pulse (at rest only on the syllable onsets), see :func:`syllable_pulse`."""
    bob_side: np.ndarray
    """Its quadrature component."""
    breath: np.ndarray
    """Breathing, a 0.25-Hz sine in [-1, 1]."""


def body_channels(
    skeleton: Skeleton, t: np.ndarray, plan: Plan, speaker: SpeakerStyle, rng: np.random.Generator
) -> np.ndarray:
    """BVH channel rows of a whole take.

    Parameters
    ----------
    skeleton : Skeleton
        The BEAT skeleton (:func:`beatlite.skeleton.beat.beat_skeleton`).
    t : (T,) float64
        Frame times, seconds.
    plan : Plan
    speaker : SpeakerStyle
    rng : numpy.random.Generator

    Returns
    -------
    (T, 228) float64
        Hips position in centimetres, rotations in degrees (each joint's CHANNELS order),
        unwrapped along time.

    Examples
    --------
    2 s at 15 fps of a silent take: 6 channels of the hips and 3 of each of the other 74 joints per
    frame; the motion is a function of the seed alone.

    >>> from beatlite.skeleton.beat import beat_skeleton
    >>> from beatlite.synth.plan import Plan
    >>> from beatlite.synth.styles import SPEAKERS
    >>> skeleton, t = beat_skeleton(), np.arange(30) / 15
    >>> silent = Plan(words=(), phrases=(), beats=(), gestures=(), duration=2.0)
    >>> ch = body_channels(skeleton, t, silent, SPEAKERS[2], np.random.default_rng(0))
    >>> ch.shape, 6 + 3 * (skeleton.n_joints - 1)
    ((30, 228), 228)
    >>> bool(np.array_equal(ch, body_channels(skeleton, t, silent, SPEAKERS[2], np.random.default_rng(0))))
    True
    """
    t = np.asarray(t, dtype=np.float64)
    ch = np.zeros((t.size, skeleton.n_channels))
    _put_hips_and_legs(ch, skeleton, t, rng)
    lift, loop = beat_lift(t, plan)
    bob_up, bob_side = syllable_pulse(t, plan)
    drive = _BodyDrive(
        t=t,
        head_pitch=emotion_track(t, plan, "head_pitch"),
        amp_e=emotion_track(t, plan, "amplitude"),
        nod=lift / 5.0,
        side_nod=loop / 5.0,
        bob_up=bob_up,
        bob_side=bob_side,
        breath=np.sin(2 * np.pi * 0.25 * t + rng.uniform(0, 2 * np.pi)),
    )
    _put_spine(ch, skeleton, drive, speaker, rng)
    _put_neck_and_head(ch, skeleton, drive, rng)
    paths = wrist_paths(t, plan, speaker, rng)
    for side in ("right", "left"):
        _put_arm(ch, skeleton, side, paths[side], drive)
    return ch


def _put_hips_and_legs(ch: np.ndarray, skeleton: Skeleton, t: np.ndarray, rng: np.random.Generator) -> None:
    """Hips: small translation sway and weight shift; the legs counter-rotate so they stay vertical.

    Slow: idle sway must not add speed minima between beats.
    """
    zero = np.zeros_like(t)
    hips_pos = np.stack(
        [_sines(t, rng, 1.6, 0.03, 0.1), _sines(t, rng, 0.4, 0.05, 0.12), _sines(t, rng, 1.0, 0.03, 0.1)],
        axis=1,
    )
    ch[:, skeleton.position_channel_indices(0)] = hips_pos
    hips_rot = _euler(
        _sines(t, rng, 1.2, 0.03, 0.1), _sines(t, rng, 2.5, 0.03, 0.08), _sines(t, rng, 1.2, 0.03, 0.1)
    )
    _put(ch, skeleton, "Hips", hips_rot)
    hips_inv = np.swapaxes(hips_rot, 1, 2)
    for side in ("Right", "Left"):
        _put(ch, skeleton, f"{side}UpLeg", hips_inv)
        _put(ch, skeleton, f"{side}Leg", _euler(zero + 2.0, zero, zero))
        _put(ch, skeleton, f"{side}Foot", _euler(zero - 2.0, zero, zero))


def _put_spine(
    ch: np.ndarray, skeleton: Skeleton, d: _BodyDrive, speaker: SpeakerStyle, rng: np.random.Generator
) -> None:
    """Spine: lean, breathing, beat emphasis, a little twist (shared by the four spine joints)."""
    t = d.t
    lean = speaker.lean + 1.5 * np.clip(d.head_pitch, 0, None) / 14.0 * 4.0
    twist = _sines(t, rng, 3.0, 0.03, 0.1)
    spine_rot = _euler(
        (lean + 0.3 * d.breath + 0.8 * d.bob_up * d.amp_e) / 4.0,
        (twist + 0.8 * d.bob_side * d.amp_e) / 4.0,
        _sines(t, rng, 1.0, 0.03, 0.1) / 4.0,
    )
    for name in ("Spine", "Spine1", "Spine2", "Spine3"):
        _put(ch, skeleton, name, spine_rot)


def _put_neck_and_head(ch: np.ndarray, skeleton: Skeleton, d: _BodyDrive, rng: np.random.Generator) -> None:
    """Neck and head: emotion head pitch, nods at beats, slow looking around."""
    t = d.t
    look = _sines(t, rng, 10.0, 0.03, 0.1)
    tilt = _sines(t, rng, 3.0, 0.04, 0.12)
    head_x = d.head_pitch + 2.5 * d.nod * d.amp_e + _sines(t, rng, 1.5, 0.05, 0.15) - 0.3 * d.breath
    look = look + 2.5 * d.side_nod * d.amp_e
    _put(ch, skeleton, "Neck", _euler(head_x * 0.3, look * 0.3, tilt * 0.3))
    _put(ch, skeleton, "Neck1", _euler(head_x * 0.2, look * 0.2, tilt * 0.2))
    _put(ch, skeleton, "Head", _euler(head_x * 0.5, look * 0.5, tilt * 0.5))


def _put_arm(ch: np.ndarray, skeleton: Skeleton, side: str, p: dict[str, np.ndarray], d: _BodyDrive) -> None:
    """One arm: clavicle shrug, two-bone IK to the wrist target, wrist roll and flexion, fingers.

    ``p`` is the side's entry of :func:`wrist_paths`.
    """
    cap = side.capitalize()
    sgn = 1.0 if side == "right" else -1.0
    shrug = -sgn * (1.5 + 0.3 * d.breath + 2.0 * d.bob_up * d.amp_e)
    protract = sgn * 2.0 * d.bob_side * d.amp_e
    clav = _euler(np.zeros_like(d.t), protract, shrug)
    _put(ch, skeleton, f"{cap}Shoulder", clav)
    j_sh = skeleton.index(f"{cap}Shoulder")
    j_arm = skeleton.index(f"{cap}Arm")
    j_fore = skeleton.index(f"{cap}ForeArm")
    j_hand = skeleton.index(f"{cap}Hand")
    # wrist target (chest frame) -> clavicle frame
    local_target = np.einsum("tji,tj->ti", clav, p["wrist"] - skeleton.offsets[j_sh][None, :])
    pole = np.einsum("tji,j->ti", clav, _mirror(_ELBOW_POLE, side))
    shoulder, elbow = two_bone_ik(
        local_target, skeleton.offsets[j_arm], skeleton.offsets[j_fore], skeleton.offsets[j_hand], pole
    )
    _put(ch, skeleton, f"{cap}Arm", shoulder)
    _put(ch, skeleton, f"{cap}ForeArm", elbow)
    # wrist: roll about the forearm axis (supination), flexion towards the palm
    axis = _normalize(skeleton.offsets[skeleton.index(f"{cap}HandMiddle1")])
    palm_normal = np.array([0.0, -1.0, 0.0])
    flex_axis = _normalize(np.cross(axis, palm_normal))
    roll = axis_angle_to_matrix(np.deg2rad(sgn * p["roll"])[:, None] * axis[None, :])
    flex = axis_angle_to_matrix(np.deg2rad(p["flex"])[:, None] * flex_axis[None, :])
    _put(ch, skeleton, f"{cap}Hand", roll @ flex)
    _fingers(ch, skeleton, cap, p["curl"], palm_normal)


def _fingers(ch: np.ndarray, skeleton: Skeleton, cap: str, curl: np.ndarray, palm_normal: np.ndarray) -> None:
    """Write finger joint rotations from per-finger curls (T, 5): index, middle, ring, pinky, thumb."""
    names = {0: "Index", 1: "Middle", 2: "Ring", 3: "Pinky"}
    for k, finger in names.items():
        for level in (1, 2, 3):
            j = skeleton.index(f"{cap}Hand{finger}{level}")
            axis = _normalize(np.cross(_normalize(skeleton.offsets[j + 1]), palm_normal))
            angle = np.deg2rad(_CURL_DEG[level - 1]) * curl[:, k]
            _put(
                ch,
                skeleton,
                f"{cap}Hand{finger}{level}",
                axis_angle_to_matrix(angle[:, None] * axis[None, :]),
            )
        if finger != "Middle":
            j = skeleton.index(f"{cap}Hand{finger}")
            axis = _normalize(np.cross(_normalize(skeleton.offsets[j + 1]), palm_normal))
            angle = np.deg2rad(_CARPAL_DEG) * curl[:, k]
            _put(ch, skeleton, f"{cap}Hand{finger}", axis_angle_to_matrix(angle[:, None] * axis[None, :]))
    for level in (1, 2, 3):
        j = skeleton.index(f"{cap}HandThumb{level}")
        axis = _normalize(np.cross(_normalize(skeleton.offsets[j + 1]), palm_normal))
        angle = np.deg2rad(_THUMB_DEG[level - 1]) * curl[:, 4]
        _put(ch, skeleton, f"{cap}HandThumb{level}", axis_angle_to_matrix(angle[:, None] * axis[None, :]))
