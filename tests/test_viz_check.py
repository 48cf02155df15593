"""beatlite.viz.check: each problem found on a purposely bad figure and not on a good one; save_figure runs it."""

from __future__ import annotations

import re
import warnings

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from beatlite.viz import check, style  # noqa: E402


def good_figure() -> plt.Figure:
    """Two panels with data, 9-12 pt text, three series in three colours (and one label in both panels)."""
    with style.figure_style():
        fig, (a, b) = plt.subplots(1, 2, figsize=(6.4, 3.0), layout="constrained")
        t = np.linspace(0, 1, 20)
        a.plot(t, t, color="C0", label="CaMN")
        a.plot(t, t**2, color="C1", label="HA2G")
        a.set(xlabel="time (s)", ylabel="score (0-1)", title="curves")
        style.legend_outside(a, "top")
        b.bar([0, 1], [1.0, 2.0], color=["C2", "C3"])
        b.plot(t, t, color="C0", label="CaMN")  # the same series in another panel keeps its colour
        b.set_ylabel("FGD")
        b.axvline(np.nan, color="C1", label="legend only")  # no finite point, but another colour
        b.axis("on")
    return fig


def kinds(problems: list[check.FigureProblem]) -> list[str]:
    return [p.kind for p in problems]


def test_a_good_figure_has_no_problem():
    fig = good_figure()
    assert check.check_figure(fig, dpi=150) == []
    plt.close(fig)


def test_a_panel_that_only_says_nothing_is_here_is_empty_and_a_blank_grid_cell_is_not():
    fig, axes = plt.subplots(1, 4, figsize=(8, 2))
    axes[0].plot([0, 1], [0, 1])
    axes[1].text(0.5, 0.5, "no bones here yet", transform=axes[1].transAxes)
    axes[1].axis("off")  # switched off, but it shows words: a panel without data
    axes[2].axvline(np.nan, label="only a legend entry")  # a line with no finite point draws nothing
    axes[3].axis("off")  # an unused grid cell: nothing at all is drawn there
    problems = check.check_figure(fig, dpi=150)
    assert kinds(problems) == ["empty panel", "empty panel"]
    assert "axes 2 of 4" in problems[0].detail and "no bones here yet" in problems[0].detail
    assert "axes 3 of 4" in problems[1].detail
    plt.close(fig)


@pytest.mark.parametrize(("points", "dpi", "small"), [(5.0, 100, True), (5.0, 150, False), (3.5, 150, True)])
def test_text_under_8_px_at_the_saved_dpi_is_flagged(points, dpi, small):
    # 5 pt at 100 dpi = 6.94 px; at 150 dpi 10.4 px; 3.5 pt at 150 dpi = 7.29 px
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    ax.set_xlabel("time (s)", fontsize=points)
    problems = check.check_figure(fig, dpi=dpi)
    assert kinds(problems) == (["small text"] if small else [])
    if small:
        assert f"{points * dpi / 72:.1f} px" in problems[0].detail and "'time (s)'" in problems[0].detail
    plt.close(fig)


@pytest.mark.parametrize(
    ("label", "points", "shrink"),
    [
        (r"$x_0$ error", 8, 0.7),  # 7.8 px: flagged
        (r"$x_0$ error", 9, 0.7),  # 8.75 px
        (r"$x_{a_b}$", 10, 0.7**2),  # 6.8 px: flagged
        (r"$\epsilon$ error", 8, 1.0),  # 11.1 px: no script
    ],
)
def test_mathtext_subscripts_are_measured_at_the_size_they_are_drawn(label, points, shrink):
    """Mathtext draws a sub- or superscript at 0.7 of the font size (0.7**2 a level deeper): an 8-pt ``$x_0$``
    legend entry at 100 dpi has 11.1 px letters but a 7.8 px subscript (before: measured at the font size, it
    passed, as notebook 10's legends did)."""
    fig, ax = plt.subplots(dpi=100)
    ax.plot([0, 1], [0, 1], label=label)
    ax.legend(fontsize=points)
    problems = check.check_figure(fig, dpi=100)
    px = points * 100 / 72 * shrink
    if px < 8:
        assert [str(p) for p in problems] == [
            f"small text: {label!r} is {px:.1f} px high (its smallest math symbols) at 100 dpi (under 8 px)"
        ]
    else:
        assert problems == []
    plt.close(fig)


