"""Bad real-world input (issue 14, items 4-6): every former crash is a FormatError naming file and field,
inconsistent-but-readable files warn, the BVH writer takes any depth, and lengths in metres are noticed."""

from __future__ import annotations

import io
import json
import os
import signal
import struct
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
import soundfile as sf

from beatlite.io import (
    ARKIT_51,
    BVHWarning,
    FormatError,
    Motion,
    atomic_write,
    load_take,
    parse_take_name,
    read_audio,
    read_bvh,
    read_emotion,
    read_facial,
    read_semantic,
    read_textgrid,
    write_bvh,
)
from beatlite.io.errors import FormatWarning
from beatlite.io.textfile import describe_bytes
from beatlite.skeleton import forward_kinematics
from beatlite.skeleton.core import Skeleton

REPO = Path(__file__).resolve().parents[1]
BVH = """HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Xrotation Yrotation Zrotation
  JOINT Spine
  {
    OFFSET 0 10 0
    CHANNELS 3 Xrotation Yrotation Zrotation
    End Site
    {
      OFFSET 0 10 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.033333
1 2 3 4 5 6 7 8 9
2 3 4 5 6 7 8 9 10
"""
TEXTGRID = """File type = "ooTextFile"
Object class = "TextGrid"

xmin = 0
xmax = 2
tiers? <exists>
size = 1
item []:
    item [1]:
        class = "IntervalTier"
        name = "words"
        xmin = 0
        xmax = 2
        intervals: size = 2
        intervals [1]:
            xmin = 0
            xmax = 1
            text = "hello"
        intervals [2]:
            xmin = 1
            xmax = 2
            text = ""
"""


def put(tmp_path: Path, name: str, content: str | bytes) -> Path:
    p = tmp_path / name
    p.write_bytes(content.encode("utf-8") if isinstance(content, str) else content)
    return p


def wav_bytes(seconds: float = 0.5, sr: int = 16000) -> bytes:
    buffer = io.BytesIO()
    y = 0.3 * np.sin(np.arange(int(seconds * sr)) / 5.0)
    sf.write(buffer, y.astype(np.float32), sr, subtype="PCM_16", format="WAV")
    return buffer.getvalue()


def facial_json(weights: list, times: list | None = None, names: list | None = None) -> str:
    names = list(ARKIT_51) if names is None else names
    times = [i / 60 for i in range(len(weights))] if times is None else times
    return json.dumps({"names": names, "frames": [{"time": t, "weights": w} for t, w in zip(times, weights)]})


# ----------------------------------------------------------------------------- former crashes


def test_facial_deep_nesting_and_huge_numbers(tmp_path: Path) -> None:
    deep = put(tmp_path, "deep.json", "[" * 100_000 + "]" * 100_000)
    with pytest.raises(FormatError, match="nested too deeply"):
        read_facial(deep)
    row = [0.5] * 51
    huge_time = facial_json([row]).replace('"time": 0.0', '"time": ' + "9" * 400)
    with pytest.raises(FormatError, match="time .* not a finite number") as err:
        read_facial(put(tmp_path, "t.json", huge_time))
    assert err.value.field == "frames[0].time"
    for digits in (400, 5000):  # 400 overflows float; 5000 is beyond Python's int digit limit
        text = facial_json([row]).replace("0.5", "9" * digits, 1)
        with pytest.raises(FormatError, match="weight 0 .* not a finite number") as err:
            read_facial(put(tmp_path, f"w{digits}.json", text))
        assert err.value.field == "frames[0].weights"


@pytest.mark.parametrize("bad", ['"0.5"', "true", "null", "[0.5]"])
def test_facial_non_numeric_weights(tmp_path: Path, bad: str) -> None:
    text = facial_json([[0.5] * 51]).replace("0.5", bad, 1)
    with pytest.raises(FormatError, match="not a finite number"):
        read_facial(put(tmp_path, "f.json", text))


@pytest.mark.parametrize(
    ("name", "field"),
    [
        ("2_scott_0_\u00b2_1", "start"),
        ("2_scott_0_1_" + "1" * 4300, "end"),
        ("\u0662_scott_0_1_1", "speaker_id"),
    ],
)
def test_take_name_unicode_digits_and_huge_fields(name: str, field: str) -> None:
    with pytest.raises(FormatError) as err:
        parse_take_name(name)
    assert err.value.field == field


