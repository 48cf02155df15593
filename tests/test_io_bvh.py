"""Tests of the BVH reader/writer, the gzip-transparent helpers and atomic writes."""

from __future__ import annotations

import gzip
import math
import os
import warnings
from pathlib import Path

import numpy as np
import pytest

from beatlite.io import BVHWarning, FormatError, Motion, atomic_write, read_bvh, read_bvh_header, write_bvh
from beatlite.io.bvh import format_frame_time, parse_frame_time
from beatlite.io.textfile import read_text, resolve
from beatlite.skeleton.core import Skeleton

# A 3-joint chain + End Site: root with 6 channels (ZXY rotations), two joints with 3.
SMALL_HEADER = """HIERARCHY
ROOT mixamorig:Hips
{
\tOFFSET 0.0 0.0 0.0
\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
\tJOINT mixamorig:Spine
\t{
\t\tOFFSET 0.0 10.5 -1.25
\t\tCHANNELS 3 Zrotation Xrotation Yrotation
\t\tJOINT Head
\t\t{
\t\t\tOFFSET 0 5 0
\t\t\tCHANNELS 3 Xrotation Yrotation Zrotation
\t\t\tEnd Site
\t\t\t{
\t\t\t\tOFFSET 0 2.5 0
\t\t\t}
\t\t}
\t}
}
"""
# the header above has 20 lines; MOTION is line 21, Frames 22, Frame Time 23, data from line 24
FIRST_DATA_LINE = 24
ROWS = [
    "1.0 2.0 3.0 10 20 30 -1 -2 -3 0.5 0.25 0.125",
    "1.5 2.5 3.5 11 21 31 -4 -5 -6 1e-3 -2.5E+1 7",
    "2.0 3.0 4.0 12 22 32 -7 -8 -9 0 0 0",
]
EXPECTED = np.array(
    [
        [1.0, 2.0, 3.0, 10, 20, 30, -1, -2, -3, 0.5, 0.25, 0.125],
        [1.5, 2.5, 3.5, 11, 21, 31, -4, -5, -6, 0.001, -25.0, 7],
        [2.0, 3.0, 4.0, 12, 22, 32, -7, -8, -9, 0, 0, 0],
    ]
)


def small_bvh(frames: str = "3", frame_time: str = "0.033333", rows: list[str] | None = None) -> str:
    rows = ROWS if rows is None else rows
    return SMALL_HEADER + f"MOTION\nFrames: {frames}\nFrame Time: {frame_time}\n" + "\n".join(rows) + "\n"


def write(tmp_path: Path, text: str | bytes, name: str = "x.bvh") -> Path:
    p = tmp_path / name
    p.write_bytes(text.encode() if isinstance(text, str) else text)
    return p


def small_skeleton() -> Skeleton:
    return Skeleton(
        names=("mixamorig:Hips", "mixamorig:Spine", "Head"),
        parents=np.array([-1, 0, 1]),
        offsets=np.array([[0.0, 0, 0], [0, 10.5, -1.25], [0, 5, 0]]),
        channels=(
            ("Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation", "Yrotation"),
            ("Zrotation", "Xrotation", "Yrotation"),
            ("Xrotation", "Yrotation", "Zrotation"),
        ),
        end_sites={2: np.array([0.0, 2.5, 0.0])},
    )


# ----------------------------------------------------------------------------- parsing


def test_small_file_hierarchy_and_values(tmp_path: Path) -> None:
    m = read_bvh(write(tmp_path, small_bvh()))
    ref = small_skeleton()
    assert m.skeleton.same_topology(ref)
    np.testing.assert_array_equal(m.skeleton.offsets, ref.offsets)
    np.testing.assert_array_equal(m.skeleton.end_sites[2], [0, 2.5, 0])
    assert m.skeleton.rotation_order(0) == "ZXY"
    np.testing.assert_array_equal(m.channels, EXPECTED)
    assert m.fps == 30.0  # 0.033333 is 1/30 to 6 decimals


