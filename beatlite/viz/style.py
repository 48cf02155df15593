"""One figure style for every beatlite plot, and a helper that saves a figure in several formats.

Nothing here changes matplotlib's global state at import time: apply the style
for a block of code with :func:`figure_style` (a ``plt.rc_context``), or pass
:data:`STYLE` to ``plt.rc_context`` yourself.

The style's rules, which every figure function of :mod:`beatlite.viz` and
:mod:`beatlite.stats` follows:

- **Slide size.** The default figure is 6.4 inches at ``savefig.dpi`` 150, :data:`SLIDE_WIDTH_PX` (960)
  pixels, less the white margin that ``savefig.bbox = "tight"`` crops (a one-panel line plot is saved about
  860 px wide); animations are drawn at :data:`SLIDE_WIDTH_PX` wide (:func:`slide_figsize`).
- **Fonts** readable on a projector: 10-12 pt text, 9 pt ticks and legends.
- **Legends outside the data**: :func:`legend_outside` puts them right of or
  above the axes, never over bars or curves.
- **Units on every axis**: labels read ``"quantity (unit)"``; a count or a
  score without unit says so (``"score (0-1)"``).
- **One colour per system** in every figure: :func:`system_colour` by name only
  (ground truth dark grey, CaMN blue, HA2G orange, and a colour of its own for
  each baseline and shipped recipe of the course, :data:`NAMED_SYSTEM_COLOURS`; a
  model you add gets one of :data:`OTHER_SYSTEM_COLOURS`, which the course does
  not use), :func:`system_colours` for the systems of one figure (distinct), and one colour per joint group
  (:data:`GROUP_COLOURS`) on every skeleton.

Usage (the doctests skip the ``with`` block: it writes files under ``build/``):

>>> import matplotlib.pyplot as plt
>>> from beatlite.viz.style import figure_style, save_figure
>>> with figure_style():                                  # doctest: +SKIP
...     fig, ax = plt.subplots()
...     ax.plot([0, 1], [0, 1])
...     save_figure(fig, "build/figures/line")           # -> line.png, line.svg

Used by every figure of the notebooks; first in notebooks/00_setup_and_tour.ipynb, section 2 (``save_figure``).
"""

from __future__ import annotations

import contextlib
import os
import zlib
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from types import MappingProxyType
from typing import Any

from matplotlib.rcsetup import cycler

from beatlite.viz._files import atomic_target

#: Colours of the three joint groups (body, hands, head) used by every skeleton plot.
GROUP_COLOURS: Mapping[str, str] = MappingProxyType(
    {"body": "#1f4e79", "hands": "#c0392b", "head": "#2e8b57"}
)

#: Colours of the compared systems, in the order ground truth, CaMN, HA2G, then extras.
SYSTEM_COLOURS: tuple[str, ...] = ("#333333", "#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b")

#: The colour of every system the course shows, by name (lower case): the ground truth's two rows, CaMN and
#: HA2G (their ablations, e.g. "CaMN w/o text", start with the name and share its colour), the baselines and the
#: other shipped recipes' rows (:data:`beatlite.train.recipes.RECIPES`' labels), so that a system keeps its colour
#: in every figure. Readable as text on white (contrast >= 3:1), mostly Paul Tol's muted and vibrant schemes, and
#: every two at least 30 CIELAB ΔE apart (the closest: ground truth (141 Euler channels) and random clip, 33.6);
#: for a simulated protanope or deuteranope twelve colours cannot all stay apart: HA2G and mean pose are 7.7 apart
#: for one, random clip and trimodal 8.3 for the other (tests/test_viz.py measures them).
NAMED_SYSTEM_COLOURS: Mapping[str, str] = MappingProxyType(
    {
        "ground truth": SYSTEM_COLOURS[0],
        "real": SYSTEM_COLOURS[0],
        "gt": SYSTEM_COLOURS[0],
        "ground truth (141 euler channels)": "#999999",
        "camn": SYSTEM_COLOURS[1],
        "ha2g": SYSTEM_COLOURS[2],
        "mean pose": "#999933",
        "random clip": "#8c564b",
        "s2g-style": "#ee3377",
        "trimodal-style": "#117733",
        "seq2seq-style": "#332288",
        "a2g-style": "#882255",
        "joint embedding-style": "#8866ff",  # a light violet: #7b4173 was 19.5 from A2G's wine
        "diffgesture-style": "#d62728",
    }
)

