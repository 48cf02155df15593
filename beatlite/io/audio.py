"""Reading and writing speech audio (WAV) as float32 arrays.

BEAT ships 48 kHz stereo or 16 kHz mono PCM WAV; the models use 16 kHz mono
float32 in [-1, 1]. :func:`read_audio` reads any WAV flavour libsndfile
understands (PCM 16/24/32, float, extra RIFF chunks, any rate and channel
count) and resamples with :func:`scipy.signal.resample_poly` (polyphase FIR,
Kaiser window beta 5). BEAT itself used ``librosa.load(sr=16000)`` (soxr
resampler), so resampled values differ from BEAT's by a small filter
difference, not in timing.

The first bytes are sniffed before libsndfile sees the file, so an MP3 saved
as ``.wav``, a Git-LFS pointer or an HTML error page gives a
:class:`FormatError` saying what the bytes look like; then the header's rate,
channel count and frame count are checked against sanity bounds before any
sample is decoded or resampled (:func:`audio_info`, which the dataset index
uses too).

Taught in notebooks/01_beat_formats.ipynb, section 8 (the audio read beside the face).
"""

from __future__ import annotations

import io
import math
import os
import struct
import warnings
from pathlib import Path
from typing import NamedTuple

import numpy as np

from beatlite.constants import SR
from beatlite.io.atomic import atomic_write
from beatlite.io.errors import FormatError, FormatWarning
from beatlite.io.textfile import GZIP_MAGIC, describe_bytes, read_bytes

__all__ = ["read_audio", "audio_info", "AudioInfo", "write_wav", "resample"]

_AUDIO_MAGIC = (b"RIFF", b"RF64", b"fLaC", b"OggS", b"FORM", b"riff")


def _looks_like_audio(head: bytes, suffix: str) -> bool:
    if head[:4] == b"RIFF":
        return head[8:12] == b"WAVE"
    if head[:4] == b"FORM":
        return head[8:12] in (b"AIFF", b"AIFC")
    if head[:4] in _AUDIO_MAGIC:
        return True
    is_mp3 = head.startswith(b"ID3") or (len(head) > 1 and head[0] == 0xFF and head[1] & 0xE0 == 0xE0)
    return is_mp3 and suffix == ".mp3"


