"""beatlite.data.index on a tiny hand-made corpus with known answers."""

from __future__ import annotations

import gzip
import shutil
from pathlib import Path

import numpy as np
import pytest
from test_data_fixtures import make_tiny_take, write_tiny_bvh, write_wav

from beatlite.data.index import MAX_DURATION_GAP, TakeIndex, TakeRecord, index_folder

# stem -> seconds; splits by BEAT's rule for the 4-hour speakers 2 and 4 (docs/reference_code.md#splits):
# speech 1-8 test, 9-56 train, 57-64 val; 74 lies inside the anger block 73-80 -> train.
GOOD = {
    "2_scott_0_1_1": 4.0,  # test, neutral
    "2_scott_0_9_9": 6.0,  # train
    "2_scott_0_57_57": 3.0,  # val
    "2_scott_0_74_74": 2.0,  # train, anger
    "4_lawrence_0_9_9": 5.0,  # train
}


def _gzip_all(folder: Path, stem: str) -> None:
    for p in list(folder.glob(f"{stem}.*")):
        with open(p, "rb") as src, gzip.open(p.with_name(p.name + ".gz"), "wb") as dst:
            shutil.copyfileobj(src, dst)
        p.unlink()


@pytest.fixture()
def corpus(tmp_path: Path) -> Path:
    root = tmp_path / "beat_english_v0.2.1"
    for stem, seconds in GOOD.items():
        make_tiny_take(root / stem.split("_")[0], stem, seconds)
    # a gzipped take (every file .gz): 5 s, train
    make_tiny_take(root / "2", "2_scott_0_10_10", 5.0)
    _gzip_all(root / "2", "2_scott_0_10_10")
    # problem takes in a flat side folder
    bad = root / "extra"
    make_tiny_take(bad, "2_scott_0_11_11", 4.0, modalities=("wav",))  # wav without bvh
    make_tiny_take(bad, "hello_world", 4.0)  # a bad name
    make_tiny_take(bad, "2_scott_0_12_12", 5.0, wav_seconds=8.0)  # 3 s disagreement
    make_tiny_take(bad, "2_scott_0_13_13", 4.0)
    (bad / "2_scott_0_13_13.json").write_text("{not json", encoding="utf-8")  # unreadable
    (bad / "README.md").write_text("not a take\n", encoding="utf-8")  # ignored
    return tmp_path


def test_counts_durations_and_splits(corpus: Path) -> None:
    idx = index_folder(corpus)
    assert len(idx) == 5 + 1 + 4  # 5 good, 1 gzipped, 4 flagged; README ignored
    ok = idx.where(ok=True)
    assert sorted(ok.stems) == sorted([*GOOD, "2_scott_0_10_10"])
    # durations from headers: BVH frames/15, WAV samples/16000, JSON frames/60, TextGrid xmax
    for r in ok:
        expected = GOOD.get(r.stem, 5.0)
        for modality in ("motion", "audio", "face", "text"):
            assert r.durations[modality] == pytest.approx(expected, abs=1e-3), (r.stem, modality)
    # split membership: train = 9, 74, lawrence 9 and the gzipped 10 -> 6 + 2 + 5 + 5 = 18 s
    train = ok.where(split="train")
    assert sorted(train.stems) == sorted(
        ["2_scott_0_9_9", "2_scott_0_10_10", "2_scott_0_74_74", "4_lawrence_0_9_9"]
    )
    assert train.total_duration == pytest.approx(18.0, abs=1e-3)
    assert ok.where(split="val").stems == ["2_scott_0_57_57"]
    assert ok.where(split="test").stems == ["2_scott_0_1_1"]
    assert ok.speaker_ids() == [2, 4]
    # name fields
    r = idx["2_scott_0_74_74"]
    assert (r.speaker_id, r.speaker, r.session_type, r.sequence, r.emotion) == (2, "scott", 0, 74, 2)
    assert r.language == "english" and r.conversation is False


def test_gz_variants_are_found(corpus: Path) -> None:
    r = index_folder(corpus)["2_scott_0_10_10"]
    assert all(p.name.endswith(".gz") for p in r.files.values())
    assert len(r.files) == 6 and r.ok