@pytest.mark.parametrize("frame_time", ["1e-320", "1e400", "5e-324", "1000", "0"])
def test_bvh_absurd_frame_time(tmp_path: Path, frame_time: str) -> None:
    p = put(tmp_path, "x.bvh", BVH.replace("0.033333", frame_time))
    with pytest.raises(FormatError) as err:
        read_bvh(p)
    assert err.value.line == 18  # the Frame Time line
    assert read_bvh(p, fps=30).fps == 30.0  # the override still reads the rows


def test_bvh_channels_must_be_whole_kinds(tmp_path: Path) -> None:
    text = BVH.replace("CHANNELS 3 Xrotation Yrotation Zrotation", "CHANNELS 3 Xrotation Yrotation Xposition")
    with pytest.raises(FormatError, match="2 rotation and 1 position") as err:
        read_bvh(put(tmp_path, "x.bvh", text))
    assert err.value.line == 9


def test_bvh_duplicate_joint_names(tmp_path: Path) -> None:
    with pytest.raises(FormatError, match="'Hips' appears twice \\(first on line 2\\)") as err:
        read_bvh(put(tmp_path, "x.bvh", BVH.replace("JOINT Spine", "JOINT Hips")))
    assert err.value.line == 6


def test_textgrid_absurd_sizes_and_times(tmp_path: Path) -> None:
    with pytest.raises(FormatError, match="size"):
        read_textgrid(put(tmp_path, "a.TextGrid", TEXTGRID.replace("size = 1", "size = 1e400")))
    with pytest.raises(FormatError, match="more than the file holds"):
        read_textgrid(
            put(tmp_path, "b.TextGrid", TEXTGRID.replace("intervals: size = 2", "intervals: size = 1e9"))
        )
    with pytest.raises(FormatError, match="not a finite number") as err:
        read_textgrid(put(tmp_path, "c.TextGrid", TEXTGRID.replace("xmax = 1\n", "xmax = 1e400\n")))
    assert err.value.line == 17
    with pytest.raises(FormatError, match="xmin 3.0 is after xmax 2.0"):
        read_textgrid(
            put(tmp_path, "d.TextGrid", TEXTGRID.replace("xmin = 0\nxmax = 2", "xmin = 3\nxmax = 2", 1))
        )
    past = TEXTGRID.replace("            xmax = 2\n", "            xmax = 2.5\n")  # the last interval
    with pytest.warns(FormatWarning, match=r"interval 2 \[1.0, 2.5\] lies outside"):
        tiers = read_textgrid(put(tmp_path, "e.TextGrid", past))
    assert tiers["words"][-1].end == 2.5


# ----------------------------------------------------------------------------- audio


def _patch(data: bytes, offset: int, fmt: str, value: int) -> bytes:
    out = bytearray(data)
    out[offset : offset + struct.calcsize(fmt)] = struct.pack(fmt, value)
    return bytes(out)


@pytest.mark.parametrize(
    ("offset", "fmt", "value", "words"),
    [
        (24, "<I", 1, "sample rate 1 Hz"),
        (24, "<I", 1_000_000, "sample rate 1000000 Hz"),
        (22, "<H", 65535, "channels"),
    ],
)
def test_wav_header_bounds_before_decoding(
    tmp_path: Path, offset: int, fmt: str, value: int, words: str
) -> None:
    p = put(tmp_path, "x.wav", _patch(wav_bytes(), offset, fmt, value))  # 16 kB file
    with pytest.raises(FormatError, match=words):
        read_audio(p)


def test_wav_empty_header_only_and_truncated(tmp_path: Path) -> None:
    data = wav_bytes(1.0)
    with pytest.raises(FormatError, match="empty file"):
        read_audio(put(tmp_path, "empty.wav", b""))
    with pytest.raises(FormatError, match="no audio samples") as err:
        read_audio(put(tmp_path, "header.wav", data[:44]))
    assert err.value.field == "frames"
    with pytest.warns(
        FormatWarning, match=r"truncated audio: the header declares 16000 frames .* holds 7989"
    ):
        y, sr = read_audio(put(tmp_path, "half.wav", data[: 44 + 2 * 7989]), sr=None)
    assert (len(y), sr) == (7989, 16000)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert len(read_audio(put(tmp_path, "whole.wav", data), sr=None)[0]) == 16000


def test_bom_comes_before_mp3_sync(tmp_path: Path) -> None:
    utf16 = "01_beat_align\t0.5\t1.0\t0.5\t0.25\n".encode("utf-16")  # FF FE: also an MP3 sync pattern
    assert describe_bytes(utf16) == "UTF-16 text"
    assert describe_bytes("x".encode("utf-32")) == "UTF-32 text"
    with pytest.raises(FormatError, match="UTF-16 text"):
        read_audio(put(tmp_path, "x.wav", utf16))
    assert read_semantic(put(tmp_path, "x.txt", utf16))[0].score == 0.25  # and the text is read
    assert read_semantic(put(tmp_path, "y.txt", "a\t0\t1\t1\t0.5\n".encode("utf-32")))[0].end == 1.0


