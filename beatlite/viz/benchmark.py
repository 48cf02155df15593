"""Figures of the model notebooks: key frames on one scale, training curves, the benchmark, Table 6, ablations.

Each function draws one figure from results the library computes (a training history, a
:class:`~beatlite.train.evaluation.ModelResults`, per-class accuracies), in the beatlite style
(:func:`beatlite.viz.style.figure_style`), optionally saves it (``out=`` stem, PNG and SVG) and
returns the matplotlib Figure.

==============================  ==================================================================
:func:`plot_keyframes`           rows of systems x columns of frames, every skeleton on one scale
:func:`plot_training_history`    loss / validation-score curves of :func:`beatlite.train.fit`
:func:`plot_benchmark`           FGD bars (a far-off row drawn cut, its value written) + FGD vs BC
:func:`plot_table6_rows`         BEAT Table 6: per-emotion accuracy, one named bar per row
:func:`plot_effects`             an ablation's change vs the full model: paper vs ours (± error)
:func:`plot_ha2g_levels`         the six levels of HA2G's body hierarchy on the rest pose
==============================  ==================================================================

Taught in notebooks/05_camn.ipynb (sections 4, 5, 7), notebooks/06_ha2g.ipynb (sections 2, 7, 8),
notebooks/07_benchmark.ipynb (sections 4, 5) and notebooks/08_visualisation_3d.ipynb (section 2).
"""

from __future__ import annotations

import itertools
import math
import os
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from beatlite.viz._inputs import to_plot_coords
from beatlite.viz.style import GROUP_COLOURS, SYSTEM_COLOURS, figure_style, save_figure

__all__ = [
    "plot_keyframes",
    "plot_training_history",
    "plot_benchmark",
    "plot_table6_rows",
    "plot_effects",
    "plot_ha2g_levels",
    "ted_colour_names",
]

Out = str | os.PathLike[str] | None


def _finish(fig: Any, out: Out) -> Any:
    if out is not None:
        save_figure(fig, out)
    return fig


def ted_colour_names() -> list[str]:
    """(43,) joint names that give TED-43 joints the colours of their BEAT joints (face points: head).

    Examples
    --------
    >>> names = ted_colour_names()
    >>> len(names), names[0]
    (43, 'Spine3')
    """
    from beatlite.skeleton.ted import TED43_FROM_BEAT, TED43_JOINTS

    return [beat or f"Head_{ted}" for beat, ted in zip(TED43_FROM_BEAT, TED43_JOINTS, strict=True)]


def _skeleton_of(skeleton: Any) -> tuple[Any, list[str] | None]:
    """(skeleton or parents, names for the colours): TED-43 parents arrays get their BEAT colours."""
    parents = np.asarray(skeleton) if not hasattr(skeleton, "names") else None
    if parents is not None and parents.shape == (43,):
        return parents, ted_colour_names()
    return skeleton, None


