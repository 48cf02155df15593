"""HA2G's training losses (torch) and the bone-angle statistics of the physical constraint.

All losses are means (scalars); the model multiplies them by its weights (docs/reference_code.md#ha2g-losses):
hierarchical Huber 250, GAN 5, KL 0.1, style diverging 0.05, contrastive 0.2 (positive)
and 0.005 (negative), physical constraint 0.01.

Angles are in units of pi radians (``arccos(cos) / pi`` in [0, 1]), as in the reference
and :func:`beatlite.metrics.beats.included_angles`.

Taught in notebooks/06_ha2g.ipynb, sections 4 (the multi-level contrastive loss) and 6 (the physical constraint).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
import torch
from torch import nn

from beatlite.models.base import huber

N_BONES = 42
PALM_BONES: tuple[tuple[int, int], ...] = ((11, 17), (28, 34))
"""TED-43 direction-vector pairs whose cross products are the left / right palm normals (docs/reference_code.md#palm-normals)."""


# ----------------------------------------------------------------------------- contrastive
def contrastive_ce(query: torch.Tensor, key: torch.Tensor, *, min_distance: float = 1e-2) -> torch.Tensor:
    """HA2G's ``SoftmaxContrastiveLoss``: cross-entropy of inverse-distance logits against the diagonal.

    Features are flattened to ``(B*T, F)`` rows and L2-normalised; ``logit_ij = 1 / max(|q_i - k_j|,
    min_distance)`` and row i's correct class is j = i (same clip, same frame).

    Parameters
    ----------
    query, key : (B, T, F) float tensors
        E.g. text features and one level of audio features.
    min_distance : float
        Floor of the distance (the reference divides by the raw distance, which is infinite
        for identical features); caps every logit at ``1 / min_distance``.

    Returns
    -------
    scalar tensor
        Mean cross-entropy, >= 0; small when every row's nearest key is its own frame.

    Examples
    --------
    Four frames of orthogonal unit features, keys equal to the queries, ``min_distance = 1``: each row's own
    key is at distance 0 (logit 1, floored), the three others at ``sqrt(2)`` (logit ``1 / sqrt(2)``), so the loss
    is ``log(1 + 3 exp(1 / sqrt(2) - 1)) = 1.175``.

    >>> import math, torch
    >>> from beatlite.models.ha2g_losses import contrastive_ce
    >>> q = torch.eye(4).reshape(1, 4, 4)
    >>> round(float(contrastive_ce(q, q, min_distance=1.0)), 3), round(math.log(1 + 3 * math.exp(2**-0.5 - 1)), 3)
    (1.175, 1.175)
    """
    if query.ndim != 3 or query.shape != key.shape:
        raise ValueError(
            f"contrastive_ce: query and key must be equal (B, T, F) shapes, got {tuple(query.shape)} "
            f"and {tuple(key.shape)}"
        )
    q = nn.functional.normalize(query.reshape(-1, query.shape[-1]), dim=1)
    k = nn.functional.normalize(key.reshape(-1, key.shape[-1]), dim=1)
    # |q - k|^2 = 2 - 2 <q, k> for unit rows; the clamp keeps rsqrt finite and differentiable at 0.
    # logits = 1 / |q - k| as one rsqrt (half the time of sqrt then 1/x on the (B T)^2 matrix)
    logits = torch.rsqrt(torch.clamp(2.0 - 2.0 * q @ k.T, min=min_distance**2))
    target = torch.arange(q.shape[0], device=q.device)
    return nn.functional.cross_entropy(logits, target)


def aligned_against_level_ce(
    query: torch.Tensor, positive: torch.Tensor, negative: torch.Tensor, *, min_distance: float = 1e-2
) -> torch.Tensor:
    """Cross-entropy of each query row's aligned ``positive`` row against every row of ``negative``.

    Row i's candidates are ``positive_i`` (the correct class) and ``negative_j`` for all j, with
    :func:`contrastive_ce`'s logits ``1 / max(|q - k|, min_distance)`` on L2-normalised rows: paper
    eq. 2 without the other rows of the positive's own level ("w/o f_a-^high", Table 3).

    Parameters
    ----------
    query, positive, negative : (B, T, F) float tensors

    Returns
    -------
    scalar tensor >= 0

    Examples
    --------
    Four orthogonal unit rows as query, positive and negative, ``min_distance = 1``: the aligned positive and
    the negative's own row both get logit 1, the three other negatives ``1 / sqrt(2)``, so the loss is
    ``log(2 + 3 exp(1 / sqrt(2) - 1)) = 1.444``.

    >>> import math, torch
    >>> from beatlite.models.ha2g_losses import aligned_against_level_ce
    >>> q = torch.eye(4).reshape(1, 4, 4)
    >>> round(float(aligned_against_level_ce(q, q, q, min_distance=1.0)), 3)
    1.444
    >>> round(math.log(2 + 3 * math.exp(2**-0.5 - 1)), 3)
    1.444
    """
    if query.ndim != 3 or query.shape != positive.shape or query.shape != negative.shape:
        raise ValueError(
            f"aligned_against_level_ce: query, positive and negative must be equal (B, T, F) shapes, got "
            f"{tuple(query.shape)}, {tuple(positive.shape)} and {tuple(negative.shape)}"
        )
    q = nn.functional.normalize(query.reshape(-1, query.shape[-1]), dim=1)
    p = nn.functional.normalize(positive.reshape(-1, positive.shape[-1]), dim=1)
    n = nn.functional.normalize(negative.reshape(-1, negative.shape[-1]), dim=1)
    floor = min_distance**2
    aligned = torch.rsqrt(torch.clamp(2.0 - 2.0 * (q * p).sum(dim=1, keepdim=True), min=floor))
    others = torch.rsqrt(torch.clamp(2.0 - 2.0 * q @ n.T, min=floor))
    logits = torch.cat([aligned, others], dim=1)
    return nn.functional.cross_entropy(logits, torch.zeros(q.shape[0], dtype=torch.int64, device=q.device))


def multilevel_contrastive_loss(
    text: torch.Tensor,
    audio: dict[str, torch.Tensor],
    *,
    positive: str = "high",
    negative: str = "low",
    min_distance: float = 1e-2,
    high_negatives: bool = True,
) -> dict[str, torch.Tensor]:
    """Paper eq. 2 as implemented: text is pulled towards one audio level and pushed from another.

    Returns ``{"positive": CE(text, audio[positive]), "negative": CE(text, audio[negative])}``;
    the model adds ``w_pos * positive - w_neg * negative`` (reference 0.2 and 0.005).
    ``w_neg = 0`` is the paper's "w/o f_a-^low,mid" (Table 3).

    Parameters
    ----------
    text : (B, T, F)
        Text features (a separate text encoder).
    audio : dict level -> (B, T, F)
        Audio features with at least the ``positive`` and ``negative`` levels.
    high_negatives : bool
        False ("w/o f_a-^high", Table 3): the positive term's candidates are the aligned
        ``positive`` feature and the ``negative`` level's features
        (:func:`aligned_against_level_ce`), not the other frames' ``positive`` features.

    Returns
    -------
    dict
        ``"positive"``, ``"negative"``: scalar tensors >= 0.

    Examples
    --------
    Each term is a :func:`contrastive_ce` (or, without high negatives, an :func:`aligned_against_level_ce`):

    >>> import torch
    >>> from beatlite.models.ha2g_losses import contrastive_ce, multilevel_contrastive_loss
    >>> _ = torch.manual_seed(0)
    >>> text = torch.randn(2, 5, 8)
    >>> audio = {"low": torch.randn(2, 5, 8), "high": torch.randn(2, 5, 8)}
    >>> terms = multilevel_contrastive_loss(text, audio)
    >>> sorted(terms), torch.equal(terms["negative"], contrastive_ce(text, audio["low"]))
    (['negative', 'positive'], True)
    """
    for level in (positive, negative):
        if level not in audio:
            raise KeyError(f"multilevel_contrastive_loss: audio has no level {level!r} (has {sorted(audio)})")
    pos = (
        contrastive_ce(text, audio[positive], min_distance=min_distance)
        if high_negatives
        else aligned_against_level_ce(text, audio[positive], audio[negative], min_distance=min_distance)
    )
    return {"positive": pos, "negative": contrastive_ce(text, audio[negative], min_distance=min_distance)}


# ----------------------------------------------------------------------------- regression, KL, style
def hierarchical_huber(
    predictions: Sequence[torch.Tensor], targets: Sequence[torch.Tensor], *, beta: float = 0.1
) -> torch.Tensor:
    """Sum over body levels of the mean Huber loss (beta 0.1; paper eq. 5 without the 1/H).

    Parameters
    ----------
    predictions, targets : sequences of (B, T, D_k) tensors, one per level

    Returns
    -------
    scalar tensor, 0 exactly when every prediction equals its target.

    Examples
    --------
    Level 0 off by 0.05 (inside beta: ``0.5 * 0.05^2 / 0.1 = 0.0125``), level 1 off by 1 (outside:
    ``1 - 0.05 = 0.95``): 0.9625 in all.

    >>> import torch
    >>> from beatlite.models.ha2g_losses import hierarchical_huber
    >>> predictions = [torch.full((1, 2, 3), 0.05), torch.ones(1, 2, 6)]
    >>> targets = [torch.zeros(1, 2, 3), torch.zeros(1, 2, 6)]
    >>> round(float(hierarchical_huber(predictions, targets)), 4)
    0.9625
    """
    if len(predictions) != len(targets) or not predictions:
        raise ValueError(f"need one target per level, got {len(predictions)} predictions and {len(targets)}")
    total = predictions[0].new_zeros(())
    for k, (p, t) in enumerate(zip(predictions, targets)):
        if p.shape != t.shape:
            raise ValueError(f"level {k}: prediction {tuple(p.shape)} and target {tuple(t.shape)} differ")
        total = total + huber(p, t, beta)
    return total


def style_diverging_loss(
    pose: torch.Tensor,
    pose_other: torch.Tensor,
    z: torch.Tensor,
    z_other: torch.Tensor,
    *,
    beta: float = 0.05,
    clip: float = 1000.0,
    reference: bool = False,
) -> torch.Tensor:
    """Paper eq. 7 (Trimodal's diversity regulariser): reward outputs that move with the style code.

    ``-mean_b min(sum_{t,d} Huber_beta(pose_b, pose_other_b) / (zdist + 1e-5), clip)`` with the
    z distance detached. ``reference=True`` (HA2G's code): ``zdist_b = mean_z |z_b - z_other_b|``
    per sample and ``pose_other`` detached (only ``pose`` is pushed away). ``reference=False``
    (the ``"shared"`` style design): ``zdist`` = the batch mean of ``|z - z_other|`` and both
    outputs receive gradient.

    Parameters
    ----------
    pose, pose_other : (B, T, D)
        Outputs for the batch's style codes and for other speakers' codes.
    z, z_other : (B, Z)
        The two style codes.

    Returns
    -------
    scalar tensor in [-clip, 0].

    Examples
    --------
    Outputs 1 apart on 2 frames x 3 channels (Huber ``1 - 0.05 / 2 = 0.975`` each, 5.85 per clip) for codes 1
    apart: about -5.85; ``clip`` bounds the reward.

    >>> import torch
    >>> from beatlite.models.ha2g_losses import style_diverging_loss
    >>> pose, z = torch.zeros(1, 2, 3), torch.zeros(1, 4)
    >>> round(float(style_diverging_loss(pose, pose + 1, z, z + 1)), 3)
    -5.85
    >>> float(style_diverging_loss(pose, pose + 1, z, z + 1, clip=2.0))
    -2.0
    """
    if pose.shape != pose_other.shape or pose.ndim != 3:
        raise ValueError(
            f"pose {tuple(pose.shape)} and pose_other {tuple(pose_other.shape)} must be (B, T, D)"
        )
    if reference:
        pose_other = pose_other.detach()
    diff = nn.functional.smooth_l1_loss(pose / beta, pose_other / beta, reduction="none") * beta
    per_clip = diff.sum(dim=(1, 2))
    gap = (z - z_other).abs().detach()
    z_l1 = gap.mean(dim=1) if reference else gap.mean()
    return -torch.clamp(per_clip / (z_l1 + 1e-5), max=clip).mean()


# ----------------------------------------------------------------------------- physical constraint
def directions_with_palms(dirvec: torch.Tensor, mean_dirvec: torch.Tensor) -> torch.Tensor:
    """Mean-subtracted 126-d direction vectors -> 44 unit vectors (42 bones + 2 palm normals).

    Adds ``mean_dirvec`` back, normalises each bone, appends ``cross(v11, v17)`` and
    ``cross(v28, v34)`` normalised (docs/reference_code.md#palm-normals).

    Parameters
    ----------
    dirvec : (..., 126) tensor
    mean_dirvec : (126,) tensor

    Returns
    -------
    (..., 44, 3) tensor

    Examples
    --------
    Every bone along x except bones 17 and 28 along y: the left palm normal is ``x cross y = z``, the right one
    ``y cross x = -z``.

    >>> import torch
    >>> from beatlite.models.ha2g_losses import directions_with_palms
    >>> bones = torch.tensor([1.0, 0.0, 0.0]).repeat(42, 1)
    >>> bones[[17, 28]] = torch.tensor([0.0, 1.0, 0.0])
    >>> v = directions_with_palms(bones.reshape(126), torch.zeros(126))
    >>> tuple(v.shape), v[42].tolist(), v[43].tolist()
    ((44, 3), [0.0, 0.0, 1.0], [0.0, 0.0, -1.0])
    """
    if dirvec.shape[-1] != 3 * N_BONES:
        raise ValueError(f"dirvec must end with {3 * N_BONES} channels, got shape {tuple(dirvec.shape)}")
    v = (dirvec + mean_dirvec).reshape(*dirvec.shape[:-1], N_BONES, 3)
    v = nn.functional.normalize(v, dim=-1, eps=1e-8)
    palms = [torch.linalg.cross(v[..., a, :], v[..., b, :], dim=-1) for a, b in PALM_BONES]
    palms_t = nn.functional.normalize(torch.stack(palms, dim=-2), dim=-1, eps=1e-8)
    return torch.cat([v, palms_t], dim=-2)


def bone_angles(dirvec: torch.Tensor, mean_dirvec: torch.Tensor, pairs: torch.Tensor) -> torch.Tensor:
    """Included angles of ``pairs`` of the 44 vectors, in units of pi (differentiable).

    Parameters
    ----------
    dirvec : (..., 126) tensor, mean-subtracted directions
    mean_dirvec : (126,) tensor
    pairs : (P, 2) int64 tensor, indices into the 44 vectors

    Returns
    -------
    (..., P) tensor in [0, 1]. The cosine is clamped to ``±(1 - 1e-6)`` so the gradient stays finite.

    Examples
    --------
    Bones 0 and 1 along x, bone 2 along y: 0 between the first two (0.00045 from the clamp), a right angle
    (1/2 of pi) between bones 1 and 2.

    >>> import torch
    >>> from beatlite.models.ha2g_losses import bone_angles
    >>> bones = torch.tensor([1.0, 0.0, 0.0]).repeat(42, 1)
    >>> bones[2] = torch.tensor([0.0, 1.0, 0.0])
    >>> bone_angles(bones.reshape(126), torch.zeros(126), torch.tensor([[0, 1], [1, 2]])).numpy().round(3)
    array([0. , 0.5], dtype=float32)
    """
    v = directions_with_palms(dirvec, mean_dirvec)
    cos = (v[..., pairs[:, 0], :] * v[..., pairs[:, 1], :]).sum(-1)
    return torch.arccos(torch.clamp(cos, -1.0 + 1e-6, 1.0 - 1e-6)) / torch.pi


def physical_constraint_loss(angles: torch.Tensor, mean: torch.Tensor, var: torch.Tensor) -> torch.Tensor:
    """Paper eq. 8 as implemented: ``sum_p mean_{b,t} (theta_p - mu_p)^2 / (2 sigma_p^2)``.

    The negative Gaussian log-likelihood without its constant; 0 exactly at the mean angles.

    Parameters
    ----------
    angles : (..., P) tensor, units of pi
    mean, var : (P,) tensors (units of pi and pi^2)

    Returns
    -------
    scalar tensor >= 0.

    Examples
    --------
    Two pairs, each one standard deviation from its mean on every frame: ``1 / 2`` each, 1 in all.

    >>> import torch
    >>> from beatlite.models.ha2g_losses import physical_constraint_loss
    >>> mean, var = torch.tensor([0.5, 0.2]), torch.tensor([0.01, 0.04])
    >>> round(float(physical_constraint_loss(mean + var.sqrt().expand(3, 2), mean, var)), 4)
    1.0
    """
    if angles.shape[-1] != mean.shape[0] or mean.shape != var.shape:
        raise ValueError(
            f"angles (..., P) {tuple(angles.shape)}, mean {tuple(mean.shape)} and var {tuple(var.shape)} "
            "must agree on P"
        )
    z = (angles - mean).pow(2) / (2.0 * var)
    return z.reshape(-1, mean.shape[0]).mean(dim=0).sum()


def costliest_pair_question(
    angles: np.ndarray, mean: np.ndarray, var: np.ndarray, *, k: int = 4, name: str = "costliest pair"
) -> tuple[dict[str, str], str]:
    """Notebook 06's "which pair costs the most?" question on measured angles: its options and its key.

    Each pair's term of :func:`physical_constraint_loss` is ``mean_t (theta_p - mu_p)^2 / (2 sigma_p^2)``; the
    options are the ``k`` costliest pairs in pair order, lettered a, b, ...; the key is the course's key
    (:func:`beatlite.exercise.course_key`) of the costliest one's letter. Computed here, not in the student's
    cell, so the cell shows neither the costs nor the answer.

    Parameters
    ----------
    angles : (..., P) array, units of pi (P = 41: :data:`beatlite.skeleton.ted.ANGLE_PAIRS`)
    mean, var : (P,) arrays, the angle statistics of the model (units of pi, pi^2)
    k : int
        Number of options (the k costliest pairs).
    name : str
        The question's name, part of the key.

    Returns
    -------
    options : dict
        Letter -> ``"vector vs vector"`` (:data:`beatlite.skeleton.ted.TED_VECTOR_NAMES`).
    key : str
        For :func:`beatlite.exercise.choice`.

    Examples
    --------
    >>> from beatlite.exercise import course_key
    >>> from beatlite.skeleton.ted import ANGLE_PAIRS, TED_VECTOR_NAMES
    >>> mean, var = np.full(41, 0.5), np.full(41, 0.01)
    >>> angles = np.full((10, 41), 0.5)
    >>> angles[:, [3, 9, 20, 30]] += [0.1, 0.3, 0.2, 0.05]  # pair 9 costs 0.3^2 / 0.02 = 4.5, the most
    >>> options, key = costliest_pair_question(angles, mean, var)
    >>> list(options)
    ['a', 'b', 'c', 'd']
    >>> options["b"] == " vs ".join(TED_VECTOR_NAMES[v] for v in ANGLE_PAIRS[9])
    True
    >>> key == course_key("costliest pair", "b")
    True
    """
    from beatlite.exercise import course_key
    from beatlite.skeleton.ted import ANGLE_PAIRS, TED_VECTOR_NAMES

    mean, var = np.asarray(mean, dtype=np.float64), np.asarray(var, dtype=np.float64)
    a = np.asarray(angles, dtype=np.float64)
    if a.shape[-1] != mean.shape[0] or mean.shape != var.shape or mean.shape[0] != len(ANGLE_PAIRS):
        raise ValueError(
            f"angles (..., {len(ANGLE_PAIRS)}), mean and var must agree on P, got {a.shape}, {mean.shape}, {var.shape}"
        )
    if not 1 <= k <= min(26, len(mean)):
        raise ValueError(f"k must be in 1..{min(26, len(mean))}, got {k}")
    per_pair = ((a - mean) ** 2 / (2.0 * var)).reshape(-1, len(mean)).mean(axis=0)
    shown = sorted(int(p) for p in np.argsort(per_pair, kind="stable")[-k:])
    letters = "abcdefghijklmnopqrstuvwxyz"[:k]
    options = {
        letter: " vs ".join(TED_VECTOR_NAMES[v] for v in ANGLE_PAIRS[p]) for letter, p in zip(letters, shown)
    }
    return options, course_key(name, letters[shown.index(int(np.argmax(per_pair)))])


@dataclass(frozen=True)
class AngleStatistics:
    """Training-set statistics of the bone angles (units of pi radians).

    Attributes
    ----------
    mean, var : (P,) float64
        Mean and variance over all training frames (var floored at ``var_floor``).
    change : (P,) float64
        Mean absolute frame-to-frame change (HA2G's ``change_angle``, for beat consistency).
    """

    mean: np.ndarray
    var: np.ndarray
    change: np.ndarray


def _window_angles(d: np.ndarray, m: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """(N, T, 126) mean-subtracted directions and their mean -> (N, T, P) bone angles (units of pi)."""
    from beatlite.metrics.beats import append_palm_normals, included_angles

    d = np.asarray(d, dtype=np.float64)
    if d.ndim != 3 or d.shape[2] != 3 * N_BONES or d.shape[0] < 1 or d.shape[1] < 2:
        raise ValueError(f"dirvec_windows must be (N >= 1, T >= 2, 126), got shape {d.shape}")
    if not np.all(np.isfinite(d)):
        raise ValueError("dirvec_windows and mean_dirvec must be finite")
    n, t, _ = d.shape
    v = (d + m).reshape(n * t, N_BONES, 3)
    norm = np.linalg.norm(v, axis=-1, keepdims=True)
    v = np.divide(v, norm, out=np.zeros_like(v), where=norm > 1e-12)
    return included_angles(append_palm_normals(v), pairs).reshape(n, t, -1)


def angle_statistics(
    dirvec_windows: np.ndarray | Iterable[np.ndarray],
    mean_dirvec: np.ndarray,
    *,
    pairs: np.ndarray | None = None,
    var_floor: float = 1e-5,
) -> AngleStatistics:
    """Per-pair mean / variance / mean change of the bone angles over training windows.

    The reference hard-codes these numbers for TED Expressive (``calculate_angle_stats.py``);
    beatlite computes them from whichever training data it is given.

    Parameters
    ----------
    dirvec_windows : (N, T, 126) float, or an iterable of (N_i, T, 126) chunks
        Mean-subtracted unit direction vectors (``windows["dirvec"]``); chunks (a window store read
        piece by piece) are pooled with Chan et al.'s update: one chunk gives exactly the statistics
        of the whole array, several agree with it up to float64 rounding.
    mean_dirvec : (126,) float
        The mean that was subtracted.
    pairs : (P, 2) int, optional
        Indices into the 42 bones + 2 palm normals (default ``ted.ANGLE_PAIRS``).
    var_floor : float
        Lower bound of the variance (a pair that never moves would divide by zero).

    Returns
    -------
    AngleStatistics

    Examples
    --------
    One window of two frames: bone 1 at a right angle to bone 0 (1/2 of pi), then along it (0). Mean 0.25,
    variance ``0.25^2 = 0.0625``, mean change 0.5 per frame.

    >>> import numpy as np
    >>> from beatlite.models.ha2g_losses import angle_statistics
    >>> d = np.tile([1.0, 0.0, 0.0], (1, 2, 42))  # (N=1, T=2, 126): every bone along x
    >>> d[0, 0, 3:6] = [0.0, 1.0, 0.0]  # frame 0: bone 1 along y
    >>> stats = angle_statistics(d, np.zeros(126), pairs=np.array([[0, 1]]))
    >>> stats.mean.round(4).tolist(), stats.var.round(4).tolist(), stats.change.round(4).tolist()
    ([0.25], [0.0625], [0.5])
    """
    m = np.asarray(mean_dirvec, dtype=np.float64)
    if m.shape != (3 * N_BONES,):
        raise ValueError(f"mean_dirvec must be (126,), got shape {m.shape}")
    if not np.all(np.isfinite(m)):
        raise ValueError("dirvec_windows and mean_dirvec must be finite")
    from beatlite.metrics.consistency import default_angle_pairs

    pr = default_angle_pairs() if pairs is None else np.asarray(pairs, dtype=np.int64)
    chunks = [dirvec_windows] if isinstance(dirvec_windows, np.ndarray) else dirvec_windows
    count, mean, m2, change_sum, change_count = 0, 0.0, 0.0, 0.0, 0
    for chunk in chunks:
        theta = _window_angles(chunk, m, pr)
        flat = theta.reshape(-1, theta.shape[-1])
        c_mean = flat.sum(axis=0) / len(flat)
        c_m2 = ((flat - c_mean) ** 2).sum(axis=0)
        total = count + len(flat)
        delta = c_mean - mean
        mean = mean + delta * (len(flat) / total) if count else c_mean
        m2 = m2 + c_m2 + delta**2 * (count * len(flat) / total) if count else c_m2
        count = total
        change_sum = change_sum + np.abs(np.diff(theta, axis=1)).sum(axis=(0, 1))
        change_count += theta.shape[0] * (theta.shape[1] - 1)
    if not count:
        raise ValueError("dirvec_windows must be (N >= 1, T >= 2, 126), got no windows")
    return AngleStatistics(mean=mean, var=np.maximum(m2 / count, var_floor), change=change_sum / change_count)
