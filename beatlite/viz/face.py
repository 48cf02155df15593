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
#: Inches per heat-map row: 51 rows at 8-pt labels need 0.17 in each to stay readable.
ROW_INCHES = 0.17


def most_active(weights: np.ndarray, top: int) -> np.ndarray:
    """Indices of the ``top`` blendshapes with the largest standard deviation over time, in ascending order.

    Parameters
    ----------
    weights : (T, K) float
        Blendshape weights.
    top : int
        How many to keep (all K when ``top >= K``).

    Returns
    -------
    (min(top, K),) int64

    Examples
    --------
    >>> w = np.array([[0.0, 0.5, 0.0], [0.0, 0.5, 1.0], [0.0, 0.5, 0.0]])
    >>> most_active(w, 1).tolist()          # only the third one moves
    [2]
    """
    if isinstance(top, bool) or not isinstance(top, int | np.integer) or top < 1:
        raise ValueError(f"top must be a positive integer, got {top!r}")
    order = np.argsort(-np.asarray(weights).std(axis=0), kind="stable")
    return np.sort(order[: int(top)]).astype(np.int64)


def _check_weights(weights: Any, names: Sequence[str] | None, kind: str, frame: int | None) -> np.ndarray:
    w = np.asarray(weights, dtype=np.float64)
    if w.ndim != 2 or w.shape[0] == 0 or w.shape[1] == 0:
        raise ValueError(f"weights must be a (T, K) array with T, K >= 1, got shape {w.shape}")
    if not np.all(np.isfinite(w)):
        raise ValueError(f"weights contains NaN or infinite values (shape {w.shape})")
    if names is not None and len(names) != w.shape[1]:
        raise ValueError(f"names: {len(names)} names for {w.shape[1]} blendshapes (weights shape {w.shape})")
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    if frame is not None and not -w.shape[0] <= int(frame) < w.shape[0]:
        raise ValueError(f"frame={frame} is out of range for {w.shape[0]} frames")
    return w


def _heatmap(ax: Any, w: np.ndarray, labels: list[str], fps: float, frame: int | None) -> None:
    """Rows = blendshapes (first name at the top), columns = time in seconds, colour bar in weight units."""
    n_frames, k = w.shape
    im = ax.imshow(w.T, aspect="auto", origin="upper", extent=(0.0, n_frames / fps, k - 0.5, -0.5),
                   vmin=0.0, vmax=max(1.0, float(w.max())), cmap="magma", interpolation="nearest")  # fmt: skip
    ax.set_yticks(np.arange(k), labels, fontsize=8)
    ax.set_ylabel("blendshape")
    ax.set_xlabel("time (s)")
    ax.grid(False)
    ax.figure.colorbar(im, ax=ax, label="weight (0-1)", fraction=0.03, pad=0.02)
    if frame is not None:
        ax.axvline((int(frame) % n_frames) / fps, color="w", lw=1.2)


def _bars(ax: Any, w: np.ndarray, labels: list[str], fps: float, frame: int | None) -> None:
    """Bars of one frame, blendshape names written vertically under them."""
    f = 0 if frame is None else int(frame) % len(w)
    ax.bar(np.arange(w.shape[1]), w[f], color="#2e8b57")
    ax.set_xticks(np.arange(w.shape[1]), labels, rotation=90, fontsize=8)
    ax.set_ylim(0, max(1.0, float(w.max())))
    ax.set_ylabel("weight (0-1)")
    ax.set_title(f"blendshapes at t = {f / fps:.2f} s")


