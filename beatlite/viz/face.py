"""ARKit blendshape plots: a heat map over time, or bars of one frame.

BEAT's faces are 51 ARKit blendshape weights in [0, 1] at 60 fps (ARKit's 52
without ``tongueOut``). The animation panel of the same data is the
``face=`` option of :func:`beatlite.viz.animation.animate_skeletons`.

Taught in notebooks/08_visualisation_3d.ipynb, section 5 (the face in sync with the voice); first used in notebooks/01_beat_formats.ipynb, section 8.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from beatlite.viz._inputs import check_fps
from beatlite.viz.style import figure_style

KINDS = ("heatmap", "bars")


def plot_blendshapes(
    weights: Any,
    names: Sequence[str] | None = None,
    fps: float = 60.0,
    *,
    kind: str = "heatmap",
    frame: int | None = None,
    ax: Any = None,
    figsize: tuple[float, float] = (9.0, 5.0),
) -> Any:
    """Plot blendshape weights as a heat map (blendshape x time) or as bars of one frame.

    Parameters
    ----------
    weights : (T, K) float, usually K = 51, values in [0, 1]
        Blendshape weights per frame.
    names : sequence of str, optional
        K blendshape names (row / bar labels); indices otherwise.
    fps : float
        Frame rate of ``weights`` (BEAT facial JSON: 60), frames per second.
    kind : {"heatmap", "bars"}
        Heat map over the whole clip, or bars of ``frame``.
    frame : int, optional
        For ``"heatmap"``, draw a cursor at this frame; for ``"bars"``, the frame
        to show (default 0).
    ax : matplotlib Axes, optional
        Draw into it; a new figure otherwise.
    figsize : (float, float)
        Size of a new figure, inches.

    Returns
    -------
    matplotlib.figure.Figure
    """
    w = np.asarray(weights, dtype=np.float64)
    if w.ndim != 2 or w.shape[0] == 0 or w.shape[1] == 0:
        raise ValueError(f"weights must be a (T, K) array with T, K >= 1, got shape {w.shape}")
    if not np.all(np.isfinite(w)):
        raise ValueError(f"weights contains NaN or infinite values (shape {w.shape})")
    n_frames, k = w.shape
    if names is not None and len(names) != k:
        raise ValueError(f"names: {len(names)} names for {k} blendshapes (weights shape {w.shape})")
    fps = check_fps(fps)
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    if frame is not None and not -n_frames <= int(frame) < n_frames:
        raise ValueError(f"frame={frame} is out of range for {n_frames} frames")
    labels = list(names) if names is not None else [str(i) for i in range(k)]
    with figure_style():
        if ax is None:
            import matplotlib.pyplot as plt

            fig, ax = plt.subplots(figsize=figsize)
        else:
            fig = ax.figure
        if kind == "heatmap":
            im = ax.imshow(
                w.T,
                aspect="auto",
                origin="lower",
                extent=(0.0, n_frames / fps, -0.5, k - 0.5),
                vmin=0.0,
                vmax=max(1.0, float(w.max())),
                cmap="magma",
                interpolation="nearest",
            )
            ax.set_yticks(np.arange(k), labels, fontsize=5 if k > 20 else 8)
            ax.set_xlabel("time (s)")
            ax.grid(False)
            fig.colorbar(im, ax=ax, label="weight", fraction=0.03)
            if frame is not None:
                ax.axvline((int(frame) % n_frames) / fps, color="w", lw=1.2)
        else:
            f = 0 if frame is None else int(frame) % n_frames
            ax.bar(np.arange(k), w[f], color="#2e8b57")
            ax.set_xticks(np.arange(k), labels, rotation=90, fontsize=5 if k > 20 else 8)
            ax.set_ylim(0, max(1.0, float(w.max())))
            ax.set_ylabel("weight")
            ax.set_title(f"blendshapes at t = {f / fps:.2f} s")
    return fig