#: Colours of systems without a named colour (a user's own models): none of :data:`NAMED_SYSTEM_COLOURS`'.
OTHER_SYSTEM_COLOURS: tuple[str, ...] = ("#d55e00", "#009e73", "#e377c2", "#aa4499", "#393b79", "#bcbd22")

#: Smallest width in pixels of a saved figure, an animation or a GIF ("slide size").
SLIDE_WIDTH_PX = 960

#: The beatlite rcParams (read-only). Use with ``plt.rc_context(dict(STYLE))`` or :func:`figure_style`.
STYLE: Mapping[str, Any] = MappingProxyType(
    {
        "figure.dpi": 100,
        "savefig.dpi": 150,
        "savefig.bbox": "tight",
        "figure.figsize": (6.4, 4.0),
        "figure.facecolor": "white",
        "axes.facecolor": "white",
        "axes.grid": True,
        "grid.alpha": 0.3,
        "grid.linewidth": 0.6,
        "axes.spines.top": False,
        "axes.spines.right": False,
        "axes.titlesize": 12,
        "axes.labelsize": 11,
        "axes.prop_cycle": cycler(color=list(SYSTEM_COLOURS)),
        "font.size": 10,
        "legend.fontsize": 9,
        "legend.frameon": False,
        "legend.borderaxespad": 0.3,
        "xtick.labelsize": 9,
        "ytick.labelsize": 9,
        "lines.linewidth": 1.5,
        "image.cmap": "viridis",
        "svg.fonttype": "none",
        "svg.hashsalt": "beatlite",  # deterministic SVG ids
        "animation.embed_limit": 50.0,  # MB; lets to_jshtml embed a few hundred frames
    }
)


@contextlib.contextmanager
def figure_style(**overrides: Any) -> Iterator[None]:
    """Apply the beatlite style (plus any rcParams overrides) inside a ``with`` block.

    Parameters
    ----------
    **overrides
        rcParams to change on top of :data:`STYLE`; their names contain dots, so
        pass them as ``figure_style(**{"font.size": 12})``.

    Yields
    ------
    None
        Figures created inside the block use the style; rcParams are restored on exit.

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> before = plt.rcParams["font.size"]
    >>> with figure_style(**{"font.size": 12}):
    ...     plt.rcParams["font.size"], plt.rcParams["savefig.dpi"], plt.rcParams["legend.frameon"]
    (12.0, 150.0, False)
    >>> plt.rcParams["font.size"] == before
    True
    """
    import matplotlib.pyplot as plt

    params = dict(STYLE)
    params.update(overrides)
    with plt.rc_context(params):
        yield


