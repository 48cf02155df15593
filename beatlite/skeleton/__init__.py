"""The BEAT skeleton, rotation conversions, forward kinematics and bone directions (NumPy only).

==========================  ==================================================================
``core.Skeleton``            joint hierarchy: names, parents, offsets (cm), channels, End Sites
``beat``                     the 75-joint BEAT skeleton, named joint subsets, CaMN 141-d assembly
``rotations``                Euler (6 orders) <-> matrix <-> quaternion <-> axis-angle <-> 6D
``kinematics``               forward kinematics: channel rows -> world positions/rotations
``directions``               unit bone vectors <-> joint positions
``ted``                      the TED-Expressive 43-joint body for HA2G (bones, levels, angle pairs) and
                             the results tables' common space (BEAT Euler/channels <-> TED-43)
==========================  ==================================================================

Taught in notebooks/01_beat_formats.ipynb, sections 2 and 4-7 (the skeleton, Euler angles, forward kinematics, joint subsets).
"""

from __future__ import annotations

from beatlite.skeleton.beat import (
    BEAT_N_CHANNELS,
    BEAT_N_JOINTS,
    HIPS_HEIGHT_CM,
    JOINT_SUBSETS,
    beat_skeleton,
    camn_assemble,
    camn_split,
    expand_subset,
    subset_columns,
)
from beatlite.skeleton.core import POSITION_CHANNELS, ROTATION_CHANNELS, Skeleton
from beatlite.skeleton.directions import directions_to_positions, positions_to_directions, skeleton_bones
from beatlite.skeleton.kinematics import forward_kinematics, global_transforms, local_rotations, rest_pose
from beatlite.skeleton.rotations import (
    EULER_ORDERS,
    axis_angle_to_matrix,
    euler_to_matrix,
    matrix_to_6d,
    matrix_to_axis_angle,
    matrix_to_euler,
    matrix_to_quat,
    quat_to_matrix,
    sixd_to_matrix,
    unwrap_degrees,
)
from beatlite.skeleton.ted import (
    ANGLE_PAIRS,
    HA2G_LEVELS,
    HEAD_LANDMARK_OFFSETS,
    TED43_FROM_BEAT,
    TED43_JOINTS,
    TED_BONES,
    TED_VECTOR_NAMES,
    beat_to_ted43,
    channels_to_directions,
    directions_to_ted_positions,
    euler_to_directions,
    pair_angles,
    palm_normals,
    rest_bone_lengths,
)

__all__ = [
    "ANGLE_PAIRS",
    "HA2G_LEVELS",
    "HEAD_LANDMARK_OFFSETS",
    "TED43_FROM_BEAT",
    "TED43_JOINTS",
    "TED_BONES",
    "TED_VECTOR_NAMES",
    "beat_to_ted43",
    "channels_to_directions",
    "directions_to_positions",
    "directions_to_ted_positions",
    "euler_to_directions",
    "pair_angles",
    "palm_normals",
    "positions_to_directions",
    "skeleton_bones",
    "BEAT_N_CHANNELS",
    "BEAT_N_JOINTS",
    "EULER_ORDERS",
    "HIPS_HEIGHT_CM",
    "JOINT_SUBSETS",
    "POSITION_CHANNELS",
    "ROTATION_CHANNELS",
    "Skeleton",
    "axis_angle_to_matrix",
    "beat_skeleton",
    "camn_assemble",
    "camn_split",
    "euler_to_matrix",
    "expand_subset",
    "forward_kinematics",
    "global_transforms",
    "local_rotations",
    "matrix_to_6d",
    "matrix_to_axis_angle",
    "matrix_to_euler",
    "matrix_to_quat",
    "quat_to_matrix",
    "rest_bone_lengths",
    "rest_pose",
    "sixd_to_matrix",
    "subset_columns",
    "unwrap_degrees",
]