# ----------------------------------------------------------------------------- line endings, annotations


def test_cr_only_bvh_reads_like_lf(tmp_path: Path) -> None:
    lf = read_bvh(put(tmp_path, "lf.bvh", BVH))
    cr = read_bvh(put(tmp_path, "cr.bvh", BVH.replace("\n", "\r")))
    np.testing.assert_array_equal(cr.channels, lf.channels)
    assert cr.skeleton.names == lf.skeleton.names
    with pytest.raises(FormatError, match="not a number") as err:
        read_bvh(put(tmp_path, "bad.bvh", BVH.replace("2 3 4", "2 x 4").replace("\n", "\r")))
    assert err.value.line == 19  # lines are counted after CR -> LF


def test_semantic_and_emotion_times(tmp_path: Path) -> None:
    with pytest.raises(FormatError, match="negative time") as err:
        read_semantic(put(tmp_path, "a.txt", "01_beat\t-1.0\t2.0\t3.0\t0.5\n"))
    assert err.value.line == 1
    with pytest.raises(FormatError, match="negative time"):
        read_emotion(put(tmp_path, "a.csv", "x,0.0,-2.0,2.0,1\n"))
    with pytest.warns(FormatWarning, match="1 rows have a duration that is not end - start, e.g. line 2"):
        segments = read_semantic(put(tmp_path, "b.txt", "a\t0\t1\t1\t0.5\nb\t1\t2\t5\t0.5\n"))
    assert [s.end - s.start for s in segments] == [1.0, 1.0]
    with pytest.warns(FormatWarning, match="duration"):
        read_emotion(put(tmp_path, "b.csv", "x,0.0,2.0,9.0,1\n"))


def test_empty_emotion_file_is_an_error_not_neutral(tmp_path: Path) -> None:
    from test_io_take import make_take

    with pytest.raises(FormatError, match="no emotion rows"):
        read_emotion(put(tmp_path, "x.csv", "\n\n"))
    stem = make_take(tmp_path)
    (tmp_path / f"{stem.name}.csv").write_text("", encoding="utf-8")
    with pytest.raises(FormatError, match="no emotion rows"):
        load_take(stem)


# ----------------------------------------------------------------------------- writer


def chain(n: int, *, names: tuple[str, ...] | None = None) -> Skeleton:
    return Skeleton(
        names=names or tuple(f"j{i}" for i in range(n)),
        parents=np.arange(-1, n - 1),
        offsets=np.tile([0.0, 1.0, 0.0], (n, 1)),
        channels=(("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation"),)
        + (("Zrotation", "Xrotation", "Yrotation"),) * (n - 1),
        end_sites={n - 1: np.array([0.0, 1.0, 0.0])},
    )


def test_writer_has_no_recursion_limit(tmp_path: Path) -> None:
    skel = chain(5000)  # Python's default recursion limit is 1000
    channels = np.random.default_rng(0).integers(-90, 90, size=(2, skel.n_channels)).astype(np.float64)
    write_bvh(tmp_path / "deep.bvh", Motion(skel, channels, 30))
    back = read_bvh(tmp_path / "deep.bvh", units="cm")
    assert back.skeleton.names == skel.names and np.array_equal(back.skeleton.parents, skel.parents)
    np.testing.assert_array_equal(back.channels, channels)


@pytest.mark.parametrize("bad", ["a{b", "a}b", "two\nlines", "tab\there", " edge", "dou  ble", ""])
def test_writer_refuses_names_it_cannot_read_back(tmp_path: Path, bad: str) -> None:
    skel = chain(2, names=("Hips", bad))
    with pytest.raises(ValueError, match="cannot be read back"):
        write_bvh(tmp_path / "x.bvh", Motion(skel, np.zeros((1, skel.n_channels)), 30))
    assert not any(tmp_path.iterdir())  # nothing written, no temp file left
    dup = chain(2, names=("Hips", "Hips"))
    with pytest.raises(ValueError, match="appears twice"):
        write_bvh(tmp_path / "x.bvh", Motion(dup, np.zeros((1, dup.n_channels)), 30))