def resample(y: np.ndarray, sr_from: int, sr_to: int) -> np.ndarray:
    """Resample along axis 0 with :func:`scipy.signal.resample_poly`.

    Parameters
    ----------
    y : (N,) or (N, C) float array
        Signal.
    sr_from, sr_to : int
        Sampling rates in Hz.

    Returns
    -------
    (ceil(N * sr_to / sr_from),) or (..., C) float32

    Examples
    --------
    >>> y = np.sin(2 * np.pi * 5 * np.arange(48000) / 48000)  # 1 s of 5 Hz at 48 kHz
    >>> z = resample(y, 48000, 16000)
    >>> z.shape, z.dtype
    ((16000,), dtype('float32'))
    """
    from scipy.signal import resample_poly

    if sr_from == sr_to:
        return np.asarray(y, dtype=np.float32)
    g = math.gcd(int(sr_from), int(sr_to))
    out = resample_poly(np.asarray(y, dtype=np.float64), int(sr_to) // g, int(sr_from) // g, axis=0)
    return out.astype(np.float32)


def _check_rate(value: object, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer | float) or value != int(value):
        raise TypeError(f"{name} must be a positive integer number of Hz, got {value!r}")
    if int(value) <= 0:
        raise ValueError(f"{name} must be a positive integer number of Hz, got {value!r}")
    return int(value)


#: Accepted sample rates, Hz (checked before any sample is decoded).
RATE_RANGE = (1000, 768_000)
#: Accepted channel counts.
MAX_CHANNELS = 64
#: Decoded float32 bytes allowed per byte of file (PCM needs at most 4; FLAC/OGG compress more).
MAX_EXPANSION = 64
_MIN_DECODED_BYTES = 64 * 2**20


class AudioInfo(NamedTuple):
    """What the header of an audio file says, checked against sanity bounds.

    Attributes
    ----------
    frames : int
        Sample frames present in the file (per channel).
    samplerate : int
        Hz.
    channels : int
    declared_frames : int or None
        Frames the RIFF ``data`` chunk declares (``None`` when not a WAV or not stated);
        more than ``frames`` means a truncated file.

    Examples
    --------
    >>> info = AudioInfo(frames=16000, samplerate=16000, channels=1, declared_frames=16000)
    >>> info.frames / info.samplerate  # seconds
    1.0
    """

    frames: int
    samplerate: int
    channels: int
    declared_frames: int | None

    @property
    def duration(self) -> float:
        """``frames / samplerate`` seconds."""
        return self.frames / self.samplerate


def _declared_wav_frames(head: bytes) -> int | None:
    """Frames the ``data`` chunk of a RIFF/WAVE header declares (chunks walked from byte 12)."""
    if head[:4] != b"RIFF" or head[8:12] != b"WAVE":
        return None
    pos, block_align = 12, 0
    while pos + 8 <= len(head):
        chunk, size = head[pos : pos + 4], struct.unpack("<I", head[pos + 4 : pos + 8])[0]
        if chunk == b"fmt " and pos + 22 <= len(head):
            block_align = struct.unpack("<H", head[pos + 20 : pos + 22])[0]
        if chunk == b"data":
            unknown = size in (0, 0xFFFFFFFF) or block_align == 0
            return None if unknown else size // block_align
        pos += 8 + size + (size & 1)
    return None


def _audio_source(p: Path) -> tuple[str | io.BytesIO, bytes, int]:
    """What libsndfile should open (path, or bytes for gzip), the first 64 KiB, and the file size."""
    with open(p, "rb") as f:
        head = f.read(65536)
    source: str | io.BytesIO = str(p)
    suffix = p.suffix.lower()
    size = p.stat().st_size
    if head[:2] == GZIP_MAGIC:
        data = read_bytes(p)
        head, source, size = data[:65536], io.BytesIO(data), len(data)
        suffix = Path(p.stem).suffix.lower()
    if not _looks_like_audio(head, suffix):
        raise FormatError(p, f"not a WAV/audio file: the bytes look like {describe_bytes(head)}")
    return source, head, size


def _checked_info(p: Path, source: str | io.BytesIO, head: bytes, size: int) -> AudioInfo:
    import soundfile as sf

    try:
        info = sf.info(source)
    except (sf.LibsndfileError, RuntimeError, TypeError) as exc:
        raise FormatError(p, f"cannot decode audio ({describe_bytes(head[:64])}): {exc}") from None
    if isinstance(source, io.BytesIO):
        source.seek(0)
    rate, channels, frames = int(info.samplerate), int(info.channels), int(info.frames)
    if not RATE_RANGE[0] <= rate <= RATE_RANGE[1]:
        raise FormatError(
            p, f"sample rate {rate} Hz is outside {RATE_RANGE[0]}..{RATE_RANGE[1]} Hz", field="samplerate"
        )
    if not 1 <= channels <= MAX_CHANNELS:
        raise FormatError(p, f"{channels} channels is outside 1..{MAX_CHANNELS}", field="channels")
    if frames <= 0:
        raise FormatError(p, "no audio samples (an empty or header-only file)", field="frames")
    if frames * channels * 4 > max(MAX_EXPANSION * size, _MIN_DECODED_BYTES):
        raise FormatError(
            p,
            f"header claims {frames} frames x {channels} channels, too many for {size} bytes",
            field="frames",
        )
    return AudioInfo(frames, rate, channels, _declared_wav_frames(head))


def audio_info(path: str | os.PathLike[str]) -> AudioInfo:
    """Check an audio file as :func:`read_audio` does, decoding no samples.

    Parameters
    ----------
    path : str or PathLike
        WAV (or FLAC/OGG/AIFF), optionally gzipped.

    Returns
    -------
    AudioInfo
        ``frames``, ``samplerate`` (Hz), ``channels``, ``declared_frames``.

    Raises
    ------
    FormatError
        Bytes that are not audio, an undecodable header, a rate outside
        :data:`RATE_RANGE`, more than :data:`MAX_CHANNELS` channels, no samples, or
        more frames than the file size can hold.

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "tone.wav"
    >>> write_wav(path, np.zeros((8000, 2)), 16000)
    >>> audio_info(path)
    AudioInfo(frames=8000, samplerate=16000, channels=2, declared_frames=8000)
    >>> tmp.cleanup()
    """
    p = Path(path)
    return _checked_info(p, *_audio_source(p))


def read_audio(
    path: str | os.PathLike[str], *, sr: int | None = SR, mono: bool = True
) -> tuple[np.ndarray, int]:
    """Read an audio file as float32 samples in [-1, 1].

    Parameters
    ----------
    path : str or PathLike
        A WAV file (any PCM/float flavour; FLAC/OGG/AIFF also work), optionally
        gzipped (``.wav.gz``).
    sr : int or None
        Target rate in Hz (default 16000, the models' rate). ``None`` keeps the
        file's native rate.
    mono : bool
        If True (default) channels are averaged to one.

    Returns
    -------
    y : (N,) float32 if ``mono`` else (N, C) float32
        Samples.
    sr : int
        Their rate in Hz.

    Raises
    ------
    FormatError
        If the bytes are not audio (naming what they look like), the header fails
        the checks of :func:`audio_info` (checked before any sample is decoded),
        libsndfile cannot decode them, or a sample is NaN or infinite (a float WAV;
        field ``samples``). A truncated WAV (fewer samples than its ``data`` chunk
        declares) is read with a :class:`FormatWarning`.

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "tone.wav"
    >>> write_wav(path, np.full(32000, 0.5), 32000)  # 1 s at 32 kHz
    >>> y, sr = read_audio(path)  # resampled to 16 kHz, mono
    >>> y.shape, sr, round(float(y[8000]), 3)
    ((16000,), 16000, 0.5)
    >>> tmp.cleanup()
    """
    import soundfile as sf

    target = None if sr is None else _check_rate(sr, "sr")
    p = Path(path)
    source, head, size = _audio_source(p)
    info = _checked_info(p, source, head, size)
    if info.declared_frames is not None and info.declared_frames > info.frames:
        warnings.warn(
            f"{p}: truncated audio: the header declares {info.declared_frames} frames "
            f"({info.declared_frames / info.samplerate:.3f} s) but the file holds {info.frames} "
            f"({info.duration:.3f} s); using what is there",
            FormatWarning,
            stacklevel=2,
        )
    try:
        y, native = sf.read(source, dtype="float32", always_2d=True)
    except (sf.LibsndfileError, RuntimeError, TypeError) as exc:
        raise FormatError(p, f"cannot decode audio ({describe_bytes(head[:64])}): {exc}") from None
    finite = np.isfinite(y)
    if not finite.all():  # a float WAV may hold NaN or inf: they would spread through resampling and features
        frame, channel = (int(i) for i in np.argwhere(~finite)[0])
        raise FormatError(
            p,
            f"sample {frame} of channel {channel} is {y[frame, channel]}, not a finite number",
            field="samples",
        )
    if mono:
        y = y.mean(axis=1, dtype=np.float32) if y.shape[1] > 1 else y[:, 0]
    if target is not None and target != native:
        y = resample(y, native, target)
        native = target
    return np.ascontiguousarray(y, dtype=np.float32), int(native)


def write_wav(path: str | os.PathLike[str], y: np.ndarray, sr: int, subtype: str = "PCM_16") -> None:
    """Write samples to a WAV file atomically.

    Parameters
    ----------
    path : str or PathLike
        Destination (``.wav``; ``.wav.gz`` gzips it).
    y : (N,) or (N, C) float array
        Samples in [-1, 1]; values outside are clipped for integer subtypes.
    sr : int
        Rate in Hz.
    subtype : str
        libsndfile subtype: ``"PCM_16"`` (default), ``"PCM_24"``, ``"PCM_32"``, ``"FLOAT"``.

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "ramp.wav.gz"  # gzipped
    >>> y = np.linspace(-1, 1, 101)
    >>> write_wav(path, y, 16000)
    >>> back, sr = read_audio(path, sr=None)
    >>> sr, bool(np.abs(back - y).max() <= 1 / 2**15)  # PCM_16: within one quantisation step
    (16000, True)
    >>> tmp.cleanup()
    """
    import soundfile as sf

    rate = _check_rate(sr, "sr")
    arr = np.asarray(y)
    if arr.ndim not in (1, 2):
        raise ValueError(f"write_wav: y must be (N,) or (N, C), got shape {arr.shape}")
    if not np.issubdtype(arr.dtype, np.number):
        raise TypeError(f"write_wav: y must be numeric, got dtype {arr.dtype}")
    arr = arr.astype(np.float32 if subtype.upper() == "FLOAT" else np.float64)
    if not np.isfinite(arr).all():
        raise ValueError("write_wav: y contains NaN or infinite samples")
    if subtype.upper().startswith("PCM"):
        arr = np.clip(arr, -1.0, 1.0)
    if subtype.upper() not in sf.available_subtypes("WAV"):
        raise ValueError(f"write_wav: subtype {subtype!r} not in {sorted(sf.available_subtypes('WAV'))}")
    buffer = io.BytesIO()  # libsndfile seeks back to patch the header: write in memory, then copy
    sf.write(buffer, arr, rate, subtype=subtype.upper(), format="WAV")
    with atomic_write(path, "wb") as f:
        f.write(buffer.getvalue())
