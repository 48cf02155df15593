"""Extra motion statistics: PCK, MAE, velocity / acceleration / jerk statistics, GENEA's speed histograms.

Simple, interpretable numbers to report beside the paper metrics.

Taught in notebooks/04_metrics.ipynb, section 2.1 (from PCK).
"""

from __future__ import annotations

import numpy as np

from beatlite.metrics._checks import as_array, positive


def pck(generated: np.ndarray, ground_truth: np.ndarray, delta: float = 10.0) -> float:
    """Percentage of Correct Keypoints: fraction of (frame, joint) within ``delta`` of the truth.

    ``PCK = (1/(T J)) sum_t sum_j 1[||p_t^j - p^_t^j||_2 < delta]`` (SRGR with all weights 1).

    Parameters
    ----------
    generated, ground_truth : (T, J, 3) float, centimetres
    delta : float, centimetres

    Returns
    -------
    float in [0, 1].

    Examples
    --------
    One frame of four joints, 0, 5, 15 and 30 cm from the truth: two of them are within
    10 cm.

    >>> import numpy as np
    >>> from beatlite.metrics.extras import pck
    >>> truth = np.zeros((1, 4, 3))
    >>> generated = truth.copy()
    >>> generated[0, :, 0] = [0.0, 5.0, 15.0, 30.0]
    >>> pck(generated, truth, 10.0)
    0.5
    >>> pck(generated, truth, 20.0)
    0.75
    """
    g, t = _pair(generated, ground_truth)
    return float(np.mean(np.linalg.norm(g - t, axis=-1) < positive(delta, "delta")))


def mae(generated: np.ndarray, ground_truth: np.ndarray) -> float:
    """Mean absolute error over every element, ``mean |x - x^|`` (units of the inputs).

    Parameters
    ----------
    generated, ground_truth : (T, ...) float of the same shape (positions in cm or angles in degrees).

    Examples
    --------
    >>> mae(np.array([[1.0, 2.0], [3.0, 4.0]]), np.zeros((2, 2)))
    2.5
    """
    g = as_array(generated, "generated", ndim=(1, 2, 3, 4))
    t = as_array(ground_truth, "ground_truth", ndim=(1, 2, 3, 4))
    if g.shape != t.shape:
        raise ValueError(f"generated and ground_truth must have the same shape, got {g.shape} and {t.shape}")
    return float(np.mean(np.abs(g - t)))


def mpjpe(generated: np.ndarray, ground_truth: np.ndarray) -> float:
    """Mean per-joint position error, ``mean_{t,j} ||p_t^j - p^_t^j||_2`` in centimetres.

    Parameters
    ----------
    generated, ground_truth : (T, J, 3) float, centimetres

    Examples
    --------
    >>> truth = np.zeros((1, 2, 3))
    >>> generated = np.array([[[3.0, 4.0, 0.0], [0.0, 0.0, 1.0]]])  # 5 cm and 1 cm off
    >>> mpjpe(generated, truth)
    3.0
    """
    g, t = _pair(generated, ground_truth)
    return float(np.mean(np.linalg.norm(g - t, axis=-1)))


def velocity_stats(positions: np.ndarray, fps: float) -> dict[str, float]:
    """Speed statistics of joint positions (forward differences).

    ``v_{t,j} = ||p_{t+1,j} - p_{t,j}|| * fps``: the first of the finite differences that
    :func:`jerk_stats` takes to order 3. For *timing* (motion beats) beatlite uses central differences
    instead, see :func:`beatlite.metrics.beats.position_speed`.

    Parameters
    ----------
    positions : (T, J, 3) float, centimetres, T >= 2
    fps : float

    Returns
    -------
    dict with ``mean``, ``std``, ``max`` in cm/s over all frames and joints.

    Examples
    --------
    >>> positions = np.zeros((3, 1, 3))
    >>> positions[:, 0, 0] = [0.0, 1.0, 3.0]  # cm
    >>> velocity_stats(positions, fps=10)  # speeds 10 and 20 cm/s
    {'mean': 15.0, 'std': 5.0, 'max': 20.0}
    """
    v = _derivative_norm(positions, fps, 1)
    return {"mean": float(v.mean()), "std": float(v.std()), "max": float(v.max())}


def jerk_stats(positions: np.ndarray, fps: float) -> dict[str, float]:
    """Jerk (third derivative) statistics: ``||Delta^3 p_t|| * fps^3`` in cm/s^3.

    Parameters
    ----------
    positions : (T, J, 3) float, centimetres, T >= 4
    fps : float

    Returns
    -------
    dict with ``mean``, ``std``, ``max`` over all frames and joints. Smooth motion has low jerk.

    Examples
    --------
    >>> positions = np.zeros((5, 1, 3))
    >>> positions[:, 0, 0] = np.arange(5.0) ** 3  # cm; third difference 6 everywhere
    >>> jerk_stats(positions, fps=10)  # 6 * 10**3 cm/s^3
    {'mean': 6000.0, 'std': 0.0, 'max': 6000.0}
    """
    j = _derivative_norm(positions, fps, 3)
    return {"mean": float(j.mean()), "std": float(j.std()), "max": float(j.max())}


