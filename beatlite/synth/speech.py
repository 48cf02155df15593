"""Word-by-word speech with espeak-ng, and the exact word/phone timing it implies.

Every word is spoken by its own ``espeak-ng -x -w word.wav`` call (inside a
temporary folder that is deleted afterwards), trimmed of the silence espeak adds
around it, and placed on the timeline with chosen gaps. The word intervals of
the TextGrid are therefore exact: they are where the trimmed word audio was put.
The phones tier is approximate: the phoneme string espeak prints (``-x``) is cut
into phones and those phones share the word's duration equally.

Audio leaves this module at 16 kHz (espeak's 22050 Hz output is resampled with
:func:`scipy.signal.resample_poly`, up 320 / down 441).

Part of the corpus generator :mod:`beatlite.synth`, which no notebook teaches (``data_samples/README.md`` describes its rules).
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from beatlite.constants import SR

ESPEAK_SR = 22050
"""Sample rate of espeak-ng's WAV output, Hz."""

OUTPUT_SR = SR
"""Sample rate of the generated corpus audio, Hz (BEAT's loaders read 16 kHz): the models' rate."""

# espeak-ng's ASCII phoneme mnemonics for English (``-x`` output), longest first, so a greedy
# left-to-right match cuts "h@l'oU" into h, @, l, oU. Stress marks and syllable marks are dropped.
_PHONES = sorted(
    (
        "aI@ aU@ aI aU eI oU OI e@ i@ U@ 3: A: O: u: i: A@ O@ o@ @L @2 @5 I2 I# e# a# aa "
        "tS dZ n- l- r- t# "
        "a A E I O U V 0 @ 3 e i u o p b t d k g f v T D s z S Z h m n N l r w j x"
    ).split(),
    key=len,
    reverse=True,
)
_IGNORED = set("'\",%=_|:!#-2")


class EspeakNotFoundError(RuntimeError):
    """espeak-ng is not installed (the generator needs it for speech)."""


@dataclass(frozen=True)
class Voice:
    """espeak-ng settings for one speaker in one emotion.

    Attributes
    ----------
    name : str
        espeak voice + variant, e.g. ``"en-us+m3"``.
    rate : int
        Speaking rate ``-s``, words per minute (espeak default 175).
    pitch : int
        Base pitch ``-p``, 0..99 (default 50).
    amplitude : int
        Loudness ``-a``, 0..200 (default 100).
    """

    name: str
    rate: int
    pitch: int
    amplitude: int


@dataclass(frozen=True)
class SpokenWord:
    """One word as spoken: its trimmed audio and its phones.

    Attributes
    ----------
    word : str
        The word (lower case).
    audio : (N,) float32
        Trimmed waveform at :data:`ESPEAK_SR` Hz, in [-1, 1].
    phones : tuple of str
        espeak phonemes of the word (stress marks removed); at least one.
    """

    word: str
    audio: np.ndarray
    phones: tuple[str, ...]


def espeak_path() -> str:
    """Path of the ``espeak-ng`` executable.

    Raises
    ------
    EspeakNotFoundError
        When it is not on ``PATH``, with the command that installs it.

    Examples
    --------
    With an empty ``PATH`` nothing is found, and the error says how to install it:

    >>> import os
    >>> from unittest import mock
    >>> with mock.patch.dict(os.environ, {"PATH": ""}):
    ...     try:
    ...         espeak_path()
    ...     except EspeakNotFoundError as e:
    ...         print("apt-get install espeak-ng" in str(e))
    True
    """
    path = shutil.which("espeak-ng")
    if path is None:
        raise EspeakNotFoundError(
            "espeak-ng was not found on PATH; the corpus generator needs it to speak the transcripts. "
            "Install it with `sudo apt-get install espeak-ng` (Debian/Ubuntu) or `brew install espeak-ng` "
            "(macOS), then run `python -m beatlite.synth` again."
        )
    return path


def split_phonemes(text: str) -> tuple[str, ...]:
    """Cut an espeak ``-x`` phoneme string into phones.

    Parameters
    ----------
    text : str
        e.g. ``"s'3:k@L"``.

    Returns
    -------
    tuple of str
        e.g. ``("s", "3:", "k", "@L")``; stress and syllable marks are dropped,
        an unknown character becomes a phone of its own.

    Examples
    --------
    The longest phone that matches wins ("oU", not "o" then "U"); the stress mark ``'`` is dropped:

    >>> split_phonemes("h@l'oU"), split_phonemes("s'3:k@L")
    (('h', '@', 'l', 'oU'), ('s', '3:', 'k', '@L'))
    """
    phones: list[str] = []
    i = 0
    text = text.strip()
    while i < len(text):
        ch = text[i]
        if ch.isspace() or (ch in _IGNORED and not any(text.startswith(p, i) for p in _PHONES)):
            i += 1
            continue
        for p in _PHONES:
            if text.startswith(p, i):
                phones.append(p)
                i += len(p)
                break
        else:
            phones.append(ch)
            i += 1
    return tuple(phones)


