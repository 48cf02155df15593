"""beatlite.data.windows on tiny hand-made BEAT takes whose every value is known."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from childproc import run_ok
from test_data_fixtures import (
    SR,
    write_beat_bvh,
    write_emotion,
    write_face_json,
    write_semantic,
    write_textgrid,
    write_wav,
)

from beatlite.data.index import index_folder
from beatlite.data.normalize import Normalizer, Normalizers
from beatlite.data.vocab import Vocab
from beatlite.data.windows import (
    Windows,
    audio_samples,
    audio_start,
    build_windows,
    mel_frames,
    window_starts,
)

FPS = 15
# stem -> frames at 15 fps; 4-hour speaker 2: 9 and 10 train, 57 val, 1 test
TAKES = {"2_scott_0_9_9": 100, "2_scott_0_10_10": 60, "2_scott_0_57_57": 50, "2_scott_0_1_1": 40}
VOCAB = Vocab(["hello", "world"])


def channels_for(stem: str, n: int, scale: float = 1.0) -> np.ndarray:
    """Smooth, distinct rotation channels per take (degrees); root translation 0."""
    from beatlite.skeleton import beat_skeleton

    seed = sum(map(ord, stem))
    rng = np.random.default_rng(seed)
    c = beat_skeleton().n_channels
    t = np.arange(n)[:, None]
    ch = 20 * scale * np.sin(0.1 * t * rng.uniform(0.5, 1.5, size=(1, c)) + rng.uniform(0, 6, size=(1, c)))
    ch[:, :3] = 0.0
    return np.round(ch, 4)


def ramp(n: int) -> np.ndarray:
    """Audio whose sample k is k / 2**20 (identifies the sample index), float32-exact."""
    return (np.arange(n) / 2**20).astype(np.float32)


def write_take(folder: Path, stem: str, n: int, scale: float = 1.0) -> None:
    seconds = n / FPS
    write_beat_bvh(folder / f"{stem}.bvh", channels_for(stem, n, scale))
    write_wav(folder / f"{stem}.wav", ramp(int(round(seconds * SR))))
    write_face_json(folder / f"{stem}.json", np.full((int(round(seconds * 60)), 51), 0.25))
    write_textgrid(
        folder / f"{stem}.TextGrid", [(0.5, 1.0, "Hello"), (1.0, 1.4, "world,"), (1.6, 1.8, "zebra")], seconds
    )
    write_semantic(folder / f"{stem}.txt", [("08_metaphoric_l", 1.0, 2.0, 0.5, "hello")])
    write_emotion(folder / f"{stem}.csv", [(0.0, seconds, 2)], stem)


@pytest.fixture(scope="module")
def corpus(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("windows_corpus")
    for stem, n in TAKES.items():
        write_take(root, stem, n)
    return root


@pytest.fixture(scope="module")
def train(corpus: Path) -> Windows:
    return build_windows(index_folder(corpus), split="train", vocab=VOCAB, cache=False)


def test_window_starts_and_sizes() -> None:
    assert window_starts(100, 34, 10).tolist() == [0, 10, 20, 30, 40, 50, 60]
    assert window_starts(33, 34, 10).tolist() == [] and window_starts(34, 34, 10).tolist() == [0]
    assert audio_samples(34, 15, 16000) == 36266  # floor(34 / 15 * 16000) = floor(36266.67)
    assert audio_start(10, 15, 16000) == 10666  # floor(10 * 16000 / 15)
    assert audio_start(15, 15, 16000) == 16000
    assert mel_frames(36266) == 70  # round((36266 - 1024) / 512 + 1) = round(69.83)
    with pytest.raises(ValueError, match="stride"):
        window_starts(100, 34, 0)


def test_counts_shapes_dtypes(train: Windows) -> None:
    # take 9: 100 frames -> 7 windows (0..60); take 10: 60 frames -> (60 - 34) // 10 + 1 = 3 windows
    assert len(train) == 10
    assert train["take"].tolist() == ["2_scott_0_9_9"] * 7 + ["2_scott_0_10_10"] * 3
    assert train["start"].tolist() == [0, 10, 20, 30, 40, 50, 60, 0, 10, 20]
    expected = {
        "pose": ((10, 34, 141), np.float32),
        "pose_raw": ((10, 34, 141), np.float32),
        "dirvec": ((10, 34, 126), np.float32),
        "audio": ((10, 36266), np.float32),
        "mel": ((10, 70, 128), np.float32),
        "face": ((10, 34, 51), np.float32),
        "word": ((10, 34), np.int64),
        "emotion": ((10, 34), np.int64),
        "semantic": ((10, 34), np.float32),
        "speaker": ((10,), np.int64),
    }
    for key, (shape, dtype) in expected.items():
        assert train[key].shape == shape and train[key].dtype == dtype, key
    assert train.keys() == [
        "pose",
        "pose_raw",
        "dirvec",
        "audio",
        "mel",
        "face",
        "word",
        "emotion",
        "semantic",
    ] + [
        "speaker",
        "take",
        "start",
    ]
    assert np.all(train["speaker"] == 1)  # speaker id 2 -> index 1
    assert train[3]["start"] == 30 and train[-1]["take"] == "2_scott_0_10_10"  # int -> one item
    assert list(train) == train.keys() and train.get("positions") is None and "dirvec_mean" not in train


def test_pose_values_and_train_normalisation(train: Windows) -> None:
    from beatlite.skeleton import beat_skeleton, subset_columns

    cols = subset_columns(beat_skeleton(), "spine_neck_141")
    ch9 = channels_for("2_scott_0_9_9", 100)[:, cols]
    ch10 = channels_for("2_scott_0_10_10", 60)[:, cols]
    # window 3 of take 9 = frames 30..63
    assert np.allclose(train["pose_raw"][3], ch9[30:64], atol=1e-4)
    # statistics of all 160 train frames, computed here with numpy
    frames = np.concatenate([ch9, ch10])
    assert np.allclose(train.normalizers.pose.mean, frames.mean(axis=0), atol=1e-4)
    assert np.allclose(train.normalizers.pose.std, frames.std(axis=0), atol=1e-4)
    assert np.allclose(train["pose"][8], (ch10[10:44] - frames.mean(0)) / frames.std(0), atol=1e-3)
    assert np.allclose(train.normalizers.pose.inverse_transform(train["pose"]), train["pose_raw"], atol=1e-3)


def test_dirvec_are_unit_directions_minus_train_mean(train: Windows) -> None:
    d = (train["dirvec"] + train.normalizers.dirvec.mean).reshape(10, 34, 42, 3)
    assert np.allclose(np.linalg.norm(d, axis=-1), 1.0, atol=1e-5)
    assert np.all(train.normalizers.dirvec.std == 1.0)


def test_audio_mel_face_word_semantic_emotion(train: Windows) -> None:
    for i in (0, 1, 6):
        s = int(train["start"][i])
        a0 = (s * 16000) // 15
        # sample k of the ramp is k / 2**20, stored as 16-bit PCM (step 2**-15: round(k / 32) steps): the
        # window starts at sample floor(s * 16000 / 15) (a shift of one sample moves the steps' edges)
        k = a0 + np.arange(36266)
        np.testing.assert_array_equal(train["audio"][i] * 2**15, np.rint(k / 32))
    mel = train["mel"]
    assert np.all(np.isfinite(mel)) and mel.max() <= 0.0 and mel.min() >= -80.0 - 1e-3
    assert np.allclose(train["face"], 0.25, atol=1e-6)
    # words at t = i / 15: hello [0.5, 1.0) -> frames 8..14, world [1.0, 1.4) -> 15..20,
    # zebra (not in the vocabulary) [1.6, 1.8) -> 24..26 UNK (frame 27 = 1.8 s is outside)
    w = train["word"][0]
    expected = np.zeros(34, np.int64)
    expected[8:15], expected[15:21], expected[24:27] = 4, 5, 3
    assert w.tolist() == expected.tolist()
    # window 1 starts at frame 10: hello frames 10..14 -> positions 0..4
    assert train["word"][1][:5].tolist() == [4] * 5
    sem = train["semantic"][0]  # score 0.5 on [1.0, 2.0) s = frames 15..29
    assert np.all(sem[16:29] == 0.5) and np.all(sem[:14] == 0) and np.all(sem[31:] == 0)
    assert np.all(train["emotion"] == 2)


def test_normalisation_uses_train_only(corpus: Path, tmp_path: Path) -> None:
    import shutil

    copy = tmp_path / "copy"
    shutil.copytree(corpus, copy)
    base = build_windows(index_folder(copy), split="val", vocab=VOCAB, cache=False)
    write_take(copy, "2_scott_0_57_57", 50, scale=3.0)  # change the val take
    changed_val = build_windows(index_folder(copy), split="val", vocab=VOCAB, cache=False)
    assert np.array_equal(base.normalizers.pose.mean, changed_val.normalizers.pose.mean)
    assert np.array_equal(base.normalizers.pose.std, changed_val.normalizers.pose.std)
    assert np.array_equal(base.normalizers.dirvec.mean, changed_val.normalizers.dirvec.mean)
    assert not np.allclose(base["pose_raw"], changed_val["pose_raw"])
    write_take(copy, "2_scott_0_9_9", 100, scale=3.0)  # change a train take: the statistics move
    changed_train = build_windows(index_folder(copy), split="val", vocab=VOCAB, cache=False)
    assert not np.allclose(base.normalizers.pose.std, changed_train.normalizers.pose.std)


def test_explicit_stats_and_errors(corpus: Path, train: Windows) -> None:
    idx = index_folder(corpus)
    fake = Normalizers(Normalizer(np.zeros(141), np.ones(141)), Normalizer(np.zeros(126), np.ones(126)))
    test = build_windows(idx, split="test", vocab=VOCAB, stats=fake, cache=False)
    assert np.array_equal(test["pose"], test["pose_raw"])  # identity statistics
    with pytest.raises(ValueError, match="split must be"):
        build_windows(idx, split="dev", cache=False)
    with pytest.raises(ValueError, match="no usable takes"):
        build_windows(idx.where(split="test"), split="val", cache=False)
    with pytest.raises(ValueError, match="no usable train takes"):
        build_windows(idx.where(split="test"), split="test", cache=False)
    with pytest.raises(KeyError, match="no key 'positions'"):
        train["positions"]


def test_positions_option(corpus: Path) -> None:
    w = build_windows(index_folder(corpus), split="test", vocab=VOCAB, positions=True, cache=False)
    assert w["positions"].shape == (1, 34, 47, 3) and w["positions"].dtype == np.float32
    # the Spine joint sits above the (fixed) Hips at the origin: its height is positive
    assert np.all(w["positions"][0, :, 0, 1] > 0)


def test_whole_take_mode(corpus: Path) -> None:
    w = build_windows(index_folder(corpus), split="test", vocab=VOCAB, whole_takes=True, cache=False)
    assert len(w) == 1 and w["take"].tolist() == ["2_scott_0_1_1"]
    item = w.item(0)
    # 40 frames -> floor(40 / 15 * 16000) = 42666 samples -> round((42666 - 1024) / 512 + 1) = 82 mel frames
    assert (
        item["pose"].shape == (40, 141) and item["audio"].shape == (42666,) and item["mel"].shape == (82, 128)
    )
    assert item["word"].shape == (40,) and item["start"] == 0
    assert isinstance(w["pose"], list) and w["pose"][0].shape == (40, 141)
    with pytest.raises(ValueError, match="different lengths"):
        w.batch()


def test_the_store_behind_the_windows_is_kept_and_reused(corpus: Path, tmp_path: Path) -> None:
    """``cache=folder``: the windows come from a store kept there, built once; later calls, other window
    parameters and whole takes read it without rebuilding a take; saved windows load back."""
    idx = index_folder(corpus)
    first = build_windows(idx, split="test", vocab=VOCAB, cache=tmp_path)
    (folder,) = (tmp_path / "store").iterdir()
    built = {p: p.stat().st_mtime_ns for p in folder.glob("takes/*/meta.json")}
    assert len(built) == len(idx)
    second = build_windows(idx, split="test", vocab=VOCAB, cache=tmp_path)
    for k in first.keys():
        assert np.array_equal(first[k], second[k]), k
    assert (
        np.array_equal(second.normalizers.pose.std, first.normalizers.pose.std)
        and second.params == first.params
    )
    other = build_windows(idx, split="test", vocab=VOCAB, stride=5, cache=tmp_path)  # new window parameters
    assert len(other) > len(first) and other.fingerprint != first.fingerprint
    whole = build_windows(idx, split="test", vocab=VOCAB, whole_takes=True, cache=tmp_path)
    assert {p: p.stat().st_mtime_ns for p in folder.glob("takes/*/meta.json")} == built  # nothing rebuilt
    again = Windows.load(whole.save(tmp_path / "whole.npz"))
    assert np.array_equal(again.item(0)["mel"], whole.item(0)["mel"])
    (tmp_path / "junk.npz").write_bytes(b"junk")
    with pytest.raises(ValueError, match="junk.npz"):
        Windows.load(tmp_path / "junk.npz")


def test_the_windows_read_the_training_store_and_never_write_it(corpus: Path, tmp_path: Path) -> None:
    """The corpus' own store (the one training builds) is read as it is when it holds exactly the index's
    takes, all current; a sub-index, or a store without its manifest, gets a store of its own beside it: the
    training store is never written (no take dropped, its manifest and vocabulary left as they are)."""
    from beatlite.data.store import build_store, default_store_folder, store_params

    idx = index_folder(corpus)
    training = default_store_folder(idx, store_params())
    training = tmp_path / "store" / training.name
    build_store(idx, training, vocab=VOCAB, workers=0)
    files = {p: p.stat().st_mtime_ns for p in training.rglob("*") if p.is_file() and p.name != ".build.lock"}
    full = build_windows(idx, split="test", vocab=VOCAB, cache=tmp_path)
    assert [p.name for p in (tmp_path / "store").iterdir()] == [training.name]  # read, not copied
    sub = build_windows(idx.where(split=["train", "test"]), split="test", vocab=VOCAB, cache=tmp_path)
    assert np.array_equal(sub["pose"], full["pose"]) and len(list((tmp_path / "store").iterdir())) == 2
    (training / "store.json").unlink()  # a store whose manifest is gone (or not written yet): not shared
    build_windows(idx.where(split=["train", "test"]), split="test", vocab=VOCAB, cache=tmp_path)
    assert {p: t for p, t in files.items() if p.name != "store.json"} == {
        p: p.stat().st_mtime_ns for p in training.rglob("*") if p.is_file() and p.name != ".build.lock"
    }


def test_torch_dataset(train: Windows) -> None:
    import torch
    from torch.utils.data import DataLoader

    from beatlite.data.torch_dataset import WindowDataset

    ds = WindowDataset(train)
    assert len(ds) == 10
    batch = next(iter(DataLoader(ds, batch_size=4, shuffle=False)))
    assert batch["pose"].shape == (4, 34, 141) and batch["pose"].dtype == torch.float32
    assert batch["word"].dtype == torch.int64 and batch["speaker"].tolist() == [1, 1, 1, 1]
    assert batch["take"] == ["2_scott_0_9_9"] * 4
    with pytest.raises(KeyError, match="positions"):
        WindowDataset(train, keys=["positions"])


def test_import_does_not_load_torch() -> None:
    import sys

    code = "import sys, beatlite.data, beatlite.data.windows, beatlite.stats; print('torch' in sys.modules)"
    out = run_ok([sys.executable, "-c", code])
    assert out.stdout.strip() == "False"


def test_b_half_words_use_the_sequence_offset(tmp_path: Path) -> None:
    # 1-hour speaker 10 (kieks): "_b" halves keep the whole sequence's TextGrid times; speech -> 30 s offset
    stem = "10_kieks_0_65_65_b"
    write_take(tmp_path, stem, 40)
    write_textgrid(tmp_path / f"{stem}.TextGrid", [(30.5, 31.0, "hello")], 62.0)
    idx = index_folder(tmp_path)
    assert idx[stem].half == "b" and idx[stem].split == "val"
    fake = Normalizers(Normalizer(np.zeros(141), np.ones(141)), Normalizer(np.zeros(126), np.ones(126)))
    w = build_windows(idx, split="val", vocab=VOCAB, stats=fake, whole_takes=True, cache=False)
    # frame i at 30 + i / 15 s: [30.5, 31.0) -> frames 8..14
    expected = np.zeros(40, np.int64)
    expected[8:15] = VOCAB["hello"]
    assert w.item(0)["word"].tolist() == expected.tolist()
