"""The take list of ``data_samples/`` and the generation of one take or the whole corpus.

Part of the corpus generator :mod:`beatlite.synth`, which no notebook teaches (``data_samples/README.md`` describes its rules).
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from beatlite.io.names import emotion_of, split_of
from beatlite.synth.onsets import speech_onsets
from beatlite.synth.plan import Plan, TimedWord, make_plan, semantic_segments
from beatlite.synth.speech import (
    ESPEAK_SR,
    OUTPUT_SR,
    SpokenWord,
    Voice,
    espeak_path,
    resample_to_output,
    speak_words,
)
from beatlite.synth.styles import EMOTION_NAMES, EMOTION_STYLES, SPEAKERS, SpeakerStyle
from beatlite.synth.transcripts import sentence_order

if TYPE_CHECKING:
    from beatlite.io import Motion

DURATION_STEP_S = 0.2
"""Take durations are rounded up to a multiple of this (integer frames at 15/30/60/120 fps and 16 kHz)."""
FACE_FPS = 60
"""Facial blendshape rate (BEAT: 60 fps)."""
BVH_PRECISION = 3
"""Decimals of the compact BVH files (degrees / cm)."""


@dataclass(frozen=True)
class TakeSpec:
    """One take of the corpus.

    Attributes
    ----------
    speaker_id : int
        BEAT speaker id (key of :data:`beatlite.synth.styles.SPEAKERS`).
    session : int
        0 = English speech, 1 = English conversation.
    seq : int
        Sequence id (start = end).
    target_s : float
        Wanted amount of speech, seconds (the take ends after the sentence that reaches it).

    Examples
    --------
    Speech sequence 65 is the first of the happiness block (65-72); BEAT's split rule puts
    speaker 2's sequence 65 in test.

    >>> spec = TakeSpec(2, 0, 65, 10.0)
    >>> spec.name, spec.speaker.name, EMOTION_NAMES[spec.emotion], spec.split
    ('2_scott_0_65_65', 'scott', 'happiness', 'test')
    >>> TakeSpec(2, 1, 2, 18.0).emotion  # a conversation is neutral by its name
    0
    """

    speaker_id: int
    session: int
    seq: int
    target_s: float

    @property
    def speaker(self) -> SpeakerStyle:
        """The speaker's style."""
        return SPEAKERS[self.speaker_id]

    @property
    def name(self) -> str:
        """BEAT file stem ``{id}_{name}_{type}_{start}_{end}``, e.g. ``2_scott_0_65_65``."""
        return f"{self.speaker_id}_{self.speaker.name}_{self.session}_{self.seq}_{self.seq}"

    @property
    def emotion(self) -> int:
        """Emotion id implied by the sequence id (conversation: 0 = neutral)."""
        return emotion_of(self.seq, conversation=self.session == 1)

    @property
    def split(self) -> str:
        """``train`` / ``val`` / ``test`` by BEAT's within-speaker rule (:func:`beatlite.io.names.split_of`)."""
        return split_of(self.speaker_id, self.session == 1, self.seq)


# speaker -> speech sequence ids by split (see README: every speaker has train/val/test takes and
# anger, neutral and sadness; every emotion is in train and in test).
_SPEECH_SEQUENCES: dict[int, dict[str, tuple[int, ...]]] = {
    2: {"train": (9, 10, 74, 82, 66, 88), "val": (57, 86), "test": (1, 73)},
    4: {"train": (11, 12, 75, 83, 97, 105), "val": (58, 80), "test": (65, 81)},
    6: {"train": (13, 14, 76, 84, 113, 67), "val": (59, 72), "test": (87, 95)},
    8: {"train": (15, 16, 77, 85, 89, 106), "val": (60, 102), "test": (103, 111)},
}
SPEECH_TARGET_S = 11.0
"""Speech per speech take, seconds (before rounding up to whole sentences)."""
CONVERSATION_TARGET_S = 18.0
"""Speech per conversation take, seconds (plus listening pauses)."""