def test_problem_takes_are_flagged_not_crashing(corpus: Path) -> None:
    idx = index_folder(corpus)
    problems = idx.problems()
    assert set(problems) == {"2_scott_0_11_11", "hello_world", "2_scott_0_12_12", "2_scott_0_13_13"}
    wav_only = idx["2_scott_0_11_11"]
    assert any("missing motion (.bvh or .npz)" in p for p in wav_only.problems)
    assert not wav_only.usable and wav_only.has("audio") and not wav_only.has("motion")
    bad_name = idx["hello_world"]
    assert bad_name.speaker_id is None and bad_name.split is None
    assert any(p.startswith("bad name") for p in bad_name.problems) and not bad_name.usable
    gap = idx["2_scott_0_12_12"]
    assert any("durations disagree" in p and "audio 8.00 s" in p for p in gap.problems)
    assert not gap.usable and 8.0 - 5.0 > MAX_DURATION_GAP
    (corpus / "beat_english_v0.2.1" / "extra" / "2_scott_0_11_11.bvh").write_text(
        "HIERARCHY\n", encoding="utf-8"
    )
    no_header = index_folder(corpus)["2_scott_0_11_11"]  # now a BVH without a readable header
    assert any(p.startswith("unreadable motion file") for p in no_header.problems) and not no_header.usable
    broken = idx["2_scott_0_13_13"]
    assert any(p.startswith("unreadable face file 2_scott_0_13_13.json") for p in broken.problems)
    # face is optional, but a face file that is present and broken makes load_take raise: not usable
    assert "face" not in broken.durations and not broken.usable
    # bad-name takes sort last
    assert idx.stems[-1] == "hello_world"


def test_missing_optional_files_are_listed(tmp_path: Path) -> None:
    make_tiny_take(tmp_path, "2_scott_0_9_9", 3.0, modalities=("bvh", "wav"))
    r = index_folder(tmp_path)["2_scott_0_9_9"]
    assert r.usable and not r.ok
    assert {p.split(" (")[0] for p in r.problems} == {
        "missing face",
        "missing text",
        "missing semantic",
        "missing emotion",
    }


def test_flat_folder_non_recursive(tmp_path: Path) -> None:
    make_tiny_take(tmp_path, "2_scott_0_9_9", 3.0)
    make_tiny_take(tmp_path / "sub", "2_scott_0_1_1", 3.0)
    assert index_folder(tmp_path, recursive=False).stems == ["2_scott_0_9_9"]
    assert sorted(index_folder(tmp_path).stems) == ["2_scott_0_1_1", "2_scott_0_9_9"]


def test_duplicate_files_flagged(tmp_path: Path) -> None:
    make_tiny_take(tmp_path / "a", "2_scott_0_9_9", 3.0)
    (tmp_path / "b").mkdir()
    write_tiny_bvh(tmp_path / "b" / "2_scott_0_9_9.bvh", 45)
    r = index_folder(tmp_path)["2_scott_0_9_9"]
    assert any(p.startswith("duplicate motion files") for p in r.problems)
    assert r.files["motion"].parent.name == "a"  # sorted path order: a/ before b/


def test_read_durations_false_lists_files_only(tmp_path: Path) -> None:
    make_tiny_take(tmp_path, "2_scott_0_9_9", 3.0)
    r = index_folder(tmp_path, read_durations=False)["2_scott_0_9_9"]
    assert r.durations == {} and len(r.files) == 6 and r.duration == 0.0 and r.usable


def test_where_variants_and_errors(corpus: Path) -> None:
    idx = index_folder(corpus)
    assert len(idx.where(speaker_id=[2, 4], ok=True)) == 6
    assert len(idx.where(sequence=lambda s: s is not None and s >= 57, ok=True)) == 2  # 57 and 74
    assert len(idx.where(split={"val", "test"}, ok=True)) == 2
    with pytest.raises(ValueError, match="unknown field 'splitt'"):
        idx.where(splitt="train")
    with pytest.raises(KeyError, match="no take '2_scott_0_99_99'"):
        idx["2_scott_0_99_99"]


def test_rows_and_markdown(corpus: Path) -> None:
    idx = index_folder(corpus).where(ok=True)
    rows = idx.to_rows()
    assert len(rows) == 6
    assert {"stem", "speaker_id", "split", "duration", "has_motion", "dur_audio", "problems"} <= set(rows[0])
    md = idx.to_markdown().splitlines()
    assert md[0].startswith("| stem | speaker |") and len(md) == 2 + 6
    assert (
        "| 2_scott_0_1_1 | scott | english | neutral | test | 4.0 | bvh wav json textgrid txt csv |  |" in md
    )
    short = idx.to_markdown(["stem", "split"], max_rows=2).splitlines()
    assert short[-1] == "... (4 more)" and short[0] == "| stem | split |"
    with pytest.raises(ValueError, match="unknown columns"):
        idx.to_markdown(["nope"])


