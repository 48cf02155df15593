"""One check of a finished figure: empty panels, text too small to read, two series in one colour, a legend
colour nothing is drawn in.

:func:`check_figure` returns the problems it finds, as :class:`FigureProblem` records;
:func:`beatlite.viz.style.save_figure` calls it on every figure it saves and warns
(:class:`FigureWarning`) or raises (:class:`FigureError`) as ``BEATLITE_FIGURE_CHECK`` says
(``warn``, the default; ``raise``, set by ``make run``, ``make test`` and the test suite; ``off``).

What counts as a problem:

- **empty panel**: a visible axes that shows no data (no line with a finite point, no patch,
  image or non-empty collection), e.g. one that only says "nothing here yet"; an axes switched
  off with nothing in it at all is a blank space, not a panel, and passes;
- **small text**: a visible, non-empty text (titles, labels, tick labels, legend entries,
  annotations) whose font is smaller than :data:`MIN_TEXT_PX` pixels at the saved size
  (font size in points x dpi / 72; for mathtext, its smallest symbols: a sub- or superscript
  is drawn at 0.7 of the font size) or, with ``fit``, once the picture is scaled down to fit
  that box (:data:`SLIDE_FIGURE_BOX`, the most a slide of the course shows: a figure much taller
  than wide is shown small, its text with it);
- **shared colour**: two labelled series (lines, bars, scatter points, filled areas with
  different labels, as in a legend) of one axes or of the figure's legends drawn in the same
  colour; the same label in several panels is one series and may keep its colour. Where a
  legend is drawn, its own entries count, proxy handles (``Line2D([], [], ...)``, ``Patch``) too;
- **legend colour**: a legend entry in a colour that nothing of the figure is drawn in (no
  line, marker, bar, area or image pixel), e.g. a proxy handle left in another colour than its series.

>>> import matplotlib.pyplot as plt
>>> fig, (a, b) = plt.subplots(1, 2)
>>> _ = a.plot([0, 1], [0, 1], color="C0", label="CaMN")
>>> _ = a.plot([0, 1], [1, 0], color="C0", label="mean pose")
>>> _ = b.text(0.5, 0.5, "no data yet", fontsize=3)
>>> for problem in check_figure(fig, dpi=150):
...     print(problem)
empty panel: axes 2 of 2 shows no data (its text: 'no data yet')
small text: 'no data yet' is 6.2 px high at 150 dpi (under 8 px)
shared colour: axes 1 of 2: 'CaMN' and 'mean pose' are both #1f77b4
>>> plt.close(fig)

Used on every figure the notebooks save (``bl.viz.save_figure``, first in notebooks/00_setup_and_tour.ipynb)
and on the animation players of notebooks 05 and 08 (``to_html(dpi=80)``).
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

from beatlite.paths import env_choice

#: Smallest readable font size, pixels of the saved (or shown) picture.
MIN_TEXT_PX = 8.0

#: The largest picture a slide shows at its own size, pixels (width, height): the output column of the
#: course's 1280 x 800 slides and their figures' height limit (``scripts/build_site.py`` reads both from here: its
#: CSS max-height and its slide-height estimates); a larger picture is scaled down to fit, its text with it.
SLIDE_FIGURE_BOX = (1089, 600)

#: Two colours closer than this in every RGB channel (0-1) count as one colour.
COLOUR_TOLERANCE = 0.02

#: ``BEATLITE_FIGURE_CHECK`` values: what :func:`beatlite.viz.style.save_figure` does with problems.
CHECK_MODES = ("warn", "raise", "off")


class FigureWarning(UserWarning):
    """A saved figure has a problem :func:`check_figure` flags (``BEATLITE_FIGURE_CHECK=warn``)."""


class FigureError(ValueError):
    """A saved figure has a problem :func:`check_figure` flags (``BEATLITE_FIGURE_CHECK=raise``)."""


@dataclass(frozen=True)
class FigureProblem:
    """One problem of a figure: ``kind`` is ``"empty panel"``, ``"small text"``, ``"shared colour"`` or
    ``"legend colour"``."""

    kind: str
    detail: str

    def __str__(self) -> str:
        return f"{self.kind}: {self.detail}"


def check_mode() -> str:
    """``BEATLITE_FIGURE_CHECK`` (``warn`` when unset): ``warn``, ``raise`` or ``off``.

    Case and surrounding spaces are ignored; read at every call.

    Raises
    ------
    ValueError
        Any other value.

    Examples
    --------
    >>> import os
    >>> from unittest import mock
    >>> with mock.patch.dict(os.environ, {"BEATLITE_FIGURE_CHECK": " Raise "}):
    ...     check_mode()
    'raise'
    >>> with mock.patch.dict(os.environ, {"BEATLITE_FIGURE_CHECK": ""}):
    ...     check_mode()
    'warn'
    """
    return env_choice("BEATLITE_FIGURE_CHECK", CHECK_MODES)


def check_figure(
    fig: Any,
    *,
    dpi: float | None = None,
    min_text_px: float = MIN_TEXT_PX,
    fit: tuple[float, float] | None = None,
) -> list[FigureProblem]:
    """The problems of a figure as it will be saved: empty panels, small text, shared and legend colours.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        A finished figure (drawn once here, so that tick labels exist).
    dpi : float, optional
        Resolution of the saved picture, dots per inch; default ``rcParams["savefig.dpi"]``
        (``"figure"`` means the figure's own dpi). Animations pass the dpi of their frames.
    min_text_px : float
        Smallest font size allowed, pixels at ``dpi``.
    fit : (float, float), optional
        A box, pixels (width, height), the picture is shown in, scaled down to fit when larger
        (e.g. :data:`SLIDE_FIGURE_BOX`): text is measured at that scale. The picture's size is
        the figure's tight bounding box (``savefig.bbox="tight"``) at ``dpi``.

    Returns
    -------
    list of FigureProblem
        Empty when the figure passes; in figure order (axes by axes).

    Examples
    --------
    A font of ``s`` points is ``s * dpi / 72`` pixels high: at 150 dpi, 4 pt is 8.3 px and passes the 8 px
    limit, 3.5 pt is 7.3 px and does not:

    >>> import matplotlib.pyplot as plt
    >>> fig, ax = plt.subplots()
    >>> _ = ax.plot([0, 1], [0, 1])
    >>> _ = ax.tick_params(labelsize=9)
    >>> _ = ax.set_xlabel("time (s)", fontsize=4)
    >>> check_figure(fig, dpi=150)
    []
    >>> _ = ax.set_xlabel("time (s)", fontsize=3.5)
    >>> [str(p) for p in check_figure(fig, dpi=150)]
    ["small text: 'time (s)' is 7.3 px high at 150 dpi (under 8 px)"]
    >>> plt.close(fig)
    """
    import matplotlib as mpl
    from matplotlib.figure import Figure

    if not isinstance(fig, Figure):
        raise TypeError(f"check_figure: fig must be a matplotlib Figure, got {type(fig).__name__}")
    if dpi is None or dpi == "figure":
        saved = mpl.rcParams["savefig.dpi"] if dpi is None else "figure"
        dpi = fig.dpi if saved == "figure" else float(saved)
    fig.canvas.draw()  # tick labels and layouts are final only after a draw
    axes = [ax for ax in fig.axes if ax.get_visible()]
    problems = [p for i, ax in enumerate(axes) if (p := _empty_panel(ax, i, len(axes)))]
    problems += _small_texts(fig, float(dpi), float(min_text_px), _fit_scale(fig, float(dpi), fit))
    legends = [(f"axes {i + 1} of {len(axes)}", ax, ax.get_legend()) for i, ax in enumerate(axes)]
    legends += [("figure legend", None, legend) for legend in fig.legends]
    drawn = _drawn_colours(axes)
    for where, ax, legend in legends:
        # what a legend shows: its own entries (proxy handles too), else the axes' labelled artists
        shown = _series(ax) if legend is None else _legend_series(legend)
        problems += _shared_colours(shown, where)
        if legend is not None and drawn is not None:
            problems += _unplotted_colours(shown, drawn, where)
    return problems


def report_problems(problems: Iterable[FigureProblem], what: str, mode: str | None = None) -> None:
    """Warn (:class:`FigureWarning`) or raise (:class:`FigureError`) about ``problems``, as ``mode`` says.

    ``mode`` defaults to :func:`check_mode`; nothing happens when there is no problem or the mode is ``off``.

    Parameters
    ----------
    problems : iterable of FigureProblem
        What :func:`check_figure` found.
    what : str
        The figure, for the message (e.g. ``"save_figure('fig2')"``).
    mode : {"warn", "raise", "off"}, optional

    Examples
    --------
    >>> problem = FigureProblem("empty panel", "axes 1 of 1 shows no data")
    >>> report_problems([problem], "fig2", mode="raise")
    Traceback (most recent call last):
    ...
    beatlite.viz.check.FigureError: fig2: 1 figure problem(s):
      empty panel: axes 1 of 1 shows no data
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     report_problems([problem], "fig2", mode="warn")
    ...     report_problems([problem], "fig2", mode="off")
    >>> [w.category.__name__ for w in caught]
    ['FigureWarning']
    """
    problems = list(problems)
    mode = check_mode() if mode is None else mode
    if not problems or mode == "off":
        return
    text = f"{what}: {len(problems)} figure problem(s):\n  " + "\n  ".join(map(str, problems))
    if mode == "raise":
        raise FigureError(text)
    warnings.warn(text, FigureWarning, stacklevel=3)


# ---------------------------------------------------------------------------------------------------------------


def _has_data(artist: Any) -> bool:
    """Whether an artist draws data: a line with a finite point, a non-empty collection, a patch or an image."""
    from matplotlib.collections import Collection
    from matplotlib.lines import Line2D

    if not artist.get_visible():
        return False
    if isinstance(artist, Line2D):
        xy = np.asarray(artist.get_xydata(), dtype=float)
        return bool(xy.size and np.isfinite(xy).all(axis=-1).any())
    if isinstance(artist, Collection):
        return len(artist.get_paths()) > 0 or len(artist.get_offsets()) > 0
    return True


def _empty_panel(ax: Any, index: int, n: int) -> FigureProblem | None:
    data = [a for a in (*ax.lines, *ax.patches, *ax.collections, *ax.images, *ax.tables) if _has_data(a)]
    if data:
        return None
    texts = [t.get_text() for t in ax.texts if t.get_visible() and t.get_text().strip()]
    if not ax.axison and not texts and not ax.get_title() and ax.get_legend() is None:
        return None  # a blank space left in a grid, nothing drawn
    said = f" (its text: {texts[0]!r})" if texts else ""
    return FigureProblem("empty panel", f"axes {index + 1} of {n} shows no data{said}")


def _fit_scale(fig: Any, dpi: float, fit: tuple[float, float] | None) -> tuple[float, str]:
    """How much the picture shrinks to fit ``fit`` (1 when it fits or no box is given) and how to say it."""
    if fit is None:
        return 1.0, ""
    box = fig.get_tightbbox(fig.canvas.get_renderer()).padded(0.1)  # savefig's tight box and pad, inches
    width, height = box.width * dpi, box.height * dpi
    scale = min(1.0, fit[0] / width, fit[1] / height)
    if scale >= 1.0:
        return 1.0, ""
    return scale, f", shown at {scale:.0%} of {width:.0f} x {height:.0f} px to fit {fit[0]:g} x {fit[1]:g}"


def _small_texts(
    fig: Any, dpi: float, min_px: float, fit: tuple[float, str] = (1.0, "")
) -> list[FigureProblem]:
    problems = []
    seen: set[tuple[str, float]] = set()
    scale, shown = fit
    for name, text in _drawn_texts(fig):
        shrink = _math_shrink(text)
        px = text.get_fontsize() * dpi / 72.0 * scale * shrink
        if px < min_px and (name, px) not in seen:
            seen.add((name, px))
            verb = "are" if name.startswith("tick labels") else "is"
            math = " (its smallest math symbols)" if shrink < 1.0 else ""
            problems.append(
                FigureProblem(
                    "small text",
                    f"{name} {verb} {px:.1f} px high{math} at {dpi:g} dpi{shown} (under {min_px:g} px)",
                )
            )
    return problems


@functools.cache
def _math_parser() -> Any:
    from matplotlib.mathtext import MathTextParser

    return MathTextParser("path")


def _math_shrink(text: Any) -> float:
    """The smallest glyph of a text over its font size: 1 for plain text; for mathtext (``$x_0$``) the scale of its
    sub/superscripts and fractions (0.7, 0.49 a level deeper: mathtext's shrink factor), read from its layout."""
    from matplotlib import cbook

    words = text.get_text()
    if text.get_usetex() or not text.get_parse_math() or not cbook.is_math_text(words):
        return 1.0
    prop = text.get_fontproperties()
    try:
        sizes = [glyph[1] for glyph in _math_parser().parse(words, dpi=72, prop=prop).glyphs]
    except ValueError:  # not valid mathtext: drawing it fails on its own
        return 1.0
    return min(1.0, min(sizes) / prop.get_size_in_points()) if sizes else 1.0


def _drawn_texts(fig: Any) -> list[tuple[str, Any]]:
    """(name, Text) of the visible texts a saved figure shows: figure texts and legends, and per visible
    axes its titles, texts, legend and, when its axis is on, axis labels and tick labels."""
    texts = [
        *fig.texts,
        *(t for legend in fig.legends if legend.get_visible() for t in _legend_texts(legend)),
    ]
    texts += [
        t for name in ("_suptitle", "_supxlabel", "_supylabel") if (t := getattr(fig, name, None)) is not None
    ]
    ticks: list[tuple[str, Any]] = []
    axes = [ax for ax in fig.axes if ax.get_visible()]
    for i, ax in enumerate(axes):
        texts += [ax.title, getattr(ax, "_left_title", None), getattr(ax, "_right_title", None), *ax.texts]
        legend = ax.get_legend()
        if legend is not None and legend.get_visible():
            texts += _legend_texts(legend)
        if not ax.axison:
            continue
        for n in "xyz":
            axis = getattr(ax, f"{n}axis", None)
            if axis is not None and axis.get_visible():
                texts += [axis.label, axis.get_offset_text()]
                name = f"tick labels of axes {i + 1} of {len(axes)} ({n} axis)"
                ticks += [(name, t) for t in axis.get_ticklabels(which="both")]
    named = [(_quote(t.get_text()), t) for t in texts if t is not None]
    return [(name, t) for name, t in [*named, *ticks] if t.get_visible() and t.get_text().strip()]


def _quote(words: str) -> str:
    words = words.strip()
    return repr(words if len(words) <= 40 else words[:37] + "...")


def _legend_texts(legend: Any) -> list[Any]:
    return [*legend.get_texts(), legend.get_title()]


def _series(ax: Any) -> list[tuple[str, tuple[float, float, float]]]:
    """(label, colour) of each labelled artist of ``ax`` (what a legend would show)."""
    handles, labels = ax.get_legend_handles_labels()
    return [(label, c) for h, label in zip(handles, labels, strict=True) if (c := _colour(h)) is not None]


def _legend_series(legend: Any) -> list[tuple[str, tuple[float, float, float]]]:
    """(label, colour) of each entry a legend shows, from the handles it draws (proxy artists included)."""
    pairs = zip(legend.legend_handles, (t.get_text() for t in legend.get_texts()), strict=False)
    return [(label, c) for h, label in pairs if (c := _colour(h)) is not None]


def _drawn_colours(axes: list[Any]) -> np.ndarray | None:
    """(K, 3) RGB of everything the axes draw as data (line, marker, face and edge colours, image pixels), or
    None when an image's colours cannot be read (then any legend colour may be in it)."""
    from matplotlib.colors import to_rgba, to_rgba_array
    from matplotlib.image import AxesImage
    from matplotlib.lines import Line2D

    found = [np.zeros((0, 4))]
    for ax in axes:
        for artist in (a for a in (*ax.lines, *ax.patches, *ax.collections, *ax.images) if _has_data(a)):
            try:
                if isinstance(artist, Line2D):
                    rgba = [to_rgba(c) for c in (artist.get_color(), artist.get_mfc(), artist.get_mec())]
                elif isinstance(artist, AxesImage):
                    rgba = artist.to_rgba(artist.get_array()).reshape(-1, 4)
                    rgba = rgba / 255.0 if rgba.dtype == np.uint8 else rgba
                else:
                    rgba = [*to_rgba_array(artist.get_facecolor()), *to_rgba_array(artist.get_edgecolor())]
            except (AttributeError, ValueError, TypeError):
                if isinstance(artist, AxesImage):
                    return None
                continue
            found.append(np.asarray(rgba, dtype=float).reshape(-1, 4))
    rgba = np.concatenate(found)
    return np.unique(rgba[rgba[:, 3] > 0, :3], axis=0)


def _unplotted_colours(
    shown: list[tuple[str, tuple[float, float, float]]], drawn: np.ndarray, where: str
) -> list[FigureProblem]:
    """A legend entry in a colour that nothing of the figure is drawn in (a proxy handle that matches no series)."""
    from matplotlib.colors import to_hex

    problems = []
    for label, colour in dict(shown).items():
        if not len(drawn) or np.abs(drawn - np.asarray(colour)).max(axis=1).min() >= COLOUR_TOLERANCE:
            problems.append(
                FigureProblem(
                    "legend colour", f"{where}: {label!r} is {to_hex(colour)}, a colour no plotted series has"
                )
            )
    return problems


def _colour(artist: Any) -> tuple[float, float, float] | None:
    """The RGB colour that identifies a series: a line's colour (a marker-only line's marker face, else edge
    colour), a bar's or point's face (else edge) colour."""
    from matplotlib.colors import to_rgba
    from matplotlib.container import Container
    from matplotlib.lines import Line2D

    if isinstance(artist, Container):
        children = [a for a in artist if a is not None]
        artist = children[0] if children else None
    if artist is None:
        return None
    try:
        if isinstance(artist, Line2D):
            rgba = to_rgba(artist.get_color())
            if artist.get_linestyle() == "None" and str(artist.get_marker()).lower() not in ("none", ""):
                face = to_rgba(artist.get_markerfacecolor())
                rgba = face if face[3] > 0 else to_rgba(artist.get_markeredgecolor())
        else:
            faces = np.atleast_2d(artist.get_facecolor())
            if not faces.size or faces[0, 3] == 0:
                faces = np.atleast_2d(artist.get_edgecolor())
            if not faces.size:
                return None
            rgba = tuple(faces[0])
    except (AttributeError, ValueError, TypeError):
        return None
    return (float(rgba[0]), float(rgba[1]), float(rgba[2]))


def _shared_colours(series: list[tuple[str, tuple[float, float, float]]], where: str) -> list[FigureProblem]:
    from matplotlib.colors import to_hex

    problems = []
    first: list[tuple[str, tuple[float, float, float]]] = []
    for label, colour in series:
        same = [
            other
            for other, c in first
            if other != label and max(abs(a - b) for a, b in zip(c, colour)) < COLOUR_TOLERANCE
        ]
        if same:
            problems.append(
                FigureProblem(
                    "shared colour", f"{where}: {same[0]!r} and {label!r} are both {to_hex(colour)}"
                )
            )
        if all(other != label for other, _ in first):
            first.append((label, colour))
    return problems
