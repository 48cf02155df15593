"""2D charts for the notebooks' results: training curves, model scores (bars), one score against another, ablations.

Each function follows :mod:`beatlite.viz.style`: a y label on every panel, legends
outside the data, one colour per system (:func:`beatlite.viz.style.system_colour`).
Taught in notebooks 05 and 06 (training curves, ablations) and 07 (benchmark).

>>> fig = plot_training_curves(history, {"reconstruction loss (Huber)": {"train": "train.rec",
...                                                                        "validation": "val.rec"}})  # doctest: +SKIP
>>> fig = plot_scores({"CaMN": 1.2, "HA2G": 2.0, "mean pose": 25.0}, "FGD")                  # doctest: +SKIP
>>> fig = plot_effects(["w/o text"], [20.8], [12.0], [4.0], "FGD change vs full (%)")          # doctest: +SKIP
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from beatlite.viz.style import figure_style, legend_outside, system_colour, system_colours

#: A bar longer than this many times the median positive bar is drawn cut, with its value written.
OUTLIER_FACTOR = 3.0


def _new_axes(ax: Any, figsize: tuple[float, float]) -> Any:
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.subplots(figsize=figsize, layout="constrained")[1]


def history_values(history: Sequence[Mapping[str, Any]], key: str) -> tuple[np.ndarray, np.ndarray]:
    """Epochs and values of one logged quantity: ``key`` is a dotted path such as ``"val.rec"`` or ``"val_score"``.

    Parameters
    ----------
    history : sequence of dict
        One dict per epoch, with an ``"epoch"`` entry (the training history of
        :mod:`beatlite.train`).
    key : str
        Dotted path into each dict.

    Returns
    -------
    (epochs (E,) float64, values (E,) float64)
        Only the epochs where the quantity was logged (possibly none).

    Examples
    --------
    >>> h = [{"epoch": 0, "val": {"rec": 2.0}}, {"epoch": 1, "val": {"rec": 1.5}, "val_score": 9.0}]
    >>> history_values(h, "val_score")
    (array([1.]), array([9.]))
    """
    epochs, values = [], []
    for k, entry in enumerate(history):
        value: Any = entry
        for part in key.split("."):
            value = value.get(part) if isinstance(value, Mapping) else None
        if value is not None:
            epochs.append(float(entry.get("epoch", k)))
            values.append(float(value))
    return np.asarray(epochs), np.asarray(values)


def plot_training_curves(
    history: Sequence[Mapping[str, Any]],
    panels: Mapping[str, Mapping[str, str]],
    *,
    mark_epoch: float | None = None,
    selected: tuple[float, float] | None = None,
    title: str | None = None,
    panel_size: tuple[float, float] = (3.8, 2.9),
) -> Any:
    """One panel per quantity over epochs; every panel has its y label, and says so when nothing was logged.

    Parameters
    ----------
    history : sequence of dict
        One dict per epoch (``{"epoch": 3, "train": {"rec": ...}, "val": {...}, "val_score": ...}``).
    panels : mapping y label -> mapping curve label -> dotted key
        E.g. ``{"reconstruction loss (Huber)": {"train": "train.rec", "validation": "val.rec"},
        "validation FGD": {"validation takes": "val_score"}}``. The y label
        should carry the unit or say what the loss is.
    mark_epoch : float, optional
        Draw a dotted vertical line there on every panel (e.g. where the adversarial loss starts).
    selected : (epoch, value), optional
        A star on the panel whose curve contains ``val_score`` (the exported epoch).
    title : str, optional
        Figure title.
    panel_size : (float, float)
        Inches per panel.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    Three epochs of a loss ``1 / (epoch + 1)``; the run logged no ``val_score``, so the second panel says so
    instead of staying empty:

    >>> import matplotlib.pyplot as plt
    >>> history = [{"epoch": e, "train": {"rec": 1 / (e + 1)}, "val": {"rec": 1.2 / (e + 1)}} for e in range(3)]
    >>> fig = plot_training_curves(history, {"reconstruction loss (Huber)": {"train": "train.rec",
    ...                                                                      "validation": "val.rec"},
    ...                                      "validation FGD": {"validation takes": "val_score"}})
    >>> train = fig.axes[0].get_lines()[0]
    >>> train.get_label(), np.round(train.get_ydata(), 3).tolist()
    ('train', [1.0, 0.5, 0.333])
    >>> [t.get_text() for t in fig.axes[1].texts]
    ['not logged in this run']
    >>> plt.close(fig)
    """
    import matplotlib.pyplot as plt

    if not panels:
        raise ValueError("panels must name at least one quantity to plot")
    with figure_style():
        fig, axes = plt.subplots(1, len(panels), figsize=(panel_size[0] * len(panels), panel_size[1]),
                                 layout="constrained", squeeze=False, sharex=True)  # fmt: skip
        for ax, (ylabel, curves) in zip(axes[0], panels.items()):
            _draw_curves(ax, history, curves, selected)
            ax.set_ylabel(ylabel)
            ax.set_xlabel("epoch")
            if mark_epoch is not None:
                ax.axvline(mark_epoch, color="0.6", ls=":", lw=1)
        if title:
            fig.suptitle(title)
    return fig


def _draw_curves(
    ax: Any, history: Sequence[Mapping[str, Any]], curves: Mapping[str, str], selected: Any
) -> None:
    """The curves of one panel; a note instead of an empty box when none was logged."""
    drawn = 0
    for i, (label, key) in enumerate(curves.items()):
        epochs, values = history_values(history, key)
        if len(values):
            ax.plot(epochs, values, "o-", ms=3, label=label, color=f"C{i}")
            drawn += 1
        if key == "val_score" and selected is not None:
            ax.plot(*selected, "k*", ms=11, label="exported epoch")
    if drawn:
        legend_outside(ax, "top", fontsize=8)
    else:
        epochs = [float(h.get("epoch", k)) for k, h in enumerate(history)]
        ax.set_xlim(min(epochs, default=0.0), max(epochs, default=0.0) + 1)
        ax.text(
            0.5, 0.5, "not logged in this run", ha="center", va="center", transform=ax.transAxes, color="0.4"
        )


def plot_scores(
    scores: Mapping[str, float],
    metric: str,
    *,
    lower_is_better: bool = True,
    ax: Any = None,
    figsize: tuple[float, float] = (6.4, 3.4),
) -> Any:
    """Horizontal bars of one metric per system; far outliers are cut so they do not flatten the others.

    A bar longer than :data:`OUTLIER_FACTOR` times the median of the positive values
    (e.g. the mean-pose baseline, FGD 25, beside models near 3-5) is drawn past the
    axis' last grid line with a white break mark and its value written after it;
    the axis spans the other bars. Every bar carries its value, a zero is written
    as ``0`` (not an empty slot). Bars are in the systems' colours
    (:func:`beatlite.viz.style.system_colours`, one distinct colour each), in the
    order given, first at the top; each bar is its own labelled series.

    Parameters
    ----------
    scores : mapping label -> float
        The metric of each system (finite, >= 0).
    metric : str
        x-axis label, e.g. ``"FGD"``; "(lower is better)" or "(higher is better)" is added.
    lower_is_better : bool
        Which direction is better.
    ax : matplotlib Axes, optional
        Draw into it; a new figure otherwise.
    figsize : (float, float)
        Size of a new figure, inches.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        No score, or one that is not finite or is negative.

    Examples
    --------
    The mean pose's 25 is more than 3 times the median 4 of the positive scores (3, 4, 25), so its bar is cut
    at ``1.12 * 4`` (the longest bar that fits is 4) and its value written after it:

    >>> import matplotlib.pyplot as plt
    >>> fig = plot_scores({"CaMN": 3.0, "HA2G": 4.0, "mean pose": 25.0}, "FGD")
    >>> ax = fig.axes[0]
    >>> [round(float(bar.get_width()), 2) for bar in ax.patches], [t.get_text() for t in ax.texts]
    ([3.0, 4.0, 4.48], [' 3', ' 4', ' 25 (cut)'])
    >>> ax.get_xlabel()
    'FGD (lower is better)'
    >>> plt.close(fig)
    """
    labels = list(scores)
    values = _check_scores(scores)
    limit = _axis_limit(values)
    cut = values > limit
    with figure_style():
        ax = _new_axes(ax, figsize)
        y = np.arange(len(labels))[::-1]
        colours = system_colours(labels)
        end = limit * 1.12  # where a cut bar stops, past the last bar that fits
        for yi, v, label, colour, far in zip(y, values, labels, colours, cut):
            ax.barh(yi, end if far else v, color=colour, label=label)
            text = f" {v:.3g}" + (" (cut)" if far else "")
            ax.text(end if far else v, yi, text, va="center", fontsize=9, clip_on=False)
            if far:  # a white break across the bar, just before its end
                ax.plot(
                    [limit * 1.02, limit * 1.05], [yi - 0.45, yi + 0.45], color="white", lw=3, label="_break"
                )
        ax.set_yticks(y, labels)
        ax.set_xlim(0, limit * (1.4 if cut.any() else 1.12))
        ax.set_xlabel(f"{metric} ({'lower' if lower_is_better else 'higher'} is better)")
        ax.grid(axis="y", visible=False)
    return ax.figure


def _check_scores(scores: Mapping[str, float]) -> np.ndarray:
    """``(S,) float64`` scores, or a ValueError when one is missing, not finite or negative."""
    values = np.asarray([float(v) for v in scores.values()])
    if not len(values) or not np.all(np.isfinite(values)) or np.any(values < 0):
        raise ValueError(f"scores must be finite and >= 0, got {dict(scores)}")
    return values


def _axis_limit(values: np.ndarray) -> float:
    """The largest value that is not an outlier (> :data:`OUTLIER_FACTOR` x the median positive value)."""
    positive = values[values > 0]
    if not len(positive):
        return 1.0
    inside = positive[positive <= OUTLIER_FACTOR * np.median(positive)]
    return float(inside.max())


def _finite_pair(a: float | None, b: float | None) -> bool:
    return a is not None and b is not None and bool(np.isfinite(a) and np.isfinite(b))


def plot_score_scatter(
    x: Mapping[str, float],
    y: Mapping[str, float],
    xlabel: str,
    ylabel: str,
    *,
    ax: Any = None,
    figsize: tuple[float, float] = (6.4, 4.0),
) -> Any:
    """One point per system (e.g. FGD against BC), labelled in its colour, labels clear of each other.

    Each label takes the first of a few places around its point (beside it, above or below, on
    the side facing the middle first) where it stays inside the axes and meets neither a placed
    label nor a marker (:func:`_place_labels`); with no such place it takes the first. A label
    not written right beside its point is tied to it by a thin line in its colour. Colours are
    those of :func:`plot_scores` for the same mapping (:func:`beatlite.viz.style.system_colours`
    of ``x``'s labels); each point is its own labelled series. Labels are
    placed for the figure's layout at call time: give the axes their title before calling.
    Systems missing from ``y`` or with a non-finite value are left out.

    Parameters
    ----------
    x, y : mapping label -> float
        The two scores of each system.
    xlabel, ylabel : str
        Axis labels with direction or unit, e.g. ``"FGD (lower is better)"``.
    ax : matplotlib Axes, optional
        Draw into it; a new figure otherwise.
    figsize : (float, float)
        Size of a new figure, inches.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        No system has two finite scores.

    Examples
    --------
    A system without a BC is left out; the other two are one labelled point each, at (FGD, BC):

    >>> import matplotlib.pyplot as plt
    >>> fig = plot_score_scatter({"CaMN": 3.0, "HA2G": 4.0, "Seq2Seq": 9.0}, {"CaMN": 0.7, "HA2G": 0.6},
    ...                          "FGD (lower is better)", "BC (higher is better)")
    >>> ax = fig.axes[0]
    >>> [c.get_offsets().tolist()[0] for c in ax.collections], [t.get_text() for t in ax.texts]
    ([[3.0, 0.7], [4.0, 0.6]], ['CaMN', 'HA2G'])
    >>> plt.close(fig)
    """
    keep = [k for k in x if _finite_pair(x.get(k), y.get(k))]
    if not keep:
        raise ValueError("plot_score_scatter: no system has both scores")
    xs = np.array([float(x[k]) for k in keep])
    ys = np.array([float(y[k]) for k in keep])
    by_label = dict(zip(x, system_colours(list(x)), strict=True))
    colours = [by_label[label] for label in keep]
    with figure_style():
        ax = _new_axes(ax, figsize)
        for xi, yi, label, colour in zip(xs, ys, keep, colours, strict=True):
            ax.scatter([xi], [yi], color=colour, s=40, zorder=3, label=label)
        ax.margins(x=0.15, y=0.2)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        _place_labels(ax, keep, xs, ys, colours)
    return ax.figure


#: Label places around a point, (dx, dy) points from it, with the vertical alignment that puts the text
#: there: beside it above and below, then straight above and below, then further up and down.
_PLACES = [
    (6, 3, "bottom"),
    (6, -3, "top"),
    (0, 8, "bottom"),
    (0, -8, "top"),
    (6, 16, "bottom"),
    (6, -16, "top"),
    (10, 26, "bottom"),
    (10, -26, "top"),
]

#: A label placed at most this many points above or below its point reads as its own; further away a line ties it.
_BESIDE = 8


def _place_labels(ax: Any, labels: list[str], xs: np.ndarray, ys: np.ndarray, colours: list[Any]) -> None:
    """Annotate each point with its label at the first free place of :data:`_PLACES`, top point first.

    Free: inside the axes, overlapping no placed label and no marker (a 10-point square). The places
    on the side facing the middle come first, then the mirrored ones; with none free, the first. The
    figure is drawn once first, so that the layout and the text sizes are final; the labels are left
    out of the layout, so placing them does not move the axes.
    """
    from matplotlib.text import Text
    from matplotlib.transforms import Bbox

    fig = ax.figure
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    frame = ax.get_window_extent(renderer)
    centres = ax.transData.transform(np.column_stack([xs, ys]))
    half = 5 * fig.dpi / 72
    taken = [Bbox.from_extents(cx - half, cy - half, cx + half, cy + half) for cx, cy in centres]
    middle = (centres[:, 0].min() + centres[:, 0].max()) / 2
    for i in sorted(range(len(labels)), key=lambda k: -ys[k]):
        side = -1 if centres[i, 0] > middle and len(labels) > 1 else 1
        places = [(side * dx, dy, va) for dx, dy, va in _PLACES]
        places += [(-dx, dy, va) for dx, dy, va in places if dx]  # the mirrored side
        note = ax.annotate(labels[i], (xs[i], ys[i]), xytext=(0, 0), textcoords="offset points",
                           fontsize=9, color=colours[i], arrowprops={"arrowstyle": "-", "color": colours[i],
                           "lw": 0.7, "shrinkA": 0, "shrinkB": 4})  # fmt: skip
        note.set_in_layout(False)
        for dx, dy, va in [*places, places[0]]:  # the first again when none is free
            note.xyann = (dx, dy)
            note.set(ha="center" if dx == 0 else ("left" if dx > 0 else "right"), va=va)
            note.update_positions(renderer)
            box = Text.get_window_extent(note, renderer)  # the words only, not the tie line
            inside = frame.contains(box.x0, box.y0) and frame.contains(box.x1, box.y1)
            if inside and not any(b.overlaps(box) for b in taken):
                break
        note.arrow_patch.set_visible(abs(dy) > _BESIDE)  # a label away from its point is tied to it
        taken.append(box)


def plot_effects(
    variants: Sequence[str],
    paper: Sequence[float],
    ours: Sequence[float],
    ours_error: Sequence[float],
    ylabel: str,
    *,
    labels: tuple[str, str] = ("paper (one run)", "beatlite, mean over seeds (± 2 SE)"),
    ax: Any = None,
    figsize: tuple[float, float] = (9.6, 3.2),
) -> Any:
    """An ablation study at a glance: each variant's change vs the full model, the paper's bar beside ours.

    The paper's tables have one run per row, so its bars have no error bar; ours are seed means
    with an error bar (e.g. 2 standard errors of the difference, :mod:`beatlite.train.seeds`), so a
    bar whose error bar crosses 0 is noise at this sample size.

    Parameters
    ----------
    variants : sequence of str
        Bar group labels (e.g. ``"w/o text"``).
    paper, ours : sequence of float
        Changes vs the full model (e.g. % FGD change), one per variant.
    ours_error : sequence of float
        Error bar half-lengths of ``ours`` (e.g. 2 standard errors), same unit.
    ylabel : str
        y-axis label with its unit, e.g. ``"FGD change vs full (%)"``.
    labels : (str, str)
        Legend entries of the paper's and our bars.
    ax : matplotlib Axes, optional
        Draw into it; a new figure otherwise.
    figsize : (float, float)
        Size of a new figure, inches.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> fig = plot_effects(["w/o text", "w/o audio"], [20.8, 25.9], [12.0, 3.0], [4.0, 5.0], "FGD change (%)")
    >>> [float(p.get_height()) for p in fig.axes[0].patches[2:]]  # ours, after the paper's two
    [12.0, 3.0]
    """
    if not len(variants) == len(paper) == len(ours) == len(ours_error):
        raise ValueError(
            f"variants, paper, ours and ours_error must have the same length, got "
            f"{len(variants)}, {len(paper)}, {len(ours)}, {len(ours_error)}"
        )
    with figure_style():
        ax = _new_axes(ax, figsize)
        x = np.arange(len(variants))
        ax.bar(x - 0.2, paper, 0.4, label=labels[0], color="0.6")
        ax.bar(
            x + 0.2, ours, 0.4, yerr=ours_error, capsize=3, label=labels[1], color=system_colour("CaMN", 1)
        )
        ax.axhline(0, color="k", lw=0.8)
        ax.set_xticks(x, variants, rotation=20, ha="right")
        ax.set_ylabel(ylabel)
        ax.grid(axis="x", visible=False)
        legend_outside(ax, "right")
    return ax.figure


def plot_signals(
    times: Any,
    signals: Mapping[str, Any],
    ylabel: str,
    *,
    events: Mapping[str, Any] | None = None,
    markers: Mapping[str, Any] | None = None,
    xlim: tuple[float, float] | None = None,
    clip_quantile: float | None = None,
    xlabel: str = "time (s)",
    title: str | None = None,
    styles: Mapping[str, dict] | None = None,
    ax: Any = None,
    figsize: tuple[float, float] = (9.6, 2.8),
) -> Any:
    """Curves over time (joint angles, wrist speeds, onset strength) with event lines, legend right of the data.

    Parameters
    ----------
    times : (T,) float, seconds
        Common time axis of the signals.
    signals : mapping label -> (T,) float
        The curves, in the colours C0, C1, ...
    ylabel : str
        y-axis label with its unit, e.g. ``"wrist speed (cm/s)"``.
    events : mapping label -> (E,) float seconds, optional
        Times drawn as vertical lines over the whole height (e.g. ``{"audio onsets": onsets}``).
    markers : mapping curve label -> (M,) float seconds, optional
        Times marked on that curve with a triangle (e.g. speed minima), in the curve's colour.
    xlim : (float, float), optional
        Time range shown, seconds; the y range follows the data inside it.
    clip_quantile : float in (0, 1], optional
        Upper y limit = 1.2 x this quantile of the shown values, so that one large
        swing does not flatten the rest (the cut is written in the corner); ``None``: all data.
    xlabel : str
        x-axis label with its unit (``times`` need not be time, e.g. ``"motion shifted by (s)"``).
    title : str, optional
        Axes title.
    styles : mapping curve label -> dict, optional
        Extra ``Axes.plot`` keywords per curve, e.g. ``{"ls": "--"}`` or ``{"marker": "o", "ms": 3}``.
    ax : matplotlib Axes, optional
        Draw into it; a new figure otherwise.
    figsize : (float, float)
        Size of a new figure, inches.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> t = np.arange(100) / 15
    >>> fig = plot_signals(t, {"right wrist": np.abs(np.sin(t))}, "speed (cm/s)", events={"onsets": [1.0, 2.5]})
    >>> fig.axes[0].get_ylabel()
    'speed (cm/s)'
    """
    t = np.asarray(times, dtype=np.float64).reshape(-1)
    curves = {k: np.asarray(v, dtype=np.float64).reshape(-1) for k, v in signals.items()}
    bad = [k for k, v in curves.items() if v.shape != t.shape]
    if not curves or bad:
        raise ValueError(
            f"signals must be (T,) = {t.shape} curves, got {[(k, curves[k].shape) for k in bad]}"
        )
    shown = (t >= xlim[0]) & (t <= xlim[1]) if xlim is not None else np.ones(t.shape, bool)
    with figure_style():
        ax = _new_axes(ax, figsize)
        for i, (label, y) in enumerate(curves.items()):
            ax.plot(t, y, **{"lw": 1.1, "color": f"C{i}", "label": label, **(styles or {}).get(label, {})})
            when = np.asarray((markers or {}).get(label, []), dtype=np.float64)
            ax.plot(when, np.interp(when, t, y), "v", ms=5, color=f"C{i}", ls="none")
        _draw_events(ax, events)
        _set_signal_limits(ax, t, np.stack(list(curves.values()))[:, shown], xlim, clip_quantile)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        if title:
            ax.set_title(title)
        legend_outside(ax, "right")
    return ax.figure


def _draw_events(ax: Any, events: Mapping[str, Any] | None) -> None:
    """Vertical lines at event times, one colour per kind, from the red end of the palette."""
    for k, (label, when) in enumerate((events or {}).items()):
        ax.axvline(np.nan, color=f"C{3 + k}", lw=0.9, label=label)  # one legend entry per kind
        for x in np.asarray(when, dtype=np.float64).reshape(-1):
            ax.axvline(x, color=f"C{3 + k}", lw=0.9, alpha=0.6)


def _set_signal_limits(
    ax: Any, t: np.ndarray, shown: np.ndarray, xlim: Any, clip_quantile: float | None
) -> None:
    """x range as asked; y range from the shown values, optionally cut at a quantile."""
    ax.set_xlim(*(xlim if xlim is not None else (t.min(), t.max())))
    if shown.size == 0:
        return
    lo, hi = float(shown.min()), float(shown.max())
    if clip_quantile is not None:
        if not 0.0 < clip_quantile <= 1.0:
            raise ValueError(f"clip_quantile must be in (0, 1], got {clip_quantile!r}")
        cut = 1.2 * float(np.quantile(shown, clip_quantile))
        if cut < hi:
            hi = cut
            ax.text(1.01, 0.0, f"y axis cut at {cut:.3g}:\nhigher peaks run off", transform=ax.transAxes,
                    ha="left", va="bottom", fontsize=8, color="0.35")  # fmt: skip
    pad = 0.05 * (hi - lo) if hi > lo else 1.0
    ax.set_ylim(lo - pad, hi + pad)


def plot_waveform(
    audio: Any,
    sr: float,
    *,
    words: Any = None,
    onsets: Mapping[str, Any] | None = None,
    xlim: tuple[float, float] | None = None,
    title: str | None = None,
    ax: Any = None,
    figsize: tuple[float, float] = (9.6, 2.6),
) -> Any:
    """A waveform with its amplitude axis, optional words (shaded, written above) and onset lines.

    Parameters
    ----------
    audio : (N,) float, in [-1, 1]
        Mono waveform.
    sr : float
        Sample rate, Hz.
    words : (starts, ends, words) or WordIntervals, optional
        Word timings in seconds, shaded and written over the waveform's top margin.
    onsets : mapping label -> (E,) float seconds, optional
        Event times drawn as vertical lines (e.g. ``{"audio onsets": onsets}``); legend right of the data.
    xlim : (float, float), optional
        Time range shown, seconds (default the whole waveform); only its samples are drawn
        and set the amplitude scale.
    title : str, optional
        Axes title.
    ax : matplotlib Axes, optional
        Draw into it; a new figure otherwise.
    figsize : (float, float)
        Size of a new figure, inches.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    Two seconds of a 5 Hz tone, amplitude 0.25 then 0.5, shown over its first second: only that second's
    samples set the scale (from ``-1.05 * 0.25`` up to ``1.45 * 0.25``, the top margin holding the words), and
    only the word inside it is written:

    >>> import matplotlib.pyplot as plt
    >>> sr = 1000
    >>> t = np.arange(2 * sr) / sr
    >>> audio = np.where(t < 1, 0.25, 0.5) * np.sin(2 * np.pi * 5 * t)
    >>> words = ([0.2, 1.1], [0.6, 1.5], ["hello", "world"])
    >>> fig = plot_waveform(audio, sr, words=words, onsets={"audio onsets": [0.2, 1.1]}, xlim=(0.0, 1.0))
    >>> ax = fig.axes[0]
    >>> [round(float(v), 4) for v in ax.get_ylim()], [t.get_text() for t in ax.texts]
    ([-0.2625, 0.3625], ['hello'])
    >>> plt.close(fig)
    """
    from beatlite.viz._inputs import check_fps, check_words

    y = np.asarray(audio, dtype=np.float64).reshape(-1)
    if y.size == 0:
        raise ValueError("audio must be a non-empty (N,) waveform")
    sr = check_fps(sr, "sr")
    xlim = xlim if xlim is not None else (0.0, len(y) / sr)
    i0, i1 = max(0, int(np.floor(xlim[0] * sr))), min(len(y), int(np.ceil(xlim[1] * sr)) + 1)
    y = y[i0:i1] if i1 > i0 else y[:0]
    with figure_style():
        ax = _new_axes(ax, figsize)
        ax.plot((i0 + np.arange(len(y))) / sr, y, lw=0.4, color="0.4")
        _draw_events(ax, onsets)
        peak = max(float(np.abs(y).max()) if y.size else 0.0, 1e-6)
        ax.set_ylim(-1.05 * peak, 1.45 * peak)  # the top margin holds the words
        if words is not None:
            for start, end, word in zip(*check_words(words)):
                if end > xlim[0] and start < xlim[1]:
                    ax.axvspan(start, end, color="#4c72b0", alpha=0.12, lw=0)
                    ax.text((start + end) / 2, 1.2 * peak, word, ha="center", va="center", fontsize=8)
        ax.set_xlim(*xlim)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("amplitude (full scale = 1)")
        if title:
            ax.set_title(title)
        legend_outside(ax, "right")
    return ax.figure


def plot_log_mel(
    log_mel: Any,
    frame_rate: float,
    *,
    events: Any = None,
    xlim: tuple[float, float] | None = None,
    title: str | None = None,
    ax: Any = None,
    figsize: tuple[float, float] = (9.0, 3.0),
) -> Any:
    """A log-mel spectrogram over time, with its level colour bar and optional event lines (e.g. word onsets).

    Parameters
    ----------
    log_mel : (M, B) float, dB
        M frames of B mel bands, as :func:`beatlite.data.windows.log_mel` gives them (0 dB = the take's peak).
    frame_rate : float
        Mel frames per second (``sr / hop``, e.g. 16000 / 512 = 31.25).
    events : (E,) float seconds, optional
        Times drawn as thin white lines over the picture.
    xlim : (float, float), optional
        Time range shown, seconds (default all M frames).
    title : str, optional
        Axes title.
    ax : matplotlib Axes, optional
        Draw into it; a new figure otherwise.
    figsize : (float, float)
        Size of a new figure, inches.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> fig = plot_log_mel(np.zeros((70, 128)), 31.25)
    >>> [float(t) for t in fig.axes[0].get_xlim()], fig.axes[0].get_ylabel()  # 70 frames at 31.25 per second
    ([0.0, 2.24], 'mel band (index, 0-127)')
    """
    from beatlite.viz._inputs import check_fps

    x = np.asarray(log_mel, dtype=np.float64)
    if x.ndim != 2 or not x.size:
        raise ValueError(
            f"log_mel must be a non-empty (M, B) array of M frames and B bands, got shape {x.shape}"
        )
    frame_rate = check_fps(frame_rate, "frame_rate")
    with figure_style():
        ax = _new_axes(ax, figsize)
        extent = (0.0, len(x) / frame_rate, 0, x.shape[1])
        image = ax.imshow(x.T, origin="lower", aspect="auto", extent=extent, cmap="magma")
        for t in np.asarray(events if events is not None else [], dtype=np.float64).reshape(-1):
            ax.axvline(t, color="white", lw=0.5, alpha=0.6)
        ax.set(xlim=xlim or extent[:2], xlabel="time (s)", ylabel=f"mel band (index, 0-{x.shape[1] - 1})")
        if title:
            ax.set_title(title)
        ax.grid(False)  # no grid over the picture
        ax.figure.colorbar(image, ax=ax, label="level (dB, 0 = the take's peak)")
    return ax.figure
