"""Forward-kinematics speed: beatlite vs a straightforward per-joint implementation.

Run: ``BEATLITE_THREADS=1 .venv/bin/python bench/bench_skeleton.py``. Prints wall-clock times
(best of several runs; shared machines are noisy) for 7200 frames x 75 joints (one minute of
BEAT at 120 fps) and the speed-up over the naive version measured in the same run. Target:
well under 100 ms for ``forward_kinematics``.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.spatial.transform import Rotation

from beatlite.skeleton import beat_skeleton, forward_kinematics, global_transforms


def naive_fk(skel, channels: np.ndarray) -> np.ndarray:
    """Per joint: scipy Euler -> matrices, then (T, 3, 3) matmuls (vectorised over frames only)."""
    n_frames = channels.shape[0]
    rot = np.zeros((n_frames, skel.n_joints, 3, 3))
    pos = np.zeros((n_frames, skel.n_joints, 3))
    for j in range(skel.n_joints):
        cols = skel.rotation_channel_indices(j)
        local = Rotation.from_euler(skel.rotation_order(j), channels[:, cols], degrees=True).as_matrix()
        trans = skel.offsets[j] + (channels[:, skel.position_channel_indices(j)] if j == 0 else 0.0)
        p = skel.parents[j]
        if p < 0:
            rot[:, j], pos[:, j] = local, trans
        else:
            rot[:, j] = rot[:, p] @ local
            pos[:, j] = pos[:, p] + np.einsum("tij,j->ti", rot[:, p], trans)
    return pos


def best_of(fn, repeat: int = 7) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    skel = beat_skeleton()
    rng = np.random.default_rng(0)
    channels = rng.uniform(-180, 180, size=(7200, skel.n_channels))
    assert np.allclose(forward_kinematics(skel, channels), naive_fk(skel, channels))
    t_fast = best_of(lambda: forward_kinematics(skel, channels))
    t_glob = best_of(lambda: global_transforms(skel, channels))
    t_naive = best_of(lambda: naive_fk(skel, channels), repeat=3)
    print("7200 frames x 75 joints (best of runs, wall clock)")
    print(f"  forward_kinematics : {t_fast * 1e3:7.1f} ms")
    print(f"  global_transforms  : {t_glob * 1e3:7.1f} ms  (also returns (T, J, 3, 3) rotations)")
    print(f"  naive per-joint    : {t_naive * 1e3:7.1f} ms")
    print(f"  speed-up           : {t_naive / t_fast:7.1f} x")


if __name__ == "__main__":
    main()
