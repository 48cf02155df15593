"""The figures of beatlite.viz.benchmark: what each draws, checked on hand-made inputs."""

from __future__ import annotations

import math

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.container import BarContainer  # noqa: E402

from beatlite.skeleton.ted import TED_BONES  # noqa: E402
from beatlite.train.evaluation import ModelResults, ResultRow  # noqa: E402
from beatlite.viz import benchmark  # noqa: E402


@pytest.fixture(autouse=True)
def _close():
    yield
    plt.close("all")


def _chain(n_frames: int, scale: float) -> tuple[np.ndarray, np.ndarray]:
    """A 3-joint vertical chain of height 2 * scale cm, swaying in x: positions and parents."""
    t = np.arange(n_frames)[:, None]
    pos = np.stack([np.c_[np.sin(t) * k, scale * k * np.ones_like(t), 0 * t] for k in range(3)], axis=1)
    return pos.astype(float), np.array([-1, 0, 1])


def test_keyframes_share_one_scale_and_title_times():
    small, parents = _chain(10, 10.0)  # 20 cm tall
    large, _ = _chain(10, 50.0)  # 100 cm tall
    fig = benchmark.plot_keyframes({"small": (small, parents), "large": (large, parents)}, [0, 3, 6], 15)
    axes = fig.axes
    assert len(axes) == 6
    spans = {round(float(np.ptp(ax.get_zlim())), 6) for ax in axes}  # vertical span of every panel
    assert len(spans) == 1  # one scale for both systems
    # the largest extent: 100 cm (+ 2 x 5 cm margin)
    assert spans.pop() == pytest.approx(110.0)
    # one horizontal span for both systems too
    widths = {round(float(np.ptp(ax.get_xlim())), 6) for ax in axes}
    assert len(widths) == 1
    assert [ax.get_title() for ax in axes[:3]] == ["0.0 s", "0.2 s", "0.4 s"]
    assert not [ax for ax in axes if ax.get_title() and ax in axes[3:]]


def test_keyframes_colour_ted_joints_like_beat_joints():
    names = benchmark.ted_colour_names()
    assert len(names) == 43 and len(TED_BONES) == 42
    assert benchmark._skeleton_of(np.full(43, -1))[1] == names
    assert benchmark._skeleton_of(np.array([-1, 0, 1]))[1] is None


def _history(adv: float) -> list[dict]:
    return [
        {
            "epoch": e,
            "train": {"rec": 1.0 / (e + 1), "adv": adv * e},
            "val": {"rec": 1.2 / (e + 1), "adv": 0.0},
        }
        for e in range(5)
    ]


def test_training_history_drops_missing_panels_and_explains_zero_ones():
    fig = benchmark.plot_training_history(
        _history(0.0),
        [("rec", "Huber loss"), ("adv", "adversarial loss"), ("val_score", "FGD")],
        first_adversarial=10,
    )
    assert len(fig.axes) == 2  # no val_score in the history: no empty FGD box
    rec, adv = fig.axes
    assert rec.get_ylabel() == "Huber loss" and adv.get_ylabel() == "adversarial loss"
    np.testing.assert_allclose(rec.lines[0].get_ydata(), [1.0, 0.5, 1 / 3, 0.25, 0.2])
    assert not adv.lines and "not reached in 5 epochs" in adv.texts[0].get_text()


def test_training_history_marks_the_exported_epoch():
    history = _history(1.0)
    for h, score in zip(history, [5.0, 4.0, 3.0, 3.5, 3.2], strict=True):
        h["val_score"] = score
    fig = benchmark.plot_training_history(
        history, [("val_score", "FGD")], selected={"epoch": 2, "score": 3.0}
    )
    (ax,) = fig.axes
    star = [ln for ln in ax.lines if ln.get_marker() == "*"][0]
    assert (star.get_xdata()[0], star.get_ydata()[0]) == (2, 3.0)


def _results(fgds, bcs):
    rows = [
        ResultRow(f"m{i}", f"m{i}", "euler141", {"FGD": f, "BC": b})
        for i, (f, b) in enumerate(zip(fgds, bcs, strict=True))
    ]
    return ModelResults(rows, {})


def test_benchmark_cuts_a_far_off_bar_and_writes_its_value():
    fig = benchmark.plot_benchmark(_results([0.0, 2.0, 4.0, 25.0], [0.7, 0.8, 0.6, math.nan]))
    bars, scatter = fig.axes
    assert bars.get_xlim() == pytest.approx((0.0, 5.0))  # 1.25 x the largest other FGD
    widths = sorted(p.get_width() for p in bars.patches)
    assert widths == pytest.approx([0.0, 2.0, 4.0, 5.0])  # 25 drawn cut at the axis end
    assert any("25.0 (cut)" in t.get_text() for t in bars.texts)
    assert sorted(t.get_text() for t in scatter.texts) == ["m0", "m1", "m2"]  # no BC, no point
    assert scatter.get_xlim()[1] >= 1.4 * 4.0  # room for the labels


def test_table6_rows_name_every_bar_and_use_percent():
    acc = {"neutral": 0.5, "avg": 0.25}
    fig = benchmark.plot_table6_rows({"real": acc, "CaMN": {"avg": 0.125}})
    (ax,) = fig.axes
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == ["paper: real", "paper: CaMN (generated)", "beatlite: real", "beatlite: CaMN"]
    heights = [p.get_height() for p in ax.containers[2]]
    assert heights[0] == pytest.approx(50.0) and heights[-1] == pytest.approx(25.0)
    assert math.isnan(heights[1])


def test_effects_bars_and_errors():
    fig = benchmark.plot_effects(["a", "b"], [10.0, 20.0], [-5.0, 3.0], [1.0, 2.0], ylabel="FGD change (%)")
    (ax,) = fig.axes
    bars = [c for c in ax.containers if isinstance(c, BarContainer)]
    assert [p.get_height() for p in bars[0]] == [10.0, 20.0]
    assert [p.get_height() for p in bars[1]] == [-5.0, 3.0]
    with pytest.raises(ValueError, match="same length"):
        benchmark.plot_effects(["a"], [1.0, 2.0], [1.0], [1.0], ylabel="x")


def test_ha2g_levels_draws_six_levels_with_new_bones_in_red():
    fig = benchmark.plot_ha2g_levels()
    titles = [ax.get_title() for ax in fig.axes if ax.get_title().startswith("level")]
    assert titles[0] == "level 1: 8 bones, 24 dims" and titles[-1] == "level 6: 42 bones, 126 dims"
    body6 = fig.axes[2 * 4 + 2]  # level 6 body panel (row 3, column 3)
    assert body6.get_title().startswith("level 6") and len(body6.lines) == 42