def test_tolerated_variants(tmp_path: Path) -> None:
    """Frames: N.0, TAB after Frames:, scientific notation, trailing blank lines, CRLF, gzip."""
    text = small_bvh(frames="\t3.0") + "\n\n   \n"
    text = text.replace("Frames: \t3.0", "Frames:\t3.0").replace("\n", "\r\n")
    p = write(tmp_path, text)
    np.testing.assert_array_equal(read_bvh(p).channels, EXPECTED)
    gz = tmp_path / "y.bvh.gz"
    gz.write_bytes(gzip.compress(text.encode()))
    np.testing.assert_array_equal(read_bvh(gz).channels, EXPECTED)


def test_row_count_mismatch_warns_or_raises(tmp_path: Path) -> None:
    p = write(tmp_path, small_bvh(frames="5"))
    with pytest.warns(BVHWarning, match=r"Frames: 5.*3 rows"):
        m = read_bvh(p)
    assert m.n_frames == 3
    with pytest.raises(FormatError, match="Frames: 5"):
        read_bvh(p, strict=True)


def test_no_warning_when_counts_match(tmp_path: Path) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        read_bvh(write(tmp_path, small_bvh()), strict=True)


def test_fps_override_and_frame_time_parsing(tmp_path: Path) -> None:
    p = write(tmp_path, small_bvh(frame_time="0.041667"))  # BEAT quirk: docs/reference_code.md#bvh-header
    assert read_bvh(p).fps == 24.0
    assert read_bvh(p, fps=120).fps == 120.0
    assert parse_frame_time("0.008333") == 120.0  # |1/120 - 0.008333| = 3.3e-7 <= 1e-6
    assert parse_frame_time("0.0333333") == 30.0
    assert parse_frame_time("8.333e-3") == 120.0
    # 1/0.0333667 = 29.97 and no integer n has 1/n within 1e-7 of 0.0333667
    assert parse_frame_time("0.0333667") == pytest.approx(1 / 0.0333667, rel=1e-15)
    with pytest.raises(ValueError):
        read_bvh(p, fps=0)


@pytest.mark.parametrize("fps", [15, 120, 30, 60, 24, 1000, 7000, 29.97, 23.976, 59.94, 1 / 0.7, 12.5])
def test_frame_time_text_reads_back_as_fps(fps: float) -> None:
    text = format_frame_time(fps)
    assert parse_frame_time(text) == float(fps)
    assert len(text.split(".")[1]) >= 6


def test_frame_time_any_rate_close() -> None:
    for fps in np.random.default_rng(3).uniform(1, 500, 200):
        assert parse_frame_time(format_frame_time(fps)) == pytest.approx(fps, rel=1e-14)


def test_frame_time_like_beat() -> None:
    assert format_frame_time(120) == "0.008333"
    assert format_frame_time(15) == "0.066667"


def test_read_header_only(tmp_path: Path) -> None:
    # the motion rows are garbage: read_bvh_header must not look at them
    p = write(tmp_path, small_bvh(rows=["not numbers at all"] * 3))
    skeleton, n, dt = read_bvh_header(p)
    assert skeleton.n_joints == 3 and skeleton.n_channels == 12
    assert n == 3 and dt == 0.033333
    with pytest.raises(FormatError):
        read_bvh(p)


def test_zero_frames_are_a_format_error_but_the_header_reads(tmp_path: Path) -> None:
    """An empty MOTION block is no motion (it was read as a (0, C) take); the skeleton alone still reads."""
    path = write(tmp_path, small_bvh(frames="0", rows=[]))
    with pytest.raises(FormatError, match="no motion") as info:
        read_bvh(path)
    assert info.value.field == "Frames"
    assert read_bvh_header(path)[1] == 0


def test_a_joint_with_two_end_sites_is_a_format_error(tmp_path: Path) -> None:
    """A Skeleton holds one End Site per joint: the second silently replaced the first."""
    text = small_bvh(frames="1", rows=["0 " * 12])
    site = "End Site\n{\nOFFSET 0 1 0\n}\n"
    i = text.index("End Site")
    doubled = text[:i] + site + text[i:]
    with pytest.raises(FormatError, match="second End Site"):
        read_bvh(write(tmp_path, doubled))


