"""SRGR, Semantic-Relevant Gesture Recall (BEAT paper §5, eq. 11).

A PCK (fraction of joints within a threshold of the ground truth) in which every frame is
weighted by its semantic-relevance score, so that recalling the ground-truth gesture where
it *means* something counts and recalling it during beat gestures or rest counts little.

Two variants:

``variant="paper"`` (default) — what the paper defines, on joint **positions**::

    SRGR = (1 / (T J)) sum_t lambda_t sum_j 1[ ||p_t^j - p^_t^j||_2 < delta ]

with ``lambda_t`` in [0, 1] the frame's semantic score and ``delta`` in cm. A perfect
prediction scores ``mean_t lambda_t``. Use it to compare methods on positions (any skeleton).

``variant="reference"`` — what BEAT's ``utils/metric.py`` computes (docs/reference_code.md#srgr-reference), on **Euler
angles in degrees**, J = C/3 joints::

    hit_{t,j} = 1[ sum_{xyz} |r_{t,j} - r^_{t,j}| < 4 ],
    SRGR = (1 / (T J)) sum_t (lambda_t / 0.165) sum_j hit_{t,j}

(0.165 ~ the mean semantic score of the BEAT test set, so that a perfect prediction scores
about 1 there). Use it to reproduce numbers reported with the BEAT code (0.239 for CaMN).

Several takes are pooled frame-weighted (``sum_takes T_k SRGR_k / sum_takes T_k``), as the
reference code does.

Taught in notebooks/04_metrics.ipynb, section 2 (2.1 from PCK, 2.2 the paper's SRGR vs the released code's).
"""

from __future__ import annotations

import numpy as np

from beatlite.metrics._checks import as_array, as_list

VARIANTS = ("paper", "reference")
#: Default position threshold of the paper variant, cm (the paper gives no value; beatlite's choice).
DEFAULT_DELTA_CM = 10.0
#: Reference variant: threshold on the summed absolute Euler difference, degrees.
REFERENCE_THRESHOLD_DEG = 4.0
#: Reference variant: the normaliser of the semantic weight.
REFERENCE_NORMALISER = 0.165


def srgr(
    generated: np.ndarray | list[np.ndarray],
    ground_truth: np.ndarray | list[np.ndarray],
    semantic: np.ndarray | list[np.ndarray],
    *,
    variant: str = "paper",
    delta: float | None = None,
) -> float:
    """Semantic-Relevant Gesture Recall of one take or several.

    Parameters
    ----------
    generated, ground_truth : array or list of arrays
        ``variant="paper"``: (T, J, 3) positions, centimetres.
        ``variant="reference"``: (T, C) Euler angles, degrees, C = 3J (141 for BEAT).
    semantic : (T,) float or list
        Per-frame semantic score in [0, 1] of the ground truth
        (``beatlite.io.semantic_to_frames``).
    variant : "paper" or "reference"
        See the module docstring.
    delta : float, optional
        Threshold: cm for "paper" (default 10 cm), summed degrees for "reference" (default 4).

    Returns
    -------
    float
        Paper variant in [0, max lambda]; reference variant in [0, max lambda / 0.165].

    Examples
    --------
    Four frames of two joints; the generated second joint is 20 cm off in every frame, so
    half of the joints are recalled (delta = 10 cm). Only the first two frames are
    semantically relevant (score 1): ``SRGR = (1 + 1 + 0 + 0) / 4 * 1/2 = 0.25``.

    >>> import numpy as np
    >>> from beatlite.metrics.recall import srgr
    >>> truth = np.zeros((4, 2, 3))
    >>> generated = truth.copy()
    >>> generated[:, 1, 0] = 20.0
    >>> semantic = np.array([1.0, 1.0, 0.0, 0.0])
    >>> srgr(generated, truth, semantic)
    0.25
    >>> srgr(truth, truth, semantic)  # a perfect prediction scores mean(semantic)
    0.5

    The reference variant works on Euler angles: joint 1 is off by 1 degree per axis
    (3 < 4 summed degrees: recalled), joint 2 by 2 degrees per axis (6: missed); with
    every semantic score at 0.165 the weight ``0.165 / 0.165`` is 1.

    >>> truth = np.zeros((3, 6))
    >>> generated = truth + [1.0, 1.0, 1.0, 2.0, 2.0, 2.0]
    >>> round(srgr(generated, truth, np.full(3, 0.165), variant="reference"), 6)
    0.5
    """
    if variant not in VARIANTS:
        raise ValueError(f"variant must be one of {VARIANTS}, got {variant!r}")
    gens, many_g = as_list(generated, "generated")
    gts, many_t = as_list(ground_truth, "ground_truth")
    sems, many_s = as_list(semantic, "semantic")
    if not (many_g == many_t == many_s) or not (len(gens) == len(gts) == len(sems)):
        raise ValueError(
            f"generated, ground_truth and semantic must all be one take or lists of equal length, got "
            f"{len(gens)}, {len(gts)}, {len(sems)}"
        )
    total, frames = 0.0, 0
    for g, t, s in zip(gens, gts, sems):
        hits, weights = _hits(g, t, s, variant, delta)
        total += float((weights[:, None] * hits).sum()) / hits.shape[1]
        frames += hits.shape[0]
    return total / frames