def corpus_specs() -> list[TakeSpec]:
    """The takes of ``data_samples/``: per speaker 10 speech takes and 1 conversation.

    Returns
    -------
    list of TakeSpec
        44 takes, speaker by speaker, speech before conversation.

    Examples
    --------
    4 speakers x (10 speech takes + 1 conversation), each speaker with takes in every split:

    >>> specs = corpus_specs()
    >>> len(specs), sum(s.session == 1 for s in specs), sorted({s.speaker_id for s in specs})
    (44, 4, [2, 4, 6, 8])
    >>> sorted({s.split for s in specs if s.speaker_id == 2})
    ['test', 'train', 'val']
    >>> specs[0].name, specs[0].target_s == SPEECH_TARGET_S
    ('2_scott_0_9_9', True)
    """
    specs: list[TakeSpec] = []
    for sid, splits in _SPEECH_SEQUENCES.items():
        for seqs in splits.values():
            specs += [TakeSpec(sid, 0, s, SPEECH_TARGET_S) for s in seqs]
        specs.append(TakeSpec(sid, 1, 2, CONVERSATION_TARGET_S))
    return specs


# ----------------------------------------------------------------------------- speech timeline
@dataclass(frozen=True)
class Speech:
    """A take's audio and its timing.

    Attributes
    ----------
    audio : (N,) float32, 16 kHz
    words : tuple of TimedWord
    phones : tuple of (start, end, phone)
    emotions : tuple of (start, end, emotion id)
        Emotion segments tiling ``[0, duration]``.
    duration : float, seconds
    """

    audio: np.ndarray
    words: tuple[TimedWord, ...]
    phones: tuple[tuple[float, float, str], ...]
    emotions: tuple[tuple[float, float, int], ...]
    duration: float


def _voice(speaker: SpeakerStyle, emotion: int) -> Voice:
    e = EMOTION_STYLES[emotion]
    return Voice(
        name=speaker.voice,
        rate=int(round(speaker.rate * e.rate)),
        pitch=int(np.clip(speaker.pitch + e.pitch, 0, 99)),
        amplitude=int(e.loudness),
    )


def _turns(spec: TakeSpec, rng: np.random.Generator) -> list[tuple[int, float]]:
    """(emotion, speech seconds) per speaking turn."""
    if spec.session == 0:
        return [(spec.emotion, spec.target_s)]
    others = rng.permutation(np.arange(1, 8))[:3]
    emotions = [0, int(others[0]), int(others[1]), 0, int(others[2])]
    return [(e, spec.target_s / len(emotions)) for e in emotions]


def synthesize_speech(spec: TakeSpec, rng: np.random.Generator) -> Speech:
    """Speak a take's transcript word by word and lay the words out in time.

    Within a sentence words are separated by 40-110 ms, sentences by 0.35-0.7 s (a quarter of
    them by 1.0-1.5 s), all times the emotion's pause factor; a conversation has 2-3.5 s of
    listening (silence) between turns. The take starts with 0.6-1.2 s and ends with 0.8 s of
    silence and is rounded up to a multiple of :data:`DURATION_STEP_S`.

    Parameters
    ----------
    spec : TakeSpec
    rng : numpy.random.Generator

    Returns
    -------
    Speech

    Examples
    --------
    Skipped by the doctests (needs espeak-ng; word lengths depend on its version). The take is a whole
    number of 0.2-s steps of 16-kHz audio, spoken in one emotion, its words in order and apart:

    >>> speech = synthesize_speech(TakeSpec(2, 0, 65, 2.0), np.random.default_rng(0))  # doctest: +SKIP
    >>> round(speech.duration / DURATION_STEP_S, 6).is_integer()  # doctest: +SKIP
    True
    >>> speech.audio.shape == (round(speech.duration * OUTPUT_SR),)  # doctest: +SKIP
    True
    >>> speech.emotions == ((0.0, speech.duration, 1),)  # doctest: +SKIP
    True
    >>> all(a.end < b.start for a, b in zip(speech.words, speech.words[1:]))  # doctest: +SKIP
    True
    """
    placed, words, turn_bounds = _lay_out_words(spec, rng)
    end = words[-1].end + 0.8
    duration = math.ceil(round(end / DURATION_STEP_S, 6)) * DURATION_STEP_S
    duration = round(duration, 6)
    audio = _mix_words(placed, duration, rng)
    phones: list[tuple[float, float, str]] = []
    for (_, sw, _), w in zip(placed, words):
        step = (w.end - w.start) / len(sw.phones)
        for i, ph in enumerate(sw.phones):
            phones.append((round(w.start + i * step, 4), round(w.start + (i + 1) * step, 4), ph))
    emotions = []
    for i, (t0, e) in enumerate(turn_bounds):
        t1 = turn_bounds[i + 1][0] if i + 1 < len(turn_bounds) else duration
        emotions.append((round(t0, 3), round(t1, 3), e))
    return Speech(audio, tuple(words), tuple(phones), tuple(emotions), duration)


