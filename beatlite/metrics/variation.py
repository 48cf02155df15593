"""Diversity metrics: BEAT's L1 diversity and HA2G's feature-space Diversity.

``l1_diversity`` (BEAT, docs/reference_code.md#l1-diversity) measures how far the poses of a generated take wander from
that take's mean pose; ``diversity`` (HA2G §4.3, docs/reference_code.md#ha2g-diversity) measures how different the features of
randomly paired generated clips are. Higher means more varied motion for both; neither says
the motion is *right*.

Taught in notebooks/04_metrics.ipynb, section 4 (4.1 BEAT's L1 diversity, 4.2 HA2G's diversity).
"""

from __future__ import annotations

import numpy as np

from beatlite.constants import WINDOW_LENGTH, WINDOW_STRIDE
from beatlite.data.windows import sliding_windows
from beatlite.metrics._checks import as_array, as_list
from beatlite.metrics.frechet import Extractor


def l1_diversity(
    motion: np.ndarray | list[np.ndarray],
    *,
    windowed: bool = False,
    length: int = WINDOW_LENGTH,
    stride: int = WINDOW_STRIDE,
) -> float:
    """Mean per-frame L1 distance to the take's mean pose (BEAT "L1div").

    ``L1div = sum_k sum_t sum_d |x_{k,t,d} - mu_{k,d}| / sum_k T_k`` with ``mu_k`` the mean
    pose of take ``k``.

    Parameters
    ----------
    motion : (T, D) float or list of (T_k, D)
        Generated takes; BEAT uses de-normalised Euler degrees (D = 141), so values are
        degrees summed over the D channels (~2000-2450 for BEAT models). Positions
        (T, J, 3) are flattened to (T, 3J) centimetres.
    windowed : bool
        The reference quirk: use the concatenated ``length``-frame windows every ``stride``
        frames instead of the take itself, so overlapping frames count up to
        ``length / stride`` (3.4x) times, in the mean pose and in the sum.
    length, stride : int
        Windowing of the quirk (34, 10).

    Returns
    -------
    float, units of ``motion`` summed over channels.

    Examples
    --------
    A take of one channel, 0, 2, 4, 6 degrees, has mean pose 3 and distances 3, 1, 1, 3:
    ``L1div = 8 / 4 = 2``. A constant channel adds nothing. A second, frozen take of two
    frames pools frame-weighted: ``(8 + 0) / 6``.

    >>> import numpy as np
    >>> from beatlite.metrics.variation import l1_diversity
    >>> take = np.array([[0.0, 10.0], [2.0, 10.0], [4.0, 10.0], [6.0, 10.0]])  # (T, D) degrees
    >>> l1_diversity(take)
    2.0
    >>> round(l1_diversity([take, np.full((2, 2), 5.0)]), 6)
    1.333333
    """
    items, _ = as_list(motion, "motion")
    total, frames = 0.0, 0
    for i, m in enumerate(items):
        x = as_array(m, f"motion[{i}]", ndim=(2, 3))
        x = x.reshape(x.shape[0], int(np.prod(x.shape[1:])))  # (-1 cannot be inferred from 0 frames)
        if windowed:
            x = sliding_windows(x, length, stride).reshape(-1, x.shape[1])
        if x.shape[0] == 0:
            continue
        total += float(np.abs(x - x.mean(axis=0)).sum())
        frames += x.shape[0]
    if frames == 0:
        raise ValueError(f"motion has no frames{' long enough for one window' if windowed else ''}")
    return total / frames


def diversity(
    generated: np.ndarray | list[np.ndarray],
    *,
    extractor: Extractor | None = None,
    n_pairs: int = 500,
    seed: int = 0,
    batch_pairing: bool = False,
) -> float:
    """HA2G Diversity: mean L1 distance between features of randomly paired generated clips.

    ``Div = (1/P) sum_{(i, j)} sum_f |z_{i,f} - z_{j,f}|`` over ``P = n_pairs`` pairs of
    distinct clips drawn uniformly with ``numpy.random.default_rng(seed)``.

    Parameters
    ----------
    generated : (N, F) features, or (N, L, D) windows with ``extractor``; with
        ``batch_pairing=True`` a list of such batches.
    extractor : callable, optional
        Windows (N, L, D) -> features (N, F).
    n_pairs : int
        Number of clip pairs (500 in the paper); with ``batch_pairing``, batches.
    seed : int
        Random seed; the result is deterministic given it.
    batch_pairing : bool
        Reproduce the HA2G code: ``generated`` is a list of batches, the first ``n_pairs``
        batches are stacked and compared row by row with ``n_pairs`` batches taken in a random
        permutation (a batch may meet itself and contribute zeros; batches must be equally
        sized for the rows to pair).

    Returns
    -------
    float, feature units (L1).

    Examples
    --------
    Three clip features whose pairwise L1 distances are all 2: every random pair of
    distinct clips contributes 2, whatever the seed. With two clips, every pair is the
    same pair.

    >>> import numpy as np
    >>> from beatlite.metrics.variation import diversity
    >>> features = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 0.0, 1.0]])  # (N, F)
    >>> diversity(features)
    2.0
    >>> diversity(np.array([[0.0, 0.0], [3.0, 4.0]]))
    7.0
    """
    rng = np.random.default_rng(seed)
    if n_pairs < 1:
        raise ValueError(f"n_pairs must be >= 1, got {n_pairs}")
    if batch_pairing:
        if not isinstance(generated, (list, tuple)) or not generated:
            raise TypeError("batch_pairing=True needs generated as a non-empty list of batches")
        batches = [_features(b, extractor, f"generated[{i}]") for i, b in enumerate(generated)]
        sizes = sorted({len(b) for b in batches})
        if len(sizes) > 1:  # (stacked shapes match when every batch is used, the pairs would not)
            raise ValueError(f"batch pairing needs equal batch sizes, got batches of {sizes} rows")
        f1 = np.vstack(batches[:n_pairs])
        perm = rng.permutation(len(batches))[:n_pairs]
        f2 = np.vstack([batches[k] for k in perm])
        if f1.shape != f2.shape:
            raise ValueError(
                f"batch pairing needs equal batch sizes; stacked shapes {f1.shape} vs {f2.shape}"
            )
        return float(np.mean(np.abs(f1 - f2).sum(axis=-1)))
    feats = _features(generated, extractor, "generated")
    n = feats.shape[0]
    if n < 2:
        raise ValueError(f"generated needs at least 2 clips to form pairs, got shape {feats.shape}")
    i = rng.integers(0, n, size=n_pairs)
    j = (i + rng.integers(1, n, size=n_pairs)) % n  # uniform over the other n - 1 clips
    return float(np.mean(np.abs(feats[i] - feats[j]).sum(axis=-1)))


def _features(x: np.ndarray, extractor: Extractor | None, name: str) -> np.ndarray:
    if extractor is None:
        return as_array(x, name, ndim=2)
    w = as_array(x, name, ndim=3)
    f = np.asarray(extractor(w), dtype=np.float64)
    if f.ndim != 2 or f.shape[0] != w.shape[0]:
        raise ValueError(f"extractor must map (N, L, D) to (N, F); for {name} {w.shape} it gave {f.shape}")
    return f
