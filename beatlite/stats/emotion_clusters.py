"""Figure 3a analog: t-SNE of 2-s rotation windows coloured by emotion, with separability numbers.

The paper shows a t-SNE plot and says emotions are "basically distinguished into
different groups". A 2-D embedding can look clustered or not depending on
perplexity, so beatlite also *measures* separability on the high-dimensional
features: the silhouette score of the emotion labels and the cross-validated
k-NN accuracy and balanced accuracy, next to their chance levels (majority-class
share; 1 / number of classes), with a permutation test. Folds are grouped by
take (windows of one take never sit in both train and test), otherwise
neighbouring windows of the same take would inflate the accuracy.

Scale: features are computed take by take (:func:`emotion_features`; ``takes`` may be
the single-pass :func:`beatlite.stats.iter_corpus`), 81 numbers per window for the default
``"stats"`` of ``"body27"``. The distance matrix, silhouette and t-SNE are O(N^2), so with more
than ``max_windows`` (2000) windows a uniform subset drawn with ``seed`` is scored
(:meth:`EmotionFeatures.subsample`): bounded time and memory at any corpus size, and the
same numbers as before on corpora with fewer windows (``data_samples/``: 341).

Taught in notebooks/02_dataset_statistics.ipynb, section 3 (Figure 3a: do gestures differ by emotion?).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
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
        Emotion id of each window's middle frame (the take's per-frame ``emotion_frames``: a speech take's
        emotion from its name, a conversation's turn by turn).
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


def _window_length(fps: float, seconds: float, stride_seconds: float | None) -> tuple[int, int]:
    length = int(round(seconds * fps))
    stride = length if stride_seconds is None else int(round(stride_seconds * fps))
    if length < 2 or stride < 1:
        raise ValueError(f"rotation_windows: window of {length} frames / stride {stride} is too short")
    return length, stride


def _take_windows(take: CorpusTake, length: int, stride: int) -> np.ndarray:
    """(W, length, 141) rotation windows of one take (W may be 0)."""
    from beatlite.data.windows import sliding_windows

    return sliding_windows(take.rotations, length, stride)


def rotation_windows(
    takes: Iterable[CorpusTake], *, seconds: float = 2.0, stride_seconds: float | None = None
) -> RotationWindows:
    """Cut every take's 141-d rotations into windows of ``seconds`` (paper: "2s-rotation").

    Parameters
    ----------
    takes : iterable of CorpusTake
        A list, or a single-pass iterator such as :func:`beatlite.stats.iter_corpus`.
    seconds : float
        Window length (2 s = 30 frames at 15 fps).
    stride_seconds : float, optional
        Hop between windows (default: ``seconds``, non-overlapping).

    Returns
    -------
    RotationWindows
        ``floor(T / L)`` windows of ``L = round(seconds * fps)`` frames per take (non-overlapping).

    Examples
    --------
    A 75-frame take at 15 fps holds two 30-frame windows (frames 0-29, 30-59); its emotion turns from
    neutral to anger at frame 40, so the second window's middle frame (45) is angry. A 29-frame take
    holds none.

    >>> from types import SimpleNamespace
    >>> long = SimpleNamespace(fps=15.0, rotations=np.zeros((75, 141)), speaker_id=2,
    ...                        emotion_frames=np.repeat([0, 2], [40, 35]))
    >>> short = SimpleNamespace(fps=15.0, rotations=np.zeros((29, 141)), speaker_id=4,
    ...                         emotion_frames=np.zeros(29, int))
    >>> rw = rotation_windows([long, short], seconds=2.0)
    >>> rw.windows.shape, rw.emotion.tolist(), rw.take.tolist(), rw.speaker.tolist()
    ((2, 30, 141), [0, 2], [0, 0], [2, 2])
    """
    parts, emo, spk, tk = [], [], [], []
    for i, t, w, e in _windows_by_take(takes, seconds, stride_seconds, "rotation_windows"):
        parts.append(w)
        emo.append(e)
        spk.append(np.full(len(w), t.speaker_id))
        tk.append(np.full(len(w), i))
    return RotationWindows(
        np.concatenate(parts).astype(np.float32),
        np.concatenate(emo).astype(np.int64),
        np.concatenate(spk).astype(np.int64),
        np.concatenate(tk).astype(np.int64),
    )


def _windows_by_take(
    takes: Iterable[CorpusTake], seconds: float, stride_seconds: float | None, who: str
) -> Iterator[tuple[int, CorpusTake, np.ndarray, np.ndarray]]:
    """``(take number, take, its (W, L, 141) windows, their (W,) int64 emotions)`` for every take with a window,
    in one pass over ``takes``. A window's emotion is that of its middle frame (``emotion_frames``), as Table 6's
    windows are labelled (:func:`beatlite.stats.emotion_classifier.table6_windows`).

    Raises ``ValueError`` (naming ``who``) when there is no take, or no take has a whole window.
    """
    length = stride = None
    n_takes = found = 0
    for i, t in enumerate(takes):
        n_takes += 1
        if length is None:
            length, stride = _window_length(t.fps, seconds, stride_seconds)
        w = _take_windows(t, length, stride)
        if len(w):
            found += 1
            yield i, t, w, np.asarray(t.emotion_frames, np.int64)[np.arange(len(w)) * stride + length // 2]
    if n_takes == 0:
        raise ValueError(f"{who}: no takes")
    if not found:
        raise ValueError(f"{who}: no take is at least {length} frames long")


def subset_dims(joints: str) -> np.ndarray:
    """Positions, inside the 141-d ``spine_neck_141`` vector, of the rotation dims of a joint subset.

    Parameters
    ----------
    joints : str
        A key of :data:`beatlite.skeleton.JOINT_SUBSETS` whose joints all lie in ``spine_neck_141``
        (``"body27"``, ``"hands114"``, ``"spine_neck_141"``).

    Returns
    -------
    (3K,) int64, e.g. 27 dims for ``"body27"`` (0-17 and 75-83).

    Examples
    --------
    3 Euler angles for each of the 9 body joints: the 6 joints before the right hand's 25, then the 3 after.

    >>> dims = subset_dims("body27")
    >>> len(dims), dims[:18].tolist() == list(range(18)), dims[18:].tolist()
    (27, True, [75, 76, 77, 78, 79, 80, 81, 82, 83])
    >>> len(subset_dims("hands114")) + len(dims) == len(subset_dims("spine_neck_141"))
    True
    """
    from beatlite.skeleton import JOINT_SUBSETS

    if joints not in JOINT_SUBSETS:
        raise ValueError(f"subset_dims: joints must be one of {sorted(JOINT_SUBSETS)}, got {joints!r}")
    order = {name: i for i, name in enumerate(JOINT_SUBSETS["spine_neck_141"])}
    missing = [n for n in JOINT_SUBSETS[joints] if n not in order]
    if missing:
        raise ValueError(f"subset_dims: joints of {joints!r} not in spine_neck_141: {missing[:3]}")
    return np.array([3 * order[n] + c for n in JOINT_SUBSETS[joints] for c in range(3)], dtype=np.int64)


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
        ``F = 3 D`` for ``"stats"`` (means, then standard deviations, then mean speeds, each in
        ``windows``' units per frame), ``L D`` for ``"flat"``.

    Examples
    --------
    One channel moving 0, 2, 4 degrees: mean 2, standard deviation sqrt(8/3) = 1.633, 2 degrees per frame.

    >>> np.round(window_features(np.array([[[0.0], [2.0], [4.0]]])), 3).tolist()
    [[2.0, 1.633, 2.0]]
    >>> windows = np.zeros((5, 30, 27))  # 5 windows of 30 frames x 27 channels
    >>> window_features(windows).shape, window_features(windows, kind="flat").shape
    ((5, 81), (5, 810))
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
    balanced_accuracy : float
        Mean cross-validated k-NN balanced accuracy (mean per-class recall); its chance
        level is ``uniform_chance`` whatever the class sizes.
    fold_accuracies : (F,) float64
    chance : float
        Accuracy of always predicting the most frequent class (the chance level of
        ``knn_accuracy``).
    uniform_chance : float
        1 / number of classes (the chance level of ``balanced_accuracy``).
    p_permutation : float or None
        Permutation p-value of ``balanced_accuracy``: labels shuffled between groups
        (takes), ``(1 + #{null >= observed}) / (1 + n_permutations)``; None if not run.
    n : int
        Number of windows; ``k`` neighbours, ``n_classes``.
    """

    silhouette: float
    knn_accuracy: float
    balanced_accuracy: float
    fold_accuracies: np.ndarray
    chance: float
    uniform_chance: float
    p_permutation: float | None
    n: int
    k: int
    n_classes: int

    def summary(self) -> str:
        p = "" if self.p_permutation is None else f", permutation p {self.p_permutation:.3g}"
        return (
            f"{self.n} windows, {self.n_classes} classes: {self.k}-NN accuracy {self.knn_accuracy:.3f} "
            f"(majority chance {self.chance:.3f}), balanced accuracy {self.balanced_accuracy:.3f} "
            f"(chance {self.uniform_chance:.3f}{p}), silhouette {self.silhouette:.3f}"
        )