def test_wrong_frame_time_is_reconciled_with_the_audio(tmp_path: Path) -> None:
    # a BEAT quirk (docs/reference_code.md#bvh-header): 120-fps rows under 'Frame Time: 0.041667' (24 fps) -> the header says 10 s,
    # the audio 2 s; 24 * 5 = 120 fps is the one clean factor that makes 240 rows last 2 s
    write_tiny_bvh(tmp_path / "2_scott_0_9_9.bvh", 120 * 2, frame_time=0.041667)
    write_wav(tmp_path / "2_scott_0_9_9.wav", np.zeros(2 * 16000, np.float32))
    r = index_folder(tmp_path)["2_scott_0_9_9"]
    assert r.durations["motion"] == pytest.approx(2.0) and r.bvh_fps == 120.0
    assert not any("durations disagree" in p for p in r.problems) and r.usable
    assert any(p.startswith("warning:") and "120 fps" in p and "bvh_fps=" in p for p in r.problems)
    # an explicit override wins: at 24 fps the take is 10 s long and disagrees with its audio
    r24 = index_folder(tmp_path, bvh_fps={"2_scott_0_9_9": 24})["2_scott_0_9_9"]
    assert r24.durations["motion"] == pytest.approx(10.0) and r24.bvh_fps == 24.0
    assert any("durations disagree" in p for p in r24.problems) and not r24.usable
    with pytest.raises(ValueError, match="2_scott_0_99_99"):
        index_folder(tmp_path, bvh_fps={"2_scott_0_99_99": 24})


def test_an_override_makes_a_take_with_a_zero_frame_time_usable(tmp_path: Path) -> None:
    """load_take(bvh_fps=15) reads a BVH whose 'Frame Time' is 0; the index with the same override called its
    motion unreadable (it parsed the header's Frame Time anyway), so the take was dropped from every split."""
    from beatlite.io import load_take

    write_tiny_bvh(tmp_path / "2_scott_0_9_9.bvh", 30, frame_time=0.0)
    write_wav(tmp_path / "2_scott_0_9_9.wav", np.zeros(2 * 16000, np.float32))
    bad = index_folder(tmp_path, cache=False)["2_scott_0_9_9"]
    assert not bad.usable and any("frame time" in p for p in bad.problems)
    r = index_folder(tmp_path, cache=False, bvh_fps={"2_scott_0_9_9": 15})["2_scott_0_9_9"]
    assert r.usable, r.problems
    assert r.bvh_fps == 15.0 and r.durations["motion"] == pytest.approx(30 / 15)
    assert load_take(r.path("motion"), bvh_fps=r.bvh_fps).n_frames == 30


def test_not_a_folder(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match="is not a folder"):
        index_folder(tmp_path / "missing")
    with pytest.raises(TypeError, match="TakeRecord"):
        TakeIndex(["x"])  # type: ignore[list-item]
    assert TakeRecord("x").duration == 0.0


def test_real_beat_files(real_samples: Path) -> None:
    # the real folder holds a BEAT wav + TextGrid without their BVH, and two BVHs with non-BEAT names
    idx = index_folder(real_samples)
    take = idx["2_scott_0_2_2"]
    assert take.durations["audio"] == pytest.approx(62.0, abs=0.01)  # README: 62.0 s of 16 kHz speech
    assert take.durations["text"] == 62.0  # README: integer xmax = 62
    assert take.split == "test" and take.speaker == "scott"  # speech 1-8 of a 4-hour speaker
    assert any("missing motion" in p for p in take.problems) and not take.usable
    others = {r.stem: r for r in idx if r.stem != "2_scott_0_2_2"}
    assert set(others) == {"beat_skeleton_2_scott_0_1_1_frame0", "dataset-1_bye_normal_001"}
    for r in others.values():
        assert any(p.startswith("bad name") for p in r.problems)
    # the one-frame BEAT BVH header: Frames 1 x 1/120 s
    assert others["beat_skeleton_2_scott_0_1_1_frame0"].durations["motion"] == pytest.approx(
        1 / 120, rel=1e-3
    )