def plot_keyframes(
    systems: Mapping[str, tuple[np.ndarray, Any]],
    frames: Sequence[int],
    fps: float,
    *,
    view: str = "front",
    panel_size: float = 2.0,
    out: Out = None,
) -> Any:
    """Key frames of several systems (rows) at the same frames (columns), all on one scale.

    Every panel spans the same centimetres on each axis (the largest extent over all systems and
    frames), centred on its own skeleton, without a floor, and is as wide as that extent needs (a
    standing body gets narrow, tall panels); joints keep one colour per group (body,
    hands, head) whatever the skeleton (BEAT or TED-43), so rows compare like with like.

    Parameters
    ----------
    systems : mapping label -> (positions, skeleton)
        ``positions`` (T, J, 3) cm, Y up; ``skeleton`` a Skeleton or a (J,) parents array
        (a TED-43 parents array is coloured like the BEAT joints it copies).
    frames : sequence of int
        Frames to draw (columns); the column title is the time ``frame / fps`` in seconds.
    fps : float
    view : str
        Camera, as :func:`beatlite.viz.plot_frame` (``"front"``: the character faces us).
    panel_size : float
        Panel height, inches.
    out : str or Path, optional
        Save as ``<out>.png`` / ``.svg``.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    from beatlite.viz.plot3d import plot_frame

    frames = [int(f) for f in frames]
    if not systems or not frames:
        raise ValueError("plot_keyframes needs at least one system and one frame")
    shown = {k: np.asarray(p, np.float64)[frames] for k, (p, _) in systems.items()}
    pts = {k: to_plot_coords(v.reshape(-1, 3)) for k, v in shown.items()}
    # one half-extent per plot axis (x, depth, up), the largest over all systems: one scale for all
    half = np.max([(p.max(0) - p.min(0)) / 2 for p in pts.values()], axis=0) + 5.0
    width = panel_size * float(np.clip(half[0] / half[2], 0.6, 2.0))
    with figure_style():
        fig = plt.figure(figsize=(width * len(frames) + 0.4, panel_size * len(systems)))
        for row, (label, (positions, skeleton)) in enumerate(systems.items()):
            skel, names = _skeleton_of(skeleton)
            centre = (pts[label].max(0) + pts[label].min(0)) / 2
            for col, frame in enumerate(frames):
                ax = fig.add_subplot(len(systems), len(frames), row * len(frames) + col + 1, projection="3d")
                plot_frame(positions, skel, frame, ax=ax, view=view, floor=False, names=names)
                for setter, c, h in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre, half, strict=True):
                    setter(c - h, c + h)
                ax.set_box_aspect(tuple(half), zoom=1.15)
                ax.set_title(f"{frame / fps:.1f} s" if row == 0 else "", fontsize=9)
            fig.text(0.005, 1 - (row + 0.5) / len(systems), label, rotation=90, va="center", fontsize=10)
        fig.subplots_adjust(left=0.4 / fig.get_figwidth(), right=1, bottom=0, top=0.94, wspace=0, hspace=0)
    return _finish(fig, out)


def _series(history: Sequence[Mapping[str, Any]], key: str, split: str | None) -> np.ndarray:
    if split is None:
        return np.array([h.get(key, math.nan) for h in history], float)
    return np.array([h.get(split, {}).get(key, math.nan) for h in history], float)


def plot_training_history(
    history: Sequence[Mapping[str, Any]],
    panels: Sequence[tuple[str, str]],
    *,
    selected: Mapping[str, Any] | None = None,
    first_adversarial: int | None = None,
    chance: Mapping[str, tuple[float, str]] | None = None,
    title: str | None = None,
    out: Out = None,
) -> Any:
    """Training curves of :func:`beatlite.train.fit`: one panel per loss, train and validation.

    A panel whose values are missing (no ``val_score`` without a validation scorer) is left out;
    one whose values are all zero (an adversarial term that starts after the last epoch) says so
    in words instead of showing an empty box.

    Parameters
    ----------
    history : list of dict
        ``fit(...).history`` or a checkpoint's ``"history"``: per epoch ``{"epoch", "train": {loss:
        value}, "val": {...}, "val_score"?}``.
    panels : sequence of (key, y label)
        A loss name of ``history[i]["train"]`` or ``"val_score"`` (the validation FGD).
    selected : dict, optional
        ``{"epoch", "score"}`` of the exported epoch: a star on the ``val_score`` panel.
    first_adversarial : int, optional
        First epoch with the adversarial term: a dotted line on every panel.
    chance : dict key -> (value, label), optional
        A horizontal reference line on that panel.
    title : str, optional
    out : str or Path, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    epochs = _series(history, "epoch", None)
    kept = [
        (k, y)
        for k, y in panels
        if np.isfinite(_series(history, k, None if k == "val_score" else "train")).any()
    ]
    if not kept:
        raise ValueError(f"no panel of {[k for k, _ in panels]} has values in the history")
    with figure_style():
        fig, axes = plt.subplots(1, len(kept), figsize=(3.4 * len(kept), 2.8), squeeze=False)
        for ax, (key, ylabel) in zip(axes[0], kept, strict=True):
            splits = (
                [("val_score", None)] if key == "val_score" else [("train", "train"), ("validation", "val")]
            )
            values = {name: _series(history, key, split) for name, split in splits}
            if all(
                np.nan_to_num(v).max(initial=0) == 0 and np.nan_to_num(v).min(initial=0) == 0
                for v in values.values()
            ):
                why = f"0 in all {len(epochs)} epochs"
                if first_adversarial is not None and first_adversarial > epochs.max():
                    why = f"off until epoch {first_adversarial}:\nnot reached in {len(epochs)} epochs"
                ax.text(0.5, 0.5, why, ha="center", va="center", transform=ax.transAxes, color="0.4")
                ax.set(xticks=[], yticks=[])
            else:
                for k, (name, v) in enumerate(values.items()):
                    label = "validation takes" if key == "val_score" else name
                    ax.plot(epochs, v, "o-", ms=3, color=SYSTEM_COLOURS[1 + k], label=label)
                if key == "val_score" and selected:
                    ax.plot(selected["epoch"], selected["score"], "k*", ms=10, label="exported epoch")
                if chance and key in chance:
                    ax.axhline(chance[key][0], color="0.5", ls=":", lw=1, label=chance[key][1])
                ax.legend(fontsize=8)
            if first_adversarial is not None and first_adversarial <= epochs.max():
                ax.axvline(first_adversarial - 0.5, color="0.6", ls=":", lw=1)
            ax.set_xlabel("epoch")
            ax.set_ylabel(ylabel)
        if title:
            fig.suptitle(title, fontsize=10)
        fig.tight_layout()
    return _finish(fig, out)


