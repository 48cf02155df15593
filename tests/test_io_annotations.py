"""Tests of the semantic (.txt) and emotion (.csv) annotation readers/writers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from beatlite.io import (
    EmotionSegment,
    FormatError,
    SemanticSegment,
    emotion_to_frames,
    read_emotion,
    read_semantic,
    semantic_to_frames,
    write_emotion,
    write_semantic,
)

# the example of PM#53 (docs/reference_code.md#semantic-annotations), tab-separated
SEMANTIC = "08_metaphoric_l\t31.931\t34.035\t2.104\t0.8\tlove\n01_beat_align\t34.035\t34.577\t0.542\t0.1\n\n"


def test_read_semantic(tmp_path: Path) -> None:
    p = tmp_path / "s.txt"
    p.write_text(SEMANTIC)
    segs = read_semantic(p)
    assert segs == [
        SemanticSegment("08_metaphoric_l", 31.931, 34.035, 2.104, 0.8, "love"),
        SemanticSegment("01_beat_align", 34.035, 34.577, 0.542, 0.1, ""),
    ]


def test_semantic_to_frames() -> None:
    segs = [SemanticSegment("a", 0.2, 0.4, 0.2, 0.5), SemanticSegment("b", 0.4, 0.55, 0.15, 1.0)]
    # t = i/10: frames 2,3,4 in [0.2, 0.4] (4 is the shared boundary: the first segment wins), 5 in b
    out = semantic_to_frames(segs, 8, 10)
    assert out.dtype == np.float32
    assert out.tolist() == [0, 0, 0.5, 0.5, 0.5, 1.0, 0, 0]


def test_semantic_round_trip(tmp_path: Path) -> None:
    segs = [
        SemanticSegment("05_iconic_l", 1.25, 2.5, 1.25, 0.3, "big house"),
        SemanticSegment("00_x", 3, 4, 1, 0),
    ]
    write_semantic(tmp_path / "s.txt", segs)
    assert read_semantic(tmp_path / "s.txt") == segs


@pytest.mark.parametrize(
    ("line", "field"),
    [
        ("01_beat_align\t1.0\t2.0\t1.0\t1.5", "score"),
        ("01_beat_align\t1.0\tabc\t1.0\t0.5", "end"),
        ("01_beat_align\t3.0\t2.0\t1.0\t0.5", "start"),
        ("01_beat_align\t1.0\t2.0\t1.0\tnan", "score"),
    ],
)
def test_semantic_errors(tmp_path: Path, line: str, field: str) -> None:
    p = tmp_path / "s.txt"
    p.write_text(SEMANTIC + line + "\n")
    with pytest.raises(FormatError) as info:
        read_semantic(p)
    assert info.value.line == 4 and info.value.field == field and str(p) in str(info.value)


def test_semantic_too_few_fields(tmp_path: Path) -> None:
    p = tmp_path / "s.txt"
    p.write_text("01_beat_align\t1.0\t2.0\n")
    with pytest.raises(FormatError, match="at least 5 fields"):
        read_semantic(p)


EMOTION = "2_scott_0_65_65,0.0,30.5,30.5,1\n2_scott_0_65_65,30.5,61.0,30.5,3\n"


def test_read_emotion_and_frames(tmp_path: Path) -> None:
    p = tmp_path / "e.csv"
    p.write_text(EMOTION)
    segs = read_emotion(p)
    assert segs == [
        EmotionSegment("2_scott_0_65_65", 0.0, 30.5, 30.5, 1),
        EmotionSegment("2_scott_0_65_65", 30.5, 61.0, 30.5, 3),
    ]
    # 15 fps: frame 457 is t = 30.4667 (class 1), 458 is t = 30.5333 (class 3);
    # frame 915 is t = 61.0 (inside, closed end), 916 outside -> default
    out = emotion_to_frames(segs, 917, 15, default=0)
    assert out.dtype == np.int64
    assert out[457] == 1 and out[458] == 3 and out[915] == 3 and out[916] == 0
    assert (out[:458] == 1).all()


def test_emotion_round_trip(tmp_path: Path) -> None:
    segs = [EmotionSegment("x", 0.0, 1.5, 1.5, 7), EmotionSegment("x", 1.5, 2.0, 0.5, 0)]
    write_emotion(tmp_path / "e.csv", segs)
    assert read_emotion(tmp_path / "e.csv") == segs
    with pytest.raises(ValueError, match="class"):
        write_emotion(tmp_path / "bad.csv", [EmotionSegment("x", 0, 1, 1, 8)])
    assert not (tmp_path / "bad.csv").exists()


@pytest.mark.parametrize("value", ["8", "-1", "2.5", "happy"])
def test_emotion_class_out_of_range(tmp_path: Path, value: str) -> None:
    p = tmp_path / "e.csv"
    p.write_text(EMOTION + f"2_scott_0_65_65,61.0,62.0,1.0,{value}\n")
    with pytest.raises(FormatError) as info:
        read_emotion(p)
    assert info.value.line == 3 and info.value.field == "class" and str(p) in str(info.value)


def test_emotion_wrong_field_count(tmp_path: Path) -> None:
    p = tmp_path / "e.csv"
    p.write_text("a,1,2\n")
    with pytest.raises(FormatError, match="5 comma-separated"):
        read_emotion(p)
