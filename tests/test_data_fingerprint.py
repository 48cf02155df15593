"""beatlite.data.fingerprint and the index cache: one fingerprint of files + parameters + overrides, the
same on every machine; a corpus whose files did not change is not read again."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import time
from pathlib import Path

import numpy as np
import pytest
from test_data_windows import TAKES, VOCAB, write_take

from beatlite.data import index as index_module
from beatlite.data.fingerprint import SETTLE_S, file_digest, take_fingerprint, takes_fingerprint
from beatlite.data.index import index_folder
from beatlite.data.store import build_store
from beatlite.data.windows import build_windows

HOUR_AGO = time.time() - 3600


@pytest.fixture(autouse=True)
def own_build(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("BEATLITE_BUILD", str(tmp_path / "build"))  # the caches of this test only


def make_corpus(root: Path, *, age: float | None = HOUR_AGO) -> Path:
    """The 4 small takes of test_data_windows; ``age``: their files' mtime (None: now)."""
    root.mkdir(parents=True)
    for stem, n in TAKES.items():
        write_take(root, stem, n)
    if age is not None:
        for p in root.iterdir():
            os.utime(p, (age, age))
    return root


def test_file_digest_is_the_sha256_of_the_bytes_and_sees_a_same_size_rewrite(tmp_path: Path) -> None:
    p = tmp_path / "a.bin"
    p.write_bytes(b"abc" * 1000)
    assert file_digest(p) == hashlib.sha256(b"abc" * 1000).hexdigest()
    p.write_bytes(b"abd" * 1000)  # same size, within the timestamp granularity: not taken from memory
    assert file_digest(p) == hashlib.sha256(b"abd" * 1000).hexdigest()


def test_the_fingerprint_is_of_content_not_of_place_or_time(tmp_path: Path) -> None:
    a = index_folder(make_corpus(tmp_path / "a"), cache=False)
    b_root = tmp_path / "b"
    shutil.copytree(tmp_path / "a", b_root)  # other folder, other mtimes: a fresh clone, another machine
    for p in b_root.iterdir():
        os.utime(p, (HOUR_AGO - 100, HOUR_AGO - 100))
    b = index_folder(b_root, cache=False)
    params = {"fps": 15.0}
    assert takes_fingerprint(a, params) == takes_fingerprint(b, params)
    wa = build_windows(a, split="train", vocab=VOCAB, cache=False)
    wb = build_windows(b, split="train", vocab=VOCAB, cache=False)
    assert wa.fingerprint == wb.fingerprint and len(wa.fingerprint) == 16
    # one byte of one file, a parameter, or a per-take override: another fingerprint
    stem = next(iter(TAKES))
    text = (b_root / f"{stem}.TextGrid").read_text().replace("zebra", "zebre")
    (b_root / f"{stem}.TextGrid").write_text(text)
    assert takes_fingerprint(index_folder(b_root, cache=False), params) != takes_fingerprint(a, params)
    assert takes_fingerprint(a, {"fps": 30.0}) != takes_fingerprint(a, params)
    overridden = index_folder(tmp_path / "a", cache=False, bvh_fps={stem: 15.0})
    assert take_fingerprint(overridden[stem], params) != take_fingerprint(a[stem], params)


def test_both_window_routes_give_one_fingerprint(tmp_path: Path) -> None:
    """The store's windows and build_windows' of the same takes and parameters: one fingerprint
    (so a checkpoint trained on either resumes on the other), another for other windows."""
    index = index_folder(make_corpus(tmp_path / "corpus"))
    store = build_store(index, tmp_path / "store", vocab=VOCAB, workers=0)
    for split in ("train", "val"):
        ref = build_windows(index, split=split, vocab=VOCAB, cache=False)
        assert store.windows(split, vocab=VOCAB).fingerprint == ref.fingerprint, split
    fps = {store.windows("train", vocab=VOCAB, stride=s).fingerprint for s in (10, 5)}
    fps |= {
        store.windows("train", vocab=VOCAB, length=20).fingerprint,
        store.windows("val", vocab=VOCAB).fingerprint,
    }
    assert len(fps) == 4


def test_a_train_take_shorter_than_one_window_is_in_the_fingerprint(tmp_path: Path) -> None:
    """A 30-frame train take gives no 34-frame window but enters the train statistics: the windows it is added
    to are the same windows with other values, so they get another fingerprint (a checkpoint does not resume on
    them), the same on both routes."""
    root = make_corpus(tmp_path / "corpus")
    before = build_store(index_folder(root), tmp_path / "a", vocab=VOCAB, workers=0).windows("train")
    write_take(root, "2_scott_0_66_66", 30)
    index = index_folder(root)
    assert index["2_scott_0_66_66"].usable and index["2_scott_0_66_66"].split == "train"
    after = build_store(index, tmp_path / "b", vocab=VOCAB, workers=0).windows("train")
    assert np.array_equal(after.starts, before.starts) and len(after) == len(before)
    assert not np.allclose(after.normalizers.pose.mean, before.normalizers.pose.mean)
    assert after.fingerprint != before.fingerprint
    assert build_windows(index, split="train", vocab=VOCAB, cache=False).fingerprint == after.fingerprint