def test_small_tick_labels_of_a_hidden_axis_are_not_text_on_the_picture():
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    ax.tick_params(labelsize=3)
    # 3 pt at 150 dpi: 6.25 px; one problem per axis, not one per tick label
    problems = check.check_figure(fig, dpi=150)
    assert [p.detail for p in problems] == [
        f"tick labels of axes 1 of 1 ({a} axis) are 6.2 px high at 150 dpi (under 8 px)" for a in "xy"
    ]
    ax.axis("off")
    assert check.check_figure(fig, dpi=150) == []
    plt.close(fig)


def test_the_default_dpi_is_the_saved_one():
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    ax.set_title("t", fontsize=5)  # 6.9 px at 100 dpi, 10.4 px at 150 dpi
    with plt.rc_context({"savefig.dpi": 100}):
        assert kinds(check.check_figure(fig)) == ["small text"]
    with plt.rc_context({"savefig.dpi": 150}):
        assert check.check_figure(fig) == []
    plt.close(fig)


def test_two_series_in_one_colour_are_flagged_lines_bars_and_points():
    fig, (a, b, c) = plt.subplots(1, 3)
    a.plot([0, 1], [0, 1], color="#9467bd", label="Random clip")
    a.plot([0, 1], [1, 0], color="#9467bd", label="Mean pose")
    b.bar([0], [1.0], color="#2ca02c", label="S2G")
    b.bar([1], [2.0], color="#2ca02d", label="A2G")  # 1/255 apart in green: one colour to the eye
    c.scatter([0], [1], color="#1f77b4", label="CaMN")
    c.scatter([1], [1], color="#ff7f0e", label="HA2G")
    problems = check.check_figure(fig, dpi=150)
    assert kinds(problems) == ["shared colour", "shared colour"]
    assert "'Random clip' and 'Mean pose'" in problems[0].detail and "#9467bd" in problems[0].detail
    assert "axes 2 of 3" in problems[1].detail and "'S2G' and 'A2G'" in problems[1].detail
    plt.close(fig)


def test_a_figure_legend_with_two_entries_in_one_colour_is_flagged():
    fig, (a, b) = plt.subplots(1, 2)
    first = a.plot([0, 1], [0, 1], color="C0")[0]
    second = b.plot([0, 1], [1, 0], color="C0")[0]
    fig.legend([first, second], ["train", "validation"])
    problems = check.check_figure(fig, dpi=150)
    assert kinds(problems) == ["shared colour"] and "figure legend" in problems[0].detail
    plt.close(fig)


def test_legend_entries_made_with_proxy_handles_are_checked_for_colour():
    """Legend entries that are no artist of the axes (``Line2D([], [], ...)``, ``Patch``): two in one colour, or one in
    a colour nothing is drawn in, are flagged as for any series (before: neither was reported, the check read the
    axes' labelled artists only)."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    fig, (a, b, c) = plt.subplots(1, 3, figsize=(9, 3))
    a.plot([0, 1], [0, 1], color="#1f77b4")
    a.plot([0, 1], [1, 0], color="#ff7f0e")
    a.legend(
        handles=[Line2D([], [], color="#1f77b4", label="CaMN"), Line2D([], [], color="#1f77b4", label="HA2G")]
    )
    b.bar([0, 1], [1.0, 2.0], color=["#1f77b4", "#ff7f0e"])
    b.legend(
        handles=[Patch(color="#1f77b4", label="CaMN"), Patch(color="#2ca02c", label="S2G")]
    )  # no green bar
    c.scatter([0, 1], [0, 1], color="#9467bd")
    fig.legend(handles=[Line2D([], [], marker="o", ls="", color="w", markerfacecolor="#8c564b", label="A2G")])
    problems = check.check_figure(fig, dpi=150)
    assert [str(p) for p in problems] == [
        "shared colour: axes 1 of 3: 'CaMN' and 'HA2G' are both #1f77b4",
        "legend colour: axes 2 of 3: 'S2G' is #2ca02c, a colour no plotted series has",
        "legend colour: figure legend: 'A2G' is #8c564b, a colour no plotted series has",  # its marker's face
    ]
    plt.close(fig)


def test_proxy_legend_entries_in_the_colours_drawn_pass():
    """The usual proxies: a marker-only line for scatter points (white line, coloured face), a patch per bar colour
    (plot_annotation_timeline), an event line drawn many times with one legend entry (a NaN line), an image's
    colours."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    fig, (a, b, c) = plt.subplots(1, 3, figsize=(9, 3))
    a.scatter([0, 1], [0, 1], color="#9467bd")
    a.axvline(np.nan, color="#d62728", label="beats")
    for x in (0.2, 0.6):
        a.axvline(x, color="#d62728", alpha=0.6)
    a.legend(handles=[Line2D([], [], marker="o", ls="", color="w", markerfacecolor="#9467bd", label="points"),
                      *a.get_legend_handles_labels()[0]])  # fmt: skip
    b.bar([0, 1], [1.0, 2.0], color=["#1f77b4", "#ff7f0e"], ec="white")
    b.legend(handles=[Patch(color="#1f77b4", label="CaMN"), Patch(color="#ff7f0e", label="HA2G")])
    c.imshow(np.array([[0, 1], [2, 2]]), cmap=plt.cm.tab10, vmin=0, vmax=9)
    c.legend(handles=[Patch(color=plt.cm.tab10(k), label=f"class {k}") for k in range(3)])
    assert check.check_figure(fig, dpi=150) == []
    plt.close(fig)