def save_figure(
    fig: Any,
    path_stem: str | os.PathLike[str],
    formats: Sequence[str] = ("png", "svg"),
    *,
    fit: tuple[float, float] | None = None,
    **savefig_kwargs: Any,
) -> list[Path]:
    """Save ``fig`` once per format as ``<path_stem>.<fmt>``, atomically; create the folder if needed.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure to save.
    path_stem : str or Path
        Output path without extension, e.g. ``"build/figures/fig2_emotion"``. A
        suffix that equals one of ``formats`` is dropped (``"a.png"`` -> ``"a"``).
    formats : sequence of str
        File extensions understood by matplotlib (``"png"``, ``"svg"``, ``"pdf"``, ...).
    fit : (float, float), optional
        A box, pixels (width, height), the picture is shown in, scaled down to fit when larger
        (e.g. your slides): its text is checked at that scale. Default: the course's slide,
        :data:`beatlite.viz.check.SLIDE_FIGURE_BOX`, for a figure saved in the course's figure
        folder (:func:`beatlite.report.figures_dir`, where every notebook saves its figures);
        elsewhere (a figure for a paper) none, the picture at its saved size.
    **savefig_kwargs
        Passed to ``fig.savefig`` (``dpi``, ``bbox_inches``, ...); the style's
        ``savefig.*`` rcParams apply otherwise.

    Returns
    -------
    list of Path
        The written files, in the order of ``formats``.

    Raises
    ------
    beatlite.viz.check.FigureError
        With ``BEATLITE_FIGURE_CHECK=raise`` (``make run``, ``make test``), when
        :func:`beatlite.viz.check.check_figure` finds an empty panel, text under
        8 px, two series in one colour or a legend colour nothing is drawn in (nothing
        is written); the default ``warn`` gives a :class:`~beatlite.viz.check.FigureWarning`
        and saves. Text is measured
        at the lower of the saved dpi (150) and the figure's own dpi (100), at which
        a notebook shows the figure inline, and, with a box to fit (``fit``, the course's
        slide for the course's figures), at the scale the box shows it.

    Examples
    --------
    A ``.png`` suffix in the stem is dropped, so one call writes both formats; a figure with an empty panel is
    refused under ``BEATLITE_FIGURE_CHECK=raise`` and nothing more is written:

    >>> import tempfile
    >>> from unittest import mock
    >>> import matplotlib.pyplot as plt
    >>> from beatlite.viz.check import FigureError
    >>> with figure_style():
    ...     fig, ax = plt.subplots()
    ...     _ = ax.plot([0.0, 1.0], [0.0, 30.0])
    ...     _ = ax.set(xlabel="time (s)", ylabel="speed (cm/s)")
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     print([p.name for p in save_figure(fig, Path(tmp) / "speed.png")])
    ...     empty, _ = plt.subplots(1, 2)
    ...     with mock.patch.dict(os.environ, {"BEATLITE_FIGURE_CHECK": "raise"}):
    ...         try:
    ...             save_figure(empty, Path(tmp) / "empty")
    ...         except FigureError as error:
    ...             print(error)
    ...     print(sorted(p.name for p in Path(tmp).iterdir()))
    ['speed.png', 'speed.svg']
    save_figure('empty'): 2 figure problem(s):
      empty panel: axes 1 of 2 shows no data
      empty panel: axes 2 of 2 shows no data
    ['speed.png', 'speed.svg']
    >>> plt.close(fig)
    >>> plt.close(empty)
    """
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure

    if not isinstance(fig, Figure):
        raise TypeError(f"save_figure: fig must be a matplotlib Figure, got {type(fig).__name__}")
    if isinstance(formats, str):
        formats = (formats,)
    if not formats:
        raise ValueError("save_figure: formats must name at least one format, got an empty sequence")
    save_params = {k: v for k, v in STYLE.items() if k.startswith(("savefig.", "svg."))}
    stem = Path(path_stem)
    if stem.suffix.lstrip(".").lower() in {f.lower().lstrip(".") for f in formats}:
        stem = stem.with_suffix("")
    from beatlite.viz.check import check_figure, check_mode, report_problems

    if (mode := check_mode()) != "off":
        dpi = savefig_kwargs.get("dpi", save_params["savefig.dpi"])
        dpi = (
            fig.dpi if dpi == "figure" else min(float(dpi), fig.dpi)
        )  # saved, and shown inline at the figure's dpi
        problems = check_figure(fig, dpi=dpi, fit=_shown_in(stem, fit))
        report_problems(problems, f"save_figure({stem.name!r})", mode)
    stem.parent.mkdir(parents=True, exist_ok=True)
    written = []
    for fmt in formats:
        fmt = fmt.lower().lstrip(".")
        target = stem.parent / f"{stem.name}.{fmt}"
        with atomic_target(target) as tmp, plt.rc_context(save_params):
            fig.savefig(tmp, format=fmt, **savefig_kwargs)
        written.append(target)
    return written