def test_temp_file_of_a_killed_writer_is_cleaned(tmp_path: Path) -> None:
    target = tmp_path / "out.txt"
    code = (
        "import os, signal\n"
        "from beatlite.io import atomic_write\n"
        f"with atomic_write({str(target)!r}) as f:\n"
        "    f.write('partial')\n"
        "    os.kill(os.getpid(), signal.SIGKILL)\n"
    )
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, timeout=120)
    assert done.returncode == -signal.SIGKILL
    stale = [p.name for p in tmp_path.iterdir()]
    assert len(stale) == 1 and stale[0].startswith(".out.txt.") and stale[0].endswith(".tmp")
    with atomic_write(target) as f:
        f.write("complete\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"] and target.read_text() == "complete\n"


def test_a_new_file_follows_the_umask(tmp_path: Path) -> None:
    """A new file was always 0o644, even under umask 077 (private files readable by everyone)."""
    old = os.umask(0o077)
    try:
        with atomic_write(tmp_path / "private.txt") as f:
            f.write("secret\n")
        os.umask(0o022)
        with atomic_write(tmp_path / "shared.txt") as f:
            f.write("open\n")
    finally:
        os.umask(old)
    assert (tmp_path / "private.txt").stat().st_mode & 0o777 == 0o600  # 0o666 & ~0o077
    assert (tmp_path / "shared.txt").stat().st_mode & 0o777 == 0o644  # 0o666 & ~0o022


def test_a_sibling_targets_live_temp_file_is_not_taken_for_a_stale_one(tmp_path: Path) -> None:
    """Writing ``a`` removed ``.a.<digits>.<pid>.<random>.tmp``, the live temp file of a writer of ``a.<digits>``
    (the digits read as a dead process id)."""
    dead = 999_999_999  # beyond pid_max: no such process
    sibling = tmp_path / f".a.{dead}.{os.getpid()}.k3j_x9q2.tmp"  # this live process writing "a.999999999"
    stale = tmp_path / f".a.{dead}.k3j_x9q2.tmp"  # a killed writer of "a"
    for p in (sibling, stale):
        p.write_text("partial")
    with atomic_write(tmp_path / "a") as f:
        f.write("whole\n")
    assert sibling.exists() and not stale.exists()


# ----------------------------------------------------------------------------- units and position_mode


def test_metres_are_noticed_and_converted(tmp_path: Path) -> None:
    # an SMPL-X-like export in metres: pelvis -> spine 0.1 -> neck 0.45 -> head 0.1; legs 0.9 down
    metres = BVH.replace("OFFSET 0 10 0\n    CHANNELS", "OFFSET 0 0.55 0\n    CHANNELS")
    metres = metres.replace("      OFFSET 0 10 0", "      OFFSET 0 0.25 0").replace(
        "1 2 3 4", "0.01 0.9 0.03 4"
    )
    p = put(tmp_path, "m.bvh", metres)
    with pytest.warns(BVHWarning, match=r"only 0\.8 units tall.*metres.*units='m'"):
        raw = read_bvh(p)
    cm = read_bvh(p, units="m")
    np.testing.assert_allclose(cm.skeleton.offsets, raw.skeleton.offsets * 100)
    np.testing.assert_allclose(cm.skeleton.end_sites[1], [0.0, 25.0, 0.0])
    np.testing.assert_allclose(cm.channels[:, :3], raw.channels[:, :3] * 100)  # positions
    np.testing.assert_array_equal(cm.channels[:, 3:], raw.channels[:, 3:])  # rotations untouched
    np.testing.assert_allclose(cm.positions(), raw.positions() * 100, atol=1e-9)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        read_bvh(p, units="cm")  # the caller says so: silent
        read_bvh(put(tmp_path, "cm.bvh", BVH))  # 20 cm tall: centimetres
    with pytest.raises(ValueError, match="units"):
        read_bvh(p, units="inch")


def test_add_mode_does_not_count_a_root_offset_twice() -> None:
    # ZEGGS/LAFAN1 write the root OFFSET as the start position that the root channels already hold
    skel = Skeleton(
        names=("Hips", "Spine"),
        parents=np.array([-1, 0]),
        offsets=np.array([[10.0, 90.0, -5.0], [0.0, 10.0, 0.0]]),
        channels=(("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation"), ()),
    )
    ch = np.array([[10.0, 90.0, -5.0, 0, 0, 0], [12.0, 91.0, -5.0, 0, 0, 0]])
    for mode in ("add", "replace"):
        pos = forward_kinematics(skel, ch, position_mode=mode)
        np.testing.assert_allclose(pos[:, 0], ch[:, :3])  # the root is where its channels say
        np.testing.assert_allclose(pos[:, 1], ch[:, :3] + [0.0, 10.0, 0.0])