def _lay_out_words(
    spec: TakeSpec, rng: np.random.Generator
) -> tuple[list[tuple[int, SpokenWord, int]], list[TimedWord], list[tuple[float, int]]]:
    """Speak the take's sentences turn by turn and place them in time (see :func:`synthesize_speech`).

    Returns
    -------
    placed : list of (first sample at ESPEAK_SR, SpokenWord, emotion id)
    words : list of TimedWord
        The same words, timed in seconds.
    turn_bounds : list of (start s, emotion id)
        Where each speaking turn's emotion begins (the first at 0).
    """
    sentences = sentence_order(rng)
    cache: dict[tuple[str, Voice], SpokenWord] = {}
    placed: list[tuple[int, SpokenWord, int]] = []
    words: list[TimedWord] = []
    turn_bounds: list[tuple[float, int]] = []
    cursor = rng.uniform(0.6, 1.2)
    k = 0
    for turn, (emotion, target) in enumerate(_turns(spec, rng)):
        if turn > 0:
            cursor += rng.uniform(2.0, 3.5)
        turn_bounds.append((cursor - 0.3 if turn else 0.0, emotion))
        voice = _voice(spec.speaker, emotion)
        pause = EMOTION_STYLES[emotion].pause
        start = cursor
        while cursor - start < target:
            text = sentences[k % len(sentences)].split()
            k += 1
            for sw in speak_words(text, voice, cache):
                s0 = int(round(cursor * ESPEAK_SR))
                dur = sw.audio.size / ESPEAK_SR
                placed.append((s0, sw, emotion))
                words.append(TimedWord(round(cursor, 4), round(cursor + dur, 4), sw.word, emotion))
                cursor += dur + pause * rng.uniform(0.04, 0.11)
            if cursor - start < target:
                long = rng.random() < 0.25
                cursor += pause * (rng.uniform(1.0, 1.5) if long else rng.uniform(0.35, 0.7))
    return placed, words, turn_bounds


def _mix_words(
    placed: Sequence[tuple[int, SpokenWord, int]], duration: float, rng: np.random.Generator
) -> np.ndarray:
    """The take's waveform: the placed words summed with a faint noise floor, (duration * 16 kHz,) float32."""
    raw = np.zeros(int(round(duration * ESPEAK_SR)) + 1, dtype=np.float64)
    for s0, sw, _ in placed:
        raw[s0 : s0 + sw.audio.size] += sw.audio
    raw += rng.normal(0.0, 2e-4, size=raw.size)  # a faint noise floor
    audio = np.clip(0.9 * resample_to_output(raw), -1.0, 1.0).astype(np.float32)
    return audio[: int(round(duration * OUTPUT_SR))]


def _tier(items: Sequence[tuple[float, float, str]], duration: float) -> list[tuple[float, float, str]]:
    """Intervals tiling ``[0, duration]``: the items plus ``""`` for the gaps (as MFA writes)."""
    out: list[tuple[float, float, str]] = []
    t = 0.0
    for start, end, text in items:
        if start > t + 1e-9:
            out.append((t, start, ""))
        out.append((start, end, text))
        t = end
    if duration > t + 1e-9:
        out.append((t, duration, ""))
    return out


# ----------------------------------------------------------------------------- one take
@dataclass(frozen=True)
class TakeResult:
    """What :func:`generate_take` wrote.

    Attributes
    ----------
    name : str
        File stem.
    paths : tuple of Path
        The six files.
    duration : float
        Seconds.
    seconds : float
        Wall time spent generating.
    """

    name: str
    paths: tuple[Path, ...]
    duration: float
    seconds: float