@pytest.mark.parametrize("line", ["OFFSET 0 99 0", "CHANNELS 3 Xrotation Yrotation Zrotation", "CHANNELS 0"])
def test_a_joint_with_a_second_offset_or_channels_line_is_a_format_error(tmp_path: Path, line: str) -> None:
    """The second OFFSET or CHANNELS of a joint silently replaced the first (which one the exporter meant is
    unknowable: the rows were read with the last)."""
    text = small_bvh()
    i = text.index("\t\tCHANNELS 3 Zrotation")  # inside mixamorig:Spine, after its OFFSET (line 8)
    with pytest.raises(FormatError, match="'mixamorig:Spine' has a second") as info:
        read_bvh(write(tmp_path, text[:i] + "\t\t" + line + "\n" + text[i:]))
    assert info.value.line == (9 if line.startswith("OFFSET") else 10)  # the second of the two lines


@pytest.mark.parametrize("frame_time", ["0", "0.0", "-0.033333"])
def test_the_header_refuses_a_frame_time_of_zero_or_less(tmp_path: Path, frame_time: str) -> None:
    """read_bvh refused such a file but read_bvh_header returned the value, so bvh_duration gave -0.1 s."""
    from beatlite.data.index import bvh_duration

    p = write(tmp_path, small_bvh(frame_time=frame_time))
    for reader in (read_bvh_header, bvh_duration):
        with pytest.raises(FormatError, match="positive") as info:
            reader(p)
        assert info.value.line == FIRST_DATA_LINE - 1
    assert read_bvh(p, fps=30).n_frames == 3  # an override still reads the rows


# ----------------------------------------------------------------------------- real files


def _python_rows(path: Path, first_data_line: int) -> np.ndarray:
    """Independent oracle: per-line float() parse of the rows after the header."""
    lines = path.read_text().splitlines()[first_data_line - 1 :]
    return np.array([[float(t) for t in ln.split()] for ln in lines if ln.strip()])


def test_real_beat_skeleton(real_samples: Path) -> None:
    p = real_samples / "beat_skeleton_2_scott_0_1_1_frame0.bvh"
    m = read_bvh(p)
    sk = m.skeleton
    assert sk.n_joints == 75 and sk.n_channels == 228
    assert len(sk.end_sites) == 13
    assert sk.names[0] == "Hips" and sk.channels[0][:3] == ("Xposition", "Yposition", "Zposition")
    assert all(c == ("Xrotation", "Yrotation", "Zrotation") for c in sk.channels[1:])
    assert sk.names[sk.parents[sk.index("RightArm")]] == "RightShoulder"
    assert m.fps == 120.0 and m.n_frames == 1
    # 1 HIERARCHY + 5 root lines + 74*5 + 13*4 = 428 lines, then MOTION, Frames, Frame Time (docs/reference_code.md#bvh-header)
    np.testing.assert_array_equal(m.channels, _python_rows(p, 432))
    assert m.channels[0, :3].tolist() == [0.002950, -0.007960, -0.012340]


def test_real_bandai_bvh(real_samples: Path) -> None:
    p = real_samples / "dataset-1_bye_normal_001.bvh"
    m = read_bvh(p)
    sk = m.skeleton
    assert sk.n_joints == 22
    assert all(len(c) == 6 for c in sk.channels)
    assert all(sk.rotation_order(j) == "ZXY" for j in range(22))
    assert m.n_frames == 111 and m.fps == 30.0
    header_lines = next(i for i, ln in enumerate(p.read_text().splitlines()) if ln.startswith("Frame Time"))
    np.testing.assert_array_equal(m.channels, _python_rows(p, header_lines + 2))