def trim_silence(y: np.ndarray, *, threshold: float = 0.02, margin_s: float = 0.005) -> np.ndarray:
    """Cut leading and trailing silence from a word recording.

    Parameters
    ----------
    y : (N,) float
        Waveform at :data:`ESPEAK_SR`.
    threshold : float
        Samples with ``|y| < threshold * max|y|`` count as silence.
    margin_s : float
        Seconds of the quiet edge kept on both sides.

    Returns
    -------
    (M,) float32
        The trimmed waveform (unchanged when all samples are silent).

    Examples
    --------
    100 loud samples in 1000: kept with ``0.005 x 22050 = 110`` samples of margin on each side.

    >>> y = np.zeros(1000)
    >>> y[400:500] = 0.5
    >>> trim_silence(y).size, 100 + 2 * 110
    (320, 320)
    """
    y = np.asarray(y, dtype=np.float32)
    if y.ndim != 1:
        raise ValueError(f"trim_silence: y must be 1-D, got shape {y.shape}")
    peak = float(np.max(np.abs(y))) if y.size else 0.0
    if peak <= 0:
        return y
    loud = np.flatnonzero(np.abs(y) >= threshold * peak)
    margin = int(round(margin_s * ESPEAK_SR))
    start = max(int(loud[0]) - margin, 0)
    end = min(int(loud[-1]) + 1 + margin, y.size)
    return y[start:end]


def _read_wav(path: Path) -> np.ndarray:
    import soundfile as sf

    y, sr = sf.read(str(path), dtype="float32", always_2d=False)
    if sr != ESPEAK_SR:
        raise RuntimeError(f"espeak-ng wrote {sr} Hz audio to {path}, expected {ESPEAK_SR} Hz")
    return y if y.ndim == 1 else y.mean(axis=1)


def speak_words(
    words: Sequence[str], voice: Voice, cache: dict[tuple[str, Voice], SpokenWord] | None = None
) -> list[SpokenWord]:
    """Speak each word with its own espeak-ng call.

    Parameters
    ----------
    words : sequence of str
        Words to speak (repeated words are spoken once and reused).
    voice : Voice
        espeak settings.
    cache : dict, optional
        In-memory cache ``(word, voice) -> SpokenWord`` shared between calls (e.g. within a take).

    Returns
    -------
    list of SpokenWord
        One per input word, in order.

    Examples
    --------
    Skipped by the doctests (needs espeak-ng). A repeated word is spoken once:

    >>> voice = Voice("en-us+m3", rate=175, pitch=50, amplitude=100)  # doctest: +SKIP
    >>> spoken = speak_words(["hello", "world", "hello"], voice)  # doctest: +SKIP
    >>> [w.word for w in spoken], spoken[0] is spoken[2], spoken[0].phones  # doctest: +SKIP
    (['hello', 'world', 'hello'], True, ('h', '@', 'l', 'oU'))
    >>> spoken[0].audio.dtype, bool(np.abs(spoken[0].audio).max() <= 1.0)  # doctest: +SKIP
    (dtype('float32'), True)
    """
    exe = espeak_path()
    spoken: dict[tuple[str, Voice], SpokenWord] = {} if cache is None else cache
    todo = [w for w in dict.fromkeys(words) if (w, voice) not in spoken]
    if not todo:
        return [spoken[(w, voice)] for w in words]
    with tempfile.TemporaryDirectory(prefix="beatlite_espeak_") as tmp:
        for k, word in enumerate(todo):
            spoken[(word, voice)] = _speak_one(exe, word, voice, Path(tmp) / f"w{k}.wav")
    return [spoken[(w, voice)] for w in words]


def _speak_one(exe: str, word: str, voice: Voice, wav: Path) -> SpokenWord:
    """One espeak-ng call: ``word`` spoken into the scratch file ``wav``, silence trimmed, with its phonemes."""
    cmd = [exe, "-x", "-v", voice.name, "-s", str(voice.rate), "-p", str(voice.pitch)]
    cmd += ["-a", str(voice.amplitude), "-w", str(wav), "--", word]
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if proc.returncode != 0 or not wav.exists():
        raise RuntimeError(f"espeak-ng failed on {word!r} ({' '.join(cmd)}): {proc.stderr.strip()}")
    audio = trim_silence(_read_wav(wav))
    phones = split_phonemes(proc.stdout) or (word,)
    return SpokenWord(word, audio, phones)


def resample_to_output(y: np.ndarray) -> np.ndarray:
    """Resample espeak audio (22050 Hz) to :data:`OUTPUT_SR` (16 kHz).

    Parameters
    ----------
    y : (N,) float
        Waveform at 22050 Hz.

    Returns
    -------
    (ceil(N * 320 / 441),) float32
        :func:`scipy.signal.resample_poly`'s length (16000 / 22050 = 320 / 441, rounded up).

    Examples
    --------
    One second of a 440-Hz sine: 16000 samples, and the RMS of a unit sine, 1 / sqrt(2). Two samples
    become ceil(640 / 441) = 2, not round(1.45) = 1.

    >>> y = resample_to_output(np.sin(2 * np.pi * 440 * np.arange(ESPEAK_SR) / ESPEAK_SR))
    >>> y.shape, y.dtype, round(float(np.sqrt(np.mean(y**2))), 2)
    ((16000,), dtype('float32'), 0.71)
    >>> resample_to_output(np.ones(2)).shape, resample_to_output(np.ones(6)).shape
    ((2,), (5,))
    """
    from scipy.signal import resample_poly

    return resample_poly(np.asarray(y, dtype=np.float64), 320, 441).astype(np.float32)
