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


#: The pose representations of the batch contract and the window key of each.
REPRESENTATIONS = {"euler141": "pose", "dirvec126": "dirvec"}
#: The checkpoint-metadata entries of :meth:`Normalizers.to_meta`.
META_KEYS = ("pose_mean", "pose_std", "dirvec_mean")
#: Directions shorter than this after the mean is added back are returned as zero vectors.
MIN_DIRECTION_NORM = 1e-9


@dataclass(frozen=True, eq=False)
class Normalizers:
    """The fitted train-split normalisers of both pose representations, carried end to end.

    Fitted once by :func:`beatlite.data.build_windows` on the train split, then stored in every
    checkpoint (:meth:`to_meta`), in every evaluation set, and used by training, generation,
    evaluation and the notebooks through :meth:`transform` / :meth:`inverse_transform` only.

    Attributes
    ----------
    pose : Normalizer
        (141,) mean/std of the ``spine_neck_141`` Euler degrees (``"euler141"``, window key ``pose``).
    dirvec : Normalizer
        (126,) mean of the 42 unit bone directions with ``std = 1`` (``"dirvec126"``, key ``dirvec``):
        HA2G only subtracts the mean.

    Examples
    --------
    >>> pose = Normalizer(np.full(141, 10.0), np.full(141, 2.0))
    >>> dirvec = Normalizer(np.tile([0.0, 0.0, 0.5], 42), np.ones(126))
    >>> norms = Normalizers(pose, dirvec)
    >>> norms.inverse_transform(np.ones((1, 141)), "euler141")[0, :2]   # z * std + mean, degrees
    array([12., 12.])
    >>> norms.inverse_transform(np.zeros((1, 126)), "dirvec126")[0, 0]  # mean added back, unit length
    array([0., 0., 1.])
    """

    pose: Normalizer
    dirvec: Normalizer

    def __post_init__(self) -> None:
        if not (isinstance(self.pose, Normalizer) and isinstance(self.dirvec, Normalizer)):
            raise TypeError("Normalizers: pose and dirvec must be Normalizer objects")
        if self.dirvec.dim % 3:
            raise ValueError(f"Normalizers: dirvec must have 3 x bones dimensions, got {self.dirvec.dim}")

    def __getitem__(self, representation: str) -> Normalizer:
        """The normaliser of ``"euler141"`` or ``"dirvec126"``."""
        if representation not in REPRESENTATIONS:
            raise ValueError(
                f"representation must be one of {sorted(REPRESENTATIONS)}, got {representation!r}"
            )
        return getattr(self, REPRESENTATIONS[representation])

    def transform(self, values: np.ndarray, representation: str) -> np.ndarray:
        """Degrees (..., 141) or unit directions (..., 126) / (..., 42, 3) -> normalised (..., D)."""
        values = np.asarray(values)
        if representation == "dirvec126" and values.ndim >= 2 and values.shape[-1] == 3:
            values = values.reshape(*values.shape[:-2], -1)
        return self[representation].transform(values)

    def inverse_transform(self, z: np.ndarray, representation: str) -> np.ndarray:
        """Normalised (..., D) -> degrees (..., 141) float64, or unit directions (..., 42, 3) float64.

        Directions get the train mean added back and are re-normalised to unit length (HA2G's
        code trains on mean-subtracted directions and adds the mean back before scoring,
        docs/reference_code.md#ted-expressive).
        """
        x = self[representation].inverse_transform(np.asarray(z, dtype=np.float64))
        if representation == "euler141":
            return x
        dirs = x.reshape(*x.shape[:-1], -1, 3)
        length = np.linalg.norm(dirs, axis=-1, keepdims=True)
        return np.divide(dirs, length, out=np.zeros_like(dirs), where=length > MIN_DIRECTION_NORM)

    def to_meta(self) -> dict[str, np.ndarray]:
        """The checkpoint-metadata entries ``pose_mean``, ``pose_std``, ``dirvec_mean`` (float64 arrays)."""
        return {"pose_mean": self.pose.mean, "pose_std": self.pose.std, "dirvec_mean": self.dirvec.mean}

    @classmethod
    def from_meta(cls, meta: dict) -> Normalizers:
        """Inverse of :meth:`to_meta` (a checkpoint's ``meta``); ``KeyError`` naming a missing entry."""
        missing = [k for k in META_KEYS if k not in meta]
        if missing:
            raise KeyError(
                f"Normalizers.from_meta: the metadata has no {missing} (a checkpoint without statistics)"
            )
        mean = np.asarray(meta["dirvec_mean"], np.float64)
        return cls(Normalizer(meta["pose_mean"], meta["pose_std"]), Normalizer(mean, np.ones_like(mean)))

    @classmethod
    def in_meta(cls, meta: dict | None) -> Normalizers | None:
        """:meth:`from_meta` when ``meta`` holds all of :data:`META_KEYS`, else None (older or other checkpoints)."""
        return cls.from_meta(meta) if meta and all(k in meta for k in META_KEYS) else None

    def matches(self, other: Normalizers, *, rtol: float = 1e-5, atol: float = 1e-6) -> bool:
        """Whether ``other`` holds the same statistics (float32 round trips of a checkpoint included)."""
        pairs = ((self.pose.mean, other.pose.mean), (self.pose.std, other.pose.std))
        pairs += ((self.dirvec.mean, other.dirvec.mean),)
        return all(a.shape == b.shape and np.allclose(a, b, rtol=rtol, atol=atol) for a, b in pairs)
