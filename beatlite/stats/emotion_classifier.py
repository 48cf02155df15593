"""Table 6 analog: an emotion classifier on motion windows (scikit-learn), usable on generated motion.

The paper trains a 1D-CNN + LSTM on speaker 4's ground truth and reports
per-class accuracy on real and on generated test clips (10 s each). beatlite
uses a random forest (or a standardised logistic regression) on per-channel
window statistics (:func:`beatlite.stats.emotion_clusters.window_features`) of
the 9 body joints (``body27``) of the 141-d rotation windows, which trains in
about a second on CPU.

Taught in notebooks/02_dataset_statistics.ipynb, section 6 (Table 6: an emotion classifier on motion) and notebooks/07_benchmark.ipynb, section 5 (does generated motion carry the emotion?).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from beatlite.constants import WINDOW_LENGTH, WINDOW_STRIDE
from beatlite.stats.distributions import EMOTION_NAMES
from beatlite.stats.emotion_clusters import subset_dims, window_features

#: BEAT paper, Table 6 (Emotional Gesture Classification), accuracy in % per class, as published.
#: Note: the "avg" of the human row is the mean of its 8 classes, but those of the real (83.26)
#: and generated (67.41) rows are not (plain means: 81.705 and 65.785); probably clip-weighted.
PAPER_TABLE6: dict[str, dict[str, float]] = {
    "human": {"neutral": 84.29, "happiness": 74.86, "sadness": 82.65, "anger": 88.36, "surprise": 76.12,
              "contempt": 71.59, "fear": 80.94, "disgust": 72.33, "avg": 78.89},
    "real": {"neutral": 51.06, "happiness": 98.68, "sadness": 85.08, "anger": 38.78, "surprise": 99.39,
             "contempt": 81.08, "fear": 99.95, "disgust": 99.62, "avg": 83.26},
    "generated": {"neutral": 36.95, "happiness": 76.83, "sadness": 62.17, "anger": 37.46, "surprise": 77.91,
                  "contempt": 70.61, "fear": 81.32, "disgust": 83.03, "avg": 67.41},
}  # fmt: skip


@dataclass
class EmotionClassifier:
    """Emotion classifier on motion windows.

    Parameters
    ----------
    model : {"forest", "logistic"}
        Random forest of 200 trees (default) or a standardised multinomial logistic regression.
    features : {"stats", "flat"}
        Window features (see :func:`window_features`).
    joints : str or None
        For 141-d ``spine_neck_141`` windows, use only this subset's dims (default ``"body27"``,
        see :func:`beatlite.stats.emotion_clusters.subset_dims`); None uses every dim given.
    seed : int
        Random seed (forest, solver).

    Examples
    --------
    Skipped by the doctests: ``train_windows``, ``train_labels``, ... stand for your own windows and labels.

    >>> clf = EmotionClassifier().fit(train_windows, train_labels)  # doctest: +SKIP
    >>> clf.per_class_accuracy(test_windows, test_labels)["avg"]  # doctest: +SKIP
    """

    model: str = "forest"
    features: str = "stats"
    joints: str | None = "body27"
    seed: int = 0
    _pipeline: Any = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        if self.model not in ("logistic", "forest"):
            raise ValueError(f"EmotionClassifier: model must be 'forest' or 'logistic', got {self.model!r}")

    def _features(self, windows: np.ndarray) -> np.ndarray:
        x = np.asarray(windows)
        if self.joints is not None:
            if x.ndim != 3 or x.shape[2] != 141:
                raise ValueError(
                    f"EmotionClassifier: joints={self.joints!r} needs (N, L, 141) spine_neck_141 windows, "
                    f"got {x.shape}; pass joints=None for other layouts"
                )
            x = x[:, :, subset_dims(self.joints)]
        return window_features(x, kind=self.features)

    def fit(self, windows: np.ndarray, labels: np.ndarray) -> EmotionClassifier:
        """Train on ``windows`` (N, L, D) float (e.g. Euler degrees) with ``labels`` (N,) emotion ids."""
        from sklearn.ensemble import RandomForestClassifier
        from sklearn.linear_model import LogisticRegression
        from sklearn.pipeline import make_pipeline
        from sklearn.preprocessing import StandardScaler

        x = self._features(windows)
        y = np.asarray(labels, dtype=np.int64)
        if y.shape != (x.shape[0],):
            raise ValueError(f"EmotionClassifier.fit: labels must be ({x.shape[0]},), got {y.shape}")
        if len(np.unique(y)) < 2:
            raise ValueError("EmotionClassifier.fit: need at least 2 emotions in labels")
        if self.model == "logistic":
            head = LogisticRegression(C=0.1, max_iter=2000, random_state=self.seed)
        else:
            head = RandomForestClassifier(n_estimators=200, random_state=self.seed, n_jobs=1)
        self._pipeline = make_pipeline(StandardScaler(), head).fit(x, y)
        return self

    def _check_fitted(self) -> None:
        if self._pipeline is None:
            raise RuntimeError("EmotionClassifier: call fit() first")

    def predict(self, windows: np.ndarray) -> np.ndarray:
        """(N,) int64 predicted emotion ids of windows (N, L, D)."""
        self._check_fitted()
        return np.asarray(self._pipeline.predict(self._features(windows)), dtype=np.int64)

    def predict_proba(self, windows: np.ndarray) -> np.ndarray:
        """(N, C) float64 class probabilities, columns in :attr:`classes` order."""
        self._check_fitted()
        return self._pipeline.predict_proba(self._features(windows))

    @property
    def classes(self) -> np.ndarray:
        """(C,) int64 emotion ids seen in training."""
        self._check_fitted()
        return np.asarray(self._pipeline.classes_, dtype=np.int64)

    def per_class_accuracy(self, windows: np.ndarray, labels: np.ndarray) -> dict[str, float]:
        """Accuracy (recall) per emotion present in ``labels``, plus ``"avg"`` (their mean) and
        ``"overall"`` (fraction of all windows correct); values in [0, 1], keys are emotion names."""
        y = np.asarray(labels, dtype=np.int64)
        pred = self.predict(windows)
        if pred.shape != y.shape:
            raise ValueError(f"per_class_accuracy: labels must be {pred.shape}, got {y.shape}")
        out = {EMOTION_NAMES[int(c)]: float(np.mean(pred[y == c] == c)) for c in np.unique(y)}
        out["avg"] = float(np.mean(list(out.values())))
        out["overall"] = float(np.mean(pred == y))
        return out


def table6_windows(
    euler: list[np.ndarray],
    emotion: list[np.ndarray],
    *,
    length: int = WINDOW_LENGTH,
    stride: int = WINDOW_STRIDE,
) -> tuple[np.ndarray, np.ndarray]:
    """BEAT Table 6's samples: motion windows of whole takes, each labelled with its middle frame's emotion.

    The one definition every Table 6 of beatlite uses (notebooks 02 and 07): 34-frame windows,
    stride 10, of the 141 ``spine_neck_141`` Euler channels (the model output space, so real and
    generated motion are cut the same way).

    Parameters
    ----------
    euler : list of (T_k, 141) float, degrees
        One array per take (real, or generated and denormalised).
    emotion : list of (T_k,) int
        The take's per-frame emotion ids (the ground truth's, also for generated motion).

    Returns
    -------
    windows : (N, length, 141) float
    labels : (N,) int64
        The emotion at frame ``length // 2`` of each window.

    Examples
    --------
    >>> w, y = table6_windows([np.zeros((54, 141))], [np.repeat([0, 5], 27)])
    >>> w.shape, y.tolist()  # starts 0, 10, 20: middle frames 17, 27, 37
    ((3, 34, 141), [0, 5, 5])
    """
    from beatlite.data.windows import sliding_windows

    if len(euler) != len(emotion):
        raise ValueError(f"table6_windows: {len(euler)} motion takes but {len(emotion)} emotion tracks")
    windows = sliding_windows([np.asarray(e) for e in euler], length, stride)
    mids = sliding_windows([np.asarray(e, dtype=np.int64) for e in emotion], length, stride)[:, length // 2]
    return windows, mids


def table6(
    train: tuple[list[np.ndarray], list[np.ndarray]],
    rows: dict[str, tuple[list[np.ndarray], list[np.ndarray]]],
    *,
    seed: int = 0,
) -> dict[str, dict[str, float]]:
    """BEAT Table 6 analog: per-class accuracy of an emotion classifier trained on real train takes.

    Parameters
    ----------
    train : (euler, emotion) lists of the real **train** takes (see :func:`table6_windows`)
    rows : dict of row name -> (euler, emotion) lists
        E.g. ``{"real": real test takes, "CaMN": CaMN's generation of the same takes}``.
    seed : int
        The classifier's seed.

    Returns
    -------
    dict row name -> :meth:`EmotionClassifier.per_class_accuracy` (fractions, with ``"avg"``).

    Examples
    --------
    A still neutral take and a swinging surprised one (a 30-degree sine on every channel) to train on,
    two new takes of each kind to test: every test window is classified right.

    >>> rng = np.random.default_rng(0)
    >>> def take(amplitude, n=100):  # (n, 141) Euler degrees
    ...     return amplitude * np.sin(np.arange(n) / 2)[:, None] + rng.normal(size=(n, 141))
    >>> labels = [np.zeros(100, int), np.full(100, 5)]  # neutral, surprise
    >>> rows = table6(([take(0.0), take(30.0)], labels), {"real": ([take(0.0), take(30.0)], labels)})
    >>> rows["real"]
    {'neutral': 1.0, 'surprise': 1.0, 'avg': 1.0, 'overall': 1.0}
    """
    clf = EmotionClassifier(seed=seed).fit(*table6_windows(*train))
    return {name: clf.per_class_accuracy(*table6_windows(*takes)) for name, takes in rows.items()}


def table6_markdown(real: dict[str, float], generated: dict[str, float] | None = None) -> str:
    """Markdown table: the paper's Table 6 rows (%) and this corpus's real (and generated) rows.

    Parameters
    ----------
    real, generated : dict str -> float
        Accuracy in [0, 1] per emotion name and ``"avg"`` (:meth:`EmotionClassifier.per_class_accuracy`);
        a class absent from the dict is shown as ``-``.

    Returns
    -------
    str
        Header, rule, the 3 paper rows, then 1 or 2 beatlite rows, in percent with 2 decimals.

    Examples
    --------
    >>> lines = table6_markdown({"neutral": 0.5, "anger": 1.0, "avg": 0.75}).splitlines()
    >>> len(lines), lines[0]
    (6, '| row | neutral | happiness | sadness | anger | surprise | contempt | fear | disgust | avg |')
    >>> lines[-1]
    '| beatlite real | 50.00 | - | - | 100.00 | - | - | - | - | 75.00 |'
    """
    cols = ["neutral", "happiness", "sadness", "anger", "surprise", "contempt", "fear", "disgust", "avg"]
    lines = ["| row | " + " | ".join(cols) + " |", "|" + "|".join("---" for _ in range(len(cols) + 1)) + "|"]
    for name, row in PAPER_TABLE6.items():
        lines.append(f"| paper {name} | " + " | ".join(f"{row[c]:.2f}" for c in cols) + " |")
    for name, row in (("beatlite real", real), ("beatlite generated", generated)):
        if row is not None:
            lines.append(
                f"| {name} | "
                + " | ".join("-" if c not in row else f"{100 * row[c]:.2f}" for c in cols)
                + " |"
            )
    return "\n".join(lines)


def plot_table6(
    real: dict[str, float],
    generated: dict[str, float] | None = None,
    *,
    generated_by: str = "CaMN",
    out: str | Path | None = None,
    formats: tuple[str, ...] = ("png", "svg"),
):
    """Per-class accuracy (%) of this corpus (real, optionally generated) beside the paper's Table 6 rows.

    BEAT (ECCV 2022) Table 6 as bars: the paper's rows in light colours, this
    corpus's in the systems' colours (:func:`beatlite.viz.style.system_colour`),
    the legend right of the bars. A 0 % bar is drawn as a thick line on the axis
    with a "0" above it, so it does not look like a missing value.

    Parameters
    ----------
    real, generated : dict str -> float
        Per-class accuracy in [0, 1] (keys: emotion names and ``"avg"``) on real
        motion and, optionally, on generated motion.
    generated_by : str
        The model that generated the motion, named in the legend.
    out : str or Path, optional
        Path stem to save to with :func:`beatlite.viz.style.save_figure`.
    formats : tuple of str
        Formats to save.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    Three rows of bars (the paper's real and generated rows, this corpus's real one) over 8 emotions
    and their average: 27 bars, on a 0-100 % axis.

    >>> import matplotlib.pyplot as plt
    >>> fig = plot_table6({"neutral": 0.5, "anger": 1.0, "avg": 0.75})
    >>> len(fig.axes[0].patches), tuple(float(v) for v in fig.axes[0].get_ylim())
    (27, (0.0, 100.0))
    >>> plt.close(fig)
    """
    import matplotlib.pyplot as plt

    from beatlite.viz.style import figure_style, legend_outside, save_figure, system_colour

    names = [*EMOTION_NAMES, "avg"]
    rows: list[tuple[str, list[float], str]] = [
        ("paper, real", [PAPER_TABLE6["real"][n] for n in names], "#bdbdbd"),
        ("paper, generated", [PAPER_TABLE6["generated"][n] for n in names], "#9ecae1"),
        ("beatlite, real", [100 * real.get(n, np.nan) for n in names], system_colour("real")),
    ]
    if generated is not None:
        rows.append((f"beatlite, generated ({generated_by})", [100 * generated.get(n, np.nan) for n in names],
                     system_colour(generated_by)))  # fmt: skip
    with figure_style():
        fig, ax = plt.subplots(figsize=(11, 4.2), layout="constrained")
        x = np.arange(len(names))
        width = 0.8 / len(rows)
        for k, (label, values, colour) in enumerate(rows):
            where = x + (k - (len(rows) - 1) / 2) * width
            ax.bar(where, values, width, label=label, color=colour)
            for xi, v in zip(where, values):  # a 0 % bar has no height: say 0, so it does not read as missing
                if np.isfinite(v) and v < 0.5:
                    ax.plot([xi - width / 2, xi + width / 2], [0, 0], color=colour, lw=3, solid_capstyle="butt",
                            label="_zero", clip_on=False)  # fmt: skip
                    ax.text(
                        xi, 1.5, "0", ha="center", va="bottom", fontsize=9, color=colour, fontweight="bold"
                    )
        ax.set_xticks(x, names, rotation=30, ha="right")
        ax.set_xlabel("emotion class")
        ax.set_ylabel("accuracy (%)")
        ax.set_ylim(0, 100)
        ax.set_title("Emotion classification of motion windows (Table 6 analog)")
        legend_outside(ax, "right")
        if out is not None:
            save_figure(fig, out, formats)
    return fig
