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
def test_shipped_orderings_that_hold_across_seeds():
    """Only orderings that held for every training seed tried (4 seeds of camn_tiny and s2g_tiny, 2 of the
    ablation): FGD CaMN << mean pose (about 5.2-6.5 vs 25), SRGR CaMN > S2G (0.156-0.162 vs 0.139-0.146)
    and SRGR CaMN > CaMN w/o speaker ID (vs 0.132-0.138). FGD CaMN < S2G holds for the shipped pair and
    on 4-seed means but not seed by seed (5.2-6.5 vs 5.4-7.4), so it is not asserted."""
    if _missing() or not (checkpoints_dir() / "camn_tiny_no_speaker.pt").is_file():
        pytest.skip(f"missing checkpoints: {_missing() or ['camn_tiny_no_speaker']}")
    if not data_dir().is_dir():
        pytest.skip("no data folder")
    from beatlite.train.evaluation import evaluate_models

    res = evaluate_models(["mean_pose", "s2g_tiny", "camn_tiny", "camn_tiny_no_speaker"], ground_truth=False)
    stale = [row.source for row in res.rows if row.stale]
    assert not stale, (
        f"{stale} were trained on another version of the data: python -m beatlite.train retrain-all"
    )
    fgd = {row.source: row.metrics["FGD"] for row in res.rows}
    srgr = {row.source: row.metrics["SRGR"] for row in res.rows}
    assert fgd["camn_tiny"] < 0.5 * fgd["mean_pose"], fgd
    assert srgr["camn_tiny"] > srgr["s2g_tiny"], srgr
    assert srgr["camn_tiny"] > srgr["camn_tiny_no_speaker"], srgr