def generate_take(
    spec: TakeSpec, out_dir: str | os.PathLike[str], seed: int = 0, *, fps: int = 30, full_rate: bool = False
) -> TakeResult:
    """Generate one take and write its six files.

    Parameters
    ----------
    spec : TakeSpec
    out_dir : str or PathLike
        Existing folder.
    seed : int
        Corpus seed; the take's random streams are ``default_rng([seed, speaker, session, seq, k])``,
        so a take does not depend on which other takes are generated.
    fps : int
        BVH frame rate of the compact corpus (ignored with ``full_rate``).
    full_rate : bool
        Write BEAT's rates and plain files instead: ``.bvh`` at 120 fps with 6 decimals and plain
        ``.json``, instead of ``.bvh.gz`` at ``fps`` with 3 decimals and ``.json.gz``.

    Returns
    -------
    TakeResult

    Examples
    --------
    Skipped by the doctests (needs espeak-ng). Six files in BEAT's formats, which index as one
    usable take whose name gives its emotion and split:

    >>> import tempfile  # doctest: +SKIP
    >>> from beatlite.data.index import index_folder  # doctest: +SKIP
    >>> with tempfile.TemporaryDirectory() as tmp:  # doctest: +SKIP
    ...     result = generate_take(TakeSpec(2, 0, 65, 2.0), tmp, seed=0)
    ...     record = index_folder(tmp, cache=False)["2_scott_0_65_65"]
    ...     print([p.name.split(".", 1)[1] for p in result.paths])
    ...     print(record.usable, record.emotion_name, record.split, record.duration == result.duration)
    ['bvh.gz', 'wav', 'json.gz', 'TextGrid', 'txt', 'csv']
    True happiness test True
    """
    if not isinstance(spec, TakeSpec):
        raise TypeError(f"generate_take: spec must be a TakeSpec, got {type(spec).__name__}")
    out = Path(out_dir)
    if not out.is_dir():
        raise FileNotFoundError(f"generate_take: output folder {out} does not exist")
    _check_fps(fps, "generate_take")
    tic = time.perf_counter()
    streams = [np.random.default_rng([seed, spec.speaker_id, spec.session, spec.seq, k]) for k in range(4)]
    speech = synthesize_speech(spec, streams[0])
    onsets = speech_onsets(speech.audio, OUTPUT_SR)
    plan = make_plan(speech.words, spec.speaker, speech.duration, streams[1], onsets=onsets)
    motion, precision = _take_motion(spec, plan, speech.duration, streams[2], fps=fps, full_rate=full_rate)
    face = _take_face(speech, plan, streams[3])
    paths = _write_take(out / spec.name, speech, plan, motion, precision, face, full_rate=full_rate)
    return TakeResult(spec.name, paths, speech.duration, time.perf_counter() - tic)


def _check_fps(fps: int, caller: str) -> None:
    """Raise ``ValueError`` unless ``fps`` is a positive integer multiple of 5."""
    if not isinstance(fps, int) or isinstance(fps, bool) or fps <= 0 or fps % 5:
        raise ValueError(f"{caller}: fps must be a positive integer multiple of 5, got {fps!r}")


def _take_motion(
    spec: TakeSpec, plan: Plan, duration: float, rng: np.random.Generator, *, fps: int, full_rate: bool
) -> tuple[Motion, int]:
    """The take's body motion at ``fps`` (120 with ``full_rate``), rounded; and its BVH decimals."""
    from beatlite.io import Motion
    from beatlite.skeleton.beat import beat_skeleton
    from beatlite.synth.motion import body_channels

    bvh_fps = 120 if full_rate else fps
    n_frames = int(round(duration * bvh_fps))
    t = np.arange(n_frames) / bvh_fps
    skeleton = beat_skeleton()
    channels = body_channels(skeleton, t, plan, spec.speaker, rng)
    precision = 6 if full_rate else BVH_PRECISION
    channels = np.round(channels, precision) + 0.0  # + 0.0 turns -0.0 into 0.0
    return Motion(skeleton, channels, bvh_fps), precision


def _take_face(speech: Speech, plan: Plan, rng: np.random.Generator) -> np.ndarray:
    """The take's ARKit blendshape weights (T_face, 51) at :data:`FACE_FPS`."""
    from beatlite.io.facial import ARKIT_51
    from beatlite.synth.face import face_weights
    from beatlite.synth.motion import emotion_ids

    n_face = int(round(speech.duration * FACE_FPS))
    t_face = np.arange(n_face) / FACE_FPS
    emotion = emotion_ids(t_face, plan)
    return face_weights(ARKIT_51, n_face, FACE_FPS, speech.audio, OUTPUT_SR, speech.phones, emotion, rng)


