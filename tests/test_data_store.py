"""beatlite.data.store: the on-disk window store gives build_windows' batches, incrementally and safely."""

from __future__ import annotations

import functools
import json
import os
import shutil
import subprocess
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from test_data_windows import TAKES, VOCAB, write_take

from beatlite.data.index import index_folder
from beatlite.data.normalize import Normalizer
from beatlite.data.store import (
    STREAMS,
    WindowStore,
    _combine,
    _moments,
    _WordRecorder,
    build_store,
    quantize_audio,
)
from beatlite.data.windows import (
    audio_samples,
    audio_start,
    build_windows,
    mel_frames,
    sliding_windows,
    take_features,
    window_starts,
)
from beatlite.io import FormatError

#: 16-bit storage of audio on the step 2**-15: at most half a step off (plus float32 rounding, 0 here).
AUDIO_BOUND = 2.0**-16


@pytest.fixture()
def corpus(tmp_path: Path) -> Path:
    root = tmp_path / "corpus"
    root.mkdir()
    for stem, n in TAKES.items():
        write_take(root, stem, n)
    return root


@pytest.fixture()
def store(corpus: Path, tmp_path: Path) -> WindowStore:
    return build_store(index_folder(corpus), tmp_path / "store", vocab=VOCAB, workers=0)


def _meta_times(store: WindowStore) -> dict[str, int]:
    return {t.stem: (t.folder / "meta.json").stat().st_mtime_ns for t in store.takes}


def _rows(x: np.ndarray, start: int, n: int) -> np.ndarray:
    """``x[start:start + n]``, the last row repeated up to ``n`` rows (HA2G's mel rule at a take's end)."""
    out = x[start : start + n]
    return np.concatenate([out, np.repeat(out[-1:], n - len(out), axis=0)]) if len(out) < n else out


