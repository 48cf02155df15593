"""Benchmark: a 100-frame GIF of one BEAT skeleton with each backend (target <= 20 s on 2 cores).

Run:  BEATLITE_THREADS=1 .venv/bin/python bench/bench_viz.py [--frames 100] [--out build/bench_viz]

Prints, for matplotlib and pyvista, the time of beatlite's renderer (lines / meshes updated
in place) next to a straightforward alternative measured in the same run (matplotlib: clear
the axes and re-plot every bone each frame; pyvista: clear the scene and add new meshes each
frame), and the ratio. Timings on a shared machine are noisy: run it when the machine is idle.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402

from beatlite.skeleton.beat import beat_skeleton, expand_subset  # noqa: E402
from beatlite.skeleton.kinematics import forward_kinematics  # noqa: E402
from beatlite.viz.animation import animate_skeletons  # noqa: E402
from beatlite.viz.probe import pyvista_status  # noqa: E402
from beatlite.viz.render import render_animation  # noqa: E402

SIZE = (480, 480)


def beat_positions(n_frames: int, fps: float = 15.0, seed: int = 0) -> np.ndarray:
    """(T, 75, 3) cm: smooth synthetic gestures on the spine_neck_141 joints of the BEAT skeleton."""
    rng = np.random.default_rng(seed)
    t = np.arange(n_frames)[:, None] / fps
    angles = 25 * np.sin(2 * np.pi * (rng.random(141) * 0.8 * t + rng.random(141)))
    return forward_kinematics(beat_skeleton(), expand_subset(angles, "spine_neck_141"))


def naive_matplotlib_gif(pos: np.ndarray, parents: np.ndarray, path: Path, fps: float) -> None:
    """The straightforward way: clear the 3D axes and plot every bone again for each frame."""
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation, PillowWriter

    fig = plt.figure(figsize=(SIZE[0] / 100, SIZE[1] / 100), dpi=100)
    ax = fig.add_subplot(projection="3d")
    lo, hi = pos.reshape(-1, 3).min(0), pos.reshape(-1, 3).max(0)

    def update(k: int) -> None:
        ax.cla()
        for j, p in enumerate(parents):
            if p >= 0:
                ax.plot(*pos[k, [p, j]][:, [0, 2, 1]].T, color="C0")
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[2], hi[2])
        ax.set_zlim(lo[1], hi[1])

    FuncAnimation(fig, update, frames=len(pos), interval=1000 / fps).save(
        str(path), writer=PillowWriter(fps=fps)
    )
    plt.close(fig)


def naive_pyvista_gif(pos: np.ndarray, parents: np.ndarray, path: Path, fps: float) -> None:
    """The straightforward way: clear the plotter and add fresh tube/sphere meshes for each frame."""
    import pyvista as pv

    child = np.flatnonzero(parents >= 0)
    cells = np.column_stack([np.full(child.size, 2), parents[child], child]).ravel()
    plotter = pv.Plotter(off_screen=True, window_size=SIZE)
    plotter.open_gif(str(path), fps=fps)
    for k in range(len(pos)):
        plotter.clear()
        plotter.add_mesh(pv.PolyData(pos[k], lines=cells).tube(radius=1.0))
        plotter.add_mesh(pv.PolyData(pos[k]).glyph(geom=pv.Sphere(radius=1.5), scale=False, orient=False))
        plotter.write_frame()
    plotter.close()


def timed(fn, *args, **kwargs) -> float:
    start = time.perf_counter()
    fn(*args, **kwargs)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=100)
    parser.add_argument("--out", type=Path, default=Path("build/bench_viz"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    skel = beat_skeleton()
    pos = beat_positions(args.frames)
    fps = 15.0
    print(f"{args.frames}-frame GIF of the 75-joint BEAT skeleton, {SIZE[0]}x{SIZE[1]} px, {fps:g} fps")

    def beatlite_mpl() -> None:
        anim = animate_skeletons(pos, skel, fps, out_fps=None, width=SIZE[0], dpi=100)  # square: one panel
        anim.save_as(args.out / "mpl.gif")

    t_mpl = timed(beatlite_mpl)
    t_mpl_naive = timed(naive_matplotlib_gif, pos, skel.parents, args.out / "mpl_naive.gif", fps)
    print(f"matplotlib  beatlite (in-place set_data_3d): {t_mpl:6.2f} s   target <= 20 s: {t_mpl <= 20}")
    print(f"matplotlib  naive (cla + re-plot per frame): {t_mpl_naive:6.2f} s   ratio naive/beatlite: "
          f"{t_mpl_naive / t_mpl:.2f}")  # fmt: skip

    status = pyvista_status()
    if not status.ok:
        print(f"pyvista     skipped: {status.reason}")
        return
    t_pv = timed(render_animation, pos, skel, args.out / "pv.gif", fps=fps, out_fps=None, size=SIZE,
                 backend="pyvista")  # fmt: skip
    t_pv_naive = timed(naive_pyvista_gif, pos, skel.parents, args.out / "pv_naive.gif", fps)
    print(f"pyvista     beatlite (meshes updated in place, {status.window_class}): {t_pv:6.2f} s   "
          f"target <= 20 s: {t_pv <= 20}")  # fmt: skip
    print(f"pyvista     naive (clear + add meshes per frame):  {t_pv_naive:6.2f} s   ratio naive/beatlite: "
          f"{t_pv_naive / t_pv:.2f}")  # fmt: skip


if __name__ == "__main__":
    main()
