"""Tests of read_audio / write_wav: every WAV flavour, resampling, and non-audio bytes."""

from __future__ import annotations

import io
import struct
from pathlib import Path

import numpy as np
import pytest
import soundfile as sf

from beatlite.io import FormatError, read_audio, write_wav


def sine(sr: int, seconds: float, freq: float = 440.0, amp: float = 0.5) -> np.ndarray:
    t = np.arange(int(sr * seconds)) / sr
    return amp * np.sin(2 * np.pi * freq * t)


# quantisation step of each subtype (half a step is the worst rounding error)
FLAVOURS = {"PCM_16": 2.0**-15, "PCM_24": 2.0**-23, "PCM_32": 2.0**-31, "FLOAT": 2.0**-24}


@pytest.mark.parametrize("subtype", sorted(FLAVOURS))
def test_wav_flavours_native_rate(tmp_path: Path, subtype: str) -> None:
    y = sine(22050, 0.5)
    p = tmp_path / f"{subtype}.wav"
    sf.write(p, y, 22050, subtype=subtype)
    out, sr = read_audio(p, sr=None)
    assert sr == 22050 and out.dtype == np.float32 and out.shape == y.shape
    # half a quantisation step, plus up to |y| * step because libsndfile scales by 2**(b-1) - 1 when
    # writing and by 2**(b-1) when reading (|y| <= 0.5), plus float32 rounding (2**-25 for |y| <= 0.5)
    step = FLAVOURS[subtype]
    np.testing.assert_allclose(out, y, rtol=0, atol=step / 2 + 0.5 * step + 2.0**-24)


def test_stereo_48k_to_16k_mono(tmp_path: Path) -> None:
    left, right = sine(48000, 1.0, 440, 0.5), sine(48000, 1.0, 440, 0.3)
    p = tmp_path / "stereo.wav"
    sf.write(p, np.stack([left, right], axis=1), 48000, subtype="PCM_16")
    out, sr = read_audio(p)  # default 16 kHz mono
    assert sr == 16000 and out.shape == (16000,)
    # the mean of the channels is a 0.4-amplitude 440 Hz sine; resampling keeps it (away from the edges)
    expected = sine(16000, 1.0, 440, 0.4)
    np.testing.assert_allclose(out[500:-500], expected[500:-500], atol=2e-3)
    both, sr = read_audio(p, sr=None, mono=False)
    assert sr == 48000 and both.shape == (48000, 2)
    np.testing.assert_allclose(both[:, 1], right, atol=2.0**-15)


def _insert_list_chunk(wav: bytes) -> bytes:
    """Insert a LIST/INFO chunk between 'fmt ' and 'data' and fix the RIFF size."""
    assert wav[:4] == b"RIFF" and wav[8:12] == b"WAVE"
    pos = 12
    while wav[pos : pos + 4] != b"data":
        size = struct.unpack("<I", wav[pos + 4 : pos + 8])[0]
        pos += 8 + size + (size & 1)
    payload = b"INFO" + b"ISFT" + struct.pack("<I", 10) + b"beatlite\x00\x00"
    chunk = b"LIST" + struct.pack("<I", len(payload)) + payload
    out = wav[:pos] + chunk + wav[pos:]
    return out[:4] + struct.pack("<I", len(out) - 8) + out[8:]


def test_extra_riff_chunk(tmp_path: Path) -> None:
    y = sine(16000, 0.25)
    buf = io.BytesIO()
    sf.write(buf, y, 16000, subtype="PCM_16", format="WAV")
    data = _insert_list_chunk(buf.getvalue())
    assert b"LIST" in data
    p = tmp_path / "list.wav"
    p.write_bytes(data)
    out, sr = read_audio(p)
    plain, _ = sf.read(io.BytesIO(buf.getvalue()), dtype="float32")
    assert sr == 16000
    np.testing.assert_array_equal(out, plain)


def test_real_wav(real_samples: Path) -> None:
    p = real_samples / "2_scott_0_2_2.wav"
    y, sr = read_audio(p, sr=None)
    assert sr == 16000 and y.shape == (992000,)  # 62.0 s x 16000
    assert y.shape[0] / sr == 62.0
    raw, _ = sf.read(p, dtype="int16")
    np.testing.assert_array_equal(y, raw.astype(np.float32) / 32768)
    y16, sr16 = read_audio(p)  # already 16 kHz: no resampling
    np.testing.assert_array_equal(y16, y)


def test_write_wav_round_trip(tmp_path: Path) -> None:
    k = np.arange(-32768, 32768, 7)
    y = (k / 32768).astype(np.float32)  # exactly representable in PCM16
    write_wav(tmp_path / "w.wav", y, 8000)
    out, sr = read_audio(tmp_path / "w.wav", sr=None)
    assert sr == 8000
    np.testing.assert_array_equal(out, y)
    with pytest.raises(ValueError, match="NaN"):
        write_wav(tmp_path / "bad.wav", np.array([0.0, np.nan]), 8000)
    with pytest.raises(ValueError, match="shape"):
        write_wav(tmp_path / "bad.wav", np.zeros((2, 2, 2)), 8000)
    assert not (tmp_path / "bad.wav").exists()


def test_write_wav_float_and_clipping(tmp_path: Path) -> None:
    y = np.array([0.0, 0.5, 2.0, -3.0])
    write_wav(tmp_path / "c.wav", y, 16000)
    out, _ = read_audio(tmp_path / "c.wav", sr=None)
    assert out[2] == pytest.approx(1.0, abs=2.0**-15) and out[3] == -1.0
    write_wav(tmp_path / "f.wav", y, 16000, subtype="FLOAT")
    out, _ = read_audio(tmp_path / "f.wav", sr=None)
    np.testing.assert_array_equal(out, y.astype(np.float32))


@pytest.mark.parametrize(
    ("content", "words"),
    [
        (b"", "empty"),
        (b"ID3\x04\x00\x00\x00\x00\x00\x21" + b"\xff\xfb\x90\x00" * 200, "MP3"),
        (
            b"version https://git-lfs.github.com/spec/v1\noid sha256:" + b"0" * 64 + b"\nsize 1984044\n",
            "Git-LFS",
        ),
        (b"<!DOCTYPE html>\n<html><body>Not found</body></html>", "HTML"),
        (b"RIFF\x24\x00\x00\x00WAVEfmt \x10\x00\x00\x00" + b"\x00" * 8, "cannot decode"),
    ],
)
def test_not_audio(tmp_path: Path, content: bytes, words: str) -> None:
    p = tmp_path / "speech.wav"
    p.write_bytes(content)
    with pytest.raises(FormatError, match=words) as info:
        read_audio(p)
    assert str(p) in str(info.value)


def test_bad_rate_argument(tmp_path: Path) -> None:
    sf.write(tmp_path / "a.wav", np.zeros(10), 16000)
    with pytest.raises(ValueError, match="sr"):
        read_audio(tmp_path / "a.wav", sr=0)
    with pytest.raises(TypeError, match="sr"):
        read_audio(tmp_path / "a.wav", sr="16k")  # type: ignore[arg-type]
