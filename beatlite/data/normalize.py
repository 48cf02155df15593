"""Per-dimension mean/std normalisation computed on the training split only.

No notebook teaches it directly; notebooks/05_camn.ipynb, section 1 shows the normalised training windows that :mod:`beatlite.data.windows` makes with it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Standard deviations below this are replaced by 1 (constant dimensions are only centred).
MIN_STD = 1e-6


@dataclass(frozen=True, eq=False)
class Normalizer:
    """z-scoring ``(x - mean) / std`` over the last axis.

    Attributes
    ----------
    mean : (D,) float64
        Per-dimension mean (units of the data, e.g. degrees).
    std : (D,) float64
        Per-dimension standard deviation; entries below :data:`MIN_STD` are 1.

    Examples
    --------
    >>> n = Normalizer.fit(np.array([[0.0, 1.0], [2.0, 1.0]]))
    >>> n.mean, n.std
    (array([1., 1.]), array([1., 1.]))
    >>> n.transform(np.array([[3.0, 1.0]]))
    array([[2., 0.]])
    """

    mean: np.ndarray
    std: np.ndarray

    def __post_init__(self) -> None:
        mean = np.asarray(self.mean, dtype=np.float64)
        std = np.asarray(self.std, dtype=np.float64)
        if mean.ndim != 1 or std.shape != mean.shape:
            raise ValueError(f"Normalizer: mean and std must both be (D,), got {mean.shape} and {std.shape}")
        if not (np.all(np.isfinite(mean)) and np.all(np.isfinite(std))) or np.any(std <= 0):
            raise ValueError("Normalizer: mean must be finite and std finite and positive")
        object.__setattr__(self, "mean", mean)
        object.__setattr__(self, "std", std)

    @property
    def dim(self) -> int:
        """Number of dimensions D."""
        return int(self.mean.shape[0])

    @classmethod
    def fit(cls, frames: np.ndarray | list[np.ndarray], *, center_only: bool = False) -> Normalizer:
        """Statistics of ``frames``.

        Parameters
        ----------
        frames : (N, D) array or list of (T_i, D) arrays
            Training frames (all takes of the train split, concatenated).
        center_only : bool
            Keep ``std = 1`` (only subtract the mean, as HA2G does for direction vectors).
        """
        data = np.concatenate(frames, axis=0) if isinstance(frames, list) else np.asarray(frames)
        if data.ndim != 2 or data.shape[0] == 0:
            raise ValueError(f"Normalizer.fit: frames must be (N, D) with N >= 1, got {data.shape}")
        data = data.astype(np.float64, copy=False)
        mean = data.mean(axis=0)
        std = np.ones_like(mean) if center_only else data.std(axis=0)
        std = np.where(std < MIN_STD, 1.0, std)
        return cls(mean, std)

    def _check(self, x: np.ndarray, name: str) -> np.ndarray:
        x = np.asarray(x)
        if x.ndim == 0 or x.shape[-1] != self.dim:
            raise ValueError(f"Normalizer.{name}: x must be (..., {self.dim}), got {x.shape}")
        return x

    def transform(self, x: np.ndarray) -> np.ndarray:
        """``(x - mean) / std``; x is (..., D), result has x's float dtype (float64 for ints)."""
        x = self._check(x, "transform")
        dtype = x.dtype if np.issubdtype(x.dtype, np.floating) else np.float64
        return ((x - self.mean) / self.std).astype(dtype, copy=False)

    def inverse_transform(self, z: np.ndarray) -> np.ndarray:
        """``z * std + mean``; z is (..., D)."""
        z = self._check(z, "inverse_transform")
        dtype = z.dtype if np.issubdtype(z.dtype, np.floating) else np.float64
        return (z * self.std + self.mean).astype(dtype, copy=False)

    def to_arrays(self, prefix: str) -> dict[str, np.ndarray]:
        """``{prefix + "_mean": mean, prefix + "_std": std}`` for saving in an ``.npz``."""
        return {f"{prefix}_mean": self.mean, f"{prefix}_std": self.std}

    @classmethod
    def from_arrays(cls, arrays: dict[str, np.ndarray] | np.lib.npyio.NpzFile, prefix: str) -> Normalizer:
        """Inverse of :meth:`to_arrays`."""
        return cls(np.asarray(arrays[f"{prefix}_mean"]), np.asarray(arrays[f"{prefix}_std"]))
