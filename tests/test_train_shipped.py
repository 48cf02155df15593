"""The shipped checkpoints: they load, fit the size budget, and keep the robust FGD ordering."""

from __future__ import annotations

import pytest

torch = pytest.importorskip("torch")

from beatlite.paths import checkpoints_dir, data_dir  # noqa: E402

NEEDED = ("camn_tiny", "mean_pose", "s2g_tiny", "fgd_dirvec")


def _missing() -> list[str]:
    return [name for name in NEEDED if not (checkpoints_dir() / f"{name}.pt").is_file()]


def test_checkpoints_total_at_most_20_mb():
    files = list(checkpoints_dir().glob("*.pt"))
    if not files:
        pytest.skip("no shipped checkpoints")
    total = sum(f.stat().st_size for f in files)
    assert total <= 20 * 1024 * 1024, f"checkpoints/ holds {total / 2**20:.1f} MiB > 20 MiB"


def test_shipped_checkpoints_are_float16_inference_copies():
    from beatlite.train.__main__ import CHECKPOINTS
    from beatlite.train.checkpoint import load_checkpoint

    found = [n for n in CHECKPOINTS if (checkpoints_dir() / f"{n}.pt").is_file()]
    if not found:
        pytest.skip("no shipped checkpoints of beatlite.train")
    for name in found:
        data = load_checkpoint(checkpoints_dir() / f"{name}.pt")
        assert "optimizer" not in data and "rng" not in data, name
        floats = [v for v in data["state"].values() if torch.is_tensor(v) and v.is_floating_point()]
        assert all(v.dtype == torch.float16 for v in floats), name
        assert data["model"]["name"] == CHECKPOINTS[name][0], name


@pytest.mark.slow
def test_camn_beats_mean_pose_and_s2g_on_fgd():
    if _missing():
        pytest.skip(f"missing checkpoints: {_missing()}")
    if not data_dir().is_dir():
        pytest.skip("no data folder")
    from beatlite.train.evaluation import evaluate_models

    res = evaluate_models(["mean_pose", "s2g_tiny", "camn_tiny"], ground_truth=False)
    fgd = {row.source: row.metrics["FGD"] for row in res.rows}
    assert fgd["camn_tiny"] < fgd["mean_pose"], fgd
    assert fgd["camn_tiny"] < fgd["s2g_tiny"], fgd
