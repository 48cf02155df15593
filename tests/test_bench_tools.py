"""bench/repeat_fit.py's comparison and bench/batch_scaling.py's summary (the scripts themselves train: run, not here)."""

from __future__ import annotations

import importlib.util
import statistics
import sys
from pathlib import Path

import pytest

torch = pytest.importorskip("torch")

ROOT = Path(__file__).resolve().parents[1]


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, ROOT / "bench" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def test_repeat_fit_compares_every_tensor_bit_for_bit():
    compare = _load("repeat_fit").compare
    a = {"state": {"w": torch.tensor([1.0, 2.0]), "n": torch.tensor(3)}, "history": [{"train": {"rec": 0.5}}]}
    assert compare(a, a) == {
        "tensors": 2,
        "tensors_differing": 0,
        "largest_difference": 0.0,
        "histories_equal": True,
    }
    b = {
        "state": {"w": torch.tensor([1.0, 2.0 + 2**-22]), "n": torch.tensor(3)},
        "history": [{"train": {"rec": 0.6}}],
    }
    got = compare(a, b)
    assert (
        got["tensors_differing"] == 1 and got["largest_difference"] == 2**-22 and not got["histories_equal"]
    )


def test_batch_scaling_summarises_each_batch_and_rule_over_the_seeds():
    summary = _load("batch_scaling").summary
    rows = [{"batch": b, "rule": r, "seed": s, **{m: float(v) for m in ("FGD", "SRGR")}}
            for b, r, vals in ((32, "linear", (3, 4, 5)), (64, "sqrt", (6, 8, 10))) for s, v in zip((1, 2, 3), vals)]  # fmt: skip
    got = summary(rows)
    assert list(got) == ["32 linear", "64 sqrt"]
    assert got["32 linear"]["FGD"] == [4.0, 1.0] and got["64 sqrt"]["SRGR"] == [
        8.0,
        statistics.stdev([6, 8, 10]),
    ]
    assert summary(rows[:1]) == {"32 linear": {"FGD": [3.0, None], "SRGR": [3.0, None]}}  # one seed: no sd
