"""Tests of BEAT take-name parsing, the emotion table and the split tables (BEAT §3.1; docs/reference_code.md#take-names, #splits)."""

from __future__ import annotations

import pytest

from beatlite.io import EMOTIONS, LANGUAGES, SPEAKER_NAMES, FormatError, TakeName, parse_take_name, split_of
from beatlite.io.names import FOUR_HOUR_SPEAKERS, emotion_of


def test_example() -> None:
    assert parse_take_name("2_scott_0_1_1") == TakeName(
        speaker_id=2,
        speaker="scott",
        session_type=0,
        language="english",
        conversation=False,
        start=1,
        end=1,
        half=None,
        emotion=0,
        emotion_name="neutral",
        split="test",
    )


def test_constants() -> None:
    assert len(SPEAKER_NAMES) == 30 and len(set(SPEAKER_NAMES)) == 30
    assert SPEAKER_NAMES[0] == "wayne" and SPEAKER_NAMES[29] == "katya" and SPEAKER_NAMES[27] == "tiffnay"
    assert EMOTIONS == ("neutral", "happiness", "anger", "sadness", "contempt", "surprise", "fear", "disgust")
    assert LANGUAGES == ("english", "chinese", "spanish", "japanese")
    assert len(FOUR_HOUR_SPEAKERS) == 10


def test_path_type_half_language() -> None:
    t = parse_take_name("data/12_zhao_3_1_1_b.TextGrid.gz")
    assert (t.language, t.conversation, t.half, t.emotion_name) == ("chinese", True, "b", "neutral")
    assert t.split == "val" and t.stem == "12_zhao_3_1_1_b"
    assert parse_take_name("25_goto_6_2_2").language == "japanese"
    assert parse_take_name("1_wayne_0_1_8").end == 8  # a v0.1 range


@pytest.mark.parametrize(
    ("seq", "emotion"),
    [(0, 0), (1, 0), (64, 0), (65, 1), (72, 1), (73, 2), (80, 2), (81, 3), (86, 3), (87, 4), (94, 4)]
    + [(95, 5), (102, 5), (103, 6), (110, 6), (111, 7), (118, 7)],
)
def test_emotion_table(seq: int, emotion: int) -> None:
    assert emotion_of(seq) == emotion
    assert emotion_of(seq, conversation=True) == 0


@pytest.mark.parametrize(
    ("seq", "split"),
    [(1, "test"), (8, "test"), (9, "train"), (56, "train"), (57, "val"), (64, "val")]
    + [(65, "test"), (66, "train"), (71, "train"), (72, "val"), (81, "test"), (86, "val"), (118, "val")],
)
def test_four_hour_speech_split(seq: int, split: str) -> None:
    assert parse_take_name(f"2_scott_0_{seq}_{seq}").split == split


def test_conversation_splits() -> None:
    assert [split_of(4, True, s) for s in (1, 2, 11, 12)] == ["test", "train", "train", "val"]
    assert [split_of(5, True, 1, h) for h in ("a", "b", None)] == ["test", "val", "test+val"]
    assert split_of(5, True, 2) == "train" and split_of(5, True, 5) == "none"
    assert split_of(29, True, 0) == "train" and split_of(29, True, 4) == "train"


@pytest.mark.parametrize(
    ("seq", "half", "split"),
    [(1, None, "test"), (4, None, "test"), (5, None, "val"), (8, None, "val"), (9, None, "train")]
    + [(16, None, "train"), (17, None, "none"), (65, "a", "test"), (65, "b", "val"), (65, None, "test+val")]
    + [(66, None, "train"), (111, "b", "val"), (118, None, "train")],
)
def test_one_hour_speech_split(seq: int, half: str | None, split: str) -> None:
    assert split_of(5, False, seq, half) == split  # 5 = stewart, a 1-hour speaker


@pytest.mark.parametrize(
    ("name", "field"),
    [
        ("2_scott_0_1", "name"),
        ("x_scott_0_1_1", "speaker_id"),
        ("31_scott_0_1_1", "speaker_id"),
        ("2_wayne_0_1_1", "speaker"),
        ("2_scott_9_1_1", "session_type"),
        ("2_scott_0_119_119", "start"),
        ("2_scott_1_13_13", "start"),
        ("2_scott_0_5_4", "end"),
        ("2_scott_0_1_1_c", "half"),
    ],
)
def test_bad_names(name: str, field: str) -> None:
    with pytest.raises(FormatError) as info:
        parse_take_name(name)
    assert info.value.field == field and name in str(info.value)


def test_format_error_survives_pickling_with_its_fields():
    """A reader's FormatError raised in a worker process comes back whole (worker pools pickle it)."""
    import pickle

    from beatlite.io.errors import FormatError

    err = FormatError("take.bvh", "'abc' is not a number", line=433, column=17, field="rows")
    back = pickle.loads(pickle.dumps(err))
    assert type(back) is FormatError and str(back) == str(err)
    assert (back.path, back.reason, back.line, back.column, back.field) == (
        err.path,
        err.reason,
        433,
        17,
        "rows",
    )