def acceleration_stats(positions: np.ndarray, fps: float) -> dict[str, float]:
    """Acceleration (second derivative) statistics: ``||Delta^2 p_t|| * fps^2`` in cm/s^2.

    Parameters
    ----------
    positions : (T, J, 3) float, centimetres, T >= 3
    fps : float

    Returns
    -------
    dict with ``mean``, ``std``, ``max`` over all frames and joints.

    Examples
    --------
    >>> positions = np.zeros((4, 1, 3))
    >>> positions[:, 0, 0] = np.arange(4.0) ** 2  # cm; second difference 2 everywhere
    >>> acceleration_stats(positions, fps=10)  # 2 * 10**2 cm/s^2
    {'mean': 200.0, 'std': 0.0, 'max': 200.0}
    """
    a = _derivative_norm(positions, fps, 2)
    return {"mean": float(a.mean()), "std": float(a.std()), "max": float(a.max())}


#: Speed-histogram bins of GENEA's numerical evaluation (``calc_histogram.py``: width 1, edges 0..49 cm/s).
GENEA_SPEED_BINS = np.arange(0.0, 50.0, 1.0)


def speed_histogram(
    positions: np.ndarray | list[np.ndarray], fps: float, bins: np.ndarray = GENEA_SPEED_BINS
) -> np.ndarray:
    """Counts of per-frame joint speeds ``||p_{t+1,j} - p_{t,j}|| * fps`` (cm/s), all joints and takes pooled.

    GENEA's "histogram of moving distance" for velocity (Kucherenko et al. 2021, the GENEA Challenge 2020;
    ``calc_histogram.py`` of genea-workshop/genea_numerical_evaluations): speeds outside the bin edges
    (by default at or above 49 cm/s) are not counted, as there.

    Parameters
    ----------
    positions : (T, J, 3) float or list of them, centimetres
    fps : float
    bins : (B + 1,) float
        Bin edges, cm/s.

    Returns
    -------
    (B,) int64 counts.

    Examples
    --------
    >>> positions = np.zeros((4, 1, 3))
    >>> positions[:, 0, 0] = [0.0, 0.1, 0.3, 0.4]  # cm, at 10 fps: speeds 1, 2, 1 cm/s
    >>> speed_histogram(positions, fps=10, bins=np.array([0.0, 1.5, 3.0]))
    array([2, 1])
    """
    takes = positions if isinstance(positions, list | tuple) else [positions]
    speeds = np.concatenate([_derivative_norm(p, fps, 1).ravel() for p in takes])
    return np.histogram(speeds, bins=np.asarray(bins, np.float64))[0].astype(np.int64)


def hellinger_distance(hist1: np.ndarray, hist2: np.ndarray) -> float:
    """Hellinger distance ``sqrt(1 - sum_i sqrt(p_i q_i))`` of two histograms normalised to sum 1.

    GENEA's ``hellinger_distance.py``: 0 for equal distributions, 1 for disjoint ones. Computed as the equal
    ``sqrt(sum_i (sqrt(p_i) - sqrt(q_i))^2 / 2)``, which keeps equal histograms at 0 (``1 - sum`` leaves 1e-8).

    Examples
    --------
    >>> round(hellinger_distance(np.array([0, 4, 0]), np.array([0, 1, 1])), 4)  # sqrt(1 - sqrt(1/2))
    0.5412
    >>> hellinger_distance(np.arange(49.0), np.arange(49.0))
    0.0
    """
    p = as_array(hist1, "hist1", ndim=1)
    q = as_array(hist2, "hist2", ndim=1)
    if p.shape != q.shape:
        raise ValueError(f"histograms must have the same shape, got {p.shape} and {q.shape}")
    for name, h in (("hist1", p), ("hist2", q)):
        if (h < 0).any() or h.sum() <= 0:
            raise ValueError(f"{name} must have counts >= 0 and a positive sum (no value inside its bins?)")
    return float(np.sqrt(0.5 * np.sum((np.sqrt(p / p.sum()) - np.sqrt(q / q.sum())) ** 2)))


def _derivative_norm(positions: np.ndarray, fps: float, order: int) -> np.ndarray:
    p = as_array(positions, "positions", ndim=3, last=3)
    if p.shape[0] < order + 1:
        raise ValueError(f"positions needs at least {order + 1} frames, got shape {p.shape}")
    return np.linalg.norm(np.diff(p, n=order, axis=0), axis=-1) * positive(fps, "fps") ** order


def _pair(generated: np.ndarray, ground_truth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    g = as_array(generated, "generated", ndim=3, last=3)
    t = as_array(ground_truth, "ground_truth", ndim=3, last=3)
    if g.shape != t.shape:
        raise ValueError(f"generated and ground_truth must have the same shape, got {g.shape} and {t.shape}")
    if g.shape[0] == 0 or g.shape[1] == 0:
        raise ValueError(f"generated has no frames or no joints, shape {g.shape}")
    return g, t
