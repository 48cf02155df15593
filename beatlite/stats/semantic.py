"""Figure 4 analogs: distribution of semantic-relevance scores, per frequent word, per speaker.

Taught in notebooks/02_dataset_statistics.ipynb, section 4 (Figure 4: semantic relevance).

Every analysis reads its takes once, in order, keeping only per-segment or per-word scores: pass
:func:`beatlite.stats.corpus.iter_corpus` instead of a loaded list to stream over a large corpus
(:func:`plot_figure4` reads them three times: give it a list).
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from beatlite.stats.corpus import CorpusTake

#: BEAT paper Sec. 3.3 / Fig. 4b: "83% of the gestures have low semantic scores (<= 0.2)".
PAPER_LOW_SCORE_SHARE = 0.83
LOW_SCORE = 0.2


@dataclass
class ScoreHistogram:
    """Histogram of segment scores.

    Attributes
    ----------
    counts : (B,) int64
    edges : (B+1,) float64, score bin edges in [0, 1]
    share_low : float
        Fraction of segments with score <= 0.2 (the paper's 83 % statistic).
    n : int
        Number of segments.
    """

    counts: np.ndarray
    edges: np.ndarray
    share_low: float
    n: int


def score_histogram(takes: Iterable[CorpusTake], *, bins: int = 10) -> ScoreHistogram:
    """Histogram of the scores of all annotated semantic segments (one count per gesture).

    Parameters
    ----------
    takes : iterable of CorpusTake
        Their ``semantic_scores`` (S,) in [0, 1] are pooled.
    bins : int
        Equal-width bins over [0, 1].

    Returns
    -------
    ScoreHistogram

    Examples
    --------
    Five gestures scored 0, 0.1, 0.2, 0.5 and 1: three are at or below the paper's 0.2 threshold,
    three fall in the lower half of [0, 1].

    >>> from types import SimpleNamespace
    >>> takes = [SimpleNamespace(semantic_scores=np.array([0.0, 0.1, 0.5])),
    ...          SimpleNamespace(semantic_scores=np.array([0.2, 1.0]))]
    >>> h = score_histogram(takes, bins=2)
    >>> h.counts.tolist(), h.edges.tolist(), h.share_low, h.n
    ([3, 2], [0.0, 0.5, 1.0], 0.6, 5)
    """
    scores = np.concatenate([np.zeros(0, np.float32), *(t.semantic_scores for t in takes)])
    if scores.size == 0:
        raise ValueError("score_histogram: no semantic segments in the takes")
    counts, edges = np.histogram(scores, bins=bins, range=(0.0, 1.0))
    share = float(np.mean(scores <= LOW_SCORE + 1e-9))
    return ScoreHistogram(counts.astype(np.int64), edges, share, int(scores.size))


def word_scores(takes: Iterable[CorpusTake], *, top: int = 9) -> list[tuple[str, int, float]]:
    """Mean semantic score of the ``top`` most frequent words.

    A word occurrence's score is the mean per-frame semantic score over the frames its
    interval covers (frames ``i`` with ``start <= i / fps < end``; at least the frame of
    its start).

    Returns
    -------
    list of (word, count, mean score), by decreasing count then alphabetically.

    Examples
    --------
    At 1 fps "the" covers frames 0 and 2 (scores 0.1 and 0.5), "idea" frame 1 (0.9).

    >>> from types import SimpleNamespace
    >>> take = SimpleNamespace(fps=1.0, semantic=np.array([0.1, 0.9, 0.5]), words=("The", "idea", "the"),
    ...                        word_starts=np.array([0.0, 1.0, 2.0]), word_ends=np.array([1.0, 2.0, 3.0]))
    >>> [(w, n, round(s, 3)) for w, n, s in word_scores([take])]
    [('the', 2, 0.3), ('idea', 1, 0.9)]
    >>> word_scores([take], top=1)[0][0]
    'the'
    """
    scores = word_occurrence_scores(takes)
    ranked = sorted(scores, key=lambda w: (-len(scores[w]), w))[:top]
    return [(w, len(scores[w]), float(np.mean(scores[w]))) for w in ranked]


def word_occurrence_scores(takes: Iterable[CorpusTake]) -> dict[str, list[float]]:
    """Lower-cased word -> the score of each of its occurrences (see :func:`word_scores`).

    Examples
    --------
    At 2 fps, "idea" from 0.5 s to 1.5 s covers frames 1 and 2 (0.4 and 0.8): its score is 0.6.

    >>> from types import SimpleNamespace
    >>> take = SimpleNamespace(fps=2.0, semantic=np.array([0.0, 0.4, 0.8, 0.0]), words=("my", "Idea"),
    ...                        word_starts=np.array([0.0, 0.5]), word_ends=np.array([0.5, 1.5]))
    >>> {w: [round(s, 3) for s in v] for w, v in word_occurrence_scores([take]).items()}
    {'my': [0.0], 'idea': [0.6]}
    """
    scores: dict[str, list[float]] = defaultdict(list)
    for t in takes:
        for start, end, word in zip(t.word_starts, t.word_ends, t.words):
            w = word.strip().lower()
            if not w:
                continue
            a = int(np.floor(start * t.fps))
            b = max(a + 1, int(np.ceil(end * t.fps)))
            seg = t.semantic[a:b]
            if seg.size:
                scores[w].append(float(seg.mean()))
    return dict(scores)


def word_class_scores(
    takes: Iterable[CorpusTake], *, function_words: frozenset[str] | None = None
) -> dict[str, dict[str, float]]:
    """Mean semantic score of function words vs content words (the contrast of BEAT's Fig. 4c).

    BEAT's Figure 4c colours nine frequent words by lexical class. Here a word is a *function
    word* when it is in ``function_words`` (default: scikit-learn's ``ENGLISH_STOP_WORDS``, 318
    pronouns, articles, prepositions, auxiliaries, ...) and a *content word* otherwise.

    Returns
    -------
    dict ``{"function": {...}, "content": {...}}``, each with ``"occurrences"`` (int), ``"words"``
    (distinct words) and ``"mean"`` (mean score over occurrences, NaN when there are none).

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> take = SimpleNamespace(fps=1.0, semantic=np.array([0.1, 0.9, 0.5]),
    ...                        word_starts=np.array([0.0, 1.0, 2.0]), word_ends=np.array([1.0, 2.0, 3.0]),
    ...                        words=("the", "idea", "of"))
    >>> out = word_class_scores([take])
    >>> round(out["function"]["mean"], 3), out["function"]["occurrences"], out["content"]["mean"]
    (0.3, 2, 0.9)
    """
    if function_words is None:
        from sklearn.feature_extraction.text import ENGLISH_STOP_WORDS

        function_words = ENGLISH_STOP_WORDS
    scores = word_occurrence_scores(takes)
    out = {}
    for name, keep in (("function", True), ("content", False)):
        words = [w for w in scores if (w in function_words) == keep]
        values = [s for w in words for s in scores[w]]
        out[name] = {
            "occurrences": len(values),
            "words": len(words),
            "mean": float(np.mean(values)) if values else float("nan"),
        }
    return out


def speaker_scores(takes: Iterable[CorpusTake]) -> dict[int, dict[str, float]]:
    """Per speaker id: ``mean`` segment score, ``share_low`` (<= 0.2) and ``n`` segments.

    Returns
    -------
    dict speaker id -> {"mean": float in [0, 1], "share_low": float in [0, 1], "n": int}, in id order;
    speakers without segments are left out.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> takes = [SimpleNamespace(speaker_id=4, semantic_scores=np.array([0.0, 1.0])),
    ...          SimpleNamespace(speaker_id=2, semantic_scores=np.array([0.0, 0.125, 0.25, 0.625]))]
    >>> speaker_scores(takes)  # speaker 2: mean 1.0 / 4, two of four <= 0.2
    {2: {'mean': 0.25, 'share_low': 0.5, 'n': 4}, 4: {'mean': 0.5, 'share_low': 0.5, 'n': 2}}
    """
    by: dict[int, list[np.ndarray]] = defaultdict(list)
    for t in takes:
        by[t.speaker_id].append(t.semantic_scores)
    out = {}
    for sid in sorted(by):
        s = np.concatenate(by[sid])
        if s.size:
            out[sid] = {
                "mean": float(s.mean()),
                "share_low": float(np.mean(s <= LOW_SCORE + 1e-9)),
                "n": int(s.size),
            }
    return out


def plot_figure4(
    takes: Sequence[CorpusTake],
    *,
    top: int = 9,
    out: str | Path | None = None,
    formats: tuple[str, ...] = ("png", "svg"),
):
    """BEAT Fig. 4 analog in the paper's order: (a) mean score per speaker, (b) score histogram, (c) words.

    The histogram marks the paper's low-score threshold (0.2) and states the
    share of gestures at or below it; every axis has its unit. Takes without word
    timings (no TextGrid) get no panel (c) (two panels, none empty).

    Parameters
    ----------
    takes : sequence of CorpusTake
        Read three times (give a list).
    top : int
        Words in panel (c).
    out : str or Path, optional
        Path stem to save the figure to with :func:`beatlite.viz.style.save_figure`.
    formats : tuple of str
        Formats to save.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    Two takes of ``data_samples/`` with their TextGrids: three panels, one bar per speaker in (a),
    ``top`` words in (c).

    >>> import matplotlib.pyplot as plt
    >>> from beatlite.data.index import index_folder
    >>> from beatlite.data.examples import example_corpus
    >>> from beatlite.stats.corpus import load_corpus
    >>> tmp = example_corpus()
    >>> fig = plot_figure4(load_corpus(index_folder(tmp.name, cache=False)), top=5)
    >>> len(fig.axes), len(fig.axes[0].patches), len(fig.axes[2].patches)
    (3, 1, 5)
    >>> plt.close(fig)
    >>> tmp.cleanup()
    """
    import matplotlib.pyplot as plt

    from beatlite.viz.style import SYSTEM_COLOURS, figure_style, save_figure

    hist = score_histogram(takes)
    words = word_scores(takes, top=top)
    spk = speaker_scores(takes)
    with figure_style():
        n = 3 if words else 2  # no word timings (no TextGrid): no empty panel for them
        fig, axes = plt.subplots(1, n, figsize=(13 * n / 3, 4.2), layout="constrained")
        axes[0].bar([str(s) for s in spk], [v["mean"] for v in spk.values()], color=SYSTEM_COLOURS[0])
        axes[0].set_xlabel("speaker id")
        axes[0].set_ylabel("mean semantic score (0-1)")
        axes[0].set_title("(a) per speaker")
        centers = (hist.edges[:-1] + hist.edges[1:]) / 2
        axes[1].bar(centers, hist.counts / max(hist.n, 1) * 100, width=np.diff(hist.edges) * 0.9,
                    color=SYSTEM_COLOURS[0])  # fmt: skip
        axes[1].axvline(LOW_SCORE, color="#d62728", ls="--", lw=1.2)
        axes[1].text(
            LOW_SCORE,
            0.97,
            f" {LOW_SCORE}",
            color="#d62728",
            va="top",
            transform=axes[1].get_xaxis_transform(),
        )
        axes[1].set_xlabel("semantic score (0-1)")
        axes[1].set_ylabel("share of gestures (%)")
        axes[1].set_title(
            f"(b) {hist.share_low * 100:.0f}% <= {LOW_SCORE} (paper {PAPER_LOW_SCORE_SHARE * 100:.0f}%)"
        )
        if words:
            axes[2].bar([w for w, _, _ in words], [s for _, _, s in words], color=SYSTEM_COLOURS[0])
            axes[2].set_xlabel("word")
            axes[2].set_ylabel("mean semantic score (0-1)")
            axes[2].set_title(f"(c) {len(words)} most frequent words")
            axes[2].tick_params(axis="x", rotation=45)
        if out is not None:
            save_figure(fig, out, formats)
    return fig