def test_docs_state_the_position_mode_default() -> None:
    import inspect

    default = inspect.signature(forward_kinematics).parameters["position_mode"].default
    docs = (REPO / "docs" / "architecture.md").read_text(encoding="utf-8")
    assert f'position_mode="{default}"' in docs and 'position_mode="add") ->' not in docs


def test_gzip_bombs_are_refused_while_they_inflate(tmp_path: Path) -> None:
    """A small .gz that inflates without limit (1.7 MB -> 700 MB took 71 s and 3.7 GB) is refused once it passes
    GZIP_MAX_RATIO times its size; the readers never hold more than that."""
    import gzip

    from beatlite.io import read_audio, read_bvh
    from beatlite.io.textfile import GZIP_MAX_RATIO, read_bytes

    repo = Path(__file__).resolve().parents[1]
    body = gzip.decompress((repo / "data_samples" / "2_scott_0_1_1.bvh.gz").read_bytes())
    head, _, rows = body.partition(b"MOTION")
    row = rows.split(b"\n")[3] + b"\n"
    with gzip.open(
        tmp_path / "bomb.bvh.gz", "wb"
    ) as f:  # a real header, then one row 300,000 times (about 330 MB)
        f.write(head + b"MOTION\nFrames: 300000\nFrame Time: 0.0333333\n")
        for _ in range(30):
            f.write(row * 10000)
    size = (tmp_path / "bomb.bvh.gz").stat().st_size
    assert len(row) * 300000 > GZIP_MAX_RATIO * size + 2**20  # it does inflate beyond the limit
    with pytest.raises(FormatError, match="decompression bomb"):
        read_bvh(tmp_path / "bomb.bvh.gz")
    wav = io.BytesIO()
    sf.write(wav, np.zeros(16000 * 600, np.int16), 16000, subtype="PCM_16", format="WAV")  # 10 min of silence
    (tmp_path / "quiet.wav.gz").write_bytes(gzip.compress(wav.getvalue()))
    with pytest.raises(FormatError, match="decompression bomb"):
        read_audio(tmp_path / "quiet.wav.gz")
    # what real files inflate to passes: every gzipped file of data_samples reads whole
    for p in sorted((repo / "data_samples").glob("*.gz"))[:10]:
        assert len(read_bytes(p)) == len(gzip.decompress(p.read_bytes()))


def test_a_gzip_bomb_without_a_newline_is_refused_within_the_limit(tmp_path: Path) -> None:
    """A .bvh.gz of zeros has no newline: reading its first line inflated it all before the ratio was checked
    (400 KB -> 400 MB took 20 s and 836 MB). Now a line is read no further than the limit."""
    import gzip
    import tracemalloc

    from beatlite.data.index import bvh_duration
    from beatlite.io import read_bvh_header
    from beatlite.io.textfile import GZIP_MAX_RATIO

    path = tmp_path / "zeros.bvh.gz"
    with gzip.GzipFile(path, "wb", mtime=0) as f:
        for _ in range(300):
            f.write(bytes(2**20))  # 300 MiB of zeros in about 300 KB
    limit = GZIP_MAX_RATIO * path.stat().st_size + 2**20
    assert 300 * 2**20 > 4 * limit  # the file does inflate far beyond the limit
    for reader in (read_bvh, read_bvh_header, bvh_duration):
        tracemalloc.start()
        try:
            with pytest.raises(FormatError, match="decompression bomb"):
                reader(path)
            peak = tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()
        assert peak < 3 * limit, f"{reader.__name__}: peak {peak} bytes for a limit of {limit}"


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("subtype", ["FLOAT", "DOUBLE"])
def test_a_float_wav_with_a_non_finite_sample_is_refused(tmp_path: Path, bad: float, subtype: str) -> None:
    """A float WAV may store NaN or inf; read_audio returned them (and resampling spread NaN over the neighbours)."""
    y = np.full((3000, 2), 0.25)
    y[1234, 1] = bad
    path = tmp_path / "take.wav"
    sf.write(path, y, 48000, subtype=subtype)
    for sr in (None, 16000):
        with pytest.raises(FormatError, match="sample 1234 of channel 1") as info:
            read_audio(path, sr=sr)
        assert info.value.field == "samples"
    y[1234, 1] = 0.5  # the same file with a finite sample reads
    sf.write(path, y, 48000, subtype=subtype)
    assert read_audio(path, sr=None, mono=False)[0][1234, 1] == 0.5