def bad_figure() -> plt.Figure:
    fig, (a, b) = plt.subplots(1, 2)
    a.plot([0, 1], [0, 1])
    b.text(0.5, 0.5, "nothing yet")
    return fig


def test_save_figure_raises_warns_or_stays_quiet_as_beatlite_figure_check_says(tmp_path, monkeypatch):
    fig = bad_figure()
    monkeypatch.setenv("BEATLITE_FIGURE_CHECK", "raise")
    with pytest.raises(check.FigureError, match="empty panel: axes 2 of 2"):
        style.save_figure(fig, tmp_path / "bad")
    assert list(tmp_path.iterdir()) == []  # nothing written
    monkeypatch.setenv("BEATLITE_FIGURE_CHECK", "warn")
    with pytest.warns(check.FigureWarning, match="save_figure\\('warned'\\): 1 figure problem"):
        written = style.save_figure(fig, tmp_path / "warned", formats=("png",))
    assert [p.name for p in written] == ["warned.png"] and written[0].stat().st_size > 0
    monkeypatch.setenv("BEATLITE_FIGURE_CHECK", "off")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        style.save_figure(fig, tmp_path / "quiet", formats=("png",))
    monkeypatch.setenv("BEATLITE_FIGURE_CHECK", "loud")
    with pytest.raises(ValueError, match="BEATLITE_FIGURE_CHECK"):
        style.save_figure(fig, tmp_path / "x", formats=("png",))
    plt.close(fig)


def test_save_figure_checks_text_at_the_dpi_it_saves_with(tmp_path, monkeypatch):
    monkeypatch.setenv("BEATLITE_FIGURE_CHECK", "raise")
    fig, ax = plt.subplots(dpi=100)
    ax.plot([0, 1], [0, 1])
    ax.set_xlabel("x (cm)", fontsize=7)  # 14.6 px at the style's 150 dpi, 9.7 px at 100, 5.8 px at 60
    style.save_figure(fig, tmp_path / "fine", formats=("png",))
    with pytest.raises(check.FigureError, match="small text: 'x \\(cm\\)' is 5.8 px high at 60 dpi"):
        style.save_figure(fig, tmp_path / "coarse", formats=("png",), dpi=60)
    plt.close(fig)


def test_save_figure_checks_text_at_the_size_a_notebook_shows_it_inline_too(tmp_path, monkeypatch):
    """A notebook shows a figure at its own dpi (IPython's inline PNG); saved at 150 dpi it may be larger."""
    monkeypatch.setenv("BEATLITE_FIGURE_CHECK", "raise")
    fig, ax = plt.subplots(dpi=60)
    ax.plot([0, 1], [0, 1])
    ax.set_xlabel("x (cm)", fontsize=9)  # 18.8 px in the 150-dpi file, 7.5 px inline at 60 dpi
    with pytest.raises(check.FigureError, match="'x \\(cm\\)' is 7.5 px high at 60 dpi"):
        style.save_figure(fig, tmp_path / "coarse", formats=("png",))
    fig.set_dpi(100)  # 12.5 px inline
    style.save_figure(fig, tmp_path / "fine", formats=("png",))
    plt.close(fig)