def test_the_store_rebuilds_a_take_whose_override_changed(tmp_path: Path) -> None:
    """The store's fingerprint used to omit ``bvh_fps``: the old motion stayed after the override changed."""
    root = make_corpus(tmp_path / "corpus")
    store = build_store(index_folder(root), tmp_path / "store", vocab=VOCAB, workers=0)
    stem = next(iter(TAKES))
    before = {t.stem: (t.folder / "meta.json").stat().st_mtime_ns for t in store.takes}
    time.sleep(0.01)
    overridden = index_folder(root, bvh_fps={stem: 15.0})
    store = build_store(overridden, tmp_path / "store", vocab=VOCAB, workers=0)
    after = {t.stem: (t.folder / "meta.json").stat().st_mtime_ns for t in store.takes}
    assert [s for s in before if before[s] != after[s]] == [stem]
    ref = build_windows(overridden, split="train", vocab=VOCAB, cache=False)
    assert np.array_equal(store.windows("train", stats=ref.normalizers).batch()["pose_raw"], ref["pose_raw"])


def test_a_second_index_of_an_unchanged_corpus_reads_no_file(tmp_path: Path, monkeypatch) -> None:
    root = make_corpus(tmp_path / "corpus")
    calls: list[str] = []
    original = index_module.index_take
    monkeypatch.setattr(
        index_module, "index_take", lambda stem, *a, **k: calls.append(stem) or original(stem, *a, **k)
    )
    first = index_folder(root)
    assert sorted(calls) == sorted(TAKES)
    calls.clear()
    second = index_folder(root)
    assert calls == [] and second.to_rows() == first.to_rows() == index_folder(root, cache=False).to_rows()
    # one file touched: only its take is read again; an override: only that take
    stem, other = list(TAKES)[:2]
    os.utime(root / f"{stem}.wav", (HOUR_AGO + 10, HOUR_AGO + 10))
    calls.clear()
    index_folder(root)
    assert calls == [stem]
    calls.clear()
    index_folder(root, bvh_fps={other: 15.0})
    assert calls == [other]


def test_a_same_size_edit_with_its_modification_time_set_back_is_read_again(tmp_path: Path) -> None:
    """``touch -r`` after an edit of the same size restores (size, mtime): the change time still tells."""
    root = make_corpus(tmp_path / "corpus")
    stem = next(iter(TAKES))
    params = {"fps": 15.0}
    before = takes_fingerprint(index_folder(root), params)  # indexed, cached and hashed
    path = root / f"{stem}.TextGrid"
    text, stat = path.read_text(), path.stat()
    assert "zebra" in text
    for _ in range(300):  # past the file system's timestamp granularity (1 s on some): the change time moves
        time.sleep(0.01)
        path.write_text(text.replace("zebra", "zebre"))
        os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns))
        if path.stat().st_ctime_ns != stat.st_ctime_ns:
            break
    assert (path.stat().st_size, path.stat().st_mtime_ns) == (stat.st_size, stat.st_mtime_ns)
    fresh = takes_fingerprint(index_folder(root, cache=False), params)
    assert takes_fingerprint(index_folder(root), params) == fresh != before


def test_fresh_files_are_never_cached_and_a_broken_cache_is_ignored(tmp_path: Path, monkeypatch) -> None:
    from beatlite.data.index_cache import cache_path

    root = make_corpus(tmp_path / "corpus", age=None)  # written just now: inside SETTLE_S
    calls: list[str] = []
    original = index_module.index_take
    monkeypatch.setattr(
        index_module, "index_take", lambda stem, *a, **k: calls.append(stem) or original(stem, *a, **k)
    )
    index_folder(root)
    index_folder(root)
    assert len(calls) == 2 * len(TAKES), f"files younger than {SETTLE_S} s must be read every time"
    for p in root.iterdir():
        os.utime(p, (HOUR_AGO, HOUR_AGO))
    expected = index_folder(root).to_rows()
    path = cache_path(root, True)
    for garbage in ("{not json", json.dumps({"version": 1, "takes": {s: {"key": 1} for s in TAKES}}), "[]"):
        path.write_text(garbage)
        assert index_folder(root).to_rows() == expected


def test_parallel_indexing_gives_the_same_records(tmp_path: Path) -> None:
    root = make_corpus(tmp_path / "corpus")
    serial = index_folder(root, cache=False)
    parallel = index_folder(root, workers=2)
    assert parallel.to_rows() == serial.to_rows()
    assert [r.files for r in parallel] == [r.files for r in serial]


def test_a_flipped_bit_in_the_index_cache_is_read_again_not_served(tmp_path: Path) -> None:
    """A bit flipped in the index cache that still parses (a digit of a duration, a hex digit of a file's
    sha256, a digit of a stem) was served as the take's record: measured on 3 takes of data_samples/, 86 of 389
    single-bit flips gave other records or take fingerprints. Each entry carries the sha256 of its content now;
    an entry that does not match it is indexed again."""
    import re

    from beatlite.data.index_cache import cache_path

    root = make_corpus(tmp_path / "corpus")
    params = {"fps": 15.0}
    expected = index_folder(root, cache=False)
    index_folder(root)  # indexed and cached
    path = cache_path(root, True)
    good = path.read_bytes()
    for pattern in (rb'"durations": \{"[a-z]+": ', rb'"digests": \{"[a-z]+": "', rb'"record": \{"stem": "'):
        at = re.search(pattern, good).end()  # a digit (or hex digit) follows: flipping bit 0 keeps it one
        path.write_bytes(good[:at] + bytes([good[at] ^ 1]) + good[at + 1 :])
        got = index_folder(root)
        assert got.to_rows() == expected.to_rows(), pattern
        assert takes_fingerprint(got, params) == takes_fingerprint(expected, params), pattern
