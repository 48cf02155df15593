"""The window store on data_samples/: every key of every split equals the windows cut from each take's features
(16-bit 16 kHz audio: stored exactly), and its statistics ``Normalizer.fit`` over the train frames."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from beatlite.data.index import index_folder
from beatlite.data.normalize import Normalizer
from beatlite.data.store import build_store
from beatlite.data.windows import audio_start, build_windows, sliding_windows, take_features, window_starts

pytestmark = pytest.mark.slow


def _cut(records: list, stats, vocab) -> dict[str, np.ndarray]:  # noqa: ANN001
    """The windows of ``records`` cut from their features by the teaching functions."""
    feats = [take_features(r, vocab=vocab, mel=False) for r in records]
    pose_raw = sliding_windows([f.pose_raw for f in feats])
    audio = [
        f.audio[audio_start(int(s), 15, 16000) :][:36266] for f in feats for s in window_starts(f.n_frames)
    ]
    return {
        "pose": stats.pose.transform(pose_raw).astype(np.float32),
        "dirvec": stats.dirvec.transform(sliding_windows([f.dirs for f in feats])).astype(np.float32),
        "audio": np.stack(audio),
        **{
            k: sliding_windows([getattr(f, k) for f in feats])
            for k in ("face", "word", "emotion", "semantic")
        },
    }


@pytest.mark.slow
def test_store_equals_the_takes_features_on_data_samples(data_samples: Path, tmp_path: Path) -> None:
    idx = index_folder(data_samples)
    store = build_store(idx, tmp_path / "store", workers=2)
    train_records = [r for r in idx if r.usable and r.split == "train"]
    frames = [take_features(r, mel=False) for r in train_records]
    fitted = Normalizer.fit(np.concatenate([f.pose_raw for f in frames]))
    norms = store.statistics("train")
    assert np.allclose(norms.pose.mean, fitted.mean, rtol=1e-12, atol=1e-10)
    assert np.allclose(norms.pose.std, fitted.std, rtol=1e-12, atol=0)
    dir_mean = np.concatenate([f.dirs for f in frames]).mean(0)
    assert np.allclose(norms.dirvec.mean, dir_mean, rtol=0, atol=1e-12)
    for split in ("train", "val", "test"):
        records = [r for r in idx if r.usable and r.split == split]
        got = store.windows(split, stats=norms).batch()
        want = _cut(records, norms, store.vocab)
        for key, value in want.items():  # audio included: 16-bit PCM at 16 kHz is stored exactly
            assert np.array_equal(got[key], value.astype(got[key].dtype)), (split, key)
    held = build_windows(idx, split="test", cache=tmp_path / "cache")  # the same windows, held in memory
    assert all(np.array_equal(held[k], v) for k, v in store.windows("test").batch().items())