@pytest.mark.parametrize("size, flagged", [((4, 16), True), ((16, 4), False), ((6, 4), False)])
def test_text_a_slide_shrinks_under_8_px_is_flagged(size, flagged):
    """A slide shows a figure at most SLIDE_FIGURE_BOX (1089 x 600 px): one 16 in high at 100 dpi (its tight box
    70-100 % of 1600 px: the default margins cropped) is shown at under half its size, so its 10-pt labels
    (13.9 px inline) come out under 8 px; 16 in wide it is shown at over 68 %, its labels over 9 px."""
    fig, ax = plt.subplots(figsize=size, dpi=100)
    ax.plot([0, 1], [0, 1])
    ax.set_xlabel("time (s)", fontsize=10)
    ax.tick_params(labelsize=10)
    assert check.check_figure(fig, dpi=100) == []  # at its own size it is fine
    problems = check.check_figure(fig, dpi=100, fit=check.SLIDE_FIGURE_BOX)
    assert bool(problems) == flagged, problems
    if flagged:
        px = [float(m) for p in problems for m in re.findall(r"is ([0-9.]+) px high", str(p))]
        low, high = 10 * 100 / 72 * 600 / 1600, 10 * 100 / 72 * 600 / (0.7 * 1600)
        assert px and all(low <= v <= high for v in px), problems
        assert "shown at" in str(problems[0]) and "to fit 1089 x 600" in str(problems[0])
    plt.close(fig)


def test_save_figure_checks_the_slide_box_only_for_the_course_s_figures_or_a_box_it_is_given(
    tmp_path, monkeypatch
):
    """A figure 16 in high (shown on a slide at under half its size, its 10-pt labels under 8 px: the test above) is
    refused where the course saves its figures (bl.report.figures_dir(), every notebook's) and where ``fit`` names a
    box, and saved as it is elsewhere: a library user's figure for a paper is not a slide (before: refused
    everywhere, 'shown at 46% of 362 x 1296 px to fit 1089 x 600')."""
    from beatlite import report

    monkeypatch.setenv("BEATLITE_FIGURE_CHECK", "raise")
    monkeypatch.setenv("BEATLITE_BUILD", str(tmp_path / "build"))
    fig, ax = plt.subplots(figsize=(4, 16), dpi=100)
    ax.plot([0, 1], [0, 1])
    ax.set_xlabel("time (s)", fontsize=10)
    ax.tick_params(labelsize=10)
    slide = "'time \\(s\\)' is [0-9.]+ px high at 100 dpi, shown at [0-9]+% of .* to fit"
    with pytest.raises(check.FigureError, match=slide + " 1089 x 600"):
        style.save_figure(fig, report.figures_dir() / "00_tall", formats=("png",))
    # a box of one's own: as low as a slide, then high enough to show the picture at its own size
    with pytest.raises(check.FigureError, match=slide + " 1920 x 600"):
        style.save_figure(fig, tmp_path / "own_slides", formats=("png",), fit=(1920, 600))
    style.save_figure(fig, tmp_path / "own_slides", formats=("png",), fit=(1920, 1600))
    written = style.save_figure(fig, tmp_path / "paper" / "fig_tall", formats=("png",))
    assert [p.name for p in written] == ["fig_tall.png"]
    assert not report.figures_dir().exists()  # nothing written where it was refused
    plt.close(fig)


def test_the_test_suite_turns_a_figure_warning_into_an_error(monkeypatch):
    """pyproject's filterwarnings: a figure saved by any test with a problem fails that test."""
    monkeypatch.setenv("BEATLITE_FIGURE_CHECK", "warn")
    with pytest.raises(check.FigureWarning):
        check.report_problems([check.FigureProblem("empty panel", "axes 1 of 1 shows no data")], "t")
