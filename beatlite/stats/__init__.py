"""The BEAT paper's dataset analysis on any BEAT-format corpus (Table 1, Figs. 2-4, Table 6).

=========================  ================================================================
``table1``                  Table 1 analog: the corpus row beside the paper's rows
``distributions``           Fig. 2 analogs: emotion / language shares, minutes per speaker
``corpus``                  :func:`load_corpus` / :func:`iter_corpus`: per-take streams for the analyses below
``emotion_clusters``        Fig. 3a: t-SNE of 2-s rotation windows + measured separability
``semantic``                Fig. 4 analogs: semantic score histogram, per word, per speaker
``correlations``            gesture energy vs audio, face, emotion, speaker, with p-values
``emotion_classifier``      Table 6 analog: :class:`EmotionClassifier` on motion windows
``agreement``               metrics vs people: Bradley–Terry strengths from votes, Kendall's τ with intervals
=========================  ================================================================

Taught in notebooks/02_dataset_statistics.ipynb (dataset statistics), sections 1-6; ``agreement`` in
notebooks/09_scoring.ipynb, section 4.
"""

from __future__ import annotations

from beatlite.stats.agreement import (
    TauResult,
    bradley_terry,
    bradley_terry_order,
    bradley_terry_step,
    kendall_tau,
    simulate_votes,
    vote_agreement,
)
from beatlite.stats.corpus import CorpusTake, iter_corpus, load_corpus
from beatlite.stats.corpus_table import PAPER_TABLE1, corpus_row, table1, table1_markdown
from beatlite.stats.correlations import gesture_correlations, plot_correlations, speed_by_emotion
from beatlite.stats.distributions import emotion_shares, language_shares, plot_figure2, speaker_durations
from beatlite.stats.emotion_classifier import (
    PAPER_TABLE6,
    EmotionClassifier,
    plot_table6,
    table6,
    table6_windows,
)
from beatlite.stats.emotion_clusters import (
    emotion_features,
    emotion_separability,
    plot_emotion_tsne,
    rotation_windows,
)
from beatlite.stats.semantic import plot_figure4, score_histogram, speaker_scores, word_scores

__all__ = [
    "PAPER_TABLE1",
    "PAPER_TABLE6",
    "CorpusTake",
    "TauResult",
    "bradley_terry",
    "bradley_terry_order",
    "bradley_terry_step",
    "kendall_tau",
    "simulate_votes",
    "vote_agreement",
    "EmotionClassifier",
    "corpus_row",
    "emotion_features",
    "emotion_separability",
    "emotion_shares",
    "gesture_correlations",
    "language_shares",
    "iter_corpus",
    "load_corpus",
    "plot_correlations",
    "plot_emotion_tsne",
    "plot_figure2",
    "plot_figure4",
    "plot_table6",
    "table6",
    "table6_windows",
    "rotation_windows",
    "score_histogram",
    "speaker_durations",
    "speaker_scores",
    "speed_by_emotion",
    "table1",
    "table1_markdown",
    "word_scores",
]
