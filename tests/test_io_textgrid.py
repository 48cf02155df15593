"""Tests of the TextGrid reader/writer and of word-to-frame alignment."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from beatlite.io import (
    FormatError,
    Interval,
    WordIntervals,
    read_textgrid,
    read_words,
    words_to_frames,
    write_textgrid,
)

LONG = '''File type = "ooTextFile"
Object class = "TextGrid"

xmin = 0
xmax = 2.5
tiers? <exists>
size = 2
item []:
    item [1]:
        class = "IntervalTier"
        name = "words"
        xmin = 0
        xmax = 2.5
        intervals: size = 4
        intervals [1]:
            xmin = 0
            xmax = 0.7
            text = ""
        intervals [2]:
            xmin = 0.7
            xmax = 1.2
            text = "café"
        intervals [3]:
            xmin = 1.2
            xmax = 2.0
            text = "say ""hi"""
        intervals [4]:
            xmin = 2.0
            xmax = 2.5
            text = ""
    item [2]:
        class = "TextTier"
        name = "events"
        xmin = 0
        xmax = 2.5
        points: size = 1
        points [1]:
            number = 1.5
            mark = "clap"
'''

SHORT = '''File type = "ooTextFile"
Object class = "TextGrid"

0
2.5
<exists>
2
"IntervalTier"
"words"
0
2.5
4
0
0.7
""
0.7
1.2
"café"
1.2
2.0
"say ""hi"""
2.0
2.5
""
"TextTier"
"events"
0
2.5
1
1.5
"clap"
'''

EXPECTED = {
    "words": [
        Interval(0.0, 0.7, ""),
        Interval(0.7, 1.2, "café"),
        Interval(1.2, 2.0, 'say "hi"'),
        Interval(2.0, 2.5, ""),
    ],
    "events": [Interval(1.5, 1.5, "clap")],
}


@pytest.mark.parametrize("encoding", ["utf-8", "utf-16", "utf-8-sig"])
@pytest.mark.parametrize("text", [LONG, SHORT], ids=["long", "short"])
def test_long_and_short_formats_and_encodings(tmp_path: Path, text: str, encoding: str) -> None:
    p = tmp_path / "t.TextGrid"
    p.write_bytes(text.encode(encoding))  # Python's utf-16 codec writes a BOM
    assert read_textgrid(p) == EXPECTED
    words = read_words(p)
    assert words.words == ("café", 'say "hi"') and words.xmax == 2.5
    np.testing.assert_array_equal(words.starts, [0.7, 1.2])
    np.testing.assert_array_equal(words.ends, [1.2, 2.0])


def test_crlf(tmp_path: Path) -> None:
    p = tmp_path / "t.TextGrid"
    p.write_bytes(LONG.replace("\n", "\r\n").encode())
    assert read_textgrid(p) == EXPECTED


def test_overlapping_intervals(tmp_path: Path) -> None:
    p = tmp_path / "t.TextGrid"
    p.write_text(LONG.replace("            xmin = 1.2\n", "            xmin = 1.1\n"))
    with pytest.raises(FormatError) as info:
        read_textgrid(p)
    msg = str(info.value)
    # interval 3 of tier 'words' starts on line 24 of LONG (its 'xmin = ...' line)
    assert "'words'" in msg and "interval 3" in msg and info.value.line == 24 and str(p) in msg


def test_truncated_and_missing_tier(tmp_path: Path) -> None:
    p = tmp_path / "t.TextGrid"
    p.write_text(LONG[: LONG.index("intervals [3]")])
    with pytest.raises(FormatError, match="ends early"):
        read_textgrid(p)
    p.write_text(LONG)
    with pytest.raises(FormatError, match="no tier named 'phones'"):
        read_words(p, tier="phones")
    assert read_words(p, tier=0).words == ("café", 'say "hi"')


def test_a_file_that_ends_early_names_its_last_line(tmp_path: Path) -> None:
    """The header's ``xmax`` is not a number (a label to the reader): the values end on line 4, the file's last
    line, whatever blank lines follow it."""
    p = tmp_path / "t.TextGrid"
    head = 'File type = "ooTextFile"\nObject class = "TextGrid"\nxmin = 0\nxmax = garbage'
    for tail in ("", "\n", "\n\n  \n"):
        p.write_text(head + tail)
        with pytest.raises(FormatError, match="ends early: expected xmax") as info:
            read_textgrid(p)
        assert info.value.line == 4, (tail, info.value.line)


def test_real_textgrid(real_samples: Path) -> None:
    p = real_samples / "2_scott_0_2_2.TextGrid"
    tiers = read_textgrid(p)
    assert list(tiers) == ["words", "phones"]
    words = tiers["words"]
    assert len(words) == 223 and len(tiers["phones"]) == 701
    assert words[0] == Interval(0.0, 1.45, "") and words[1] == Interval(1.45, 1.87, "so")
    assert words[-1].end == 62.0
    # independent count of the empty marks of the words tier (the part of the file before item [2])
    text = p.read_text()
    words_part = text[: text.index("item [2]")]
    n_empty = len(re.findall(r'text = ""\s*$', words_part, flags=re.MULTILINE))
    assert sum(1 for iv in words if iv.text == "") == n_empty
    w = read_words(p)
    assert len(w) == 223 - n_empty and "" not in w.words
    assert np.all(np.diff(w.starts) > 0)


def test_real_textgrid_round_trip(real_samples: Path, tmp_path: Path) -> None:
    tiers = read_textgrid(real_samples / "2_scott_0_2_2.TextGrid")
    write_textgrid(tmp_path / "copy.TextGrid", tiers, 62)
    assert read_textgrid(tmp_path / "copy.TextGrid") == tiers
    first_lines = (tmp_path / "copy.TextGrid").read_text().splitlines()[:8]
    assert first_lines == (real_samples / "2_scott_0_2_2.TextGrid").read_text().splitlines()[:8]


def test_writer_fills_gaps_and_validates(tmp_path: Path) -> None:
    p = tmp_path / "w.TextGrid.gz"
    write_textgrid(p, {"words": [Interval(0.5, 1.0, "hi")]}, 2.0)
    assert read_textgrid(p)["words"] == [
        Interval(0.0, 0.5, ""),
        Interval(0.5, 1.0, "hi"),
        Interval(1.0, 2.0, ""),
    ]
    with pytest.raises(ValueError, match="before"):
        write_textgrid(tmp_path / "x.TextGrid", {"w": [Interval(0, 1, "a"), Interval(0.5, 1.5, "b")]}, 2.0)
    with pytest.raises(ValueError, match="xmax"):
        write_textgrid(tmp_path / "x.TextGrid", {"w": [Interval(0, 3, "a")]}, 2.0)
    assert not (tmp_path / "x.TextGrid").exists()


# ----------------------------------------------------------------------------- alignment

VOCAB = {"hello": 5, "world": 6}
TIER = [
    Interval(0.0, 0.5, "hello"),
    Interval(0.5, 1.0, "world"),
    Interval(1.0, 1.2, ""),
    Interval(1.2, 1.5, "oov"),
    Interval(1.5, 1.6, " "),
]


def test_span_rule() -> None:
    # frames at t = i / 10: 0-4 in [0, .5) hello, 5-9 in [.5, 1) world, 10-11 silence,
    # 12-14 in [1.2, 1.5) an out-of-vocabulary word, 15 (t=1.5) in " " (blank = silence), 16-17 outside
    out = words_to_frames(TIER, 18, 10, VOCAB, rule="span")
    assert out.tolist() == [5] * 5 + [6] * 5 + [0, 0] + [3] * 3 + [0, 0, 0]
    assert out.dtype == np.int64


def test_onset_rule() -> None:
    # only frames floor(start * 10) = 0, 5, 12 carry a word
    out = words_to_frames(TIER, 18, 10, VOCAB, rule="onset")
    expected = np.zeros(18, dtype=np.int64)
    expected[[0, 5, 12]] = [5, 6, 3]
    np.testing.assert_array_equal(out, expected)


def test_beat_rule_matches_reference_semantics() -> None:
    # closed intervals, first wins: t=0.5 -> hello, t=1.0 -> world, t=1.1 and t=1.2 -> "" (1.2 ends the
    # silence first), t=1.3..1.5 -> oov (UNK), t=1.6 -> " " (PAD), t=1.7 -> no interval (UNK)
    vocab = {**VOCAB, "": 7}
    out = words_to_frames(TIER, 18, 10, vocab, rule="beat")
    assert out.tolist() == [5] * 6 + [6] * 5 + [7, 7] + [3] * 3 + [0] + [3]
    # without "" in the vocabulary, MFA silence becomes UNK, not PAD (docs/reference_code.md#textgrid)
    out = words_to_frames(TIER, 18, 10, VOCAB, rule="beat")
    assert out[11:13].tolist() == [3, 3]


def test_beat_rule_from_word_intervals_rebuilds_silences() -> None:
    words = WordIntervals(
        np.array([0.0, 0.5, 1.2]), np.array([0.5, 1.0, 1.5]), ("hello", "world", "oov"), xmax=1.6
    )
    vocab = {**VOCAB, "": 7}
    out = words_to_frames(words, 18, 10, vocab, rule="beat")
    # same as above except t=1.6, now inside the rebuilt silence [1.5, 1.6]
    assert out.tolist() == [5] * 6 + [6] * 5 + [7, 7] + [3] * 3 + [7] + [3]


def _brute_force(starts, ends, marks, t, vocab, rule):  # O(T*W) oracle
    out = []
    for ti in t:
        if rule == "span":
            hit = [m for s, e, m in zip(starts, ends, marks) if s <= ti < e and m.strip()]
            out.append(vocab.get(hit[0], 3) if hit else 0)
        else:
            hit = [m for s, e, m in zip(starts, ends, marks) if s <= ti <= e]
            out.append(3 if not hit else 0 if hit[0] == " " else vocab.get(hit[0], 3))
    return out


@pytest.mark.parametrize("rule", ["span", "beat"])
def test_rules_against_brute_force(rule: str) -> None:
    rng = np.random.default_rng(4)
    bounds = np.concatenate([[0.0], np.cumsum(rng.choice([0.1, 0.2, 0.25, 0.4, 1 / 3], 60))])
    marks = [str(rng.choice(["a", "b", "c", "", " ", "zz"])) for _ in range(60)]
    tier = [Interval(float(s), float(e), m) for s, e, m in zip(bounds[:-1], bounds[1:], marks)]
    vocab = {"a": 10, "b": 11, "c": 12, "": 13}
    fps = 15
    n = int(bounds[-1] * fps) + 5
    t = np.arange(n) / fps
    expected = _brute_force(bounds[:-1], bounds[1:], marks, t, vocab, rule)
    assert words_to_frames(tier, n, fps, vocab, rule=rule).tolist() == expected


def test_offset_and_bad_args() -> None:
    # with a 1 s offset, frame 0 is at t = 1.0: world for "span"
    assert words_to_frames(TIER, 1, 10, VOCAB, offset=1.0 - 0.05).tolist() == [6]
    with pytest.raises(ValueError, match="rule"):
        words_to_frames(TIER, 3, 10, VOCAB, rule="nearest")
    with pytest.raises(ValueError, match="n_frames"):
        words_to_frames(TIER, -1, 10, VOCAB)
    with pytest.raises(TypeError, match="words"):
        words_to_frames("hello", 3, 10, VOCAB)  # type: ignore[arg-type]
