"""The window store on data_samples/: every key a model uses equals build_windows' batches, every split."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from beatlite.data.index import index_folder
from beatlite.data.store import build_store
from beatlite.data.windows import build_windows

pytestmark = pytest.mark.slow


@pytest.mark.slow
def test_store_equals_build_windows_on_data_samples(data_samples: Path, tmp_path: Path) -> None:
    idx = index_folder(data_samples)
    store = build_store(idx, tmp_path / "store", workers=2)
    train = build_windows(idx, split="train", cache=tmp_path / "cache")
    stats = train.normalizers
    for split in ("train", "val", "test"):
        ref = (
            train
            if split == "train"
            else build_windows(idx, split=split, stats=stats, cache=tmp_path / "cache")
        )
        got = store.windows(split, stats=stats)
        assert len(got) == len(ref) > 0
        a, b = ref.batch(), got.batch()
        # data_samples' audio is 16 kHz 16-bit PCM: stored exactly, so every key is bit-identical
        for key in ref.keys():
            assert a[key].dtype == b[key].dtype and np.array_equal(a[key], b[key]), (split, key)
    # the store's own streamed statistics: equal to the in-memory ones up to float rounding
    norms = store.statistics("train")
    pose_norm, dir_norm = norms.pose, norms.dirvec
    assert np.allclose(pose_norm.mean, train.normalizers.pose.mean, rtol=1e-12, atol=1e-10)
    assert np.allclose(pose_norm.std, train.normalizers.pose.std, rtol=1e-12, atol=0)
    assert np.allclose(dir_norm.mean, train.normalizers.dirvec.mean, rtol=0, atol=1e-12)
    own = store.windows("train").batch()
    assert (
        np.abs(own["pose"] - train["pose"]).max() < 1e-5
        and np.abs(own["dirvec"] - train["dirvec"]).max() < 1e-6
    )