def test_real_files_round_trip(real_samples: Path, tmp_path: Path) -> None:
    # BEAT prints 6 decimals: exact at precision 6
    m = read_bvh(real_samples / "beat_skeleton_2_scott_0_1_1_frame0.bvh")
    write_bvh(tmp_path / "beat.bvh", m)
    back = read_bvh(tmp_path / "beat.bvh")
    assert back.skeleton.same_topology(m.skeleton) and back.fps == 120.0
    np.testing.assert_array_equal(back.skeleton.offsets, m.skeleton.offsets)
    np.testing.assert_array_equal(back.channels, m.channels)
    # Bandai prints %g (e.g. 5.1072e-06): 8 fixed decimals are within half a unit of 1e-8
    m = read_bvh(real_samples / "dataset-1_bye_normal_001.bvh")
    write_bvh(tmp_path / "bandai.bvh", m, precision=8)
    back = read_bvh(tmp_path / "bandai.bvh")
    assert back.skeleton.same_topology(m.skeleton) and back.fps == 30.0
    np.testing.assert_array_equal(back.skeleton.offsets, m.skeleton.offsets)
    np.testing.assert_allclose(back.channels, m.channels, rtol=0, atol=0.5e-8 * (1 + 1e-6))


# ----------------------------------------------------------------------------- writer


@pytest.mark.parametrize("precision", [6, 3, 9])
def test_write_read_round_trip_exact(tmp_path: Path, precision: int) -> None:
    rng = np.random.default_rng(0)
    values = np.round(rng.normal(0, 90, (50, 12)), precision)
    motion = Motion(small_skeleton(), values, fps=15)
    p = tmp_path / "r.bvh"
    write_bvh(p, motion, precision=precision)
    back = read_bvh(p, strict=True)
    assert back.skeleton.same_topology(motion.skeleton)
    np.testing.assert_array_equal(back.skeleton.offsets, motion.skeleton.offsets)
    np.testing.assert_array_equal(back.skeleton.end_sites[2], motion.skeleton.end_sites[2])
    assert back.channels.tobytes() == values.tobytes()  # bit-identical
    assert back.fps == 15.0


def test_write_gz_and_odd_fps(tmp_path: Path) -> None:
    motion = Motion(small_skeleton(), np.zeros((4, 12)), fps=29.97)
    p = tmp_path / "r.bvh.gz"
    write_bvh(p, motion)
    assert p.read_bytes()[:2] == b"\x1f\x8b"
    assert read_bvh(p).fps == 29.97
    assert resolve(tmp_path / "r", ".bvh") == p


def test_write_rejects_bad_input(tmp_path: Path) -> None:
    with pytest.raises(TypeError, match="motion"):
        write_bvh(tmp_path / "a.bvh", np.zeros((3, 12)))  # type: ignore[arg-type]
    bad = Motion(small_skeleton(), np.full((2, 12), np.nan), fps=30)
    with pytest.raises(ValueError, match="not finite"):
        write_bvh(tmp_path / "a.bvh", bad)
    assert not (tmp_path / "a.bvh").exists()


# ----------------------------------------------------------------------------- bad input


def _error(path: Path, **kwargs: object) -> FormatError:
    with pytest.raises(FormatError) as info:
        read_bvh(path, **kwargs)  # type: ignore[arg-type]
    assert str(path) in str(info.value)
    return info.value


def test_empty_file(tmp_path: Path) -> None:
    err = _error(write(tmp_path, ""))
    assert "empty" in str(err)


def test_truncated_motion_row(tmp_path: Path) -> None:
    rows = ROWS[:1] + [ROWS[1].rsplit(" ", 3)[0]] + ROWS[2:]  # second row loses 3 values
    err = _error(write(tmp_path, small_bvh(rows=rows)))
    assert err.line == FIRST_DATA_LINE + 1
    assert "9 values" in str(err) and "12 channels" in str(err)


def test_non_numeric_token(tmp_path: Path) -> None:
    rows = [ROWS[0], ROWS[1], ROWS[2].replace("-8", "abc")]  # 8th token of the 3rd row
    err = _error(write(tmp_path, small_bvh(rows=rows)))
    assert (err.line, err.column) == (FIRST_DATA_LINE + 2, 8)
    assert "'abc'" in str(err) and "line 26, column 8" in str(err)


