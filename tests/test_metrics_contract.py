"""The metric contract (beatlite.metrics.testing.check_metric) over every key of METRICS, on data_samples'
test takes: the ground truth scored against itself and a degraded system (noise on its bone directions)."""

from __future__ import annotations

import numpy as np
import pytest

from beatlite.metrics.scoring import METRICS, evaluate
from beatlite.metrics.testing import check_metric

pytest.importorskip("torch")


@pytest.fixture(scope="module")
def values() -> dict[str, tuple[float, float]]:
    """{key: (ground truth vs itself, degraded vs ground truth)} for every metric whose inputs exist."""
    from beatlite.metrics.extractor import load_extractor
    from beatlite.train.testset import directions_takes, load_test_set

    test = load_test_set()
    extractor, euler_extractor, rot6d_extractor = (load_extractor(s) for s in ("dirvec", "pose", "rot6d"))
    truth = test.ground_truth(extractor, euler_extractor, rot6d_extractor)
    rng = np.random.default_rng(0)
    noisy = []
    for d in test.gt_directions:  # 0.3 rad of noise per bone direction, re-normalised
        n = d + 0.3 * rng.standard_normal(d.shape)
        noisy.append(n / np.linalg.norm(n, axis=-1, keepdims=True))
    euler = [e + rng.normal(0, 10.0, e.shape) for e in test.gt_euler]  # 10 degrees of noise
    degraded = directions_takes(
        noisy, test, extractor, euler=euler, euler_extractor=euler_extractor, rot6d_extractor=rot6d_extractor
    )
    gt, bad = evaluate(truth.takes, truth), evaluate(degraded, truth)
    assert not gt.skipped and not bad.skipped, (gt.skipped, bad.skipped)  # every metric is scored here
    return {key: (gt.values()[key], bad.values()[key]) for key in METRICS}


@pytest.mark.parametrize("key", sorted(METRICS))
def test_every_metric_keeps_the_contract(key: str, values: dict[str, tuple[float, float]]) -> None:
    truth_value, degraded_value = values[key]
    check_metric(key, METRICS[key], truth_value=truth_value, degraded_value=degraded_value)


def test_the_contract_catches_a_metric_that_breaks_it() -> None:
    """A metric declaring PCK's bounds but returning 2, and one blind to the degradation: both caught."""
    import dataclasses

    pck = METRICS["PCK"]
    with pytest.raises(AssertionError, match="outside its bounds"):
        check_metric("broken", pck, truth_value=1.0, degraded_value=2.0)
    with pytest.raises(AssertionError, match="not its perfect value"):
        check_metric("broken", pck, truth_value=0.9, degraded_value=0.5)
    with pytest.raises(AssertionError, match="no source"):
        check_metric("broken", dataclasses.replace(pck, source=""), truth_value=1.0, degraded_value=0.5)
