"""The :class:`Skeleton` data structure shared by every part of beatlite.

Taught in notebooks/01_beat_formats.ipynb, section 2 (the BVH file: a skeleton, then one row of numbers per frame).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

POSITION_CHANNELS = ("Xposition", "Yposition", "Zposition")
ROTATION_CHANNELS = ("Xrotation", "Yrotation", "Zrotation")


def _check_hierarchy(
    names: tuple[str, ...], parents: np.ndarray, offsets: np.ndarray, channels: tuple[tuple[str, ...], ...]
) -> None:
    """Raise ``ValueError`` unless the sizes agree (J names, (J,) parents, (J, 3) offsets, J channel
    lists) and the joints are in depth-first order (root parent -1, ``0 <= parents[j] < j``)."""
    n = len(names)
    if parents.shape != (n,) or offsets.shape != (n, 3) or len(channels) != n:
        raise ValueError(
            f"Skeleton: {n} names but parents {parents.shape}, offsets {offsets.shape}, "
            f"{len(channels)} channel lists"
        )
    for j, p in enumerate(parents):
        if (j == 0 and p != -1) or (j > 0 and not 0 <= p < j):
            raise ValueError(f"Skeleton: joint {j} ({names[j]!r}) has invalid parent {p}")


@dataclass(frozen=True, eq=False)
class Skeleton:
    """A joint hierarchy as a BVH HIERARCHY block describes it.

    Joints are stored in depth-first (file) order, so ``parents[j] < j`` for
    every joint except the root, whose parent is ``-1``.

    Attributes
    ----------
    names : tuple of str, length J
        Joint names, e.g. ``"RightForeArm"``. May contain colons.
    parents : (J,) int64
        Index of each joint's parent, ``-1`` for the root.
    offsets : (J, 3) float64, centimetres
        Translation of each joint from its parent in the parent's frame
        (the BVH ``OFFSET``).
    channels : tuple of tuple of str, length J
        Per-joint channel names in file order, e.g.
        ``("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation")``.
        A joint may have 0, 3 or 6 channels.
    end_sites : dict int -> (3,) float64
        ``End Site`` offsets keyed by the index of the joint that owns them.

    Examples
    --------
    >>> arm = Skeleton(("Shoulder", "Elbow"), [-1, 0], [[0, 0, 0], [30, 0, 0]],
    ...                (("Zrotation", "Xrotation", "Yrotation"),) * 2)
    >>> arm.n_joints, arm.n_channels
    (2, 6)
    >>> arm.parents
    array([-1,  0])
    """

    names: tuple[str, ...]
    parents: np.ndarray
    offsets: np.ndarray
    channels: tuple[tuple[str, ...], ...]
    end_sites: dict[int, np.ndarray] = field(default_factory=dict)

    def __post_init__(self) -> None:
        parents = np.asarray(self.parents, dtype=np.int64)
        offsets = np.asarray(self.offsets, dtype=np.float64).reshape(-1, 3)
        _check_hierarchy(self.names, parents, offsets, self.channels)
        object.__setattr__(self, "parents", parents)
        object.__setattr__(self, "offsets", offsets)
        object.__setattr__(self, "names", tuple(self.names))
        object.__setattr__(self, "channels", tuple(tuple(c) for c in self.channels))
        object.__setattr__(
            self, "end_sites", {int(k): np.asarray(v, dtype=np.float64) for k, v in self.end_sites.items()}
        )

    # ------------------------------------------------------------------ sizes
    @property
    def n_joints(self) -> int:
        """Number of joints J (End Sites are not joints)."""
        return len(self.names)

    @property
    def n_channels(self) -> int:
        """Total number of motion channels C (228 for BEAT)."""
        return int(sum(len(c) for c in self.channels))

    @property
    def channel_starts(self) -> np.ndarray:
        """(J,) int64: index of each joint's first channel in a motion row."""
        counts = np.array([len(c) for c in self.channels], dtype=np.int64)
        return np.concatenate([[0], np.cumsum(counts)[:-1]])

    def index(self, name: str) -> int:
        """Index of the joint called ``name``; ``KeyError`` listing close names if absent."""
        try:
            return self.names.index(name)
        except ValueError:
            close = [n for n in self.names if name.lower() in n.lower()][:5]
            raise KeyError(f"no joint named {name!r}; similar: {close}") from None

    def indices(self, names: list[str] | tuple[str, ...]) -> np.ndarray:
        """(K,) int64 indices of several joints, in the order given."""
        return np.array([self.index(n) for n in names], dtype=np.int64)

    def children(self, j: int) -> list[int]:
        """Indices of the direct children of joint ``j``."""
        return [int(i) for i in np.flatnonzero(self.parents == j)]

    def rotation_order(self, j: int) -> str:
        """Euler order of joint ``j`` as written in its CHANNELS, e.g. ``"ZXY"`` ('' if none)."""
        return "".join(c[0] for c in self.channels[j] if c.endswith("rotation"))

    def rotation_channel_indices(self, j: int) -> np.ndarray:
        """(3,) int64: the columns of joint ``j``'s rotation channels, in file order."""
        start = int(self.channel_starts[j])
        return np.array(
            [start + k for k, c in enumerate(self.channels[j]) if c.endswith("rotation")], dtype=np.int64
        )

    def position_channel_indices(self, j: int) -> np.ndarray:
        """(3,) int64 columns of joint ``j``'s X/Y/Z position channels (empty if none), X,Y,Z order."""
        start = int(self.channel_starts[j])
        cols = {c: start + k for k, c in enumerate(self.channels[j])}
        if not all(c in cols for c in POSITION_CHANNELS):
            return np.zeros(0, dtype=np.int64)
        return np.array([cols[c] for c in POSITION_CHANNELS], dtype=np.int64)

    def bone_lengths(self) -> np.ndarray:
        """(J,) float64 centimetres: length of each joint's offset (0 for the root)."""
        return np.linalg.norm(self.offsets, axis=1)

    def subset_channels(self, joint_names: list[str] | tuple[str, ...]) -> np.ndarray:
        """Column indices (rotation channels only, 3 per joint) for the named joints, in that order."""
        return np.concatenate([self.rotation_channel_indices(self.index(n)) for n in joint_names])

    def same_topology(self, other: "Skeleton") -> bool:
        """True when names, parents and channel layout are equal (offsets may differ)."""
        return (
            self.names == other.names
            and np.array_equal(self.parents, other.parents)
            and self.channels == other.channels
        )