# ----------------------------------------------------------------------------- an honest index (issue 14)


def test_gzip_is_sniffed_from_bytes_as_the_readers_do(tmp_path: Path) -> None:
    from beatlite.io import load_take

    make_tiny_take(tmp_path, "2_scott_0_9_9", 3.0)
    tg = tmp_path / "2_scott_0_9_9.TextGrid"
    tg.write_bytes(gzip.compress(tg.read_bytes()))  # gzipped content without the .gz suffix
    face = tmp_path / "2_scott_0_9_9.json"
    face.rename(tmp_path / "2_scott_0_9_9.json.gz")  # a .gz name over plain JSON
    r = index_folder(tmp_path)["2_scott_0_9_9"]
    assert r.ok and r.usable and r.durations["text"] == 3.0 and r.durations["face"] == pytest.approx(3.0)
    take = load_take(r.path("motion"))
    assert take.words is not None and take.face is not None and take.n_frames == 45


@pytest.mark.parametrize(
    ("ext", "content", "words"),
    [
        ("wav", b"ID3\x04\x00\x00\x00\x00\x00\x00" + bytes(200), "MP3 audio"),
        ("txt", "01_beat\t0.0\t1.0\t1.0\t2.5\n", "score 2.5 is outside"),
        ("csv", "", "no emotion rows"),
        (
            "TextGrid",
            'File type = "ooTextFile"\nObject class = "TextGrid"\n0\n2\n<exists>\n1\n',
            "more than the file holds",
        ),
    ],
)
def test_broken_bodies_make_a_take_unusable(
    tmp_path: Path, ext: str, content: str | bytes, words: str
) -> None:
    from beatlite.io import FormatError, load_take

    make_tiny_take(tmp_path, "2_scott_0_9_9", 3.0)
    p = tmp_path / f"2_scott_0_9_9.{ext}"
    p.write_bytes(content if isinstance(content, bytes) else content.encode("utf-8"))
    r = index_folder(tmp_path)["2_scott_0_9_9"]
    assert not r.usable and any(x.startswith("unreadable") and words in x for x in r.problems)
    with pytest.raises(FormatError, match=words):
        load_take(r.path("motion"))  # the index said what loading says


def _mutated_corpus(root: Path, n: int, rng: np.random.Generator) -> None:
    from test_io_fuzz import mutate

    stems = [
        f"{s}_{name}_0_{q}_{q}"
        for s, name in ((2, "scott"), (4, "lawrence"), (6, "carla"))
        for q in range(1, 119)
    ]
    for stem in stems[:n]:
        folder = root / stem.split("_")[0]
        make_tiny_take(folder, stem, float(rng.choice([2.0, 3.0, 4.0])))
        victim = sorted(folder.glob(f"{stem}.*"))[int(rng.integers(6))]
        victim.write_bytes(mutate(victim.read_bytes(), rng, max_ops=1))


def test_usable_means_load_take_succeeds(tmp_path: Path) -> None:
    """Property test over 240 takes with one mutated file each: every take the index calls usable loads."""
    import warnings

    from beatlite.io import load_take

    _mutated_corpus(tmp_path, 240, np.random.default_rng(14))
    idx = index_folder(tmp_path)
    assert len(idx) == 240
    usable = [r for r in idx if r.usable]
    for r in usable:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                take = load_take(r.path("motion"), bvh_fps=r.bvh_fps)
            except Exception as exc:  # noqa: BLE001 - any failure disproves the property
                pytest.fail(f"{r.stem} is usable but load_take raised {type(exc).__name__}: {exc}")
        assert abs(take.duration - r.duration) <= 1 / 15 + 1e-9, r.stem  # and it lasts what the index says
    # the mutations leave some takes usable and break others (so the property is exercised both ways)
    assert 40 <= len(usable) <= 200, len(usable)