def _knn_predict(dist: np.ndarray, train_labels: np.ndarray, k: int) -> np.ndarray:
    """Majority vote of the ``k`` nearest training rows (ties -> smallest label, as scikit-learn).

    ``dist`` is (n_test, n_train); ``train_labels`` (n_train,) int64 in 0..C-1.
    """
    k = min(k, dist.shape[1])
    nearest = np.argpartition(dist, k - 1, axis=1)[:, :k]
    votes = train_labels[nearest]
    n_classes = int(train_labels.max()) + 1
    counts = np.zeros((len(dist), n_classes), dtype=np.int64)
    np.add.at(counts, (np.repeat(np.arange(len(dist)), k), votes.ravel()), 1)
    return counts.argmax(axis=1)


def _cv_knn(dist: np.ndarray, y: np.ndarray, groups: np.ndarray | None, k: int, folds: int, seed: int):
    """(accuracies, balanced accuracies) of k-NN over stratified (group) folds, from a distance matrix."""
    from sklearn.model_selection import StratifiedGroupKFold, StratifiedKFold

    _, counts = np.unique(y, return_counts=True)
    if groups is not None:
        n_folds = max(2, min(folds, len(np.unique(groups))))
        splits = StratifiedGroupKFold(n_splits=n_folds, shuffle=True, random_state=seed).split(
            dist, y, groups
        )
    else:
        n_folds = max(2, min(folds, int(counts.min())))
        splits = StratifiedKFold(n_splits=n_folds, shuffle=True, random_state=seed).split(dist, y)
    accs, bals = [], []
    for train, test in splits:
        pred = _knn_predict(dist[np.ix_(test, train)], y[train], k)
        accs.append(float(np.mean(pred == y[test])))
        bals.append(float(np.mean([np.mean(pred[y[test] == c] == c) for c in np.unique(y[test])])))
    return np.array(accs), np.array(bals)


