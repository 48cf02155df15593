"""Multi-process training with torch's own engine: ``torchrun`` with the gloo backend on the CPU."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

torch = pytest.importorskip("torch")

SCRIPT = Path(__file__).with_name("ddp_fit.py")


def _env() -> dict[str, str]:
    root = str(Path(__file__).resolve().parents[1])
    env = {
        k: v for k, v in os.environ.items() if k not in ("WORLD_SIZE", "RANK", "LOCAL_RANK", "MASTER_ADDR")
    }
    env["PYTHONPATH"] = root + os.pathsep + env.get("PYTHONPATH", "")
    env["BEATLITE_THREADS"] = "1"
    return env


@pytest.mark.slow
def test_two_processes_take_the_same_steps_as_one_with_two_micro_batches(tmp_path):
    """2-process training (a global batch of 16 split over the processes, gradients summed) ends with the
    same weights as 1 process splitting each batch of 16 into 2 micro-batches, within float rounding."""
    torchrun = shutil.which("torchrun", path=str(Path(sys.executable).parent)) or shutil.which("torchrun")
    if torchrun is None:
        pytest.skip("torchrun is not installed")
    one, two = tmp_path / "one.pt", tmp_path / "two.pt"
    subprocess.run([sys.executable, str(SCRIPT), str(one), "2"], check=True, env=_env(), timeout=900)
    cmd = [torchrun, "--standalone", "--nproc_per_node=2", str(SCRIPT), str(two), "1"]
    subprocess.run(cmd, check=True, env=_env(), timeout=900)
    a, b = torch.load(one, weights_only=False), torch.load(two, weights_only=False)
    assert a["params"].keys() == b["params"].keys()
    worst = max(float((a["params"][k] - b["params"][k]).abs().max()) for k in a["params"])
    moved = max(float((a["params"][k] - a["start"][k]).abs().max()) for k in a["params"])
    # float32 sums in another order (all-reduce vs accumulation): differences of rounding size, far
    # below what the epoch changed
    assert worst < 1e-4 and moved > 1e-3, (worst, moved)
    print(f"largest weight change {moved:.3g}, largest difference 1 vs 2 processes {worst:.3g}")
    la, lb = a["history"][0]["train"], b["history"][0]["train"]
    assert la.keys() == lb.keys() and all(abs(la[k] - lb[k]) <= 1e-4 * (1 + abs(la[k])) for k in la)