def test_wrong_channel_count_in_rows(tmp_path: Path) -> None:
    rows = [r.rsplit(" ", 1)[0] for r in ROWS]  # every row has 11 values
    err = _error(write(tmp_path, small_bvh(rows=rows)))
    assert "11 values" in str(err) and "12 channels" in str(err) and err.line == FIRST_DATA_LINE


def test_wrong_channel_count_in_hierarchy(tmp_path: Path) -> None:
    text = small_bvh().replace(
        "CHANNELS 3 Zrotation Xrotation Yrotation", "CHANNELS 4 Zrotation Xrotation Yrotation"
    )
    err = _error(write(tmp_path, text))
    assert err.line == 9 and "4 channels" in str(err)
    text = small_bvh().replace("CHANNELS 3 Zrotation Xrotation Yrotation", "CHANNELS 3 Zrotation Xrotation")
    err = _error(write(tmp_path, text))
    assert err.line == 9 and "lists 2" in str(err)


def test_missing_motion(tmp_path: Path) -> None:
    err = _error(write(tmp_path, SMALL_HEADER))
    assert "MOTION" in str(err)


def test_binary_garbage(tmp_path: Path) -> None:
    data = bytes(np.random.default_rng(1).integers(0, 256, 4096, dtype=np.uint8))
    _error(write(tmp_path, b"\x89PNG\r\n\x1a\n" + data))


def test_git_lfs_pointer(tmp_path: Path) -> None:
    text = "version https://git-lfs.github.com/spec/v1\noid sha256:" + "ab" * 32 + "\nsize 16809072\n"
    err = _error(write(tmp_path, text))
    assert "Git-LFS" in str(err)


def test_bad_frames_line(tmp_path: Path) -> None:
    err = _error(write(tmp_path, small_bvh(frames="3.5")))
    assert err.line == 22


def test_nonfinite_value(tmp_path: Path) -> None:
    rows = [ROWS[0], ROWS[1].replace("7", "nan"), ROWS[2]]
    err = _error(write(tmp_path, small_bvh(rows=rows)))
    assert (err.line, err.column) == (FIRST_DATA_LINE + 1, 12)


# ----------------------------------------------------------------------------- helpers


def test_atomic_write_failure_keeps_old_file(tmp_path: Path) -> None:
    p = tmp_path / "f.txt"
    p.write_text("old\n")
    with pytest.raises(RuntimeError), atomic_write(p) as f:
        f.write("new content that must not land\n")
        raise RuntimeError("boom")
    assert p.read_text() == "old\n"
    assert sorted(os.listdir(tmp_path)) == ["f.txt"]  # no temp file left behind


def test_atomic_write_gz_text_and_binary(tmp_path: Path) -> None:
    with atomic_write(tmp_path / "a.txt.gz") as f:
        f.write("héllo\n")
    assert gzip.decompress((tmp_path / "a.txt.gz").read_bytes()).decode() == "héllo\n"
    assert read_text(tmp_path / "a.txt.gz") == "héllo\n"
    with atomic_write(tmp_path / "b.bin", "wb") as f:
        f.write(b"\x00\x01")
    assert (tmp_path / "b.bin").read_bytes() == b"\x00\x01"
    with pytest.raises(ValueError, match="mode"):
        with atomic_write(tmp_path / "c", "a"):
            pass


def test_resolve(tmp_path: Path) -> None:
    (tmp_path / "t.TextGrid.gz").write_bytes(gzip.compress(b"x"))
    (tmp_path / "t.wav").write_bytes(b"")
    assert resolve(tmp_path / "t", "TextGrid") == tmp_path / "t.TextGrid.gz"
    assert resolve(tmp_path / "t", ".wav") == tmp_path / "t.wav"
    assert resolve(tmp_path / "t.wav", ".wav") == tmp_path / "t.wav"
    with pytest.raises(FileNotFoundError, match=r"t\.bvh"):
        resolve(tmp_path / "t", ".bvh")


def test_read_text_crlf_bom(tmp_path: Path) -> None:
    p = write(tmp_path, b"\xef\xbb\xbfa\r\nb\rc\n", "t.txt")
    assert read_text(p) == "a\nb\nc\n"
    assert math.isclose(1.0, 1.0)