def separability(
    features: np.ndarray,
    labels: np.ndarray,
    *,
    groups: np.ndarray | None = None,
    k: int = 5,
    folds: int = 5,
    n_permutations: int = 0,
    seed: int = 0,
) -> Separability:
    """Silhouette and cross-validated k-NN (balanced) accuracy of ``labels`` on ``features``.

    Features are standardised once over all rows (no labels involved); k-NN uses Euclidean
    distance with a majority vote (ties to the smallest label, like scikit-learn's
    ``KNeighborsClassifier``), so one distance matrix serves every fold and permutation.

    Parameters
    ----------
    features : (N, F) float
    labels : (N,) int
    groups : (N,) int, optional
        Group of each row (e.g. take); folds never split a group (StratifiedGroupKFold), and
        the permutation test shuffles labels between groups (each group keeps one label
        when it had one).
    k : int
        Neighbours.
    folds : int
        Number of folds (at most the number of groups; without groups, at most the smallest
        class size; at least 2). A class with fewer groups than folds is absent from some
        test folds; balanced accuracy averages the classes present in each fold.
    n_permutations : int
        Label shuffles for :attr:`Separability.p_permutation` (0: skip).
    seed : int
        Seed of the folds and the shuffles.

    Returns
    -------
    Separability

    Examples
    --------
    Two blobs 20 standard deviations apart, 10 rows each: every row's nearest neighbours share its
    label (accuracy 1 against chance 1/2).

    >>> rng = np.random.default_rng(0)
    >>> features = np.concatenate([rng.normal(0, 1, (10, 4)), rng.normal(20, 1, (10, 4))])
    >>> labels = np.repeat([0, 1], 10)
    >>> sep = separability(features, labels, k=3)
    >>> sep.knn_accuracy, sep.balanced_accuracy, sep.chance, sep.uniform_chance, sep.n, sep.n_classes
    (1.0, 1.0, 0.5, 0.5, 20, 2)
    >>> bool(sep.silhouette > 0.9)
    True
    """
    from scipy.spatial.distance import cdist
    from sklearn.metrics import silhouette_score
    from sklearn.preprocessing import StandardScaler

    x = np.asarray(features, dtype=np.float64)
    y_in = np.asarray(labels)
    if x.ndim != 2 or y_in.shape != (x.shape[0],):
        raise ValueError(
            f"separability: features must be (N, F) and labels (N,), got {x.shape} and {y_in.shape}"
        )
    classes, y = np.unique(y_in, return_inverse=True)
    counts = np.bincount(y)
    if len(classes) < 2:
        raise ValueError(f"separability: need at least 2 classes, got {classes.tolist()}")
    g = None
    if groups is not None:
        g = np.asarray(groups)
        if g.shape != y.shape:
            raise ValueError(f"separability: groups must be (N,) like labels, got {g.shape}")
    xs = StandardScaler().fit_transform(x)  # label-free, so standardising all rows at once leaks nothing
    sil = float(silhouette_score(xs, y, metric="euclidean"))
    dist = cdist(xs, xs, "sqeuclidean")
    accs, bals = _cv_knn(dist, y, g, k, folds, seed)
    p_perm = None
    if n_permutations > 0:
        rng = np.random.default_rng(seed)
        observed = float(bals.mean())
        unit = np.arange(len(y)) if g is None else g
        _, first, inverse = np.unique(unit, return_index=True, return_inverse=True)
        unit_labels = y[first]
        hits = 0
        for _ in range(n_permutations):
            y_perm = rng.permutation(unit_labels)[inverse]
            hits += _cv_knn(dist, y_perm, g, k, folds, seed)[1].mean() >= observed - 1e-12
        p_perm = (1 + hits) / (1 + n_permutations)
    return Separability(
        silhouette=sil,
        knn_accuracy=float(accs.mean()),
        balanced_accuracy=float(bals.mean()),
        fold_accuracies=accs,
        chance=float(counts.max() / counts.sum()),
        uniform_chance=1.0 / len(classes),
        p_permutation=p_perm,
        n=int(len(y)),
        k=int(k),
        n_classes=int(len(classes)),
    )