def test_one_stem_rule_and_a_foreign_skeleton_make_takes_unusable_with_a_reason(tmp_path: Path) -> None:
    """``2_scott_0_1_1.v2.bvh`` was "usable" (the index kept ``.v2`` in the stem, load_take cut it off and
    read the other take's files); a BVH of another skeleton under a BEAT name was "usable" and then failed
    in build_store (``KeyError: no joint named 'Spine'``). "usable" now means: loads and windows."""
    from beatlite.io.take import take_stem

    make_tiny_take(tmp_path, "2_scott_0_1_1", 3.0)
    make_tiny_take(tmp_path, "2_scott_0_1_1.v2", 3.0)
    make_tiny_take(tmp_path, "2_scott_0_9_9", 3.0)
    lines = ["HIERARCHY", "ROOT Hips", "{", "  OFFSET 0 0 0", "  CHANNELS 6 Xposition Yposition Zposition "
             "Xrotation Yrotation Zrotation", "  JOINT Chest", "  {", "    OFFSET 0 10 0",
             "    CHANNELS 3 Xrotation Yrotation Zrotation", "    End Site", "    {", "      OFFSET 0 10 0",
             "    }", "  }", "}", "MOTION", "Frames: 45", "Frame Time: 0.066667"]  # fmt: skip
    (tmp_path / "2_scott_0_9_9.bvh").write_text("\n".join(lines + ["0 0 0 0 0 0 0 0 0"] * 45) + "\n")
    idx = index_folder(tmp_path, cache=False)
    assert idx["2_scott_0_1_1"].usable
    assert idx["2_scott_0_1_1"].files["motion"].name == "2_scott_0_1_1.bvh"
    v2 = idx["2_scott_0_1_1.v2"]
    assert not v2.usable and any("take name" in p for p in v2.problems), v2.problems
    assert take_stem(tmp_path / "2_scott_0_1_1.v2.bvh").name == "2_scott_0_1_1.v2"  # the index's stem
    foreign = idx["2_scott_0_9_9"]
    assert not foreign.usable and any("not BEAT's skeleton" in p and "Spine" in p for p in foreign.problems)


@pytest.mark.filterwarnings("ignore:.*modalities differ in length")  # a cut take is truncated to its motion
def test_usable_means_the_window_features_build_on_random_broken_takes(tmp_path: Path) -> None:
    """A property, on seeded random takes (a renamed joint, a dot in the name, motion cut short): every take the
    index calls usable builds its window features (what build_store runs), every other take says why."""
    from test_data_windows import write_take

    from beatlite.data.windows import take_features
    from beatlite.skeleton.beat import beat_skeleton

    rng = np.random.default_rng(25)
    joints = beat_skeleton().names[1:]
    for i in range(12):
        stem = f"2_scott_0_{i + 1}_{i + 1}" + (".v2" if rng.random() < 0.2 else "")
        write_take(tmp_path, stem, int(rng.integers(40, 90)))
        bvh = tmp_path / f"{stem}.bvh"
        if (
            rng.random() < 0.5
        ):  # rename one joint (a leg joint leaves the take usable, a spine or hand joint not)
            name = str(rng.choice(joints))
            bvh.write_text(bvh.read_text().replace(f"JOINT {name}\n", f"JOINT {name}_x\n"))
        if rng.random() < 0.2:  # cut the motion to a third: the durations disagree
            lines = bvh.read_text().splitlines()
            motion = lines.index("MOTION")
            rows = lines[motion + 3 :]
            lines[motion + 1] = f"Frames: {len(rows) // 3}"
            bvh.write_text("\n".join(lines[: motion + 3] + rows[: len(rows) // 3]) + "\n")
    index = index_folder(tmp_path, cache=False)
    usable = [r for r in index if r.usable]
    assert 0 < len(usable) < len(index)  # the draw has both kinds
    for record in index:
        if record.usable:
            take_features(record, mel=False)  # raises if "usable" lied
        else:
            assert record.problems, record.stem


@pytest.mark.parametrize(("xmax", "line"), [("e", 5), ("1e400", 5), ("-", 5)])
def test_textgrid_duration_of_an_unreadable_xmax_is_a_format_error(
    tmp_path: Path, xmax: str, line: int
) -> None:
    """'xmax = e' raised a bare ValueError (no file named) and 'xmax = 1e400' returned inf."""
    from beatlite.data.index import textgrid_duration
    from beatlite.io import FormatError

    path = tmp_path / "t.TextGrid"
    path.write_text(f'File type = "ooTextFile"\nObject class = "TextGrid"\n\nxmin = 0\nxmax = {xmax}\n')
    with pytest.raises(FormatError, match="xmax") as info:
        textgrid_duration(path)
    assert info.value.path == path and info.value.line == line and info.value.field == "xmax"
    path.write_text(
        'File type = "ooTextFile"\nObject class = "TextGrid"\n\n0\n2.5\n<exists>\n'
    )  # short format
    assert textgrid_duration(path) == 2.5
