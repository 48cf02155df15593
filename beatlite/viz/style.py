"""One figure style for every beatlite plot, and a helper that saves a figure in several formats.

Nothing here changes matplotlib's global state at import time: apply the style
for a block of code with :func:`figure_style` (a ``plt.rc_context``), or pass
:data:`STYLE` to ``plt.rc_context`` yourself.

The style's rules, which every figure function of :mod:`beatlite.viz` and
:mod:`beatlite.stats` follows:

- **Slide size.** A saved figure is at least :data:`SLIDE_WIDTH_PX` (960) pixels
  wide: the default figure is 6.4 inches at ``savefig.dpi`` 150; animations are
  drawn at :data:`SLIDE_WIDTH_PX` wide (:func:`slide_figsize`).
- **Fonts** readable on a projector: 10-12 pt text, 9 pt ticks and legends.
- **Legends outside the data**: :func:`legend_outside` puts them right of or
  above the axes, never over bars or curves.
- **Units on every axis**: labels read ``"quantity (unit)"``; a count or a
  score without unit says so (``"score (0-1)"``).
- **One colour per system** in every figure: :func:`system_colour` (ground truth
  dark grey, CaMN blue, HA2G orange), and one colour per joint group
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

#: The colour of a system by name (lower case), so that a model keeps its colour in every figure.
NAMED_SYSTEM_COLOURS: Mapping[str, str] = MappingProxyType(
    {
        "ground truth": SYSTEM_COLOURS[0],
        "real": SYSTEM_COLOURS[0],
        "gt": SYSTEM_COLOURS[0],
        "camn": SYSTEM_COLOURS[1],
        "ha2g": SYSTEM_COLOURS[2],
    }
)

#: Colours of systems without a named colour (baselines, new models): never grey, blue or orange.
OTHER_SYSTEM_COLOURS: tuple[str, ...] = (
    "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#bcbd22", "#17becf",  # tab10 without the named systems' colours
    "#393b79", "#637939", "#843c39", "#7b4173",  # tab20b's darkest: distinct, and readable as text on white
)  # fmt: skip

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
        8 px or two series in one colour (nothing is written); the default ``warn``
        gives a :class:`~beatlite.viz.check.FigureWarning` and saves. Text is measured
        at the lower of the saved dpi (150) and the figure's own dpi (100), at which
        a notebook shows the figure inline, and as a slide shows that picture (scaled
        down to :data:`beatlite.viz.check.SLIDE_FIGURE_BOX` when larger).
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
    from beatlite.viz.check import SLIDE_FIGURE_BOX, check_figure, check_mode, report_problems

    if (mode := check_mode()) != "off":
        dpi = savefig_kwargs.get("dpi", save_params["savefig.dpi"])
        dpi = (
            fig.dpi if dpi == "figure" else min(float(dpi), fig.dpi)
        )  # saved, and shown inline at the figure's dpi
        problems = check_figure(fig, dpi=dpi, fit=SLIDE_FIGURE_BOX)
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


def system_colour(label: str, index: int = 0) -> str:
    """The colour of a compared system: by name when known (ground truth, CaMN, HA2G), else by position.

    Parameters
    ----------
    label : str
        System name, e.g. ``"CaMN"``, ``"HA2G (ours)"``, ``"ground truth"``; the
        first word that names a known system decides (case-insensitive).
    index : int
        Position of the system in the figure, used for other names:
        ``OTHER_SYSTEM_COLOURS[index % 10]``, so a baseline never takes the colour of
        ground truth, CaMN or HA2G.

    Returns
    -------
    str
        A hex colour.

    Examples
    --------
    >>> system_colour("CaMN (tiny)"), system_colour("ground truth"), system_colour("mean pose", 1)
    ('#1f77b4', '#333333', '#9467bd')
    """
    low = str(label).lower()
    for name in sorted(NAMED_SYSTEM_COLOURS, key=len, reverse=True):
        if low.startswith(name):
            return NAMED_SYSTEM_COLOURS[name]
    return OTHER_SYSTEM_COLOURS[int(index) % len(OTHER_SYSTEM_COLOURS)]


def system_colours(labels: Sequence[str]) -> list[str]:
    """One distinct colour per system of a figure: named systems by name, the others in turn.

    Unlike ``system_colour(label, index)`` with the position in the figure, the
    systems without a named colour count only among themselves, so up to ten of
    them never share a colour, whatever the order (e.g. rows ranked by a score).
    A label whose named colour is already taken by another label of the list (e.g.
    a second ground-truth row) gets a lighter shade of it.

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
    >>> system_colours(["Ground truth", "Ground truth (141 channels)", "CaMN", "Mean pose", "Random clip"])
    ['#333333', '#999999', '#1f77b4', '#2ca02c', '#9467bd']
    """
    from matplotlib.colors import to_hex, to_rgb

    colours: dict[str, str] = {}
    unnamed = 0
    for label in labels:
        if label in colours:
            continue
        low = str(label).lower()
        named = next((NAMED_SYSTEM_COLOURS[n] for n in sorted(NAMED_SYSTEM_COLOURS, key=len, reverse=True)
                      if low.startswith(n)), None)  # fmt: skip
        if named is None:
            colours[label] = OTHER_SYSTEM_COLOURS[unnamed % len(OTHER_SYSTEM_COLOURS)]
            unnamed += 1
            continue
        colour, lighter = named, 0
        while colour in colours.values() and lighter < 3:  # a second row of a named system: a lighter shade
            lighter += 1
            mix = 1.0 - 0.5**lighter
            colour = to_hex([c + (1.0 - c) * mix for c in to_rgb(named)])
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