def tree_text(skeleton: Skeleton) -> str:
    """The joint tree one *branch* per line: a chain of single-child joints joined by ``>``.

    A branch starts at the root or at a child of a joint with several children, and ends at a
    joint with zero or several children; it is indented by two spaces per branch level. Each
    name carries its joint index and channel count, ``*`` marks a joint that owns an End Site.
    BEAT's 75 joints fit in 21 lines this way (a plain one-joint-per-line tree takes 75).

    Examples
    --------
    >>> s = Skeleton(("Hips", "Spine", "Head", "LeftLeg", "LeftFoot"), [-1, 0, 1, 0, 3],
    ...              np.zeros((5, 3)), [("Xrotation",) * 6] + [("Xrotation",) * 3] * 4, {2: np.zeros(3)})
    >>> print(tree_text(s))
    0 Hips (6)
      1 Spine (3) > 2 Head (3) *
      3 LeftLeg (3) > 4 LeftFoot (3)
    """
    children: list[list[int]] = [[] for _ in range(skeleton.n_joints)]
    for j in range(1, skeleton.n_joints):
        children[int(skeleton.parents[j])].append(j)

    def label(j: int) -> str:
        end = " *" if j in skeleton.end_sites else ""
        return f"{j} {skeleton.names[j]} ({len(skeleton.channels[j])}){end}"

    lines: list[str] = []
    stack = [(0, 0)] if skeleton.n_joints else []
    while stack:
        j, level = stack.pop()
        chain = [j]
        while len(children[chain[-1]]) == 1:
            chain.append(children[chain[-1]][0])
        lines.append("  " * level + " > ".join(label(k) for k in chain))
        stack.extend((c, level + 1) for c in reversed(children[chain[-1]]))
    return "\n".join(lines)