def _write_take(
    stem: Path,
    speech: Speech,
    plan: Plan,
    motion: Motion,
    precision: int,
    face: np.ndarray,
    *,
    full_rate: bool,
) -> tuple[Path, ...]:
    """Write the six files of a take at ``stem``: BVH, WAV, facial JSON, TextGrid, semantic TXT, emotion CSV."""
    from beatlite.io import write_bvh
    from beatlite.io.audio import write_wav
    from beatlite.io.facial import ARKIT_51, write_facial
    from beatlite.synth import _annotations

    paths = (
        Path(f"{stem}.bvh" if full_rate else f"{stem}.bvh.gz"),
        Path(f"{stem}.wav"),
        Path(f"{stem}.json" if full_rate else f"{stem}.json.gz"),
        Path(f"{stem}.TextGrid"),
        Path(f"{stem}.txt"),
        Path(f"{stem}.csv"),
    )
    write_bvh(paths[0], motion, precision=precision)
    write_wav(paths[1], speech.audio, OUTPUT_SR)
    write_facial(paths[2], ARKIT_51, face, FACE_FPS)
    words = _tier([(w.start, w.end, w.word) for w in speech.words], speech.duration)
    phones = _tier(speech.phones, speech.duration)
    _annotations.write_textgrid(paths[3], {"words": words, "phones": phones}, speech.duration)
    _annotations.write_semantic(paths[4], semantic_segments(plan))
    emotions = [(EMOTION_NAMES[e], s, t1, e) for s, t1, e in speech.emotions]
    _annotations.write_emotion(paths[5], emotions)
    return paths


# ----------------------------------------------------------------------------- whole corpus
def _run(args: tuple[TakeSpec, str, int, int, bool]) -> TakeResult:
    spec, out, seed, fps, full_rate = args
    return generate_take(spec, out, seed, fps=fps, full_rate=full_rate)


def generate_corpus(
    out_dir: str | os.PathLike[str],
    seed: int = 0,
    *,
    fps: int = 30,
    full_rate: bool = False,
    workers: int | None = None,
    specs: Sequence[TakeSpec] | None = None,
) -> list[TakeResult]:
    """Generate every take of :func:`corpus_specs` (or ``specs``) into ``out_dir``.

    Parameters
    ----------
    out_dir : str or PathLike
        Created if missing.
    seed : int
        Corpus seed.
    fps, full_rate
        As in :func:`generate_take`.
    workers : int, optional
        Processes (default: ``min(2, os.cpu_count())``; 1 runs in this process).
    specs : sequence of TakeSpec, optional
        A subset of takes.

    Returns
    -------
    list of TakeResult, in the order of ``specs``.

    Examples
    --------
    Skipped by the doctests (needs espeak-ng). Two short takes of :func:`corpus_specs`' speakers, in
    this process:

    >>> import tempfile  # doctest: +SKIP
    >>> with tempfile.TemporaryDirectory() as tmp:  # doctest: +SKIP
    ...     results = generate_corpus(tmp, specs=[TakeSpec(2, 0, 1, 1.0), TakeSpec(4, 0, 65, 1.0)], workers=1)
    ...     print([r.name for r in results], len(list(Path(tmp).iterdir())))
    ['2_scott_0_1_1', '4_lawrence_0_65_65'] 12
    """
    _check_fps(fps, "generate_corpus")
    espeak_path()  # fail early with the install hint
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    specs = list(corpus_specs() if specs is None else specs)
    workers = min(2, os.cpu_count() or 1) if workers is None else int(workers)
    if workers < 1:
        raise ValueError(f"generate_corpus: workers must be >= 1, got {workers}")
    jobs = [(s, str(out), seed, fps, full_rate) for s in specs]
    if workers == 1:
        return [_run(j) for j in jobs]
    return _run_in_pool(jobs, workers)


def _run_in_pool(jobs: Sequence[tuple[TakeSpec, str, int, int, bool]], workers: int) -> list[TakeResult]:
    """:func:`_run` each job in ``workers`` spawned processes, long takes first; results in job order."""
    import multiprocessing as mp

    order = sorted(range(len(jobs)), key=lambda i: -jobs[i][0].target_s)  # long takes first
    with mp.get_context("spawn").Pool(workers) as pool:
        results = pool.map(_run, [jobs[i] for i in order], chunksize=1)
    by_index = dict(zip(order, results))
    return [by_index[i] for i in range(len(jobs))]
