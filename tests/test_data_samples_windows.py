"""build_windows on data_samples/: the batch contract the CaMN and HA2G models consume."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from beatlite.data.index import index_folder
from beatlite.data.windows import build_windows, window_starts

pytestmark = pytest.mark.slow


def test_windows_contract_on_data_samples(data_samples: Path, tmp_path: Path) -> None:
    from beatlite.io import load_take

    idx = index_folder(data_samples)
    train = build_windows(idx, split="train", cache=tmp_path)
    test = build_windows(idx, split="test", whole_takes=True, cache=tmp_path)
    # one whole-take item per usable test take, full length; window counts follow from those lengths
    test_stems = [r.stem for r in idx.where(split="test", usable=True)]
    assert test["take"].tolist() == test_stems
    lengths = [len(p) for p in test["pose"]]
    assert lengths == [load_take(idx[s].path("motion")).n_frames for s in test_stems]
    windows = build_windows(idx, split="test", cache=tmp_path, stats=train.normalizers)
    assert len(windows) == sum(len(window_starts(n, 34, 10)) for n in lengths)
    shapes = {
        "pose": (34, 141),
        "pose_raw": (34, 141),
        "dirvec": (34, 126),
        "audio": (36266,),
        "mel": (70, 128),
        "face": (34, 51),
        "word": (34,),
        "emotion": (34,),
        "semantic": (34,),
        "speaker": (),
    }
    for key, shape in shapes.items():
        assert train[key].shape == (len(train), *shape), key
        assert np.all(np.isfinite(train[key])), key
    # z-scored with train statistics: over the train windows mean ~0 and std ~1 per dim
    flat = train["pose"].reshape(-1, 141)
    moving = train["pose_raw"].reshape(-1, 141).std(axis=0) > 1e-3
    assert np.abs(flat.mean(axis=0)).max() < 0.3
    assert np.allclose(flat.std(axis=0)[moving], 1.0, atol=0.3)
    assert np.all(flat[:, ~moving] == 0)  # constant channels (std replaced by 1) are only centred
    assert set(np.unique(train["speaker"])) == {1, 3, 5, 7}  # speaker ids 2, 4, 6, 8 minus 1
    assert train["word"].max() < train.params["vocab_size"] and (train["word"] > 3).mean() > 0.3
    assert set(np.unique(train["emotion"])) <= set(range(8))
    assert 0.0 <= train["semantic"].min() and train["semantic"].max() <= 1.0
    # whole-take items cut to the same frames as the windows
    item = test.item(0)
    first = windows.batch(np.flatnonzero(windows["take"] == test_stems[0])[:1])
    assert np.allclose(item["pose"][:34], first["pose"][0], atol=1e-5)
    assert np.array_equal(item["audio"][:36266], first["audio"][0])