def test_batches_equal_windows_cut_from_each_takes_features(corpus: Path, store: WindowStore) -> None:
    """The store's batches equal the windows cut directly from each take's features by the teaching
    functions (``take_features``, ``sliding_windows``, ``audio_start``), and its pooled statistics equal
    ``Normalizer.fit`` over every train frame; ``build_windows`` holds the same batches in memory."""
    idx = index_folder(corpus)
    got = store.windows("train")
    features = [take_features(r, vocab=VOCAB) for r in idx if r.split == "train"]
    pose_raw = np.concatenate([f.pose_raw for f in features])
    fitted = Normalizer.fit(pose_raw)
    norms = store.statistics("train")
    assert np.allclose(norms.pose.mean, fitted.mean, rtol=1e-12, atol=1e-12)
    assert np.allclose(norms.pose.std, fitted.std, rtol=1e-12, atol=0)
    dir_mean = np.concatenate([f.dirs for f in features]).mean(0)
    assert np.allclose(norms.dirvec.mean, dir_mean, rtol=0, atol=1e-14) and np.all(norms.dirvec.std == 1)
    starts = [window_starts(f.n_frames) for f in features]
    expected = {
        "pose_raw": sliding_windows([f.pose_raw for f in features]).astype(np.float32),
        "pose": norms.pose.transform(sliding_windows([f.pose_raw for f in features])).astype(np.float32),
        "dirvec": norms.dirvec.transform(sliding_windows([f.dirs for f in features])).astype(np.float32),
        **{k: sliding_windows([getattr(f, k) for f in features]) for k in ("face", "word", "emotion", "semantic")},
        "audio": np.stack([f.audio[audio_start(int(s), 15, 16000) :][:36266] for f, ss in zip(features, starts)
                           for s in ss]),
        "mel": np.stack([_rows(f.mel, audio_start(int(s), 15, 16000) // 512, 70) for f, ss in zip(features, starts)
                         for s in ss]),
        "start": np.concatenate(starts),
    }  # fmt: skip
    a = got.batch()
    assert len(got) == len(a["start"]) == 10
    for key, value in expected.items():
        assert a[key].shape == value.shape, key
        if key == "audio":  # the ramp k / 2**20 is not on the 16-bit grid
            assert 0 < np.abs(a[key] - value).max() <= AUDIO_BOUND
        else:
            assert np.array_equal(a[key], value.astype(a[key].dtype)), key
    ref = build_windows(idx, split="train", vocab=VOCAB, cache=False)
    assert ref.keys() == got.keys() and all(np.array_equal(ref[k], a[k]) for k in ref.keys())
    assert ref.fingerprint == got.fingerprint
    # item / key access as Windows, the word key through the take-local ids
    assert np.array_equal(got.item(3)["word"], a["word"][3]) and np.array_equal(got["start"], a["start"])
    assert set(np.unique(a["word"])) >= {0, VOCAB["hello"], VOCAB["world"], 3}  # "zebra" -> UNK


def test_word_recorder_maps_to_the_vocabulary() -> None:
    from beatlite.io.textgrid import Interval, WordIntervals, words_to_frames

    words = WordIntervals(
        np.array([0.1, 0.5, 0.9]), np.array([0.4, 0.8, 1.2]), ("Hello", "zebra", "world,"), 1.5
    )
    tier = [
        Interval(0.0, 0.1, ""),
        Interval(0.1, 0.4, "Hello"),
        Interval(0.4, 0.6, " "),
        Interval(0.6, 1.0, "world"),
    ]
    for source, rule in ((words, "span"), (words, "onset"), (words, "beat"), (tier, "beat")):
        rec = _WordRecorder()
        local = words_to_frames(source, 25, 15, rec, rule=rule)
        table = np.array([0, 1, 2, 3, *[VOCAB.get(m, 3) for m in rec.marks]])
        assert np.array_equal(table[local], words_to_frames(source, 25, 15, VOCAB, rule=rule)), rule


def test_quantize_audio() -> None:
    q, step = quantize_audio(np.array([0.5, -1.0, 2.0**-15, 32767 / 32768], np.float32))
    assert step == 2.0**-15 and q.tolist() == [16384, -32768, 1, 32767]
    y = np.random.default_rng(0).uniform(-1.3, 1.1, 5000)  # peak above 1: step = peak / 32767
    q, step = quantize_audio(y)
    assert step == pytest.approx(np.abs(y).max() / 32767, rel=1e-15)
    assert np.abs(q * step - y).max() <= step / 2 * (1 + 1e-9)
    with pytest.raises(ValueError, match="NaN"):
        quantize_audio(np.array([0.0, np.nan]))


def test_streamed_moments_equal_the_whole_array() -> None:
    rng = np.random.default_rng(1)
    parts = [rng.normal(loc=30.0, scale=s, size=(n, 5)) for n, s in ((7, 1.0), (1, 2.0), (40, 0.5), (0, 1.0))]
    n, mean, var = _combine([_moments(p) for p in parts], Path("x"))
    whole = Normalizer.fit([p for p in parts if len(p)])
    assert (
        n == 48
        and np.allclose(mean, whole.mean, rtol=1e-13)
        and np.allclose(np.sqrt(var), whole.std, rtol=1e-12)
    )


def test_incremental_rebuild(corpus: Path, store: WindowStore, tmp_path: Path) -> None:
    folder = tmp_path / "store"
    before = _meta_times(store)
    again = build_store(index_folder(corpus), folder, vocab=VOCAB, workers=0)
    assert _meta_times(again) == before  # nothing changed: nothing rebuilt
    changed = "2_scott_0_10_10"
    write_take(corpus, changed, 75, scale=2.0)  # new content, new size/mtime
    shutil.rmtree(corpus / "x", ignore_errors=True)
    os.remove(corpus / "2_scott_0_1_1.bvh")  # a take without motion leaves the store
    with pytest.warns(UserWarning, match="skipping 1 unusable"):
        after = build_store(index_folder(corpus), folder, vocab=VOCAB, workers=0)
    times = _meta_times(after)
    assert [s for s in times if times[s] != before.get(s)] == [changed]
    assert "2_scott_0_1_1" not in times and not (folder / "takes" / "2_scott_0_1_1").exists()
    assert after.take(changed).n_frames == 75
    ref = build_windows(index_folder(corpus), split="train", vocab=VOCAB, cache=False)
    assert np.array_equal(after.windows("train", stats=ref.normalizers).batch()["pose"], ref["pose"])
    # another parameter: every take is rebuilt
    with pytest.warns(UserWarning, match="skipping 1 unusable"):
        build_store(index_folder(corpus), folder, vocab=VOCAB, workers=0, word_rule="onset")
    assert all(v != times[s] for s, v in _meta_times(WindowStore.open(folder)).items())


def test_takes_used_despite_a_readers_warning_are_named(corpus: Path, tmp_path: Path) -> None:
    """A BVH missing half its rows (header unchanged) is read at half the rate (index_folder's warning): the build
    says so, naming the take, instead of training on it silently."""
    stem = "2_scott_0_9_9"
    lines = (corpus / f"{stem}.bvh").read_text().splitlines()
    start = lines.index("MOTION") + 3
    (corpus / f"{stem}.bvh").write_text("\n".join(lines[: start + (len(lines) - start) // 2]) + "\n")
    with pytest.warns(
        UserWarning, match=rf"1 takes are used although their readers warned \({stem}\).*7.5 fps"
    ):
        store = build_store(index_folder(corpus), tmp_path / "store", vocab=VOCAB, workers=0)
    assert stem in [t.stem for t in store.takes]  # used: the warning is the only sign


def test_parallel_build_equals_serial(corpus: Path, store: WindowStore, tmp_path: Path) -> None:
    par = build_store(index_folder(corpus), tmp_path / "par", vocab=VOCAB, workers=2, progress=True)
    a, b = store.windows(None).batch(), par.windows(None).batch()
    assert all(np.array_equal(a[k], b[k]) for k in a)
    for t in store.takes:
        for name in t.meta["shapes"]:
            assert (t.folder / f"{name}.npy").read_bytes() == (
                par.take(t.stem).folder / f"{name}.npy"
            ).read_bytes()


def test_a_main_script_read_from_stdin_builds_and_indexes_in_this_process(
    corpus: Path, store: WindowStore, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``python - <<EOF`` scripts: spawned workers would re-run ``__main__`` from ``"<stdin>"`` and all fail
    (``BrokenProcessPool``, seen on the GPU machine); asked for 2 workers, both steps work in this process with
    a warning and give the serial store's bytes."""
    import sys

    monkeypatch.setattr(sys.modules["__main__"], "__file__", "<stdin>", raising=False)
    monkeypatch.setenv("BEATLITE_BUILD", str(tmp_path / "build"))  # an empty index cache: every take indexed
    with pytest.warns(RuntimeWarning, match="index_folder: the main script '<stdin>' is not a file"):
        index = index_folder(corpus, workers=2)
    with pytest.warns(RuntimeWarning, match="build_store: .* working in this process"):
        built = build_store(index, tmp_path / "s", vocab=VOCAB, workers=2)
    a, b = store.windows(None).batch(), built.windows(None).batch()
    assert all(np.array_equal(a[k], b[k]) for k in a)
    with warnings.catch_warnings():  # nothing to spawn for (the store is current): no warning
        warnings.simplefilter("error")
        build_store(index, tmp_path / "s", vocab=VOCAB, workers=2)


def test_only_the_asked_streams_are_read(store: WindowStore) -> None:
    for t in store.takes:
        os.remove(t.folder / "mel.npy")
    reopened = WindowStore.open(store.folder)
    camn = reopened.windows("train", keys=("pose", "audio", "word", "speaker"))
    assert camn.batch([0, 4])["pose"].shape == (2, 34, 141) and camn.keys() == [
        "pose",
        "audio",
        "word",
        "speaker",
    ]
    with pytest.raises(FormatError, match="mel.npy"):
        reopened.windows("train").batch([0])
    with pytest.raises(KeyError, match="positions"):
        reopened.windows("train", keys=("positions",))


def test_corrupt_files_raise_format_error_naming_them(store: WindowStore) -> None:
    take = store.takes[int(store.windows("train").take_ids[0])]
    pose = take.folder / "pose_raw.npy"
    pose.write_bytes(pose.read_bytes()[:-8])  # truncated
    with pytest.raises(FormatError, match="pose_raw.npy.*truncated"):
        WindowStore.open(store.folder).windows("train").batch([0])
    np.save(pose, np.zeros((3, 141), np.float32))  # wrong dtype and shape
    with pytest.raises(FormatError, match="pose_raw.npy.*meta.json says"):
        WindowStore.open(store.folder).windows("train").batch([0])
    (take.folder / "face.npy").write_bytes(b"not numpy")
    with pytest.raises(FormatError, match="face.npy"):
        WindowStore.open(store.folder).windows("train", keys=("face",)).batch([0])
    (take.folder / "meta.json").write_text("{broken")
    with pytest.raises(FormatError, match="meta.json"):
        WindowStore.open(store.folder)
    manifest = json.loads((store.folder / "store.json").read_text())
    del manifest["vocab"]
    (store.folder / "store.json").write_text(json.dumps(manifest))
    with pytest.raises(FormatError, match="store.json.*vocab"):
        WindowStore.open(store.folder)


def test_build_heals_a_corrupt_entry(corpus: Path, store: WindowStore) -> None:
    take = store.takes[0]
    good = (take.folder / "audio.npy").read_bytes()
    (take.folder / "audio.npy").write_bytes(good[:100])
    healed = build_store(index_folder(corpus), store.folder, vocab=VOCAB, workers=0)
    assert (healed.take(take.stem).folder / "audio.npy").read_bytes() == good


def test_torch_loader_over_the_store(store: WindowStore) -> None:
    import torch

    from beatlite.data.torch_dataset import WindowDataset, window_loader

    windows = store.windows("train", keys=("pose", "audio", "word", "speaker", "take", "start"))
    whole = windows.batch()
    for workers in (0, 2):
        loader = window_loader(windows, batch_size=4, shuffle=False, num_workers=workers)
        batches = list(loader)
        assert [len(b["take"]) for b in batches] == [4, 4, 2]
        for key in ("pose", "audio", "word", "speaker"):
            got = torch.cat([b[key] for b in batches]).numpy()
            assert np.array_equal(got, whole[key]), (workers, key)
        assert sum((b["take"] for b in batches), []) == whole["take"].tolist()
        first = [
            b["start"].tolist() for b in window_loader(windows, keys=("start",), seed=3, num_workers=workers)
        ]
        again = [b["start"].tolist() for b in window_loader(windows, keys=("start",), seed=3)]
        assert first == again  # a seed gives the same order, whatever the workers
        assert sum(first, []) != whole["start"].tolist()  # and it is shuffled
        seen = torch.cat(
            [b["pose"] for b in window_loader(windows, batch_size=3, seed=3, num_workers=workers)]
        )
        assert len(seen) == len(whole["pose"])
        assert sorted(map(bytes, seen.numpy())) == sorted(map(bytes, whole["pose"]))  # each window once
    item = WindowDataset(windows)[2]
    assert item["pose"].shape == (34, 141) and item["take"] == whole["take"][2]


def test_unreadable_take_raises_its_format_error_from_a_worker(corpus: Path, tmp_path: Path) -> None:
    bvh = corpus / "2_scott_0_9_9.bvh"
    index = index_folder(corpus)  # indexed while the file is fine: the index calls the take usable
    lines = bvh.read_text(encoding="utf-8").splitlines()
    bvh.write_text("\n".join([*lines[:-1], "abc"]) + "\n", encoding="utf-8")  # header fine, last row broken
    for workers in (0, 2):
        with pytest.raises(FormatError, match=r"2_scott_0_9_9\.bvh, line \d+"):
            build_store(index, tmp_path / f"store{workers}", vocab=VOCAB, workers=workers)
    # indexed now, the take is unusable (the index runs the readers) and names the line
    record = index_folder(corpus)["2_scott_0_9_9"]
    assert not record.usable and any("line" in p for p in record.problems)


def test_default_vocabulary_follows_the_textgrids(corpus: Path, tmp_path: Path) -> None:
    from test_data_fixtures import write_textgrid

    from beatlite.data.vocab import build_vocab

    store = build_store(index_folder(corpus), tmp_path / "v", workers=0)
    assert store.vocab.itos == build_vocab(index_folder(corpus)).itos
    write_textgrid(corpus / "2_scott_0_9_9.TextGrid", [(0.5, 1.0, "Giraffe")], 100 / 15)
    again = build_store(index_folder(corpus), tmp_path / "v", workers=0)
    assert again.vocab.itos == build_vocab(index_folder(corpus)).itos and "giraffe" in again.vocab
    word = again.windows("train").batch([0])["word"][0]
    assert again.vocab["giraffe"] in word.tolist()  # the changed take was rebuilt with the new word


def test_default_vocabulary_reads_the_textgrids_of_usable_takes_only(corpus: Path, tmp_path: Path) -> None:
    """A take whose TextGrid does not read is unusable: the store skips it, and its default vocabulary is that
    of the stored takes' TextGrids (read here one by one) instead of failing on the broken one."""
    from beatlite.data.vocab import vocab_from_sentences
    from beatlite.io import read_words

    bad = "2_scott_0_10_10"
    (corpus / f"{bad}.TextGrid").write_text('File type = "ooTextFile"\nObject class = "TextGrid"\nxmin = 0\n')
    index = index_folder(corpus)
    assert not index[bad].usable
    with pytest.warns(UserWarning, match="skipping 1 unusable"):
        store = build_store(index, tmp_path / "v", workers=0)
    stems = [stem for stem in TAKES if stem != bad]
    assert [t.stem for t in store.takes] == [r.stem for r in index if r.stem in stems]
    words = [list(read_words(corpus / f"{stem}.TextGrid").words) for stem in stems]
    assert store.vocab.itos == vocab_from_sentences(words).itos


def test_whole_take_equals_the_takes_features(corpus: Path, store: WindowStore) -> None:
    """A whole take: the take's features at full length (audio cut to ``audio_samples(T)``, the mel to
    ``mel_frames`` of that), normalised with the given statistics; ``build_windows(whole_takes=True)`` holds the
    same items."""
    idx = index_folder(corpus)
    stats = store.statistics("train")
    ref = build_windows(idx, split="val", vocab=VOCAB, stats=stats, whole_takes=True, cache=False)
    for i, r in enumerate(r for r in idx if r.split == "val"):
        f, got = take_features(r, vocab=VOCAB), store.whole_take(r.stem, stats=stats, vocab=VOCAB)
        n_audio = audio_samples(f.n_frames, 15, 16000)
        want = {
            "pose": stats.pose.transform(f.pose_raw).astype(np.float32), "pose_raw": f.pose_raw.astype(np.float32),
            "dirvec": stats.dirvec.transform(f.dirs).astype(np.float32), "face": f.face, "word": f.word,
            "emotion": f.emotion, "semantic": f.semantic, "mel": _rows(f.mel, 0, mel_frames(n_audio)),
        }  # fmt: skip
        for key, value in want.items():
            assert np.array_equal(got[key], value.astype(got[key].dtype)), key
        assert (
            got["audio"].shape == (n_audio,) and np.abs(got["audio"] - f.audio[:n_audio]).max() <= AUDIO_BOUND
        )
        assert got["take"] == r.stem and all(np.array_equal(ref.item(i)[k], got[k]) for k in ref.keys())
    # 100 frames: 106666 samples, round((106666 - 1024) / 512 + 1) = 207 mel frames (HA2G's clip rule)
    assert store.whole_take("2_scott_0_9_9", keys=("mel",))["mel"].shape == (207, 128)


def test_fit_reads_a_store_through_a_dataloader_like_the_windows_in_memory(
    corpus: Path, store: WindowStore
) -> None:
    """Training on a store (batches read by DataLoader workers) takes the same steps as on build_windows'
    arrays when the model reads no audio (the store keeps audio as 16-bit PCM); workers change nothing."""
    torch = pytest.importorskip("torch")
    from beatlite.models import build_model
    from beatlite.train import TrainConfig, fit

    ref = build_windows(index_folder(corpus), split="train", vocab=VOCAB, cache=False)
    runs = {}
    for name, windows, workers in (
        ("memory", ref, 0),
        ("store", store.windows("train", stats=ref.normalizers), 0),
        ("store, 2 workers", store.windows("train", stats=ref.normalizers), 2),
    ):
        torch.manual_seed(0)
        model = build_model("s2g", preset="tiny")  # reads pose and mel
        config = TrainConfig(epochs=2, batch_size=4, seed=1, threads=1, progress=False, workers=workers)
        history = fit(model, windows, config).history
        runs[name] = (history, [p.detach().clone() for p in model.parameters()])
    for name in ("store", "store, 2 workers"):
        assert runs[name][0] == runs["memory"][0], name
        assert all(torch.equal(a, b) for a, b in zip(runs[name][1], runs["memory"][1], strict=True)), name


def _build_in_child(root: str, folder: str) -> list[str]:
    from test_data_windows import VOCAB as vocab

    return [
        t.stem for t in build_store(index_folder(root, cache=False), folder, vocab=vocab, workers=0).takes
    ]


def test_processes_building_one_store_at_once_take_turns(corpus: Path, tmp_path: Path) -> None:
    """retrain-all --jobs 2 and torchrun start processes that build the same store: without the lock one
    read a take's entry while the other rewrote it (FormatError: meta.json missing)."""
    from concurrent.futures import ProcessPoolExecutor
    from multiprocessing import get_context

    folder = tmp_path / "shared_store"
    with ProcessPoolExecutor(3, mp_context=get_context("spawn")) as pool:
        stems = list(pool.map(_build_in_child, [str(corpus)] * 3, [str(folder)] * 3))
    assert stems[0] == stems[1] == stems[2] and len(stems[0]) == len(TAKES)
    ref = build_windows(index_folder(corpus), split="train", vocab=VOCAB, cache=False)
    got = WindowStore.open(folder).windows("train", stats=ref.normalizers).batch()
    assert np.array_equal(got["pose_raw"], ref["pose_raw"])


def test_a_rebuilt_take_is_read_from_its_new_files_in_the_same_process(
    corpus: Path, store: WindowStore
) -> None:
    """Reading batches keeps each stream file open (by path) for later reads; a rebuild replaces the files (new
    inodes, same paths), so a store reopened in the same process read the replaced take's old rows. The store
    opened before the rebuild now refuses to read the replaced file."""
    before = store.windows("train", keys=("pose_raw",)).batch()["pose_raw"]  # opens (and keeps) the files
    write_take(corpus, "2_scott_0_9_9", TAKES["2_scott_0_9_9"], scale=2.0)  # same length, other motion
    rebuilt = build_store(index_folder(corpus), store.folder, vocab=VOCAB, workers=0)
    ref = build_windows(index_folder(corpus), split="train", vocab=VOCAB, cache=False)
    got = rebuilt.windows("train", keys=("pose_raw",)).batch()["pose_raw"]
    assert not np.array_equal(ref["pose_raw"], before)  # the take changed
    assert np.array_equal(got, ref["pose_raw"])
    with pytest.raises(
        FormatError, match="pose_raw.npy.*replaced since"
    ):  # the store opened before: no old rows
        store.windows("train", keys=("pose_raw",)).batch()


def test_a_bit_flip_in_a_npy_header_is_a_format_error_and_healed(corpus: Path, store: WindowStore) -> None:
    """numpy parses a ``.npy`` header as a Python literal: a flipped bit of its length field (byte 8) or of the
    text made it raise ``tokenize.TokenError``, neither a FormatError nor healed by the next build."""
    take = store.takes[int(store.windows("train").take_ids[0])]
    pose = take.folder / "pose_raw.npy"
    good = pose.read_bytes()
    for at, bit in ((8, 6), (20, 2), (60, 0)):  # the header length, inside the dict, in its padding
        bad = bytearray(good)
        bad[at] ^= 1 << bit
        pose.write_bytes(bytes(bad))
        with pytest.raises(FormatError, match="pose_raw.npy"):
            WindowStore.open(store.folder).windows("train", keys=("pose_raw",)).batch()
        healed = build_store(index_folder(corpus), store.folder, vocab=VOCAB, workers=0)
        assert (
            pose.read_bytes() == good and healed.take(take.stem).stream("pose_raw").shape[0] == take.n_frames
        )


_BUILD_CHILD = (
    "import sys; from beatlite.data.index import index_folder; from beatlite.data.store import build_store; "
    "from test_data_windows import VOCAB; build_store(index_folder(sys.argv[1], cache=False), sys.argv[2], "
    "vocab=VOCAB, workers=0)"
)


def _limit_file_size(limit: int) -> None:
    """(In the child, before exec) writes past ``limit`` bytes fail (EFBIG), as a full disk's do (ENOSPC)."""
    import resource
    import signal

    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_FSIZE and SIGXFSZ as on Linux")
def test_a_build_that_cannot_write_names_the_store_and_leaves_nothing_misread(
    corpus: Path, tmp_path: Path
) -> None:
    """A write that fails midway (the file-size limit here: 50 kB fails the first stream, 150 kB the third)
    raised numpy's bare ``OSError: 14100 requested and 6234 written`` (no folder named) and left the take's
    written streams behind; it names the store's entry and removes it, and a later build equals a fresh one."""
    folder, fresh = tmp_path / "store", tmp_path / "fresh"
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(Path(__file__).parent), os.environ.get("PYTHONPATH", "")]),
    }
    for limit in (50_000, 150_000):
        cmd = [sys.executable, "-c", _BUILD_CHILD, str(corpus), str(folder)]
        done = subprocess.run(
            cmd,
            env=env,
            capture_output=True,
            text=True,
            preexec_fn=functools.partial(_limit_file_size, limit),
        )
        last = done.stderr.strip().splitlines()[-1]
        assert done.returncode == 1 and last.startswith("OSError:"), done.stderr
        assert f"cannot write the window store {folder}" in last, done.stderr  # (or one of its takes)
        assert not [p for p in folder.rglob("*") if p.name.endswith(".tmp")]
        assert all((take / "meta.json").is_file() for take in (folder / "takes").iterdir()), done.stderr
    build_store(index_folder(corpus), folder, vocab=VOCAB, workers=0)
    build_store(index_folder(corpus), fresh, vocab=VOCAB, workers=0)
    files = sorted(p.relative_to(fresh) for p in fresh.rglob("*") if p.is_file())
    assert sorted(p.relative_to(folder) for p in folder.rglob("*") if p.is_file()) == files
    assert all((folder / p).read_bytes() == (fresh / p).read_bytes() for p in files)


def _read_only(monkeypatch: pytest.MonkeyPatch, folder: Path) -> None:
    """Make ``folder`` read-only as a read-only mount does (root ignores file modes): creating, opening for
    writing, renaming or removing anything under it raises ``OSError(EROFS)``."""
    import builtins
    import errno

    from beatlite.io import atomic

    root = folder.resolve()

    def under(path: Any) -> bool:
        return isinstance(path, str | os.PathLike) and Path(os.fspath(path)).resolve().is_relative_to(root)

    def refuse(path: Any) -> None:
        raise OSError(errno.EROFS, "Read-only file system", str(path))

    real_open, real_os_open, real_mkdir = builtins.open, os.open, os.mkdir

    def fake_open(file: Any, mode: str = "r", *args: Any, **kwargs: Any) -> Any:
        if under(file) and any(c in mode for c in "wax+"):
            refuse(file)
        return real_open(file, mode, *args, **kwargs)

    def fake_os_open(path: Any, flags: int, *args: Any, **kwargs: Any) -> int:
        if under(path) and flags & (os.O_WRONLY | os.O_RDWR | os.O_CREAT):
            refuse(path)
        return real_os_open(path, flags, *args, **kwargs)

    def fake_mkdir(path: Any, *args: Any, **kwargs: Any) -> None:
        if under(path) and not os.path.exists(path):
            refuse(path)
        real_mkdir(path, *args, **kwargs)

    def refusing(real: Any) -> Any:
        return lambda path, *args, **kwargs: refuse(path) if under(path) else real(path, *args, **kwargs)

    monkeypatch.setattr(atomic, "open", fake_open, raising=False)
    monkeypatch.setattr(os, "open", fake_os_open)
    monkeypatch.setattr(os, "mkdir", fake_mkdir)
    for name in ("unlink", "replace", "rename", "rmdir"):
        monkeypatch.setattr(os, name, refusing(getattr(os, name)))


def test_a_current_store_on_read_only_media_is_opened_without_writing(
    corpus: Path, store: WindowStore, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Opening a current store wrote its lock file open (``a+b``) and store.json again, so on a read-only
    mount (measured: a bind mount, ``OSError: [Errno 30] Read-only file system: '.../.build.lock'``) neither
    ``open_if_current`` nor ``build_store`` could read it. They write nothing now; a stale one is a clear error."""
    from beatlite.data.store import open_if_current, store_params

    expected = store.windows("train").batch()
    index = index_folder(corpus)
    _read_only(monkeypatch, store.folder)
    for opened in (
        open_if_current(index, store.folder, store_params()),
        build_store(index, store.folder, vocab=VOCAB),
    ):
        got = opened.windows("train").batch()
        assert all(np.array_equal(got[k], expected[k]) for k in expected)
    write_take(corpus, "2_scott_0_9_9", TAKES["2_scott_0_9_9"], scale=2.0)
    with pytest.raises(OSError, match=f"cannot write the window store {store.folder}"):
        build_store(index_folder(corpus), store.folder, vocab=VOCAB, workers=0)


def _flip_bit_after(path: Path, marker: str, *, skip: str = "") -> None:
    """Flip the lowest bit of the first character after ``marker`` that is not in ``skip`` (a digit stays a
    digit, a letter a letter: the JSON still parses)."""
    data = bytearray(path.read_bytes())
    at = data.index(marker.encode()) + len(marker)
    while chr(data[at]) in skip:
        at += 1
    data[at] ^= 1
    path.write_bytes(bytes(data))


def test_a_flipped_bit_in_the_stores_json_is_a_format_error_and_healed(corpus: Path, tmp_path: Path) -> None:
    """A bit flipped in a number of a take's meta.json (its statistics) or a word of store.json's vocabulary
    still parses: the store gave other statistics or word ids without a word, and the next build kept them
    (store.json's vocabulary is reused while the TextGrids are unchanged). Each file carries the sha256 of its
    content now: a mismatch is a FormatError naming it, and the build rewrites the file."""
    index = index_folder(corpus)
    fresh = build_store(index, tmp_path / "fresh", workers=0)  # the default vocabulary: kept in store.json
    assert "hello" in fresh.vocab.itos
    files = sorted(p.relative_to(fresh.folder) for p in fresh.folder.rglob("*") if p.is_file())
    take = fresh.takes[int(fresh.windows("train").take_ids[0])].folder.relative_to(fresh.folder)
    for name, marker, skip in ((take / "meta.json", '"sum": [', "-"), ("store.json", '"hello', "")):
        folder = tmp_path / f"flipped_{Path(name).stem}"
        shutil.copytree(fresh.folder, folder)
        _flip_bit_after(folder / name, marker, skip=skip)
        with pytest.raises(FormatError, match=Path(name).name):
            WindowStore.open(folder).statistics("train")
        build_store(index, folder, workers=0)
        assert all((folder / p).read_bytes() == (fresh.folder / p).read_bytes() for p in files), name


def test_a_build_killed_at_any_rename_is_finished_by_the_next_one_bit_for_bit(
    corpus: Path, tmp_path: Path
) -> None:
    """A build process killed just before its k-th rename (a stream's, a take's meta.json, store.json: each
    leaves a complete temp file behind) leaves no lock held and nothing that the next build misreads: it
    equals a fresh build file for file, and no temp file is left."""
    folder, fresh = tmp_path / "store", tmp_path / "fresh"
    build_store(index_folder(corpus), fresh, vocab=VOCAB, workers=0)
    files = sorted(p.relative_to(fresh) for p in fresh.rglob("*") if p.is_file())
    per_take = len(STREAMS)  # its 8 streams (no positions) and meta.json
    renames = len(TAKES) * per_take + 1  # then store.json
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(Path(__file__).parent), os.environ.get("PYTHONPATH", "")]),
    }
    kill = (
        "import os, sys; real, n = os.replace, [0]\n"
        "def replace(*a, **k):\n"
        "    n[0] += 1\n"
        "    if n[0] == int(sys.argv[3]): os._exit(9)\n"
        "    real(*a, **k)\n"
        "os.replace = replace\n"
    )
    for k in (1, per_take, renames):  # the first stream, the first take's meta.json, store.json
        done = subprocess.run([sys.executable, "-c", kill + _BUILD_CHILD, str(corpus), str(folder), str(k)],
                              env=env, capture_output=True, text=True)  # fmt: skip
        assert done.returncode == 9, done.stderr
        assert [p for p in folder.rglob("*") if p.name.endswith(".tmp")], (
            "the killed writer left its temp file"
        )
        build_store(index_folder(corpus), folder, vocab=VOCAB, workers=0)
        assert not [p for p in folder.rglob("*") if p.name.endswith(".tmp")]
        assert sorted(p.relative_to(folder) for p in folder.rglob("*") if p.is_file()) == files
        assert all((folder / p).read_bytes() == (fresh / p).read_bytes() for p in files), k
        shutil.rmtree(folder)


def test_a_read_only_corpus_is_indexed_and_built(
    corpus: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Readers never write: a corpus on read-only media is indexed (cache elsewhere) and stored elsewhere."""
    expected = build_windows(index_folder(corpus, cache=False), split="train", vocab=VOCAB, cache=False)
    _read_only(monkeypatch, corpus)
    store = build_store(index_folder(corpus), tmp_path / "elsewhere", vocab=VOCAB, workers=0)
    got = store.windows("train", stats=expected.normalizers).batch()
    assert all(np.array_equal(got[k], expected[k]) for k in expected.keys())


def test_a_word_id_outside_the_takes_marks_is_a_format_error(store: WindowStore) -> None:
    """A bit flipped in word.npy can give a take-local id past the take's word marks: batches raised numpy's
    IndexError (measured: 13 of 24 bit flips of one take's word.npy), as did holding the streams on the device
    (ResidentWindows); it is a FormatError naming the file."""
    view = store.windows("train", keys=("word",))
    take = store.takes[int(view.take_ids[-1])]
    word = take.folder / "word.npy"
    data = bytearray(word.read_bytes())
    data[len(data) - 4 * take.n_frames + 3] ^= (
        0x40  # the high byte of frame 0's little-endian int32: 2**30 more
    )
    word.write_bytes(bytes(data))
    with pytest.raises(FormatError, match="word.npy.*word id"):
        WindowStore.open(store.folder).windows("train", keys=("word",)).batch()
    from beatlite.data.resident import ResidentWindows

    with pytest.raises(FormatError, match="word.npy.*word id"):  # the streams held on the device: the same
        ResidentWindows(WindowStore.open(store.folder).windows("train", keys=("word",)), ["word"])