def per_group_standardize(features: np.ndarray, groups: np.ndarray) -> np.ndarray:
    """z-score ``features`` (N, F) within each group (e.g. speaker); constant columns become 0.

    Removes each speaker's overall style (mean pose, typical speed) so that what remains is
    the within-speaker variation, e.g. by emotion. Uses no labels.

    Parameters
    ----------
    features : (N, F) float
    groups : (N,)
        Group of each row (e.g. speaker id).

    Returns
    -------
    (N, F) float64, mean 0 and standard deviation 1 per column within each group.

    Examples
    --------
    Speaker 2 moves at 1 or 3 cm/s, speaker 4 at 10 or 30: each becomes -1, +1 within its speaker.

    >>> speed, speaker = np.array([[1.0], [3.0], [10.0], [30.0]]), np.array([2, 2, 4, 4])
    >>> per_group_standardize(speed, speaker).ravel().tolist()
    [-1.0, 1.0, -1.0, 1.0]
    """
    x = np.asarray(features, dtype=np.float64).copy()
    g = np.asarray(groups)
    for gid in np.unique(g):
        m = g == gid
        mu, sd = x[m].mean(axis=0), x[m].std(axis=0)
        x[m] = (x[m] - mu) / np.where(sd > 1e-12, sd, 1.0)
    return x