def srgr_per_frame(
    generated: np.ndarray, ground_truth: np.ndarray, semantic: np.ndarray, *, variant: str = "paper",
    delta: float | None = None,
) -> np.ndarray:  # fmt: skip
    """Per-frame terms ``w_t (1/J) sum_j hit_{t,j}`` of one take, (T,) float64; their mean is SRGR.

    Examples
    --------
    >>> truth = np.zeros((3, 2, 3))
    >>> generated = truth.copy()
    >>> generated[1, 0, 0] = 50.0  # one of two joints misses in frame 1
    >>> terms = srgr_per_frame(generated, truth, np.array([1.0, 1.0, 0.5]))
    >>> terms
    array([1. , 0.5, 0.5])
    >>> round(float(terms.mean()), 6) == round(srgr(generated, truth, np.array([1.0, 1.0, 0.5])), 6)
    True
    """
    hits, weights = _hits(generated, ground_truth, semantic, variant, delta)
    return weights * hits.mean(axis=1)


def _hits(g, t, s, variant: str, delta: float | None) -> tuple[np.ndarray, np.ndarray]:
    if variant == "paper":
        gen = as_array(g, "generated", ndim=3, last=3)
        gt = as_array(t, "ground_truth", ndim=3, last=3)
        thr = DEFAULT_DELTA_CM if delta is None else float(delta)
        if gen.shape != gt.shape:
            raise ValueError(
                f"generated and ground_truth must have the same shape, got {gen.shape} and {gt.shape}"
            )
        hits = np.linalg.norm(gen - gt, axis=-1) < thr
    elif variant == "reference":
        gen = as_array(g, "generated", ndim=2)
        gt = as_array(t, "ground_truth", ndim=2)
        if gen.shape != gt.shape:
            raise ValueError(
                f"generated and ground_truth must have the same shape, got {gen.shape} and {gt.shape}"
            )
        if gen.shape[1] % 3:
            raise ValueError(f"reference SRGR needs Euler triplets (T, 3J), got shape {gen.shape}")
        thr = REFERENCE_THRESHOLD_DEG if delta is None else float(delta)
        diff = np.abs(gen - gt).reshape(gen.shape[0], -1, 3).sum(axis=-1)
        hits = diff < thr
    else:
        raise ValueError(f"variant must be one of {VARIANTS}, got {variant!r}")
    if not thr > 0:
        raise ValueError(f"delta must be positive, got {delta!r}")
    sem = as_array(s, "semantic", ndim=1)
    if sem.shape[0] != gen.shape[0]:
        raise ValueError(f"semantic must have one value per frame ({gen.shape[0]}), got shape {sem.shape}")
    if gen.shape[0] == 0:
        raise ValueError("generated has no frames")
    weights = sem / REFERENCE_NORMALISER if variant == "reference" else sem
    return hits.astype(np.float64), weights
