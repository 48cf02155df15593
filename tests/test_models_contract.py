"""The model contract suite (:func:`beatlite.models.testing.check_model`) over every registered model."""

from __future__ import annotations

from pathlib import Path

import pytest

from beatlite.models import MODELS
from beatlite.models.testing import CHECKS, STORE_CHECKS, model_case


@pytest.mark.parametrize("check", sorted(CHECKS))
@pytest.mark.parametrize("name", sorted(MODELS))
def test_model_contract(name: str, check: str, tmp_path: Path) -> None:
    CHECKS[check](model_case(name, tmp_path))


@pytest.mark.parametrize("check", sorted(STORE_CHECKS))
@pytest.mark.parametrize("name", sorted(MODELS))
def test_model_trains_from_a_store(name: str, check: str, small_store_windows: tuple, tmp_path: Path) -> None:
    train, reference = small_store_windows
    STORE_CHECKS[check](model_case(name, tmp_path, train=train, reference=reference))


def test_window_helpers_read_a_store_as_the_windows_in_memory(small_store_windows: tuple) -> None:
    """``prepare``'s readers: a store view in several chunks gives the in-memory arrays exactly."""
    import numpy as np

    from beatlite.models.base import window_chunks, window_count, window_rows

    train, reference = small_store_windows
    n = window_count(reference, "dirvec")
    assert window_count(train, "dirvec") == n == len(reference) > 5
    idx = [5, 0, 5, n - 1]
    assert np.array_equal(window_rows(train, "dirvec", idx), reference["dirvec"][idx])
    chunks = list(window_chunks(train, "dirvec", max_bytes=3 * 34 * 126 * 4))  # 3 windows per chunk
    assert len(chunks) == -(-n // 3) and np.array_equal(np.concatenate(chunks), reference["dirvec"])
    assert len(list(window_chunks(reference, "dirvec"))) == 1


def test_a_store_view_without_a_key_the_losses_read_is_refused_by_name(small_store_windows: tuple) -> None:
    """CaMN's loss reads ``semantic``, which its forward pass (``keys_for``) does not: ``batch_keys`` has it,
    and a view of ``keys_for`` alone is refused before any step, naming the key."""
    from beatlite.models import build_model
    from beatlite.models.camn import CaMN
    from beatlite.train import TrainConfig, fit

    train, _ = small_store_windows
    model = build_model("camn", preset="tiny", vocab_size=len(train.vocab))
    assert "semantic" in CaMN.batch_keys(model.config) and "semantic" not in CaMN.keys_for(model.config)
    view = train.store.windows("train", keys=CaMN.keys_for(model.config), stats=train.normalizers)
    with pytest.raises(KeyError, match="semantic"):
        fit(model, view, TrainConfig(epochs=1, batch_size=4, progress=False))