#: Default cap on the windows that enter the O(N^2) steps (distances, silhouette, t-SNE).
MAX_WINDOWS = 2000


@dataclass
class EmotionFeatures:
    """Features of the 2-s rotation windows of several takes (see :func:`emotion_features`).

    Attributes
    ----------
    features : (N, F) float64
    emotion, speaker, take : (N,) int64
        Emotion id of each window's middle frame (see :class:`RotationWindows`), speaker id (1..30), index of
        the take in the input order.
    """

    features: np.ndarray
    emotion: np.ndarray
    speaker: np.ndarray
    take: np.ndarray

    def __len__(self) -> int:
        return int(self.features.shape[0])

    def subsample(self, max_windows: int | None, seed: int = 0) -> EmotionFeatures:
        """At most ``max_windows`` rows drawn uniformly without replacement (``default_rng(seed)``),
        kept in their order; all rows (``self``) when there are no more than that or ``max_windows`` is None."""
        if max_windows is None or len(self) <= max_windows:
            return self
        if max_windows < 2:
            raise ValueError(f"EmotionFeatures.subsample: max_windows must be >= 2, got {max_windows}")
        keep = np.sort(np.random.default_rng(seed).choice(len(self), size=int(max_windows), replace=False))
        return EmotionFeatures(self.features[keep], self.emotion[keep], self.speaker[keep], self.take[keep])


def emotion_features(
    takes: Iterable[CorpusTake],
    *,
    seconds: float = 2.0,
    kind: str = "stats",
    joints: str = "body27",
    per_speaker: bool = True,
) -> EmotionFeatures:
    """:func:`window_features` of the ``joints`` dims of every take's 2-s rotation windows, take by take.

    Only the features are kept (O(N F) memory, e.g. 81 numbers per window for ``"stats"`` of
    ``"body27"``), so ``takes`` may be a single-pass iterator (:func:`beatlite.stats.iter_corpus`).
    ``per_speaker``: standardised within each speaker (:func:`per_group_standardize`) over all windows.

    Parameters
    ----------
    takes : iterable of CorpusTake
        Each needs ``fps``, ``rotations`` (T, 141) degrees, ``emotion_frames`` (T,) and ``speaker_id``.
    seconds : float
        Window length, seconds.
    kind : {"stats", "flat"}
        See :func:`window_features`.
    joints : str
        See :func:`subset_dims`.
    per_speaker : bool
        Standardise within each speaker.

    Returns
    -------
    EmotionFeatures
        (N, F) features: F = 3 x 27 = 81 for ``"stats"`` of ``"body27"``.

    Examples
    --------
    Six 6-s takes of one speaker hold 6 x 3 two-second windows;
    :meth:`EmotionFeatures.subsample` keeps a seeded subset in order.

    >>> from types import SimpleNamespace
    >>> rng = np.random.default_rng(0)
    >>> def take(emotion, amplitude):  # 6 s at 15 fps (three 2-s windows) of one speaker, degrees
    ...     rotations = amplitude * np.sin(np.arange(90) / 2)[:, None] + rng.normal(size=(90, 141))
    ...     emotion_frames = np.full(90, emotion)
    ...     return SimpleNamespace(fps=15.0, rotations=rotations, emotion_frames=emotion_frames, speaker_id=2)
    >>> takes = [take(0, 0.0) for _ in range(3)] + [take(2, 30.0) for _ in range(3)]  # still vs swinging
    >>> ef = emotion_features(takes)
    >>> ef.features.shape, ef.emotion.tolist()[::3], ef.take.tolist()[:6]
    ((18, 81), [0, 0, 0, 2, 2, 2], [0, 0, 0, 1, 1, 1])
    >>> sub = ef.subsample(5)
    >>> len(sub), bool(np.all(np.diff(sub.take) >= 0))
    (5, True)
    """
    dims = subset_dims(joints)
    feats, emo, spk, tk = [], [], [], []
    for i, t, w, e in _windows_by_take(takes, seconds, None, "emotion_features"):
        feats.append(window_features(w[:, :, dims].astype(np.float32), kind=kind))
        emo.append(e)
        spk.append(np.full(len(w), t.speaker_id, np.int64))
        tk.append(np.full(len(w), i, np.int64))
    out = EmotionFeatures(np.concatenate(feats), np.concatenate(emo), np.concatenate(spk), np.concatenate(tk))
    if per_speaker:
        out.features = per_group_standardize(out.features, out.speaker)
    return out


