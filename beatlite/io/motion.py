"""The :class:`Motion` container returned by the BVH reader.

Taught in notebooks/01_beat_formats.ipynb, section 3 (reading the motion).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from beatlite.skeleton.core import Skeleton


@dataclass(eq=False)
class Motion:
    """A skeleton with per-frame channel values, as stored in a BVH file.

    Attributes
    ----------
    skeleton : Skeleton
        Joint hierarchy, channel layout and offsets (centimetres).
    channels : (T, C) float64
        One row per frame; columns follow ``skeleton.channels`` (positions in
        centimetres, rotations in degrees, Euler order per joint as in the file).
    fps : float
        Frames per second.

    Examples
    --------
    >>> from beatlite.skeleton.beat import beat_skeleton
    >>> motion = Motion(beat_skeleton(), np.zeros((30, 228)), fps=15)
    >>> motion.n_frames, motion.duration
    (30, 2.0)
    """

    skeleton: Skeleton
    channels: np.ndarray
    fps: float

    def __post_init__(self) -> None:
        self.channels = np.asarray(self.channels, dtype=np.float64)
        if self.channels.ndim != 2 or self.channels.shape[1] != self.skeleton.n_channels:
            raise ValueError(
                f"Motion: channels must be (T, {self.skeleton.n_channels}), got {self.channels.shape}"
            )
        if not np.isfinite(self.fps) or self.fps <= 0:
            raise ValueError(f"Motion: fps must be positive, got {self.fps}")
        self.fps = float(self.fps)

    @property
    def n_frames(self) -> int:
        """Number of frames T."""
        return int(self.channels.shape[0])

    @property
    def duration(self) -> float:
        """Duration in seconds, ``T / fps``."""
        return self.n_frames / self.fps

    def positions(self) -> np.ndarray:
        """World joint positions by forward kinematics, (T, J, 3) float64, centimetres."""
        from beatlite.skeleton.kinematics import forward_kinematics

        return forward_kinematics(self.skeleton, self.channels)

    def __repr__(self) -> str:
        return (
            f"Motion({self.n_frames} frames @ {self.fps:g} fps = {self.duration:.2f} s, "
            f"{self.skeleton.n_joints} joints, {self.skeleton.n_channels} channels)"
        )