def _shown_in(stem: Path, fit: tuple[float, float] | None) -> tuple[float, float] | None:
    """The box a saved picture is shown in: ``fit``, else the course's slide for a figure of the course's folder."""
    if fit is not None:
        return fit
    from beatlite.report import figures_dir
    from beatlite.viz.check import SLIDE_FIGURE_BOX

    course = figures_dir().expanduser().resolve()
    return SLIDE_FIGURE_BOX if stem.expanduser().resolve().is_relative_to(course) else None


def _named_colour(label: str) -> str | None:
    """The named colour of ``label`` (the longest name it starts with, case-insensitive), or None."""
    low = str(label).strip().lower()
    return next((NAMED_SYSTEM_COLOURS[n] for n in sorted(NAMED_SYSTEM_COLOURS, key=len, reverse=True)
                 if low.startswith(n)), None)  # fmt: skip


def _other_slot(label: str) -> int:
    """The place of an unnamed ``label`` in :data:`OTHER_SYSTEM_COLOURS`: from its name, the same in every run."""
    return zlib.crc32(str(label).strip().lower().encode("utf-8")) % len(OTHER_SYSTEM_COLOURS)


def _lighter(colour: str, step: int) -> str:
    """``colour`` mixed with white: not at all for ``step`` 0, half way for 1, three quarters for 2, ..."""
    from matplotlib.colors import to_hex, to_rgb

    mix = 1.0 - 0.5**step
    return to_hex([c + (1.0 - c) * mix for c in to_rgb(colour)])


def _darker(colour: str, factor: float) -> str:
    """``colour`` with its RGB values times ``factor`` (0-1)."""
    from matplotlib.colors import to_hex, to_rgb

    return to_hex([c * factor for c in to_rgb(colour)])


def system_colour(label: str, index: int = 0) -> str:
    """The colour of a compared system, by its name only, so that it is the same in every figure.

    The systems of the course (ground truth, the baselines, every shipped recipe's
    row) have their own colours (:data:`NAMED_SYSTEM_COLOURS`); any other name (a
    model you add) gets one of :data:`OTHER_SYSTEM_COLOURS`, which none of the
    course's systems uses, chosen from the name (a checksum, not Python's salted
    ``hash``): the same in every figure and every run. Two such names may share a
    colour here: a figure with several systems uses :func:`system_colours`.

    Parameters
    ----------
    label : str
        System name, e.g. ``"CaMN"``, ``"HA2G (ours)"``, ``"ground truth"``; the
        longest known name it starts with decides (case-insensitive).
    index : int
        Ignored: kept so that calls that passed a system's position still work
        (a colour no longer depends on the figure).

    Returns
    -------
    str
        A hex colour.

    Examples
    --------
    >>> system_colour("CaMN (tiny)"), system_colour("ground truth"), system_colour("Random clip")
    ('#1f77b4', '#333333', '#8c564b')
    >>> system_colour("my model") in OTHER_SYSTEM_COLOURS
    True
    """
    named = _named_colour(label)
    return named if named is not None else OTHER_SYSTEM_COLOURS[_other_slot(label)]