def emotion_separability(
    takes: Iterable[CorpusTake],
    *,
    seconds: float = 2.0,
    kind: str = "stats",
    joints: str = "body27",
    per_speaker: bool = True,
    k: int = 5,
    n_permutations: int = 0,
    max_windows: int | None = MAX_WINDOWS,
    seed: int = 0,
) -> Separability:
    """:func:`separability` of the emotion labels of 2-s rotation windows, folds grouped by take.

    Parameters
    ----------
    takes : iterable of CorpusTake
        A list or a single-pass iterator (features are computed take by take).
    seconds : float
        Window length.
    kind : {"stats", "flat"}
        Features (:func:`window_features`).
    joints : str
        Joints whose rotations enter the features (:func:`subset_dims`): ``"body27"`` (default;
        the 9 spine/arm joints that carry the gesture -- with all 47 joints the 38 hand joints
        make up 114 of 141 dimensions and dominate the distances) or ``"spine_neck_141"``.
    per_speaker : bool
        Standardise the features within each speaker first (:func:`per_group_standardize`, over
        all windows), so that speaker style does not mask emotion (the paper's Fig. 3b compares
        emotions within one speaker).
    k, n_permutations
        See :func:`separability`.
    max_windows : int or None
        The distance matrix, silhouette and k-NN folds are O(N^2): with more windows than this,
        a uniform random subset of ``max_windows`` windows (drawn with ``seed``,
        :meth:`EmotionFeatures.subsample`) is scored, so time and memory stay bounded (2000:
        32 MB of distances). A corpus with fewer windows (``data_samples/``: 341) is scored whole,
        so its numbers do not depend on it. None: always all windows.
    seed : int
        Seed of the subset, the folds and the permutations.

    Returns
    -------
    Separability

    Examples
    --------
    Three still takes against three swinging ones (30-degree sine on every channel): each held-out
    take's windows find their 3 nearest neighbours among the other takes of their emotion.

    >>> from types import SimpleNamespace
    >>> rng = np.random.default_rng(0)
    >>> def take(emotion, amplitude):  # 6 s at 15 fps (three 2-s windows) of one speaker, degrees
    ...     rotations = amplitude * np.sin(np.arange(90) / 2)[:, None] + rng.normal(size=(90, 141))
    ...     emotion_frames = np.full(90, emotion)
    ...     return SimpleNamespace(fps=15.0, rotations=rotations, emotion_frames=emotion_frames, speaker_id=2)
    >>> takes = [take(0, 0.0) for _ in range(3)] + [take(2, 30.0) for _ in range(3)]  # still vs swinging
    >>> sep = emotion_separability(takes, k=3)
    >>> sep.n, sep.n_classes, sep.balanced_accuracy, sep.uniform_chance
    (18, 2, 1.0, 0.5)
    """
    ef = emotion_features(takes, seconds=seconds, kind=kind, joints=joints, per_speaker=per_speaker)
    ef = ef.subsample(max_windows, seed)
    return separability(
        ef.features, ef.emotion, groups=ef.take, k=k, n_permutations=n_permutations, seed=seed
    )


