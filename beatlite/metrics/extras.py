"""Extra motion statistics: PCK, MAE, and velocity / jerk statistics.

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
    """
    j = _derivative_norm(positions, fps, 3)
    return {"mean": float(j.mean()), "std": float(j.std()), "max": float(j.max())}


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
    return g, t
