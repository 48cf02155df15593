"""Figure 3a analog: t-SNE of 2-s rotation windows coloured by emotion, with separability numbers.

The paper shows a t-SNE plot and says emotions are "basically distinguished into
different groups". A 2-D embedding can look clustered or not depending on
perplexity, so beatlite also *measures* separability on the high-dimensional
features: the silhouette score of the emotion labels and the cross-validated
k-NN accuracy, next to chance (the majority-class share). Folds are grouped by
take (windows of one take never sit in both train and test), otherwise
neighbouring windows of the same take would inflate the accuracy.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from beatlite.stats.corpus import CorpusTake
from beatlite.stats.distributions import EMOTION_NAMES


@dataclass
class RotationWindows:
    """Non-overlapping rotation windows of several takes.

    Attributes
    ----------
    windows : (N, L, 141) float32, degrees
    emotion : (N,) int64
        Take-level emotion id.
    speaker : (N,) int64
        Speaker id (1..30).
    take : (N,) int64
        Index of the source take in the list given to :func:`rotation_windows`.
    """

    windows: np.ndarray
    emotion: np.ndarray
    speaker: np.ndarray
    take: np.ndarray

    def __len__(self) -> int:
        return int(self.windows.shape[0])


def rotation_windows(
    takes: Sequence[CorpusTake], *, seconds: float = 2.0, stride_seconds: float | None = None
) -> RotationWindows:
    """Cut every take's 141-d rotations into windows of ``seconds`` (paper: "2s-rotation").

    Parameters
    ----------
    takes : sequence of CorpusTake
    seconds : float
        Window length (2 s = 30 frames at 15 fps).
    stride_seconds : float, optional
        Hop between windows (default: ``seconds``, non-overlapping).
    """
    if not takes:
        raise ValueError("rotation_windows: no takes")
    fps = takes[0].fps
    length = int(round(seconds * fps))
    stride = length if stride_seconds is None else int(round(stride_seconds * fps))
    if length < 2 or stride < 1:
        raise ValueError(f"rotation_windows: window of {length} frames / stride {stride} is too short")
    parts, emo, spk, tk = [], [], [], []
    for i, t in enumerate(takes):
        starts = np.arange(0, t.n_frames - length + 1, stride)
        if len(starts) == 0:
            continue
        parts.append(t.rotations[starts[:, None] + np.arange(length)])
        emo.append(np.full(len(starts), t.emotion))
        spk.append(np.full(len(starts), t.speaker_id))
        tk.append(np.full(len(starts), i))
    if not parts:
        raise ValueError(f"rotation_windows: no take is at least {length} frames long")
    return RotationWindows(
        np.concatenate(parts).astype(np.float32),
        np.concatenate(emo).astype(np.int64),
        np.concatenate(spk).astype(np.int64),
        np.concatenate(tk).astype(np.int64),
    )


def window_features(windows: np.ndarray, *, kind: str = "stats") -> np.ndarray:
    """High-dimensional features of motion windows.

    Parameters
    ----------
    windows : (N, L, D) float
        Motion windows (e.g. Euler degrees).
    kind : {"stats", "flat"}
        ``"stats"``: per channel mean, standard deviation and mean absolute frame-to-frame
        change (N, 3D) -- pose, amplitude and speed; ``"flat"``: the raw window (N, L*D).

    Returns
    -------
    (N, F) float64
    """
    x = np.asarray(windows, dtype=np.float64)
    if x.ndim != 3 or x.shape[1] < 2:
        raise ValueError(f"window_features: windows must be (N, L>=2, D), got {x.shape}")
    if kind == "flat":
        return x.reshape(len(x), -1)
    if kind != "stats":
        raise ValueError(f"window_features: kind must be 'stats' or 'flat', got {kind!r}")
    return np.concatenate([x.mean(axis=1), x.std(axis=1), np.abs(np.diff(x, axis=1)).mean(axis=1)], axis=1)


@dataclass
class Separability:
    """How well labels separate in feature space.

    Attributes
    ----------
    silhouette : float
        Silhouette score of the labels on the standardised features (-1..1; 0 = overlapping).
    knn_accuracy : float
        Mean cross-validated k-NN accuracy (take-grouped folds when groups were given).
    fold_accuracies : (F,) float64
    chance : float
        Accuracy of always predicting the most frequent class.
    uniform_chance : float
        1 / number of classes.
    n : int
        Number of windows; ``k`` neighbours, ``n_classes``.
    """

    silhouette: float
    knn_accuracy: float
    fold_accuracies: np.ndarray
    chance: float
    uniform_chance: float
    n: int
    k: int
    n_classes: int

    def summary(self) -> str:
        return (
            f"{self.n} windows, {self.n_classes} classes: {self.k}-NN accuracy {self.knn_accuracy:.3f} "
            f"(chance {self.chance:.3f}, uniform {self.uniform_chance:.3f}), silhouette {self.silhouette:.3f}"
        )


def separability(
    features: np.ndarray,
    labels: np.ndarray,
    *,
    groups: np.ndarray | None = None,
    k: int = 5,
    folds: int = 5,
    seed: int = 0,
) -> Separability:
    """Silhouette and cross-validated k-NN accuracy of ``labels`` on ``features``.

    Parameters
    ----------
    features : (N, F) float
    labels : (N,) int
    groups : (N,) int, optional
        Group of each row (e.g. take); folds never split a group (StratifiedGroupKFold).
    k : int
        Neighbours.
    folds : int
        Number of folds (reduced to the smallest class's group count if needed, at least 2).
    seed : int
        Shuffling seed of the folds.
    """
    from sklearn.metrics import silhouette_score
    from sklearn.model_selection import StratifiedGroupKFold, StratifiedKFold
    from sklearn.neighbors import KNeighborsClassifier
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    x = np.asarray(features, dtype=np.float64)
    y = np.asarray(labels)
    if x.ndim != 2 or y.shape != (x.shape[0],):
        raise ValueError(
            f"separability: features must be (N, F) and labels (N,), got {x.shape} and {y.shape}"
        )
    classes, counts = np.unique(y, return_counts=True)
    if len(classes) < 2:
        raise ValueError(f"separability: need at least 2 classes, got {classes.tolist()}")
    xs = StandardScaler().fit_transform(x)
    sil = float(silhouette_score(xs, y, metric="euclidean"))
    if groups is not None:
        g = np.asarray(groups)
        if g.shape != y.shape:
            raise ValueError(f"separability: groups must be (N,) like labels, got {g.shape}")
        per_class = min(len(np.unique(g[y == c])) for c in classes)
        n_folds = max(2, min(folds, per_class))
        splitter = StratifiedGroupKFold(n_splits=n_folds, shuffle=True, random_state=seed)
        splits = list(splitter.split(x, y, g))
    else:
        n_folds = max(2, min(folds, int(counts.min())))
        splits = list(StratifiedKFold(n_splits=n_folds, shuffle=True, random_state=seed).split(x, y))
    accs = []
    for train, test in splits:
        model = make_pipeline(StandardScaler(), KNeighborsClassifier(n_neighbors=min(k, len(train))))
        model.fit(x[train], y[train])
        accs.append(float(np.mean(model.predict(x[test]) == y[test])))
    return Separability(
        silhouette=sil,
        knn_accuracy=float(np.mean(accs)),
        fold_accuracies=np.array(accs),
        chance=float(counts.max() / counts.sum()),
        uniform_chance=1.0 / len(classes),
        n=int(len(y)),
        k=int(k),
        n_classes=int(len(classes)),
    )


def emotion_separability(
    takes: Sequence[CorpusTake], *, seconds: float = 2.0, kind: str = "stats", k: int = 5, seed: int = 0
) -> Separability:
    """:func:`separability` of the emotion labels of 2-s rotation windows, folds grouped by take."""
    rw = rotation_windows(takes, seconds=seconds)
    return separability(window_features(rw.windows, kind=kind), rw.emotion, groups=rw.take, k=k, seed=seed)


def tsne_embedding(features: np.ndarray, *, perplexity: float = 30.0, seed: int = 0) -> np.ndarray:
    """2-D t-SNE (scikit-learn, PCA init) of standardised ``features`` (N, F) -> (N, 2) float64."""
    from sklearn.decomposition import PCA
    from sklearn.manifold import TSNE
    from sklearn.preprocessing import StandardScaler

    x = StandardScaler().fit_transform(np.asarray(features, dtype=np.float64))
    if x.shape[1] > 50:  # the usual PCA-50 step before t-SNE; also makes it faster
        x = PCA(n_components=min(50, x.shape[0]), random_state=seed).fit_transform(x)
    perplexity = min(perplexity, max(2.0, (len(x) - 1) / 3))
    tsne = TSNE(n_components=2, perplexity=perplexity, init="pca", random_state=seed, max_iter=500)
    return tsne.fit_transform(x)


def plot_emotion_tsne(
    takes: Sequence[CorpusTake],
    *,
    seconds: float = 2.0,
    kind: str = "stats",
    seed: int = 0,
    out: str | Path | None = None,
    formats: tuple[str, ...] = ("png", "svg"),
):
    """Figure 3a: t-SNE of 2-s rotation windows coloured by emotion, separability in the title.

    Returns
    -------
    (matplotlib.figure.Figure, Separability)
    """
    import matplotlib.pyplot as plt

    from beatlite.viz.style import figure_style, save_figure

    rw = rotation_windows(takes, seconds=seconds)
    feats = window_features(rw.windows, kind=kind)
    sep = separability(feats, rw.emotion, groups=rw.take, seed=seed)
    emb = tsne_embedding(feats, seed=seed)
    with figure_style():
        fig, ax = plt.subplots(figsize=(6.4, 5.2))
        cmap = plt.get_cmap("tab10")
        for e in np.unique(rw.emotion):
            m = rw.emotion == e
            ax.scatter(emb[m, 0], emb[m, 1], s=8, color=cmap(int(e)), label=EMOTION_NAMES[int(e)], alpha=0.8)
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_title(
            f"t-SNE of {seconds:g}-s rotation windows\n{sep.k}-NN acc {sep.knn_accuracy:.2f} "
            f"(chance {sep.chance:.2f}), silhouette {sep.silhouette:.2f}"
        )
        ax.legend(markerscale=2, loc="best", fontsize=8)
        fig.tight_layout()
        if out is not None:
            save_figure(fig, out, formats)
    return fig, sep
