"""The planted effects of data_samples/ appear in beatlite.stats (whole-corpus checks)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from beatlite.data.index import TakeIndex, index_folder
from beatlite.stats import (
    EmotionClassifier,
    corpus_row,
    emotion_separability,
    gesture_correlations,
    load_corpus,
    rotation_windows,
    speed_by_emotion,
)

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def index(data_samples: Path) -> TakeIndex:
    return index_folder(data_samples)


@pytest.fixture(scope="module")
def takes(index: TakeIndex) -> list:
    return load_corpus(index)


def test_corpus_is_clean_and_complete(index: TakeIndex) -> None:
    assert len(index) > 0 and index.problems() == {}
    assert index.speaker_ids() == [2, 4, 6, 8]
    assert {r.emotion for r in index} == set(range(8))
    assert {r.split for r in index} == {"train", "val", "test"}
    row = corpus_row(index)
    assert (row["n_body"], row["n_hand"], row["n_face"]) == (27, 48, 51)  # BEAT: 27 + 48 = 75 joints
    assert row["languages"] == ["english"] and row["n_speakers"] == 4


def test_speed_ordering_as_generated(takes: list) -> None:
    speeds = speed_by_emotion(takes)
    assert len(speeds) == 8
    assert max(speeds, key=speeds.get) == "anger"
    assert min(speeds, key=speeds.get) == "sadness"


def test_emotions_separate_well_above_chance(takes: list) -> None:
    sep = emotion_separability(takes, n_permutations=200)
    # take-grouped folds: balanced accuracy (chance 1/8) at least twice chance, and significant
    assert sep.balanced_accuracy >= 2 * sep.uniform_chance, sep.summary()
    assert sep.p_permutation is not None and sep.p_permutation <= 0.02, sep.summary()
    assert sep.knn_accuracy > sep.chance, sep.summary()  # beats always answering "neutral"


def test_gesture_correlations_significant(takes: list) -> None:
    res = gesture_correlations(takes, n_permutations=500)
    assert res["audio"].rho > 0 and res["audio"].p_permutation < 0.01
    assert res["emotion"].p_permutation < 0.01 and res["emotion"].eta2 > 0.3


def test_emotion_classifier_beats_chance_on_test_takes(takes: list) -> None:
    train = rotation_windows([t for t in takes if t.split == "train"])
    test = rotation_windows([t for t in takes if t.split != "train"])  # val + test takes, never seen
    acc = EmotionClassifier().fit(train.windows, train.emotion).per_class_accuracy(test.windows, test.emotion)
    assert acc["avg"] > 2 / 8, acc  # mean per-class accuracy, chance 1/8
    assert acc["sadness"] > 0.5 and acc["anger"] > 0.3, acc
    majority = np.mean(test.emotion == np.bincount(train.emotion).argmax())
    assert acc["overall"] >= majority, acc


@pytest.mark.slow
def test_take_analyses_stream_in_one_pass(index: TakeIndex, takes: list) -> None:
    """Each take analysis reads its takes once: given the one-shot iterator iter_corpus, the same numbers as
    on the loaded list (so a corpus of any size streams, holding one take at a time)."""
    from beatlite.stats.corpus import iter_corpus
    from beatlite.stats.semantic import score_histogram, speaker_scores, word_class_scores, word_scores

    subset = index.where(usable=True)

    def stream():
        return iter_corpus(subset)  # a generator: a second pass would see nothing

    assert speed_by_emotion(stream()) == speed_by_emotion(takes)
    assert word_scores(stream()) == word_scores(takes)
    assert word_class_scores(stream()) == word_class_scores(takes)
    assert speaker_scores(stream()) == speaker_scores(takes)
    a, b = score_histogram(stream()), score_histogram(takes)
    assert (a.counts == b.counts).all() and a.share_low == b.share_low and a.n == b.n
    x, y = gesture_correlations(stream(), n_permutations=50), gesture_correlations(takes, n_permutations=50)
    assert x.keys() == y.keys() == {"audio", "face", "emotion", "speaker"}
    assert all(x[k] == y[k] for k in x)
