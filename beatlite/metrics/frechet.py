"""Fréchet Gesture Distance (FGD): the Fréchet distance between Gaussian fits of features.

FGD (Yoon et al. 2020; used by BEAT/CaMN and HA2G) embeds 34-frame motion windows
with a pretrained feature extractor, fits one Gaussian to the generated features and
one to the real ones, and reports

    FGD = ||mu_1 - mu_2||^2 + Tr(Sigma_1 + Sigma_2 - 2 (Sigma_1 Sigma_2)^(1/2)).

Lower is better; 0 means identical first and second moments. The value depends
entirely on the extractor, so FGD numbers are only comparable with the same
extractor (see :mod:`beatlite.metrics.extractor`).

Taught in notebooks/04_metrics.ipynb, section 1 (FGD: the Fréchet distance between two Gaussians).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable

import numpy as np

from beatlite.metrics._checks import as_array

Extractor = Callable[[np.ndarray], np.ndarray]

#: Value the BEAT/HA2G wrapper returns when ``scipy.linalg.sqrtm`` leaves a large imaginary part.
REFERENCE_FAILURE_VALUE = 1e10


def fit_gaussian(features: np.ndarray, name: str = "features") -> tuple[np.ndarray, np.ndarray]:
    """Mean and unbiased covariance of a feature matrix.

    Parameters
    ----------
    features : (N, D) float
        One feature vector per row, N >= 2.
    name : str
        Argument name used in error messages.

    Returns
    -------
    mu : (D,) float64
        ``mean_i x_i``.
    sigma : (D, D) float64
        ``sum_i (x_i - mu)(x_i - mu)^T / (N - 1)`` (as ``np.cov(features, rowvar=False)``).

    Examples
    --------
    >>> mu, sigma = fit_gaussian(np.array([[0.0, 1.0], [2.0, 1.0], [4.0, 1.0]]))
    >>> mu
    array([2., 1.])
    >>> sigma
    array([[4., 0.],
           [0., 0.]])
    """
    x = as_array(features, name, ndim=2)
    n = x.shape[0]
    if n < 2:
        raise ValueError(
            f"{name} needs at least 2 samples (rows) to estimate a covariance, got shape {x.shape}"
        )
    mu = x.mean(axis=0)
    xc = x - mu
    return mu, _gram(xc) / (n - 1)


def _gram(xc: np.ndarray) -> np.ndarray:
    """``xc^T xc`` (D, D) by BLAS ``dsyrk`` (half the flops of a GEMM), symmetrised."""
    from scipy.linalg import blas

    upper = blas.dsyrk(1.0, np.asfortranarray(xc.T), trans=0)  # xc.T of a C array is already F-ordered
    return np.triu(upper) + np.triu(upper, 1).T


def _check_moments(mu1, sigma1, mu2, sigma2) -> tuple[np.ndarray, ...]:
    m1 = as_array(mu1, "mu1", ndim=1)
    m2 = as_array(mu2, "mu2", ndim=1)
    s1 = as_array(sigma1, "sigma1", ndim=2)
    s2 = as_array(sigma2, "sigma2", ndim=2)
    d = m1.shape[0]
    if m2.shape != (d,) or s1.shape != (d, d) or s2.shape != (d, d):
        raise ValueError(
            f"mu1 {m1.shape}, sigma1 {s1.shape}, mu2 {m2.shape}, sigma2 {s2.shape} do not agree: "
            f"expected (D,), (D, D), (D,), (D, D) with D = {d}"
        )
    return m1, s1, m2, s2


def _psd_sqrt(sigma: np.ndarray) -> np.ndarray:
    """Symmetric square root of a symmetric PSD matrix by eigen-decomposition (negatives clipped to 0)."""
    w, v = np.linalg.eigh((sigma + sigma.T) / 2)
    return (v * np.sqrt(np.clip(w, 0.0, None))) @ v.T


def frechet_distance(
    mu1: np.ndarray,
    sigma1: np.ndarray,
    mu2: np.ndarray,
    sigma2: np.ndarray,
    *,
    reference: bool = False,
    eps: float = 1e-6,
) -> float:
    """Fréchet (2-Wasserstein squared) distance between N(mu1, sigma1) and N(mu2, sigma2).

    ``d = ||mu1 - mu2||^2 + Tr(sigma1) + Tr(sigma2) - 2 Tr((sigma1 sigma2)^(1/2))``.

    The default (stable) route uses ``Tr((sigma1 sigma2)^(1/2)) = sum_i sqrt(lambda_i)`` with
    ``lambda_i`` the eigenvalues of the symmetric PSD matrix ``S^T sigma2 S``, which is similar to
    ``sigma2 sigma1`` when ``sigma1 = S S^T``: ``S`` is the Cholesky factor of ``sigma1`` (fast), or
    ``sigma1^(1/2)`` from ``numpy.linalg.eigh`` when ``sigma1`` is singular. Eigenvalues come from
    ``numpy.linalg.eigvalsh``; tiny negative ones from rounding are clipped to 0, and the result
    is clipped at 0 (it is a squared distance).

    Parameters
    ----------
    mu1, mu2 : (D,) float
        Means.
    sigma1, sigma2 : (D, D) float
        Covariances (symmetric positive semi-definite).
    reference : bool
        Follow the pytorch-fid routine that BEAT (``data_tools.py``) and HA2G
        (``embedding_space_evaluator.py``) copy: ``scipy.linalg.sqrtm(sigma1 @ sigma2)``;
        if that is not finite, retry with ``eps`` added to both diagonals; an imaginary
        part with ``|imag| > 1e-3`` on the diagonal is an error, which their wrapper maps to
        ``1e10`` — returned here too, with a ``RuntimeWarning``. No clipping at 0.
    eps : float
        Diagonal offset of the reference retry.

    Returns
    -------
    float
        The distance, in squared feature units.

    Examples
    --------
    Two 2-D Gaussians with diagonal covariances: the distance is
    ``||mu1 - mu2||^2 + sum_d (sqrt(a_d) - sqrt(b_d))^2 = 25 + 2 * (1 - 2)^2 = 27``.

    >>> import numpy as np
    >>> from beatlite.metrics.frechet import frechet_distance
    >>> round(frechet_distance(np.zeros(2), np.eye(2), np.array([3.0, 4.0]), 4 * np.eye(2)), 6)
    27.0
    >>> round(frechet_distance(np.zeros(2), np.eye(2), np.zeros(2), np.eye(2)), 6)
    0.0
    """
    m1, s1, m2, s2 = _check_moments(mu1, sigma1, mu2, sigma2)
    diff = m1 - m2
    if reference:
        return _frechet_reference(diff, s1, s2, eps)
    try:
        root1 = np.linalg.cholesky((s1 + s1.T) / 2)
    except np.linalg.LinAlgError:  # singular (e.g. fewer samples than dimensions)
        root1 = _psd_sqrt(s1)
    inner = root1.T @ s2 @ root1
    w = np.linalg.eigvalsh((inner + inner.T) / 2)
    tr_covmean = float(np.sqrt(np.clip(w, 0.0, None)).sum())
    d = float(diff @ diff + np.trace(s1) + np.trace(s2) - 2.0 * tr_covmean)
    return max(d, 0.0)


def _frechet_reference(diff: np.ndarray, s1: np.ndarray, s2: np.ndarray, eps: float) -> float:
    from scipy import linalg

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        covmean = linalg.sqrtm(s1 @ s2)
        if not np.all(np.isfinite(covmean)):
            offset = np.eye(s1.shape[0]) * eps
            covmean = linalg.sqrtm((s1 + offset) @ (s2 + offset))
    if np.iscomplexobj(covmean):
        if not np.allclose(np.diagonal(covmean).imag, 0, atol=1e-3):
            m = float(np.max(np.abs(covmean.imag)))
            warnings.warn(
                f"frechet_distance(reference=True): sqrtm left an imaginary component {m:.3g}; "
                f"returning {REFERENCE_FAILURE_VALUE:g} as the reference wrapper does",
                RuntimeWarning,
                stacklevel=3,
            )
            return REFERENCE_FAILURE_VALUE
        covmean = covmean.real
    return float(diff @ diff + np.trace(s1) + np.trace(s2) - 2.0 * np.trace(covmean))


def fgd(
    generated: np.ndarray,
    real: np.ndarray,
    *,
    extractor: Extractor | None = None,
    reference: bool = False,
) -> float:
    """Fréchet Gesture Distance between generated and real motion features.

    ``FGD = frechet_distance(mean(F_gen), cov(F_gen), mean(F_real), cov(F_real))``.

    Parameters
    ----------
    generated : (N, F) float, or (N, 34, D) windows when ``extractor`` is given
        Generated features (one row per window), N >= 2.
    real : (M, F) float, or (M, 34, D) windows when ``extractor`` is given
        Real (ground-truth) features, M >= 2.
    extractor : callable, optional
        Any function mapping windows ``(N, L, D)`` to features ``(N, F)``, e.g.
        :func:`beatlite.metrics.extractor.load_extractor`'s result. Without it the
        inputs must already be features.
    reference : bool
        Use the reference (``scipy.linalg.sqrtm``) routine, see :func:`frechet_distance`.

    Returns
    -------
    float
        FGD in squared feature units (>= 0 in the stable mode).

    Examples
    --------
    Four real feature vectors with mean 0 and covariance ``(2/3) I``. Shifting them by
    ``(2, 0)`` changes only the mean (FGD = 2^2 = 4); doubling them keeps the mean and
    scales the covariance by 4 (FGD = 2 * (sqrt(8/3) - sqrt(2/3))^2 = 4/3).

    >>> import numpy as np
    >>> from beatlite.metrics.frechet import fgd
    >>> real = np.array([[-1.0, 0.0], [1.0, 0.0], [0.0, -1.0], [0.0, 1.0]])
    >>> round(fgd(real + [2.0, 0.0], real), 6)
    4.0
    >>> round(fgd(2 * real, real), 6)
    1.333333
    """
    if extractor is not None:
        generated = _extract(extractor, generated, "generated")
        real = _extract(extractor, real, "real")
    mu1, s1 = fit_gaussian(generated, "generated")
    mu2, s2 = fit_gaussian(real, "real")
    if mu1.shape != mu2.shape:
        raise ValueError(f"generated and real features differ in width: {mu1.shape[0]} vs {mu2.shape[0]}")
    return frechet_distance(mu1, s1, mu2, s2, reference=reference)


def _extract(extractor: Extractor, windows: np.ndarray, name: str) -> np.ndarray:
    w = as_array(windows, name, ndim=3)
    feats = np.asarray(extractor(w), dtype=np.float64)
    if feats.ndim != 2 or feats.shape[0] != w.shape[0]:
        raise ValueError(
            f"extractor must map windows (N, L, D) to features (N, F); for {name} {w.shape} it returned {feats.shape}"
        )
    return feats
