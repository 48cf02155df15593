"""The planted effects of the synthetic corpus: emotion and speaker style tables.

Everything the generator varies by emotion or speaker is a number in this file,
so the README, the tests and the generator agree on them.

Part of the corpus generator :mod:`beatlite.synth`, which no notebook teaches (``data_samples/README.md`` describes its rules).
"""

from __future__ import annotations

from dataclasses import dataclass

EMOTION_NAMES = ("neutral", "happiness", "anger", "sadness", "contempt", "surprise", "fear", "disgust")
"""Emotion ids 0..7 in BEAT's order."""


@dataclass(frozen=True)
class EmotionStyle:
    """How one emotion changes speech, gesture and face.

    Attributes
    ----------
    amplitude : float
        Multiplier of beat-stroke size and of the excursion of semantic gestures.
    speed : float
        Multiplier of gesture speed (stroke and preparation durations are divided by it).
    rate : float
        Multiplier of the espeak speaking rate ``-s``.
    pitch : int
        Added to the speaker's espeak pitch ``-p``.
    loudness : int
        espeak amplitude ``-a`` (100 = default).
    pause : float
        Multiplier of the pauses between words and sentences.
    head_pitch : float
        Constant head/neck flexion, degrees (positive = head lowered).
    tremor : float
        Amplitude of an 8-11 Hz hand tremor, centimetres.
    """

    amplitude: float
    speed: float
    rate: float
    pitch: int
    loudness: int
    pause: float
    head_pitch: float = 0.0
    tremor: float = 0.0


EMOTION_STYLES: dict[int, EmotionStyle] = {
    0: EmotionStyle(amplitude=1.00, speed=1.00, rate=1.00, pitch=0, loudness=100, pause=1.00),
    1: EmotionStyle(amplitude=1.25, speed=1.20, rate=1.08, pitch=12, loudness=120, pause=0.85, head_pitch=-3),
    2: EmotionStyle(amplitude=1.50, speed=1.40, rate=1.12, pitch=4, loudness=160, pause=0.70),
    3: EmotionStyle(amplitude=0.60, speed=0.70, rate=0.78, pitch=-14, loudness=70, pause=1.60, head_pitch=14),
    4: EmotionStyle(amplitude=0.85, speed=0.90, rate=0.92, pitch=-6, loudness=95, pause=1.20, head_pitch=-4),
    5: EmotionStyle(amplitude=1.30, speed=1.25, rate=1.06, pitch=18, loudness=130, pause=0.90, head_pitch=-5),
    6: EmotionStyle(amplitude=0.80, speed=1.10, rate=1.15, pitch=10, loudness=85, pause=1.10, tremor=0.35),
    7: EmotionStyle(amplitude=0.90, speed=0.95, rate=0.92, pitch=-8, loudness=100, pause=1.20, head_pitch=3),
}
"""Emotion id -> :class:`EmotionStyle` (the table of the corpus README)."""


@dataclass(frozen=True)
class SpeakerStyle:
    """One synthetic speaker.

    Attributes
    ----------
    speaker_id : int
        BEAT speaker id (2, 4, 6, 8).
    name : str
        BEAT speaker name.
    voice : str
        espeak-ng voice + variant.
    rate : int
        Neutral speaking rate, espeak words per minute.
    pitch : int
        Neutral espeak pitch.
    handedness : str
        ``"right"``, ``"left"`` or ``"both"`` (both hands beat with equal size).
    amplitude : float
        Multiplier of beat size and gesture excursion.
    tempo : float
        Multiplier of gesture speed; the minimum gap between beats is ``0.35 / min(tempo, 1)`` s.
    rest : tuple of float
        Right-wrist rest position (x, y, z) in the chest frame, centimetres (mirrored for the left).
    gesture_center : tuple of float
        Right-wrist position in the gesture space while talking, centimetres (mirrored for the left).
    beat_direction : tuple of float
        Unit-ish direction of the beat stroke of the right hand (mirrored for the left).
    favourite : str
        Favourite hand shape / movement: ``"palm_up"``, ``"chop"``, ``"flick"`` or ``"pinch"``.
    lean : float
        Constant forward lean of the spine, degrees.
    """

    speaker_id: int
    name: str
    voice: str
    rate: int
    pitch: int
    handedness: str
    amplitude: float
    tempo: float
    rest: tuple[float, float, float]
    gesture_center: tuple[float, float, float]
    beat_direction: tuple[float, float, float]
    favourite: str
    lean: float


SPEAKERS: dict[int, SpeakerStyle] = {
    2: SpeakerStyle(
        speaker_id=2,
        name="scott",
        voice="en-us+m3",
        rate=175,
        pitch=42,
        handedness="right",
        amplitude=1.0,
        tempo=1.0,
        rest=(-22.0, -41.0, 8.0),
        gesture_center=(-18.0, -18.0, 30.0),
        beat_direction=(0.0, -1.0, 0.25),
        favourite="palm_up",
        lean=2.0,
    ),
    4: SpeakerStyle(
        speaker_id=4,
        name="lawrence",
        voice="en-gb+m1",
        rate=160,
        pitch=35,
        handedness="left",
        amplitude=1.3,
        tempo=0.85,
        rest=(-24.0, -40.0, 4.0),
        gesture_center=(-24.0, -14.0, 28.0),
        beat_direction=(-0.35, -1.0, 0.0),
        favourite="chop",
        lean=-1.0,
    ),
    6: SpeakerStyle(
        speaker_id=6,
        name="carla",
        voice="en-us+f2",
        rate=185,
        pitch=60,
        handedness="both",
        amplitude=0.8,
        tempo=1.25,
        rest=(-8.0, -32.0, 20.0),
        gesture_center=(-14.0, -20.0, 32.0),
        beat_direction=(0.2, -0.6, 0.8),
        favourite="flick",
        lean=4.0,
    ),
    8: SpeakerStyle(
        speaker_id=8,
        name="catherine",
        voice="en+f4",
        rate=172,
        pitch=55,
        handedness="right",
        amplitude=1.1,
        tempo=1.05,
        rest=(-12.0, -26.0, 18.0),
        gesture_center=(-16.0, -10.0, 30.0),
        beat_direction=(0.3, -1.0, 0.1),
        favourite="pinch",
        lean=0.0,
    ),
}
"""BEAT speaker id -> :class:`SpeakerStyle` (BEAT's 4-speaker English benchmark: 2, 4, 6, 8)."""


SEMANTIC_SCORES: dict[str, float] = {
    "00_nogesture": 0.0,
    "01_beat_align": 0.1,
    "02_deictic_l": 0.3,
    "03_deictic_m": 0.4,
    "04_deictic_h": 0.5,
    "05_iconic_l": 0.5,
    "06_iconic_m": 0.6,
    "07_iconic_h": 0.7,
    "08_metaphoric_l": 0.8,
    "09_metaphoric_m": 0.9,
    "10_metaphoric_h": 1.0,
}
"""BEAT gesture type label -> the score written in the semantic ``.txt``."""