def system_colours(labels: Sequence[str]) -> list[str]:
    """One distinct colour per system of a figure: each the colour of :func:`system_colour` where it is free.

    Named systems take their colours; a label whose named colour is already taken
    by a shorter label of the list (e.g. an ablation beside its full model) gets a
    shade of it (lighter, darker, lighter still), and a fifth row of one system a
    colour none of the figure's labels has. The other labels take their own colour
    from :data:`OTHER_SYSTEM_COLOURS` unless another of them has it; then, in
    alphabetical order, the next free one (lighter shades once all six are used).
    The colours do not depend on the order of ``labels`` (e.g. rows ranked by a
    score), and up to 24 labels never share one.

    Parameters
    ----------
    labels : sequence of str
        The systems, in the figure's order.

    Returns
    -------
    list of str
        Hex colours, one per label; equal labels get equal colours.

    Examples
    --------
    >>> system_colours(["Ground truth", "Ground truth (141 Euler channels)", "CaMN", "Mean pose", "Random clip"])
    ['#333333', '#999999', '#1f77b4', '#999933', '#8c564b']
    >>> system_colours(["CaMN", "CaMN w/o text"])
    ['#1f77b4', '#8fbbda']
    """
    colours: dict[str, str] = {}
    unnamed, overflow = [], []
    by_length = sorted(
        set(labels), key=lambda x: (len(str(x)), str(x).lower(), str(x))
    )  # "CaMN" before "CaMN w/o"
    for label in by_length:
        named = _named_colour(label)
        if named is None:
            unnamed.append(label)
            continue
        shades = (named, _lighter(named, 1), _darker(named, 0.6), _lighter(named, 2))  # rows of one system
        colour = next((c for c in shades if c not in colours.values()), None)
        if colour is None:
            overflow.append(label)  # a fifth row of one system: a free colour of the others, below
        else:
            colours[label] = colour
    n = len(OTHER_SYSTEM_COLOURS)
    taken = set(colours.values())
    for label in [*sorted(unnamed, key=lambda x: (str(x).lower(), str(x))), *overflow]:
        start = _other_slot(label) if label in unnamed else 0
        candidates = (
            _lighter(OTHER_SYSTEM_COLOURS[(start + k) % n], step) for step in range(4) for k in range(n)
        )
        colour = next((c for c in candidates if c not in taken), OTHER_SYSTEM_COLOURS[start])
        taken.add(colour)
        colours[label] = colour
    return [colours[label] for label in labels]


def slide_figsize(
    height_px: float, width_px: float = SLIDE_WIDTH_PX, dpi: float = 100
) -> tuple[float, float]:
    """Figure size in inches of a ``width_px`` x ``height_px`` picture at ``dpi`` (animations, GIFs).

    >>> slide_figsize(540)
    (9.6, 5.4)
    """
    return (float(width_px) / dpi, float(height_px) / dpi)


def legend_outside(ax: Any, where: str = "right", **kwargs: Any) -> Any:
    """Draw ``ax``'s legend outside the data area: right of the axes or in a row above it.

    Parameters
    ----------
    ax : matplotlib Axes
        Axes whose labelled artists make the legend.
    where : {"right", "top"}
        ``"right"``: one column beside the axes, top aligned; ``"top"``: one row
        above the axes (below its title), left aligned.
    **kwargs
        Passed to ``ax.legend`` (``ncols``, ``title``, ``handles``, ...).

    Returns
    -------
    matplotlib.legend.Legend
        The legend (``None`` when the axes has no labelled artist).

    Raises
    ------
    ValueError
        ``where`` is neither ``"right"`` nor ``"top"``.

    Examples
    --------
    ``"top"`` puts every entry in one row, just above the axes (y = 1.01 in axes units):

    >>> import matplotlib.pyplot as plt
    >>> fig, ax = plt.subplots()
    >>> _ = ax.plot([0, 1], [0, 1], label="CaMN")
    >>> _ = ax.plot([0, 1], [1, 0], label="HA2G")
    >>> legend = legend_outside(ax, "top")
    >>> [t.get_text() for t in legend.get_texts()], legend._ncols
    (['CaMN', 'HA2G'], 2)
    >>> legend_outside(fig.add_subplot(2, 2, 4)) is None  # nothing labelled: no legend
    True
    >>> plt.close(fig)
    """
    handles, labels = ax.get_legend_handles_labels()
    if "handles" not in kwargs and not handles:
        return None
    if where == "right":
        place = {"loc": "upper left", "bbox_to_anchor": (1.01, 1.0)}
    elif where == "top":
        n = len(kwargs.get("handles", handles))
        place = {"loc": "lower left", "bbox_to_anchor": (0.0, 1.01), "ncols": n}
    else:
        raise ValueError(f"where must be 'right' or 'top', got {where!r}")
    place.update(kwargs)
    return ax.legend(**place)