def plot_blendshapes(
    weights: Any,
    names: Sequence[str] | None = None,
    fps: float = 60.0,
    *,
    kind: str = "heatmap",
    frame: int | None = None,
    top: int | None = None,
    ax: Any = None,
    figsize: tuple[float, float] | None = None,
) -> Any:
    """Plot blendshape weights as a heat map (blendshape x time) or as bars of one frame, labelled by name.

    Parameters
    ----------
    weights : (T, K) float, usually K = 51, values in [0, 1]
        Blendshape weights per frame.
    names : sequence of str, optional
        K blendshape names (row / bar labels); ``"blendshape k"`` otherwise.
    fps : float
        Frame rate of ``weights`` (BEAT facial JSON: 60), frames per second.
    kind : {"heatmap", "bars"}
        Heat map over the whole clip, or bars of ``frame``.
    frame : int, optional
        For ``"heatmap"``, draw a cursor at this frame; for ``"bars"``, the frame
        to show (default 0).
    top : int, optional
        Keep only the ``top`` blendshapes that vary most (:func:`most_active`), in
        their original order; default all K.
    ax : matplotlib Axes, optional
        Draw into it; a new figure otherwise.
    figsize : (float, float), optional
        Size of a new figure, inches; default 9.6 wide and tall enough for 8-pt
        labels on every row (51 rows: 9.7 inches).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        ``weights`` not (T, K) finite, ``names`` not K long, an unknown ``kind`` or ``frame`` out of range.

    Examples
    --------
    Two seconds at 60 fps of three blendshapes: the jaw opens linearly (``frame / 120``), the smile steps to
    0.3 at one second, the blink stays at 0. Bars of frame 60 (t = 1 s) read those weights:

    >>> import matplotlib.pyplot as plt
    >>> names = ["eyeBlinkLeft", "jawOpen", "mouthSmileLeft"]
    >>> w = np.zeros((120, 3))
    >>> w[:, 1] = np.arange(120) / 120
    >>> w[60:, 2] = 0.3
    >>> fig = plot_blendshapes(w, names, fps=60, kind="bars", frame=60)
    >>> [float(bar.get_height()) for bar in fig.axes[0].patches], fig.axes[0].get_title()
    ([0.0, 0.5, 0.3], 'blendshapes at t = 1.00 s')
    >>> plt.close(fig)

    The heat map of the two that vary (``top=2``) spans the clip's 2 seconds:

    >>> fig = plot_blendshapes(w, names, fps=60, top=2)
    >>> [t.get_text() for t in fig.axes[0].get_yticklabels()], [float(x) for x in fig.axes[0].get_xlim()]
    (['jawOpen', 'mouthSmileLeft'], [0.0, 2.0])
    >>> plt.close(fig)
    """
    w = _check_weights(weights, names, kind, frame)
    fps = check_fps(fps)
    labels = list(names) if names is not None else [f"blendshape {j}" for j in range(w.shape[1])]
    if top is not None:
        rows = most_active(w, top)
        w, labels = w[:, rows], [labels[j] for j in rows]
    if figsize is None:
        figsize = (9.6, 1.0 + ROW_INCHES * w.shape[1]) if kind == "heatmap" else (9.6, 4.0)
    with figure_style():
        if ax is None:
            import matplotlib.pyplot as plt

            fig, ax = plt.subplots(figsize=figsize, layout="constrained")
        (_heatmap if kind == "heatmap" else _bars)(ax, w, labels, fps, frame)
    return ax.figure


def plot_blendshape_curves(
    weights: Any,
    names: Sequence[str],
    fps: float = 60.0,
    *,
    top: int = 4,
    ax: Any = None,
    figsize: tuple[float, float] = (9.6, 2.8),
) -> Any:
    """The ``top`` most active blendshapes as curves over time (none that sits at 0), legend right of the data.

    Parameters
    ----------
    weights : (T, K) float, values in [0, 1]
        Blendshape weights.
    names : sequence of str
        The K names (legend).
    fps : float
        Frame rate of ``weights``, frames per second.
    top : int
        How many curves: the blendshapes with the largest standard deviation (:func:`most_active`).
    ax : matplotlib Axes, optional
        Draw into it; a new figure otherwise.
    figsize : (float, float)
        Size of a new figure, inches.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    Of three blendshapes, the blink never moves, so the two curves drawn are the jaw and the smile:

    >>> import matplotlib.pyplot as plt
    >>> w = np.zeros((120, 3))
    >>> w[:, 1] = np.arange(120) / 120
    >>> w[60:, 2] = 0.3
    >>> fig = plot_blendshape_curves(w, ["eyeBlinkLeft", "jawOpen", "mouthSmileLeft"], fps=60, top=2)
    >>> fig.axes[0].get_legend_handles_labels()[1], fig.axes[0].get_ylabel()
    (['jawOpen', 'mouthSmileLeft'], 'weight (0-1)')
    >>> plt.close(fig)
    """
    from beatlite.viz.charts import plot_signals

    w = _check_weights(weights, names, "heatmap", None)
    rows = most_active(w, top)
    times = np.arange(len(w)) / check_fps(fps)
    return plot_signals(times, {names[j]: w[:, j] for j in rows}, "weight (0-1)", ax=ax, figsize=figsize)
