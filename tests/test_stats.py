"""beatlite.stats on hand-made takes and records with known answers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from beatlite.data.index import TakeIndex, TakeRecord
from beatlite.stats.corpus import CorpusTake, frame_rms, joint_speed
from beatlite.stats.corpus_table import PAPER_TABLE1
from beatlite.stats.correlations import (
    correlation_test,
    gesture_correlations,
    group_effect_test,
    plot_correlations,
    speed_by_emotion,
    window_means,
)
from beatlite.stats.distributions import (
    PAPER_EMOTION_SHARES,
    emotion_shares,
    language_shares,
    plot_figure2,
    speaker_durations,
)
from beatlite.stats.emotion_classifier import PAPER_TABLE6, EmotionClassifier, plot_table6, table6_markdown
from beatlite.stats.emotion_clusters import (
    emotion_features,
    plot_emotion_tsne,
    rotation_windows,
    separability,
    window_features,
)
from beatlite.stats.semantic import plot_figure4, score_histogram, speaker_scores, word_scores


def make_take(
    n: int,
    *,
    emotion: int = 0,
    speaker: int = 2,
    fps: float = 15.0,
    speed: np.ndarray | None = None,
    audio: np.ndarray | None = None,
    face: np.ndarray | None = None,
    rotations: np.ndarray | None = None,
    semantic: np.ndarray | None = None,
    scores: tuple[float, ...] = (),
    words: tuple[tuple[float, float, str], ...] = (),
    stem: str = "t",
) -> CorpusTake:
    return CorpusTake(
        stem=stem,
        split="train",
        language="english",
        speaker_id=speaker,
        emotion=emotion,
        fps=fps,
        rotations=np.zeros((n, 141), np.float32) if rotations is None else rotations.astype(np.float32),
        speed=np.ones(n, np.float32) if speed is None else speed.astype(np.float32),
        audio_rms=np.ones(n, np.float32) if audio is None else audio.astype(np.float32),
        face_activity=face,
        emotion_frames=np.full(n, emotion),
        semantic=np.zeros(n, np.float32) if semantic is None else semantic.astype(np.float32),
        semantic_scores=np.array(scores, np.float32),
        word_starts=np.array([w[0] for w in words]),
        word_ends=np.array([w[1] for w in words]),
        words=tuple(w[2] for w in words),
    )


# ------------------------------------------------------------------ per-frame streams
def test_frame_rms_hand_computed() -> None:
    # sr=10, fps=3: frame edges floor(i*10/3) = 0, 3, 6, 10
    audio = np.array([1, -1, 1, 2, 2, -2, 3, 3, -3, 3], dtype=float)
    assert np.allclose(frame_rms(audio, 3, fps=3, sr=10), [1.0, 2.0, 3.0])
    # a 4th frame beyond the audio gets 0
    assert np.allclose(frame_rms(audio, 4, fps=3, sr=10), [1.0, 2.0, 3.0, 0.0])


def test_joint_speed_two_joints() -> None:
    p = np.zeros((3, 2, 3))
    p[:, 0, 1] = [0.0, 3.0, 3.0]  # joint 0 moves 3 cm then stops
    p[:, 1, 2] = [0.0, 4.0, 8.0]  # joint 1 moves 4 cm per frame
    # fps 2: mean speeds (3+4)/2*2 = 7 then (0+4)/2*2 = 4; frame 0 repeats frame 1
    assert np.allclose(joint_speed(p, 2.0), [7.0, 7.0, 4.0])
    with pytest.raises(ValueError, match=r"\(T, J, 3\)"):
        joint_speed(np.zeros((3, 2)), 2.0)


# ------------------------------------------------------------------ correlations
def test_spearman_hand_case_and_permutation_bounds() -> None:
    # rho = 1 - 6 * sum d^2 / (n (n^2 - 1)) = 1 - 6 * 2 / 60 = 0.8
    r = correlation_test(np.array([1.0, 2, 3, 4]), np.array([1.0, 3, 2, 4]), n_permutations=50)
    assert r.rho == pytest.approx(0.8)
    assert 1 / 51 <= r.p_permutation <= 1.0 and r.n == 4


def test_circular_shift_p_value_counts_each_shift_once_when_there_are_few() -> None:
    # 4 values in one group have 4 circular shifts of y (identity included), with Spearman rho
    # 0.8, -0.4, 0.0, -0.4 (1 - 6 sum d^2 / 60 for sum d^2 = 2, 14, 10, 14): exactly 1 of the 4 is
    # as extreme as the observed 0.8, so p = 1/4, whatever the number of draws. 1000 draws among
    # the 3 non-identity shifts reported 1/1001.
    x, y = np.array([1.0, 2, 3, 4]), np.array([1.0, 3, 2, 4])
    for n in (50, 1000):
        r = correlation_test(x, y, n_permutations=n)
        assert r.p_permutation == pytest.approx(1 / 4)
        assert r.null_mean == pytest.approx(0.0, abs=1e-12)
        assert r.null_std == pytest.approx(np.sqrt((0.64 + 0.16 + 0.0 + 0.16) / 4))


def test_circular_shift_p_value_of_two_groups_matches_brute_force() -> None:
    from itertools import product

    from scipy.stats import spearmanr

    rng = np.random.default_rng(3)
    x, y = rng.normal(size=7), rng.normal(size=7)
    groups = np.array([0, 0, 0, 1, 1, 1, 1])
    rho = spearmanr(x, y).statistic
    null = [
        spearmanr(x, np.concatenate([np.roll(y[:3], a), np.roll(y[3:], b)])).statistic
        for a, b in product(range(3), range(4))
    ]
    expected = np.mean(np.abs(null) >= abs(rho) - 1e-12)  # 12 combinations, the identity among them
    r = correlation_test(x, y, groups=groups, n_permutations=500)
    assert r.p_permutation == pytest.approx(expected)
    assert r.null_mean == pytest.approx(np.mean(null)) and r.null_std == pytest.approx(np.std(null))


def test_planted_correlation_is_significant_and_independent_is_not() -> None:
    rng = np.random.default_rng(1)
    groups = np.repeat(np.arange(10), 30)
    x = rng.normal(size=300)
    related = correlation_test(x, x + 0.5 * rng.normal(size=300), groups=groups, n_permutations=500)
    assert related.rho > 0.7 and related.p_permutation < 0.01
    independent = correlation_test(x, rng.normal(size=300), groups=groups, n_permutations=500)
    assert abs(independent.rho) < 0.2 and independent.p_permutation > 0.01
    # the null of circular shifts is centred near 0
    assert abs(independent.null_mean) < 0.05


def test_correlation_undefined_or_non_finite_is_not_significant() -> None:
    # a constant signal has no rho; it used to get the smallest permutation p (1 / 51) beside rho = NaN
    r = correlation_test(np.arange(20.0), np.ones(20), groups=np.repeat([0, 1], 10), n_permutations=50)
    assert np.isnan(r.rho) and np.isnan(r.p_value) and np.isnan(r.p_permutation) and r.n == 20
    y = np.arange(20.0)
    y[3] = np.nan
    with pytest.raises(ValueError, match="y has 1 non-finite"):
        correlation_test(np.arange(20.0), y, n_permutations=50)
    with pytest.raises(ValueError, match="values has 1 non-finite"):
        group_effect_test(np.array([1.0, 2, 3, np.nan, 5, 6]), np.array([0, 0, 0, 1, 1, 1]))


def test_circular_shift_null_in_blocks_matches_np_roll() -> None:
    """The null over several blocks of shifted copies equals Spearman's rho of np.roll-ed takes, drawn in
    the same order (one (n_permutations,) draw per group, groups in sorted order), and memory stays far
    below one (n_permutations, N) int64 array, which the test used to allocate several times over."""
    import tracemalloc

    from scipy.stats import spearmanr

    rng = np.random.default_rng(2)
    n, n_perm = 20_000, 120  # 52 copies per block of 2^20 values: 3 blocks
    groups = rng.permutation(np.repeat(np.arange(40), n // 40))  # groups interleaved, not contiguous
    x = rng.normal(size=n)
    y = 0.3 * x + rng.normal(size=n)
    r = correlation_test(x, y, groups=groups, n_permutations=n_perm, seed=7)
    draws = np.random.default_rng(7)
    idx = [np.flatnonzero(groups == gid) for gid in np.unique(groups)]
    shifts = [draws.integers(1, len(i), size=n_perm) for i in idx]
    null = []
    for k in range(n_perm):
        shifted = y.copy()
        for i, s in zip(idx, shifts):
            shifted[i] = np.roll(y[i], -s[k])  # position t gets the value of t + s within its group
        null.append(spearmanr(x, shifted).statistic)
    assert r.null_mean == pytest.approx(np.mean(null), abs=1e-12)
    assert r.null_std == pytest.approx(np.std(null), abs=1e-12)
    assert r.p_permutation == (1 + np.sum(np.abs(null) >= abs(r.rho) - 1e-12)) / (1 + n_perm)
    many = 600  # blocks of 2^20 values (a few 8 MB arrays) whatever the number of copies
    tracemalloc.start()
    correlation_test(x, y, groups=groups, n_permutations=many, seed=7)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < n * many * 8 / 2  # half of one (n_permutations, N) int64 array (96 MB)


def test_group_effect_hand_computed() -> None:
    # groups a = [1, 2, 3], b = [4, 5, 6]: grand mean 3.5, SS_between = 3*1.5^2*2 = 13.5,
    # SS_total = 17.5 -> eta^2 = 0.7714; F = 13.5 / (4 / 4) = 13.5.
    r = group_effect_test(
        np.array([1.0, 2, 3, 4, 5, 6]), np.array(["a", "a", "a", "b", "b", "b"]), n_permutations=2000
    )
    assert r.eta2 == pytest.approx(13.5 / 17.5)
    assert r.f_stat == pytest.approx(13.5)
    assert r.group_means == {"a": 2.0, "b": 5.0}
    # exactly 2 of the C(6,3) = 20 label splits reach eta^2 = 0.77 -> p = 0.1
    assert 0.075 < r.p_permutation < 0.125
    with pytest.raises(ValueError, match="2 groups"):
        group_effect_test(np.ones(3), np.zeros(3))


def test_window_means_and_speed_by_emotion() -> None:
    a = make_take(4, emotion=2, speed=np.array([1.0, 3.0, 5.0, 7.0]), fps=1.0)
    b = make_take(3, emotion=2, speed=np.array([10.0, 10.0, 10.0]), fps=1.0)
    wm = window_means([a, b], seconds=2.0)
    assert np.allclose(wm["speed"], [2.0, 6.0, 10.0])  # b's 3rd frame does not fill a window
    assert wm["take"].tolist() == [0, 0, 1]
    assert np.all(np.isnan(wm["face"]))
    # frame-weighted: (1 + 3 + 5 + 7 + 30) / 7
    assert speed_by_emotion([a, b]) == {"anger": pytest.approx(46 / 7)}


def test_gesture_correlations_detects_planted_effects() -> None:
    rng = np.random.default_rng(0)
    takes = []
    for k in range(16):
        emotion, speaker = k % 2 * 2, 2 + 2 * (k % 4 // 2)  # neutral / anger, speakers 2 and 4
        base = 10.0 + 10.0 * (emotion == 2)
        audio = rng.gamma(2.0, size=300)
        speed = base + 3 * np.convolve(audio, np.ones(5) / 5, mode="same") + rng.normal(size=300)
        face = rng.gamma(2.0, size=300).astype(np.float32)  # unrelated to the motion
        takes.append(make_take(300, emotion=emotion, speaker=speaker, speed=speed, audio=audio, face=face))
    res = gesture_correlations(takes, n_permutations=300)
    assert res["audio"].rho > 0.3 and res["audio"].p_permutation < 0.01
    assert res["face"].p_permutation > 0.01
    assert res["emotion"].eta2 > 0.9 and res["emotion"].p_permutation < 0.01
    assert res["speaker"].p_permutation > 0.01  # speakers were balanced across emotions


def test_gesture_correlations_emotion_effect_counts_self_talk_takes_only() -> None:
    import dataclasses

    takes = [make_take(30, emotion=e, speed=np.full(30, v + k), stem=f"s{e}{k}") for e, v in ((0, 5.0), (2, 9.0))
             for k in range(3)]  # fmt: skip
    # a conversation is neutral by name but changes emotion turn by turn: not a neutral take of the emotion test
    talk = dataclasses.replace(make_take(30, emotion=0, speed=np.full(30, 40.0), stem="c"), conversation=True)
    res = gesture_correlations([*takes, talk], n_permutations=20)
    assert res["emotion"].n_takes == 6  # was 7, the conversation counted as neutral
    assert res["emotion"].group_means == {0: pytest.approx(6.0), 2: pytest.approx(10.0)}  # v + 0, 1, 2


# ------------------------------------------------------------------ emotion windows
def test_conversation_windows_and_frames_carry_their_turns_emotions() -> None:
    """A conversation is neutral by its name; its windows and frames count under the emotion of their turn."""
    import dataclasses

    turns = np.repeat([0, 3, 5], [30, 30, 30])  # three 2-s turns: neutral, sadness, surprise
    talk = dataclasses.replace(
        make_take(90, emotion=0, speed=np.repeat([1.0, 2.0, 4.0], 30), stem="c"),
        conversation=True,
        emotion_frames=turns,
    )
    speech = make_take(45, emotion=2, speed=np.full(45, 8.0))
    rw = rotation_windows(
        [talk, speech], seconds=2.0
    )  # 30 frames: 3 + 1 windows, middle frames 15, 45, 75, 15
    assert rw.emotion.tolist() == [0, 3, 5, 2]
    assert emotion_features([talk, speech], per_speaker=False).emotion.tolist() == [0, 3, 5, 2]
    speeds = speed_by_emotion([talk, speech])
    assert speeds == {"neutral": 1.0, "anger": 8.0, "sadness": 2.0, "surprise": 4.0}  # was neutral (1+2+4)/3


def test_window_features_hand_computed() -> None:
    x = np.array([[[0.0], [2.0], [4.0]]])  # one window, 3 frames, 1 channel
    # mean 2, std sqrt(((-2)^2 + 0 + 2^2) / 3) = sqrt(8/3), mean |diff| = 2
    assert np.allclose(window_features(x), [[2.0, np.sqrt(8 / 3), 2.0]])
    assert window_features(x, kind="flat").shape == (1, 3)
    with pytest.raises(ValueError, match="kind"):
        window_features(x, kind="nope")


def test_rotation_windows_counts() -> None:
    takes = [make_take(65, emotion=1, speaker=4), make_take(29, emotion=2), make_take(30, emotion=3)]
    rw = rotation_windows(takes, seconds=2.0)  # 30 frames: 65 -> 2 windows, 29 -> 0, 30 -> 1
    assert rw.windows.shape == (3, 30, 141)
    assert (
        rw.emotion.tolist() == [1, 1, 3]
        and rw.take.tolist() == [0, 0, 2]
        and rw.speaker.tolist() == [4, 4, 2]
    )
    # stride 15 frames: 65 -> starts 0, 15, 30 (45 + 30 > 65); 30 -> 1
    assert len(rotation_windows(takes, seconds=2.0, stride_seconds=1.0)) == 3 + 0 + 1


def test_separability_planted_vs_random() -> None:
    rng = np.random.default_rng(0)
    labels = np.repeat([0, 1, 2, 3], 50)
    centres = rng.normal(scale=4.0, size=(4, 6))
    feats = centres[labels] + rng.normal(size=(200, 6))
    groups = np.arange(200) // 10  # 20 groups of 10, one label each
    good = separability(feats, labels, groups=groups)
    assert good.knn_accuracy > 0.9 and good.silhouette > 0.3
    assert good.chance == pytest.approx(0.25) and good.uniform_chance == pytest.approx(0.25)
    noise = separability(rng.normal(size=(200, 6)), labels, groups=groups)
    assert noise.knn_accuracy < 0.45 and abs(noise.silhouette) < 0.1
    with pytest.raises(ValueError, match="2 classes"):
        separability(feats, np.zeros(200))


def _speed_windows(rng: np.random.Generator, label: int, n: int) -> np.ndarray:
    t = np.arange(30)[None, :, None]
    freq = 0.1 + 0.15 * label  # faster oscillation for higher labels
    phase = rng.uniform(0, 2 * np.pi, size=(n, 1, 4))
    return 10 * np.sin(freq * t + phase) + rng.normal(scale=0.5, size=(n, 30, 4))


def test_emotion_classifier_per_class_accuracy() -> None:
    rng = np.random.default_rng(0)
    train = np.concatenate([_speed_windows(rng, c, 40) for c in range(3)])
    test = np.concatenate([_speed_windows(rng, c, 20) for c in range(3)])
    y_train, y_test = np.repeat([0, 2, 3], 40), np.repeat([0, 2, 3], 20)
    for model in ("logistic", "forest"):
        clf = EmotionClassifier(model=model, joints=None).fit(train, y_train)
        acc = clf.per_class_accuracy(test, y_test)
        assert set(acc) == {"neutral", "anger", "sadness", "avg", "overall"}
        assert acc["avg"] > 0.9, (model, acc)
        assert clf.classes.tolist() == [0, 2, 3]
        assert clf.predict_proba(test).shape == (60, 3)
    with pytest.raises(RuntimeError, match="fit"):
        EmotionClassifier(joints=None).predict(test)
    with pytest.raises(ValueError, match="joints=None"):
        EmotionClassifier().fit(train, y_train)  # 4-d windows: no body27 subset
    with pytest.raises(ValueError, match="labels must be"):
        EmotionClassifier(joints=None).fit(train, y_train[:-1])
    with pytest.raises(ValueError, match="model"):
        EmotionClassifier(model="svm")


def test_table6_constant_matches_paper_text() -> None:
    # the caption: "the accuracy gap between the test real and generated data is 15.85"
    assert PAPER_TABLE6["real"]["avg"] - PAPER_TABLE6["generated"]["avg"] == pytest.approx(15.85)
    # the human row's "avg." is the mean of its eight classes: 631.14 / 8 = 78.8925
    human = PAPER_TABLE6["human"]
    assert np.mean([v for k, v in human.items() if k != "avg"]) == pytest.approx(human["avg"], abs=0.01)
    # ...but the real/generated "avg." are not plain class means (81.705 and 65.785): published as is
    assert np.mean([v for k, v in PAPER_TABLE6["real"].items() if k != "avg"]) == pytest.approx(81.705)
    md = table6_markdown({"neutral": 0.5, "avg": 0.5})
    assert md.splitlines()[-1].startswith("| beatlite real | 50.00 | - |")


# ------------------------------------------------------------------ semantic
def test_score_histogram_share_low() -> None:
    h = score_histogram([make_take(5, scores=(0.1, 0.1, 0.2)), make_take(5, scores=(0.8, 1.0))])
    assert h.share_low == pytest.approx(3 / 5) and h.n == 5
    # 10 bins on [0, 1]: 0.1 -> bin 1, 0.2 -> bin 2, 0.8 -> bin 8, 1.0 -> last bin
    assert h.counts.tolist() == [0, 2, 1, 0, 0, 0, 0, 0, 1, 1]


def test_word_and_speaker_scores() -> None:
    sem = np.array([0, 0, 1, 1, 0, 0, 0, 0, 0, 0], dtype=float)
    words = ((0.0, 0.2, "A"), (0.2, 0.4, "b"), (0.4, 0.5, "a"), (0.6, 0.7, ""))
    t = make_take(10, fps=10.0, semantic=sem, words=words, scores=(0.1, 0.9), speaker=4)
    # "a": frames 0-1 (mean 0) and frame 4 (0) -> count 2, mean 0; "b": frames 2-3 -> 1
    assert word_scores([t]) == [("a", 2, 0.0), ("b", 1, 1.0)]
    assert word_scores([t], top=1) == [("a", 2, 0.0)]
    assert speaker_scores([t]) == {4: {"mean": pytest.approx(0.5), "share_low": 0.5, "n": 2}}


# ------------------------------------------------------------------ distributions (records only)
def _record(stem: str, seconds: float, **fields) -> TakeRecord:
    r = TakeRecord(stem, **fields)
    r.files = {"motion": Path(f"{stem}.bvh"), "audio": Path(f"{stem}.wav")}  # never opened
    r.durations = {"motion": seconds, "audio": seconds}
    return r


def hand_index() -> TakeIndex:
    return TakeIndex(
        [
            _record(
                "a", 60, speaker_id=2, speaker="scott", language="english", emotion=0, conversation=False
            ),
            _record(
                "b", 20, speaker_id=2, speaker="scott", language="english", emotion=2, conversation=False
            ),
            _record(
                "c", 20, speaker_id=4, speaker="lawrence", language="chinese", emotion=0, conversation=False
            ),
            _record(
                "d", 100, speaker_id=4, speaker="lawrence", language="english", emotion=0, conversation=True
            ),
            TakeRecord("bad", problems=["bad name: x"]),  # not usable: ignored
        ]
    )


def test_emotion_language_speaker_shares() -> None:
    idx = hand_index()
    emo = emotion_shares(idx)  # self-talk: neutral 60 + 20, anger 20 of 100 s
    assert emo["neutral"] == pytest.approx(0.8) and emo["anger"] == pytest.approx(0.2)
    assert emo["fear"] == 0.0 and list(emo)[0] == "neutral" and len(emo) == 8
    assert emotion_shares(idx, speech_only=False)["neutral"] == pytest.approx(180 / 200)
    assert language_shares(idx) == {"english": pytest.approx(0.9), "chinese": pytest.approx(0.1)}
    assert speaker_durations(idx) == {"2_scott": 80.0, "4_lawrence": 120.0}
    assert sum(PAPER_EMOTION_SHARES.values()) == pytest.approx(1.0)


def test_paper_table1_beat_row() -> None:
    beat = PAPER_TABLE1[-1]
    assert (beat["body"], beat["hand"], beat["speakers"], beat["sequences"], beat["duration"]) == (
        "27",
        "48",
        "30",
        "2508",
        "76h",
    )


# ------------------------------------------------------------------ figures
def test_figures_are_saved_as_png_and_svg(tmp_path: Path) -> None:
    import dataclasses

    import matplotlib.pyplot as plt

    plot_figure2(hand_index(), out=tmp_path / "fig2")
    rng = np.random.default_rng(0)
    takes = [
        make_take(
            90,
            emotion=e,
            rotations=rng.normal(size=(90, 141)) + e,
            scores=(0.1, 0.5),
            semantic=np.full(90, 0.3),
            words=((0.0, 1.0, "so"),),
            stem=f"t{k}",
        )
        for k, e in enumerate([0, 0, 1, 1, 2, 2])
    ]
    fig, sep = plot_emotion_tsne(takes, out=tmp_path / "fig3a")
    assert sep.n == 18 and sep.n_classes == 3
    fig4 = plot_figure4(takes, out=tmp_path / "fig4")
    assert [ax.get_title()[:3] for ax in fig4.axes] == ["(a)", "(b)", "(c)"]  # the paper's panel order
    no_words = [
        dataclasses.replace(t, words=(), word_starts=np.zeros(0), word_ends=np.zeros(0)) for t in takes
    ]
    fig4 = plot_figure4(no_words, out=tmp_path / "fig4_no_words")  # no TextGrid: was an empty panel (c)
    assert [ax.get_title()[:3] for ax in fig4.axes] == ["(a)", "(b)"]
    corr = plot_correlations(takes, out=tmp_path / "corr")  # saved through the figure check: no empty panel
    assert [ax.get_title() for ax in corr.axes] == ["gesture vs audio energy", "gesture energy per emotion"]
    plot_table6({"neutral": 0.5, "avg": 0.5}, out=tmp_path / "table6")
    plt.close("all")
    for stem in ("fig2", "fig3a", "fig4", "corr", "table6"):
        for ext in ("png", "svg"):
            assert (tmp_path / f"{stem}.{ext}").stat().st_size > 1000


def test_subset_dims_body27_matches_reference_layout() -> None:
    from beatlite.stats.emotion_clusters import subset_dims

    # docs/reference_code.md#joint-subsets: spine/neck = dims 0-8, right shoulder/arm/forearm = 9-17, left ones = 75-83
    assert subset_dims("body27").tolist() == list(range(18)) + list(range(75, 84))
    assert subset_dims("spine_neck_141").tolist() == list(range(141))
    with pytest.raises(ValueError, match="joints must be one of"):
        subset_dims("nope")


def test_knn_vote_matches_scikit_learn() -> None:
    from scipy.spatial.distance import cdist
    from sklearn.neighbors import KNeighborsClassifier

    from beatlite.stats.emotion_clusters import _knn_predict

    rng = np.random.default_rng(3)
    xtr, xte = rng.normal(size=(60, 3)), rng.normal(size=(25, 3))
    ytr = rng.integers(0, 4, size=60)
    ours = _knn_predict(cdist(xte, xtr, "sqeuclidean"), ytr, 5)
    ref = KNeighborsClassifier(n_neighbors=5).fit(xtr, ytr).predict(xte)
    assert ours.tolist() == ref.tolist()


def test_separability_permutation_p_value() -> None:
    rng = np.random.default_rng(0)
    groups = np.repeat(np.arange(16), 8)  # 16 takes of 8 windows
    labels = np.repeat(np.arange(16) % 4, 8)
    planted = rng.normal(size=(128, 5)) + 4.0 * np.eye(5)[labels]
    good = separability(planted, labels, groups=groups, n_permutations=99)
    assert good.balanced_accuracy > 0.8 and good.p_permutation == pytest.approx(0.01)  # (1 + 0) / (1 + 99)
    noise = separability(rng.normal(size=(128, 5)), labels, groups=groups, n_permutations=99)
    assert noise.p_permutation > 0.05


def test_load_corpus_streams_and_skips_broken_takes(tmp_path: Path) -> None:
    from test_data_windows import ramp, write_take

    from beatlite.data.index import index_folder
    from beatlite.stats.corpus import load_corpus

    write_take(tmp_path, "2_scott_0_9_9", 40)
    write_take(tmp_path, "2_scott_0_10_10", 40)
    bvh = tmp_path / "2_scott_0_10_10.bvh"
    lines = bvh.read_text(encoding="utf-8").splitlines()
    bvh.write_text("\n".join([*lines[:-1], "abc"]) + "\n", encoding="utf-8")  # header fine, last row broken
    assert not index_folder(tmp_path)["2_scott_0_10_10"].usable  # the index reads the rows as loading does
    idx = index_folder(tmp_path, read_durations=False)  # lists files only: the broken take looks usable
    assert idx["2_scott_0_10_10"].usable
    with pytest.warns(UserWarning, match="skipped 1 unreadable takes: .*2_scott_0_10_10.bvh, line 471"):
        takes = load_corpus(idx)
    (t,) = takes
    assert t.stem == "2_scott_0_9_9" and t.n_frames == 40 and t.emotion == 0 and t.speaker_id == 2
    assert t.rotations.shape == (40, 141) and t.speed.shape == (40,) and np.all(t.speed > 0)
    y = ramp(40 * 16000 // 15).astype(np.float64)
    # frame 0 covers samples [0, 1066): RMS of the ramp there, computed directly
    assert t.audio_rms[0] == pytest.approx(np.sqrt(np.mean(y[:1066] ** 2)), rel=1e-5)
    assert t.face_activity is not None and np.allclose(t.face_activity, 0.0)  # constant weights
    assert np.all(t.emotion_frames == 2)  # from the .csv
    assert t.semantic_scores.tolist() == [0.5] and t.words == ("Hello", "world,", "zebra")


def test_figures_label_every_axis_and_keep_legends_off_the_data() -> None:
    import matplotlib.pyplot as plt

    fig2 = plot_figure2(hand_index())
    table6 = plot_table6({"neutral": 0.5, "avg": 0.5}, {"neutral": 0.25, "avg": 0.25}, generated_by="CaMN")
    for fig in (fig2, table6):
        assert all(ax.get_ylabel() and ax.get_xlabel() for ax in fig.axes)
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        legends = [leg for ax in fig.axes if (leg := ax.get_legend())] + list(fig.legends)
        assert legends
        for leg in legends:
            box = leg.get_window_extent(renderer)
            assert not any(box.overlaps(ax.get_window_extent(renderer)) for ax in fig.axes)
    labels = [t.get_text() for t in table6.axes[0].get_legend().get_texts()]
    assert labels[-1] == "beatlite, generated (CaMN)"  # the generated row names its model
    plt.close("all")


def test_table6_writes_a_zero_bar_as_0_and_leaves_a_missing_class_empty() -> None:
    import matplotlib.pyplot as plt

    real = {"neutral": 1.0, "anger": 0.9, "avg": 0.95}
    generated = {"neutral": 1.0, "anger": 0.0, "avg": 0.5}  # CaMN never right on anger; no other class given
    fig = plot_table6(real, generated, generated_by="CaMN")
    ax = fig.axes[0]
    zeros = [t for t in ax.texts if t.get_text() == "0"]
    assert len(zeros) == 1  # only the 0 %, not the classes without a value (NaN: no bar, no number)
    names = [t.get_text() for t in ax.get_xticklabels()]
    assert names[round(zeros[0].get_position()[0])] == "anger"  # above the anger group's slot
    from matplotlib.colors import to_hex

    generated_colour = to_hex(ax.get_legend().legend_handles[-1].get_facecolor())
    assert to_hex(zeros[0].get_color()) == generated_colour  # in the colour of the generated row
    plt.close(fig)


@pytest.mark.filterwarnings("ignore:The least populated class:UserWarning")
def test_emotion_features_stream_and_subsample() -> None:
    from beatlite.stats.emotion_clusters import (
        emotion_features,
        emotion_separability,
        per_group_standardize,
        subset_dims,
    )

    rng = np.random.default_rng(3)
    takes = [
        make_take(95, emotion=e, speaker=2 + k % 2, rotations=rng.normal(size=(95, 141)) + e, stem=f"t{k}")
        for k, e in enumerate([0, 1, 2, 0, 1, 2, 3, 3])
    ]
    # oracle: all windows at once, as emotion_separability computed them before streaming
    rw = rotation_windows(takes)
    expected = per_group_standardize(window_features(rw.windows[:, :, subset_dims("body27")]), rw.speaker)
    ef = emotion_features(iter(takes))  # a single-pass iterator is enough
    assert len(ef) == 8 * 3 and np.array_equal(ef.features, expected) and np.array_equal(ef.take, rw.take)
    whole = emotion_separability(takes)
    assert emotion_separability(iter(takes), max_windows=None).balanced_accuracy == whole.balanced_accuracy
    assert emotion_separability(takes, max_windows=24).silhouette == whole.silhouette  # 24 windows: no subset
    # more windows than max_windows: a seeded uniform subset, kept in order, scored like any features
    sub = emotion_separability(takes, max_windows=15, seed=4)
    keep = np.sort(np.random.default_rng(4).choice(24, size=15, replace=False))
    oracle = separability(expected[keep], rw.emotion[keep], groups=rw.take[keep], seed=4)
    assert (
        sub.n == 15
        and sub.balanced_accuracy == oracle.balanced_accuracy
        and sub.silhouette == oracle.silhouette
    )
    assert emotion_separability(takes, max_windows=15, seed=4).silhouette == sub.silhouette  # deterministic
    with pytest.raises(ValueError, match="no takes"):
        emotion_features(iter([]))


def test_iter_corpus_is_lazy_and_equals_load_corpus(tmp_path: Path) -> None:
    from test_data_windows import write_take

    from beatlite.data.index import index_folder
    from beatlite.stats.corpus import iter_corpus, load_corpus

    write_take(tmp_path, "2_scott_0_9_9", 40)
    write_take(tmp_path, "2_scott_0_57_57", 45)
    idx = index_folder(tmp_path)
    stream = iter_corpus(idx)
    first = next(stream)  # one take loaded, the other not yet
    rest = list(stream)
    listed = load_corpus(idx)
    assert [t.stem for t in [first, *rest]] == [t.stem for t in listed] == [r.stem for r in idx]
    assert len(listed) == 2
    assert all(np.array_equal(a.rotations, b.rotations) for a, b in zip([first, *rest], listed))
    assert [t.stem for t in iter_corpus(idx, splits=("val",))] == ["2_scott_0_57_57"]