def tsne_embedding(features: np.ndarray, *, perplexity: float = 30.0, seed: int = 0) -> np.ndarray:
    """2-D t-SNE (scikit-learn, PCA init) of standardised ``features`` (N, F) -> (N, 2) float64.

    The perplexity is capped at ``(N - 1) / 3`` (t-SNE needs more points than 3 x perplexity); 500
    iterations. Distances in the embedding have no unit; only neighbourhoods are meaningful.

    Examples
    --------
    Two blobs far apart in 6-D stay apart in 2-D: every point's nearest neighbour has its label.
    Skipped by the doctests (500 t-SNE iterations take 1-5 s on a 2-core CPU; :func:`plot_emotion_tsne`'s
    Example runs it).

    >>> rng = np.random.default_rng(0)
    >>> features = np.concatenate([rng.normal(0, 1, (10, 6)), rng.normal(20, 1, (10, 6))])
    >>> emb = tsne_embedding(features)  # doctest: +SKIP
    >>> d = np.linalg.norm(emb[:, None] - emb[None], axis=-1) + np.diag(np.full(20, np.inf))  # doctest: +SKIP
    >>> labels = np.repeat([0, 1], 10)
    >>> emb.shape, bool(np.all(labels[d.argmin(axis=1)] == labels))  # doctest: +SKIP
    ((20, 2), True)
    """
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
    takes: Iterable[CorpusTake],
    *,
    seconds: float = 2.0,
    kind: str = "stats",
    joints: str = "body27",
    per_speaker: bool = True,
    max_windows: int | None = MAX_WINDOWS,
    seed: int = 0,
    out: str | Path | None = None,
    formats: tuple[str, ...] = ("png", "svg"),
):
    """Figure 3a: t-SNE of 2-s rotation windows coloured by emotion, separability in the title.

    Features and the ``max_windows`` subset (seeded, for the t-SNE too) as in
    :func:`emotion_separability` (per-speaker standardised by default).

    Parameters
    ----------
    takes : iterable of CorpusTake
    seconds, kind, joints, per_speaker, max_windows, seed
        See :func:`emotion_separability`.
    out : str or Path, optional
        Path stem to save the figure to with :func:`beatlite.viz.style.save_figure`.
    formats : tuple of str
        Formats to save.

    Returns
    -------
    (matplotlib.figure.Figure, Separability)

    Examples
    --------
    One scatter per emotion present, named in the legend; the 5-NN scores are those of
    :func:`emotion_separability` with ``k=5``.

    >>> import matplotlib.pyplot as plt
    >>> from types import SimpleNamespace
    >>> rng = np.random.default_rng(0)
    >>> def take(emotion, amplitude):  # 6 s at 15 fps (three 2-s windows) of one speaker, degrees
    ...     rotations = amplitude * np.sin(np.arange(90) / 2)[:, None] + rng.normal(size=(90, 141))
    ...     emotion_frames = np.full(90, emotion)
    ...     return SimpleNamespace(fps=15.0, rotations=rotations, emotion_frames=emotion_frames, speaker_id=2)
    >>> takes = [take(0, 0.0) for _ in range(3)] + [take(2, 30.0) for _ in range(3)]  # still vs swinging
    >>> fig, sep = plot_emotion_tsne(takes)
    >>> [t.get_text() for t in fig.axes[0].get_legend().get_texts()], sep.k, sep.balanced_accuracy
    (['neutral', 'anger'], 5, 1.0)
    >>> plt.close(fig)
    """
    import matplotlib.pyplot as plt

    from beatlite.viz.style import figure_style, legend_outside, save_figure

    ef = emotion_features(takes, seconds=seconds, kind=kind, joints=joints, per_speaker=per_speaker)
    ef = ef.subsample(max_windows, seed)
    sep = separability(ef.features, ef.emotion, groups=ef.take, seed=seed)
    emb = tsne_embedding(ef.features, seed=seed)
    with figure_style():
        fig, ax = plt.subplots(figsize=(8.0, 5.6), layout="constrained")
        cmap = plt.get_cmap("tab10")
        for e in np.unique(ef.emotion):
            m = ef.emotion == e
            ax.scatter(emb[m, 0], emb[m, 1], s=10, color=cmap(int(e)), label=EMOTION_NAMES[int(e)], alpha=0.8)
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_xlabel("t-SNE dimension 1 (no unit)")
        ax.set_ylabel("t-SNE dimension 2 (no unit)")
        ax.set_title(
            f"t-SNE of {seconds:g}-s rotation windows\n{sep.k}-NN balanced acc {sep.balanced_accuracy:.2f} "
            f"(chance {sep.uniform_chance:.2f}), silhouette {sep.silhouette:.2f}"
        )
        legend_outside(ax, "right", title="emotion", markerscale=2)
        if out is not None:
            save_figure(fig, out, formats)
    return fig, sep
