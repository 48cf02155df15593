"""The library functions behind notebooks 00-04, on hand-made inputs with hand-derived answers.

beatlite.paths.on_data_samples, beatlite.stats (analysis_subset, word_class_scores,
paper_language_shares, speaker_split_table), beatlite.metrics.perturb and beatlite.viz.figures.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from beatlite.data.index import TakeIndex, TakeRecord
from beatlite.metrics.perturb import (
    SYSTEMS,
    delayed,
    euler_takes,
    perturbed_systems,
    shifted_beat_align,
    subset_spread,
)
from beatlite.metrics.scoring import Takes
from beatlite.paths import on_data_samples, repo_root
from beatlite.stats.corpus import analysis_subset
from beatlite.stats.distributions import paper_language_shares, speaker_split_table
from beatlite.stats.semantic import word_class_scores


# ------------------------------------------------------------------ paths
def test_on_data_samples_follows_beatlite_data(monkeypatch, tmp_path: Path) -> None:
    monkeypatch.delenv("BEATLITE_DATA", raising=False)
    assert on_data_samples()
    monkeypatch.setenv("BEATLITE_DATA", str(tmp_path))
    assert not on_data_samples()
    monkeypatch.setenv("BEATLITE_DATA", str(repo_root() / "data_samples" / ".." / "data_samples"))
    assert on_data_samples()  # the same folder spelled differently


# ------------------------------------------------------------------ stats
def _record(stem: str, seconds: float, **fields) -> TakeRecord:
    r = TakeRecord(stem, **fields)
    r.files = {"motion": Path(f"{stem}.bvh"), "audio": Path(f"{stem}.wav")}  # never opened
    r.durations = {"motion": seconds, "audio": seconds}
    return r


def _speech(stem: str, speaker: int, emotion: int, split: str, seq: int, seconds: float = 60.0) -> TakeRecord:
    return _record(
        stem, seconds, speaker_id=speaker, speaker=f"s{speaker}", emotion=emotion, split=split,
        sequence=seq, conversation=False, language="english",
    )  # fmt: skip


def test_analysis_subset_keeps_a_small_corpus_whole() -> None:
    idx = TakeIndex(
        [_speech("a", 2, 0, "train", 1), _speech("b", 2, 1, "test", 2), TakeRecord("bad", problems=["x"])]
    )
    assert analysis_subset(idx, max_minutes=2.0).stems == ["a", "b"]  # 2 min <= 2 min; unusable dropped


def test_analysis_subset_samples_per_speaker_emotion_split() -> None:
    # speaker 2: three neutral train takes (seq 5, 1, 3), one anger train take, one neutral test take;
    # speaker 4: one take; speaker 6: two takes; a conversation take (dropped: speech exists).
    records = [
        _speech("n5", 2, 0, "train", 5), _speech("n1", 2, 0, "train", 1), _speech("n3", 2, 0, "train", 3),
        _speech("a9", 2, 2, "train", 9), _speech("t2", 2, 0, "test", 2),
        _speech("x1", 4, 0, "train", 1),
        _speech("y1", 6, 0, "train", 1), _speech("y2", 6, 3, "val", 2),
        _record("c", 600, speaker_id=2, speaker="s2", emotion=0, split="train", sequence=1, conversation=True),
    ]  # fmt: skip
    idx = TakeIndex(records)
    chosen = analysis_subset(idx, max_minutes=1.0, per_group=2, max_speakers=2)
    # speakers by speech-take count: 2 (5 takes), 6 (2), 4 (1) -> 2 and 6 kept;
    # (2, neutral, train): the two lowest sequences 1 and 3, in index order
    assert chosen.stems == ["n1", "n3", "a9", "t2", "y1", "y2"]
    assert analysis_subset(idx, max_minutes=1.0, per_group=1, max_speakers=1).stems == ["n1", "a9", "t2"]
    with pytest.raises(ValueError, match="per_group"):
        analysis_subset(idx, max_minutes=1.0, per_group=0)


def test_word_class_scores_hand_computed() -> None:
    # fps 1: "the" covers frame 0 (0.1) and frame 3 (0.3); "idea" frame 1 (0.9); "of" frame 2 (0.5)
    take = SimpleNamespace(
        fps=1.0, semantic=np.array([0.1, 0.9, 0.5, 0.3]),
        word_starts=np.array([0.0, 1.0, 2.0, 3.0]), word_ends=np.array([1.0, 2.0, 3.0, 4.0]),
        words=("The", "idea", "of", "the"),
    )  # fmt: skip
    out = word_class_scores([take])
    assert out["function"] == {"occurrences": 3, "words": 2, "mean": pytest.approx((0.1 + 0.5 + 0.3) / 3)}
    assert out["content"] == {"occurrences": 1, "words": 1, "mean": pytest.approx(0.9)}
    custom = word_class_scores([take], function_words=frozenset({"idea"}))
    assert custom["function"]["mean"] == pytest.approx(0.9) and custom["content"]["occurrences"] == 3


def test_paper_language_shares_from_the_hours() -> None:
    shares = paper_language_shares()
    assert shares["english"] == pytest.approx(60 / 76) and sum(shares.values()) == pytest.approx(1.0)
    assert f"{100 * shares['english']:.1f}" == "78.9"  # the paper's "81 %" does not follow from its hours


def test_speaker_split_table_counts_and_minutes() -> None:
    idx = TakeIndex(
        [
            _speech("a", 2, 0, "train", 1, 90.0),
            _speech("b", 2, 0, "test", 2, 30.0),
            _speech("c", 4, 0, "val", 3, 60.0),
        ]
    )
    lines = speaker_split_table(idx).splitlines()
    assert lines[0] == "| speaker | train takes | val takes | test takes | train min | val min | test min |"
    assert lines[2] == "| 2_s2 | 1 | 0 | 1 | 1.5 | 0.0 | 0.5 |"
    assert lines[3] == "| 4_s4 | 0 | 1 | 0 | 0.0 | 1.0 | 0.0 |"
    assert lines[4] == "| **all** | 1 | 1 | 1 | 1.5 | 1.0 | 0.5 |"


# ------------------------------------------------------------------ metrics.perturb
def test_delayed_repeats_the_first_frame() -> None:
    x = np.arange(6.0)[:, None]
    assert delayed(x, 0)[:, 0].tolist() == x[:, 0].tolist()
    assert delayed(x, 4)[:, 0].tolist() == [0, 0, 0, 0, 0, 1]
    assert delayed(x, 10)[:, 0].tolist() == [0] * 6  # longer than the take: all first frame
    with pytest.raises(ValueError):
        delayed(x, -1)


def test_perturbed_systems_hand_computed() -> None:
    a = np.linspace(0, 14, 8)[:, None] * np.ones((1, 141))  # 0, 2, ..., 14: mean 7
    b = np.full((5, 141), 3.0)
    s = perturbed_systems([a, b], jitter_deg=2.0, delay_frames=3, seed=0)
    assert list(s) == list(SYSTEMS)
    assert s["half range"][0][:, 0].tolist() == [3.5, 4.5, 5.5, 6.5, 7.5, 8.5, 9.5, 10.5]
    assert s["delayed 1 s"][0][:, 0].tolist() == [0, 0, 0, 0, 2, 4, 6, 8]
    assert np.array_equal(s["another take"][0], np.full((8, 141), 3.0))  # b repeated to a's length
    assert np.array_equal(s["another take"][1], a[:5])  # a cut to b's length
    assert np.all(s["frozen mean pose"][0] == 7.0)
    noise = s["jitter"][0] - a
    assert noise.std() == pytest.approx(2.0, rel=0.05)  # 1128 N(0, 2) draws
    assert np.array_equal(s["jitter"][0], perturbed_systems([a, b], delay_frames=3, seed=0)["jitter"][0])


def test_euler_takes_rest_pose_matches_forward_kinematics() -> None:
    from beatlite.skeleton import JOINT_SUBSETS, beat_skeleton, rest_pose

    takes = euler_takes([np.zeros((3, 141))])
    skeleton = beat_skeleton()
    rest = rest_pose(skeleton)[skeleton.indices(JOINT_SUBSETS["spine_neck_141"])]
    np.testing.assert_allclose(takes.positions[0][1], rest, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(takes.directions[0], axis=-1), 1.0)
    with pytest.raises(ValueError, match="141"):
        euler_takes([np.zeros((3, 140))])


def test_subset_spread_perfect_system_scores_the_mean_semantic_weight() -> None:
    rng = np.random.default_rng(0)
    pos = [rng.normal(size=(54, 2, 3)), rng.normal(size=(44, 2, 3))]  # windows at 0, 10, 20 and 0, 10
    euler = [np.tile(np.arange(54.0)[:, None], (1, 3)), np.zeros((44, 3))]
    sem = [np.full(54, 0.5), np.full(44, 0.25)]
    truth = Takes(positions=pos)
    srgr, l1 = subset_spread(Takes(positions=pos, euler=euler), truth, sem, n_subsets=4, n_clips=5)
    # all 5 clips every time: SRGR = frame mean of the weights = (3 * 0.5 + 2 * 0.25) / 5
    np.testing.assert_allclose(srgr, 0.4)
    # a 34-frame ramp 0..33 (mean 16.5) is 0.5, 1.5, ..., 16.5 from its mean twice: 8.5 per channel
    # and frame, 25.5 over 3 channels; 3 ramp clips and 2 frozen clips (0) of 34 frames each
    np.testing.assert_allclose(l1, 3 * 34 * 25.5 / (5 * 34))
    with pytest.raises(ValueError, match="clips"):
        subset_spread(Takes(positions=pos, euler=euler), truth, sem, n_clips=6)


def test_shifted_beat_align_real_timing_beats_shifts() -> None:
    fps = 15
    frames = np.arange(150)
    pos = np.zeros((150, 1, 3))
    pos[:, 0, 0] = 10 * np.cos(np.pi * frames / 12)  # turns (speed minima) every 12 frames = 0.8 s
    beats = [frames[12::12] / fps]  # audio beats exactly on the turns
    true, shifted = shifted_beat_align(beats, [pos], fps, sigma=0.1, n_shifts=10, margin=3, seed=0)
    assert true == pytest.approx(1.0, abs=1e-9)
    assert shifted < 0.8
    with pytest.raises(ValueError, match="audio"):
        shifted_beat_align(beats * 2, [pos], fps)


# ------------------------------------------------------------------ viz.figures
def test_figures_have_units_and_legends_outside(tmp_path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from beatlite.viz import figures

    sr = 16000
    y = (0.5 * np.sin(np.arange(3 * sr) / 10)).astype(np.float32)
    fig = figures.plot_onsets(y, sr, np.array([0.5, 1.5]), word_starts=np.array([0.4]), t_end=2.0,
                              out=tmp_path / "onsets")  # fmt: skip
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    assert [ax.get_ylabel() for ax in fig.axes] == ["amplitude", "spectral flux\n(dB per frame)"]
    for ax in fig.axes:  # right of the axes: the legends cover no curve
        assert ax.get_legend().get_window_extent(renderer).x0 >= ax.get_window_extent(renderer).x1
    assert (tmp_path / "onsets.png").is_file() and (tmp_path / "onsets.svg").is_file()
    spread = {"a": (np.array([0.1, 0.2]), np.array([3.0, 4.0])), "b": (np.array([0.3]), np.array([5.0]))}
    fig2 = figures.plot_spread(spread)
    assert [ax.get_ylabel() for ax in fig2.axes] == ["SRGR per subset", "L1 diversity per subset"]
    plt.close("all")


# ------------------------------------------------------------------ skeleton.core.tree_text
def test_tree_text_lists_every_beat_joint_once_in_21_branches() -> None:
    import re

    from beatlite.skeleton import beat_skeleton
    from beatlite.skeleton.core import tree_text

    skeleton = beat_skeleton()
    lines = tree_text(skeleton).splitlines()
    indices = [int(i) for i in re.findall(r"(?:^|> )(\d+) ", "\n".join(line.strip() for line in lines), re.M)]
    assert sorted(indices) == list(range(75))  # each joint exactly once
    # branches: root, spine, neck/head, 2 x (shoulder..hand, 5 finger chains, 2 finger roots), 2 legs
    assert len(lines) == 21 and lines[0] == "0 Hips (6)"
    assert lines[2] == "    5 Neck (3) > 6 Neck1 (3) > 7 Head (3) > 8 HeadEnd (3) *"
    assert sum(line.endswith("*") for line in lines) == len(skeleton.end_sites) == 13


def test_speaker_split_table_default_columns_are_the_splits_present() -> None:
    idx = TakeIndex([_speech("a", 2, 0, "train", 1, 60.0), _speech("b", 5, 0, "none", 9, 120.0)])
    lines = speaker_split_table(idx).splitlines()
    assert lines[0] == "| speaker | train takes | none takes | train min | none min |"
    assert lines[-1] == "| **all** | 1 | 1 | 1.0 | 2.0 |"


# ------------------------------------------------------------------ notebook.setup
def test_setup_checks_the_version_before_seeding() -> None:
    """``setup(require=...)`` replaces a notebook's separate ``notebook.require`` line: it refuses first."""
    from beatlite import notebook

    np.random.seed(5)  # noqa: NPY002 - setup seeds the legacy global state
    state = np.random.get_state()[1].copy()  # noqa: NPY002
    with pytest.raises(RuntimeError, match=r"beatlite >= 99\.0"):
        notebook.setup(seed=0, require="99.0", verbose=False)
    assert np.array_equal(np.random.get_state()[1], state)  # noqa: NPY002 - refused before seeding
    info = notebook.setup(seed=0, require="0.1", verbose=False)
    assert info == notebook.setup(seed=0, verbose=False)
    assert np.random.rand() == np.random.RandomState(0).rand()  # noqa: NPY002
