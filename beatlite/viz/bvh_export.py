"""Export generated motion as a full BEAT BVH file that Blender (or any BVH viewer) opens.

Models output a joint subset (CaMN/HA2G on BEAT: the 141 Euler-degree channels
of ``spine_neck_141``). :func:`motion_from_subset` puts them back into the
228-channel BEAT layout (every other joint at its rest pose, the root at the
origin) and :func:`export_bvh` writes that with :func:`beatlite.io.write_bvh`.

Opening the file in Blender (2.8 to 4.x)
----------------------------------------
1. *File -> Import -> Motion Capture (.bvh)* and pick the file.
2. In the import options (right panel):

   - **Scale: 0.01** (beatlite/BEAT positions are centimetres; Blender works in metres).
   - **Forward: -Z**, **Up: Y** (the defaults). BEAT is Y-up and faces +Z; with these the
     character stands on Blender's floor (Z up) facing the *Front* view (-Y).
   - **Update Scene FPS** on (the file's ``Frame Time`` is ``1/fps``, e.g. 15 fps for model
     output), and **Update Scene Duration** on; *Time Scale* 1.
   - Rotation: Euler (the default).
3. Press *Space* to play. The root is at the origin, so the feet are ``HIPS_HEIGHT_CM`` (95 cm)
   below the floor unless you pass ``root_position=(0, 95, 0)``.

Taught in notebooks/08_visualisation_3d.ipynb, section 6 (export to Blender: BVH).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from beatlite.io.motion import Motion
from beatlite.skeleton.core import Skeleton
from beatlite.viz._inputs import check_fps


def motion_from_subset(
    channels: Any,
    fps: float,
    skeleton: Skeleton | None = None,
    *,
    subset: str = "spine_neck_141",
    root_position: Sequence[float] = (0.0, 0.0, 0.0),
) -> Motion:
    """A full BEAT :class:`Motion` from a joint subset's Euler channels; other joints at rest.

    Parameters
    ----------
    channels : (T, 3K) float, degrees
        The subset's rotation channels in :func:`beatlite.skeleton.beat.subset_columns`
        order, e.g. ``(T, 141)`` for ``"spine_neck_141"`` (CaMN / HA2G output after
        de-normalisation). A full ``(T, skeleton.n_channels)`` array is also accepted
        and used as is.
    fps : float
        Frame rate of ``channels`` (15 for the models), frames per second.
    skeleton : Skeleton, optional
        Target skeleton (default :func:`beatlite.skeleton.beat.beat_skeleton`).
    subset : str
        A key of :data:`beatlite.skeleton.beat.JOINT_SUBSETS`.
    root_position : (3,) float, centimetres
        Root (``Hips``) translation of every frame; every other non-subset channel is 0.

    Returns
    -------
    Motion
        ``(T, 228)`` float64 channels for BEAT, at ``fps``.

    Examples
    --------
    The subset's first channel is the Spine's first rotation, right after the Hips' 6 channels (3 positions,
    3 rotations); every other channel stays 0 but the root height given:

    >>> channels = np.zeros((3, 141))
    >>> channels[:, 0] = 10.0  # degrees
    >>> motion = motion_from_subset(channels, fps=15, root_position=(0.0, 95.0, 0.0))
    >>> motion.channels.shape, motion.fps, motion.skeleton.names[:2]
    ((3, 228), 15.0, ('Hips', 'Spine'))
    >>> np.flatnonzero(motion.channels[0]).tolist(), motion.channels[0, [1, 6]].tolist()
    ([1, 6], [95.0, 10.0])
    """
    from beatlite.skeleton.beat import beat_skeleton, expand_subset

    skel = beat_skeleton() if skeleton is None else skeleton
    if not isinstance(skel, Skeleton):
        raise TypeError(f"skeleton must be a Skeleton, got {type(skel).__name__}")
    fps = check_fps(fps)
    values = np.asarray(channels, dtype=np.float64)
    if values.ndim != 2 or values.shape[0] == 0:
        raise ValueError(f"channels must be a (T, 3K) array with T >= 1, got shape {values.shape}")
    if not np.all(np.isfinite(values)):
        raise ValueError(f"channels contains NaN or infinite values (shape {values.shape})")
    root = np.asarray(root_position, dtype=np.float64)
    if root.shape != (3,):
        raise ValueError(f"root_position must be (x, y, z) in centimetres, got shape {root.shape}")
    if values.shape[1] == skel.n_channels:
        full = values.copy()
    else:
        full = expand_subset(values, subset, skel)
    pos_cols = skel.position_channel_indices(0)
    if pos_cols.size and np.any(root != 0):
        full[:, pos_cols] = root
    return Motion(skel, full, fps)


def export_bvh(
    path: str | os.PathLike[str],
    channels: Any,
    fps: float,
    skeleton: Skeleton | None = None,
    *,
    subset: str = "spine_neck_141",
    root_position: Sequence[float] = (0.0, 0.0, 0.0),
    precision: int = 6,
) -> Path:
    """Write generated motion as a full BVH file (atomically); see the module docstring for Blender.

    Parameters
    ----------
    path : str or Path
        Output ``.bvh`` (``.bvh.gz`` gzips it).
    channels : (T, 3K) or (T, C) float, degrees
        Subset channels (or full rows), as for :func:`motion_from_subset`.
    fps : float
        Frame rate; written as ``Frame Time: 1/fps``.
    skeleton : Skeleton, optional
        Default :func:`beatlite.skeleton.beat.beat_skeleton`.
    subset : str
        Name of the subset ``channels`` holds.
    root_position : (3,) float, centimetres
        Root translation of every frame.
    precision : int
        Decimals written per value.

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    The written file reads back as :func:`motion_from_subset`'s motion (at the written 6 decimals):

    >>> import tempfile
    >>> from beatlite.io import read_bvh
    >>> channels = np.zeros((3, 141))
    >>> channels[:, 0] = 10.0
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     back = read_bvh(export_bvh(Path(tmp) / "camn.bvh", channels, fps=15))
    >>> back.fps, bool(np.allclose(back.channels, motion_from_subset(channels, fps=15).channels, atol=1e-6))
    (15.0, True)
    """
    from beatlite.io import write_bvh

    motion = motion_from_subset(channels, fps, skeleton, subset=subset, root_position=root_position)
    write_bvh(path, motion, precision=precision)
    return Path(path)