def plot_benchmark(results: Any, *, cut_factor: float = 1.6, out: Out = None) -> Any:
    """The benchmark at a glance: FGD per row (left) and FGD against BC (right).

    A row whose FGD is more than ``cut_factor`` times the largest of the others (the mean pose) would
    flatten every other bar: its bar is drawn cut at the axis end and its value written on it. It is
    left out of the scatter for the same reason, and so is a row without BC (no motion beat).

    Parameters
    ----------
    results : ModelResults
        From :func:`beatlite.train.evaluate_models` (columns ``FGD`` and ``BC``).
    cut_factor : float
    out : str or Path, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    labels = [r.label for r in results.rows]
    fgd = np.array([r.metrics["FGD"] for r in results.rows], float)
    bc = np.array([r.metrics["BC"] for r in results.rows], float)
    order = np.argsort(fgd)
    rest = np.sort(fgd)[:-1] if len(fgd) > 1 else fgd
    limit = rest.max() * 1.25 if len(fgd) > 1 and fgd.max() > cut_factor * rest.max() else fgd.max() * 1.1
    colours = _row_colours(labels)
    with figure_style():
        fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(11, 3.6), gridspec_kw={"width_ratios": [1, 1]})
        y = np.arange(len(labels))[::-1]
        for yy, i in zip(y, order, strict=True):
            ax0.barh(yy, min(fgd[i], limit), color=colours[labels[i]])
            if fgd[i] > limit:
                ax0.text(
                    limit * 0.98,
                    yy,
                    f"{fgd[i]:.1f} (cut) ",
                    ha="right",
                    va="center",
                    color="white",
                    fontsize=8,
                )
        ax0.set_yticks(y, [labels[i] for i in order])
        ax0.set_xlim(0, limit)
        ax0.set_xlabel("FGD (lower is better)")
        shown = [i for i in range(len(labels)) if np.isfinite(bc[i]) and fgd[i] <= limit]
        if shown:
            x_hi = max(fgd[i] for i in shown)
            span = max(bc[i] for i in shown) - min(bc[i] for i in shown) + 1e-3
            placed: list[tuple[float, float]] = []
            for i in sorted(shown, key=lambda i: fgd[i]):
                ax1.scatter(fgd[i], bc[i], color=colours[labels[i]], s=30, zorder=3)
                crowded = any(
                    abs(fgd[i] - x) < 0.25 * x_hi and abs(bc[i] - y) < 0.06 * span for x, y in placed
                )
                offset = (5, -11) if crowded else (5, 3)  # a neighbour's label is there: write below
                ax1.annotate(
                    labels[i], (fgd[i], bc[i]), fontsize=8, xytext=offset, textcoords="offset points"
                )
                if not crowded:
                    placed.append((fgd[i], bc[i]))
            ax1.set_xlim(-0.05 * x_hi, 1.45 * x_hi)  # room for the labels right of the points
            lo, hi = min(bc[i] for i in shown), max(bc[i] for i in shown)
            ax1.set_ylim(lo - 0.1 * (hi - lo + 1e-3), hi + 0.15 * (hi - lo + 1e-3))
        ax1.set_xlabel("FGD (lower is better)")
        ax1.set_ylabel("BC (higher is better)")
        ax1.set_title("closeness to the data vs synchrony")
        fig.tight_layout()
    return _finish(fig, out)


def _row_colours(labels: Sequence[str]) -> dict[str, str]:
    """One colour per row: the system colours for the ground truth, CaMN and HA2G, tab10 for the rest."""
    import matplotlib

    fixed = {"Ground truth": SYSTEM_COLOURS[0], "CaMN": SYSTEM_COLOURS[1], "HA2G": SYSTEM_COLOURS[2]}
    others = [
        c for c in matplotlib.colormaps["tab10"].colors if matplotlib.colors.to_hex(c) not in fixed.values()
    ]
    free = itertools.cycle(others)
    return {lab: fixed.get(lab) or matplotlib.colors.to_hex(next(free)) for lab in labels}


def plot_table6_rows(
    rows: Mapping[str, Mapping[str, float]],
    *,
    paper: Mapping[str, str] | None = None,
    out: Out = None,
) -> Any:
    """BEAT Table 6: per-emotion accuracy (%) of each row, with the paper's rows, every bar named.

    Parameters
    ----------
    rows : mapping row name -> {emotion: accuracy in [0, 1], "avg": ...}
        E.g. :func:`beatlite.stats.table6`'s result; the row names are the legend (``"real"``,
        ``"CaMN"``, ...).
    paper : mapping paper row -> legend label, optional
        Rows of :data:`beatlite.stats.PAPER_TABLE6` to show (default ``real`` and ``generated``,
        labelled as the paper's real and CaMN-generated motion).
    out : str or Path, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    from beatlite.stats import PAPER_TABLE6

    paper = {"real": "paper: real", "generated": "paper: CaMN (generated)"} if paper is None else paper
    names = list(PAPER_TABLE6["real"])  # the paper's order, then "avg"
    bars = [(label, [PAPER_TABLE6[k][n] for n in names]) for k, label in paper.items()]
    bars += [(f"beatlite: {k}", [100 * acc.get(n, math.nan) for n in names]) for k, acc in rows.items()]
    greys = ["0.55", "0.75"]
    with figure_style():
        fig, ax = plt.subplots(figsize=(11, 3.6))
        x = np.arange(len(names))
        width = 0.84 / len(bars)
        for k, (label, values) in enumerate(bars):
            colour = (
                greys[k]
                if k < len(paper) and k < 2
                else SYSTEM_COLOURS[(k - len(paper)) % len(SYSTEM_COLOURS)]
            )
            ax.bar(x + (k - (len(bars) - 1) / 2) * width, values, width, label=label, color=colour)
        ax.set_xticks(x, names)
        ax.set_ylabel("accuracy (%)")
        ax.set_ylim(0, 100)
        ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
        ax.set_title("Emotion classification of motion windows (BEAT Table 6 analog)")
        fig.tight_layout()
    return _finish(fig, out)


def plot_effects(
    variants: Sequence[str],
    paper: Sequence[float],
    ours: Sequence[float],
    ours_error: Sequence[float],
    *,
    ylabel: str,
    labels: tuple[str, str] = ("paper (one run)", "beatlite, mean over seeds (± 2 SE)"),
    out: Out = None,
) -> Any:
    """An ablation study at a glance: each variant's change vs the full model, the paper's beside ours.

    Parameters
    ----------
    variants : sequence of str
        Bar group labels.
    paper, ours : sequence of float
        Changes (e.g. % FGD change vs the full model), one per variant.
    ours_error : sequence of float
        Error bar half-lengths of ``ours`` (e.g. 2 standard errors).
    ylabel : str
    labels : (str, str)
        Legend entries of the paper's and our bars.
    out : str or Path, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    if not len(variants) == len(paper) == len(ours) == len(ours_error):
        raise ValueError("variants, paper, ours and ours_error must have the same length")
    with figure_style():
        fig, ax = plt.subplots(figsize=(9, 3.2))
        x = np.arange(len(variants))
        ax.bar(x - 0.2, paper, 0.4, label=labels[0], color="0.6")
        ax.bar(x + 0.2, ours, 0.4, yerr=ours_error, capsize=3, label=labels[1], color=SYSTEM_COLOURS[1])
        ax.axhline(0, color="k", lw=0.8)
        ax.set_xticks(x, variants, rotation=20, ha="right")
        ax.set_ylabel(ylabel)
        ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
        fig.tight_layout()
    return _finish(fig, out)


def plot_ha2g_levels(*, out: Out = None) -> Any:
    """HA2G's coarse-to-fine body hierarchy (paper Fig. 1): the bones each of the 6 levels adds.

    One pair of panels per level: the body seen from the front and the right hand from above. Red
    bones are new at that level, grey ones come from the levels before. Drawn on the BEAT rest pose
    in TED-43.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    from beatlite.skeleton import ted
    from beatlite.skeleton.beat import beat_skeleton
    from beatlite.skeleton.kinematics import rest_pose

    rest = ted.beat_to_ted43(rest_pose(beat_skeleton())[None])[0]  # (43, 3) cm
    bones = np.asarray(ted.TED_BONES)
    names = ted.TED43_JOINTS
    wrist = names.index("right_wrist")
    below = {wrist}  # the joints under the right wrist: bones are listed parents first
    for p, c in bones:
        if p in below:
            below.add(int(c))
    hand = [b for b, (p, _) in enumerate(bones) if p in below]
    views = {
        "body (front)": (rest[:, [0, 1]], range(len(bones))),
        "right hand (top)": (rest[:, [0, 2]] - rest[wrist, [0, 2]], hand),
    }
    limits = {}
    for view, (xy, drawn) in views.items():
        used = xy[np.unique(bones[list(drawn)])]
        limits[view] = (used.min(0) - 3, used.max(0) + 3)
    ratio = [
        float(np.ptp(np.array(limits[v]), axis=0)[0] / np.ptp(np.array(limits[v]), axis=0)[1]) for v in views
    ]
    with figure_style():
        fig, axes = plt.subplots(3, 4, figsize=(11, 3.9), gridspec_kw={"width_ratios": ratio * 2})
        previous: set[int] = set()
        for k, level in enumerate(map(set, ted.HA2G_LEVELS)):
            for j, (view, (xy, drawn)) in enumerate(views.items()):
                ax = axes[k // 2, 2 * (k % 2) + j]
                if not level & set(drawn):
                    ax.text(
                        0.5,
                        0.5,
                        "no bones yet",
                        ha="center",
                        va="center",
                        transform=ax.transAxes,
                        color="0.5",
                    )
                for bone in sorted(level & set(drawn)):
                    new = bone not in previous
                    colour = GROUP_COLOURS["hands"] if new else "0.6"
                    ax.plot(*xy[bones[bone]].T, "-o", ms=2, lw=2 if new else 1, color=colour)
                (x0, y0), (x1, y1) = limits[view]
                ax.set(xlim=(x0, x1), ylim=(y0, y1), aspect="equal")
                ax.set_axis_off()
                ax.set_title(
                    f"level {k + 1}: {len(level)} bones, {3 * len(level)} dims" if j == 0 else view,
                    fontsize=9,
                )
            previous = level
        fig.suptitle("Bones each level adds (red) to the previous levels (grey); BEAT rest pose on TED-43")
        fig.tight_layout()
    return _finish(fig, out)
