"""Static matplotlib plots of skeletons: one frame, a filmstrip, front/side/top views, joint trajectories.

Positions are ``(T, J, 3)`` float centimetres with Y up and the character facing
+Z (beatlite's convention). matplotlib's 3D axes are Z-up, so points are drawn at
``(x, -z, y)`` (a rotation, not a mirror): the *front* view looks at the face with
the character's right hand on the viewer's left.

Every function takes the skeleton as a :class:`beatlite.skeleton.core.Skeleton`
(joints coloured body / hands / head by name) or as a ``(J,)`` parents array.

Taught in notebooks/01_beat_formats.ipynb, section 6 (looking at the skeleton in 3D) and notebooks/08_visualisation_3d.ipynb, section 2 (key frames).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from beatlite.skeleton.core import Skeleton
from beatlite.viz._inputs import GROUPS, Bones, check_fps, check_positions, skeleton_bones, to_plot_coords
from beatlite.viz.style import GROUP_COLOURS, figure_style

#: Camera angles ``(elev, azim)`` in degrees of the named views (plot axes, see the module docstring).
VIEWS: Mapping[str, tuple[float, float]] = {"front": (0.0, -90.0), "side": (0.0, 0.0), "top": (90.0, -90.0)}
#: A slightly raised three-quarter view, the default of single plots.
DEFAULT_VIEW = (12.0, -60.0)

SkeletonLike = Skeleton | Sequence[int] | np.ndarray


def _view_angles(view: str | tuple[float, float]) -> tuple[float, float]:
    if isinstance(view, str):
        if view not in VIEWS and view != "default":
            raise ValueError(
                f"view must be one of {sorted(VIEWS)} or 'default' or (elev, azim), got {view!r}"
            )
        return VIEWS.get(view, DEFAULT_VIEW)
    try:
        elev, azim = (float(v) for v in view)
    except (TypeError, ValueError):
        raise TypeError(f"view must be a name or an (elev, azim) pair in degrees, got {view!r}") from None
    return elev, azim


class SkeletonArtist:
    """The lines of one skeleton in a matplotlib 3D axes, updated in place frame by frame.

    One ``Line3D`` per joint group for the bones (bones separated by NaN gaps)
    and one per group for the joints, so an update is 6 ``set_data_3d`` calls
    whatever the number of joints, and no axes are redrawn.

    Parameters
    ----------
    ax : mpl_toolkits.mplot3d.Axes3D
        Target axes.
    bones : Bones
        From :func:`beatlite.viz._inputs.skeleton_bones`.
    colours : mapping group -> colour, optional
        Defaults to :data:`beatlite.viz.style.GROUP_COLOURS`.
    linewidth : float
        Bone width in points.
    joint_size : float
        Joint marker size in points (0 hides joints).
    alpha : float
        Opacity of bones and joints.
    """

    def __init__(
        self,
        ax: Any,
        bones: Bones,
        *,
        colours: Mapping[str, str] | None = None,
        linewidth: float = 2.0,
        joint_size: float = 2.5,
        alpha: float = 1.0,
    ) -> None:
        colours = dict(GROUP_COLOURS if colours is None else colours)
        self.bones = bones
        self._bone_lines = {}
        self._joint_lines = {}
        for g in GROUPS:
            width = linewidth * (0.6 if g == "hands" else 1.0)
            (self._bone_lines[g],) = ax.plot([], [], [], "-", color=colours[g], lw=width, alpha=alpha)
            (self._joint_lines[g],) = ax.plot(
                [], [], [], "o", color=colours[g], ms=joint_size * (0.6 if g == "hands" else 1.0), alpha=alpha
            )
            self._joint_lines[g].set_visible(joint_size > 0)

    @property
    def artists(self) -> list[Any]:
        """All line artists (bones, then joints)."""
        return [*self._bone_lines.values(), *self._joint_lines.values()]

    def update(self, frame: np.ndarray) -> None:
        """Move the lines to one frame of positions, ``(J, 3)`` float centimetres, Y up."""
        pts = to_plot_coords(np.asarray(frame, dtype=np.float64))
        for g in GROUPS:
            pairs = self.bones.pairs[g]
            seg = np.full((len(pairs), 3, 3), np.nan)
            seg[:, 0] = pts[pairs[:, 0]]
            seg[:, 1] = pts[pairs[:, 1]]
            seg = seg.reshape(-1, 3)
            self._bone_lines[g].set_data_3d(seg[:, 0], seg[:, 1], seg[:, 2])
            jp = pts[self.bones.joints[g]]
            self._joint_lines[g].set_data_3d(jp[:, 0], jp[:, 1], jp[:, 2])


def setup_axes(
    ax: Any,
    positions: np.ndarray | Sequence[np.ndarray],
    *,
    view: str | tuple[float, float] = "default",
    floor: bool = True,
    axis_off: bool = True,
    margin: float = 5.0,
) -> None:
    """Fix equal-aspect limits that hold every frame, set the camera and draw a floor grid.

    Parameters
    ----------
    ax : Axes3D
        Target axes.
    positions : (T, J, 3) float or a sequence of such arrays, centimetres, Y up
        All frames that will be shown in this axes (limits do not change later).
    view : str or (elev, azim)
        ``"front"``, ``"side"``, ``"top"``, ``"default"`` (three-quarter) or angles in degrees.
    floor : bool
        Draw a grid on the plane ``y = min(y)`` (the lowest joint over all frames).
    axis_off : bool
        Hide panes, ticks and labels.
    margin : float
        Extra space around the bounding box, centimetres.
    """
    arrays = [positions] if isinstance(positions, np.ndarray) else list(positions)
    pts = to_plot_coords(np.concatenate([np.asarray(a, dtype=np.float64).reshape(-1, 3) for a in arrays]))
    lo, hi = pts.min(axis=0) - margin, pts.max(axis=0) + margin
    centre, half = (lo + hi) / 2, np.maximum((hi - lo) / 2, 1.0)
    # equal scale on the ground plane so turning the camera keeps proportions
    half[:2] = half[:2].max()
    ax.set_xlim(centre[0] - half[0], centre[0] + half[0])
    ax.set_ylim(centre[1] - half[1], centre[1] + half[1])
    ax.set_zlim(centre[2] - half[2], centre[2] + half[2])
    ax.set_box_aspect(tuple(half), zoom=1.15)
    elev, azim = _view_angles(view)
    ax.view_init(elev=elev, azim=azim)
    if isinstance(view, str) and view in VIEWS:
        ax.set_proj_type("ortho")
    if floor:
        z0 = lo[2] + margin
        n = 6
        xs = np.linspace(centre[0] - half[0], centre[0] + half[0], n)
        ys = np.linspace(centre[1] - half[1], centre[1] + half[1], n)
        segs = []
        for x in xs:
            segs += [[x, ys[0], z0], [x, ys[-1], z0], [np.nan] * 3]
        for y in ys:
            segs += [[xs[0], y, z0], [xs[-1], y, z0], [np.nan] * 3]
        grid = np.array(segs)
        ax.plot(grid[:, 0], grid[:, 1], grid[:, 2], "-", color="0.75", lw=0.6, zorder=0)
    if axis_off:
        ax.set_axis_off()
    else:
        ax.set_xlabel("x (cm)")
        ax.set_ylabel("-z (cm)")
        ax.set_zlabel("y (cm)")


def _new_figure(figsize: tuple[float, float], dpi: float | None) -> Any:
    import matplotlib.pyplot as plt

    return plt.figure(figsize=figsize, dpi=dpi)


def _prepare(positions: Any, skeleton: SkeletonLike, names: Sequence[str] | None) -> tuple[np.ndarray, Bones]:
    bones = skeleton_bones(skeleton, names)
    return check_positions(positions, bones.n_joints), bones


def _check_frame(frame: int, n_frames: int, name: str = "frame") -> int:
    if isinstance(frame, bool) or not isinstance(frame, int | np.integer):
        raise TypeError(f"{name} must be an integer frame index, got {frame!r}")
    if not -n_frames <= frame < n_frames:
        raise ValueError(f"{name}={frame} is out of range for {n_frames} frames")
    return int(frame) % n_frames


def plot_frame(
    positions: Any,
    skeleton: SkeletonLike,
    frame: int = 0,
    *,
    ax: Any = None,
    view: str | tuple[float, float] = "default",
    floor: bool = True,
    title: str | None = None,
    names: Sequence[str] | None = None,
    figsize: tuple[float, float] = (4.0, 4.0),
    dpi: float | None = None,
) -> Any:
    """Draw one frame of a skeleton in 3D: body, hands and head in different colours, over a floor grid.

    Parameters
    ----------
    positions : (T, J, 3) or (J, 3) float, centimetres, Y up
        Joint positions.
    skeleton : Skeleton or (J,) int parents array
        Hierarchy; a Skeleton's joint names choose the colours.
    frame : int
        Frame to draw (negative counts from the end).
    ax : Axes3D, optional
        Draw into this axes (made with ``projection="3d"``); a new figure otherwise.
    view : str or (elev, azim)
        ``"front"``, ``"side"``, ``"top"``, ``"default"`` or camera angles in degrees.
    floor : bool
        Draw the floor grid.
    title : str, optional
        Axes title.
    names : sequence of str, optional
        Joint names when ``skeleton`` is a parents array (for the colours).
    figsize, dpi
        Size of a new figure (inches, dots per inch).

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn into.
    """
    pos, bones = _prepare(positions, skeleton, names)
    k = _check_frame(frame, len(pos))
    with figure_style():
        if ax is None:
            fig = _new_figure(figsize, dpi)
            ax = fig.add_subplot(projection="3d")
        setup_axes(ax, pos[k : k + 1], view=view, floor=floor)
        SkeletonArtist(ax, bones).update(pos[k])
        if title:
            ax.set_title(title)
    return ax.figure


def plot_filmstrip(
    positions: Any,
    skeleton: SkeletonLike,
    frames: Sequence[int] | None = None,
    *,
    n: int = 6,
    fps: float | None = None,
    view: str | tuple[float, float] = "front",
    names: Sequence[str] | None = None,
    panel_size: float = 2.2,
    dpi: float | None = None,
) -> Any:
    """Several frames side by side with shared limits (a filmstrip).

    Parameters
    ----------
    positions : (T, J, 3) float, centimetres, Y up
        Joint positions.
    skeleton : Skeleton or (J,) int parents array
        Hierarchy.
    frames : sequence of int, optional
        Frames to show; default ``n`` frames evenly spaced from first to last.
    n : int
        Number of frames when ``frames`` is not given.
    fps : float, optional
        Frame rate; when given, panels are titled with the time in seconds.
    view : str or (elev, azim)
        Camera of every panel.
    names : sequence of str, optional
        Joint names when ``skeleton`` is a parents array.
    panel_size : float
        Width and height of each panel, inches.
    dpi : float, optional
        Figure resolution.

    Returns
    -------
    matplotlib.figure.Figure
    """
    pos, bones = _prepare(positions, skeleton, names)
    if frames is None:
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
            raise ValueError(f"n must be a positive integer, got {n!r}")
        frames = np.unique(np.round(np.linspace(0, len(pos) - 1, n)).astype(int)).tolist()
    frames = [_check_frame(f, len(pos), "frames") for f in frames]
    if not frames:
        raise ValueError("frames must list at least one frame, got an empty sequence")
    rate = None if fps is None else check_fps(fps)
    with figure_style():
        fig = _new_figure((panel_size * len(frames), panel_size), dpi)
        shown = pos[frames]
        for i, k in enumerate(frames):
            ax = fig.add_subplot(1, len(frames), i + 1, projection="3d")
            setup_axes(ax, shown, view=view)
            SkeletonArtist(ax, bones, linewidth=1.5, joint_size=1.5).update(pos[k])
            ax.set_title(f"t = {k / rate:.2f} s" if rate else f"frame {k}", fontsize=9)
        fig.subplots_adjust(left=0, right=1, bottom=0, top=0.9, wspace=0)
    return fig


def plot_views(
    positions: Any,
    skeleton: SkeletonLike,
    frame: int = 0,
    *,
    views: Sequence[str] = ("front", "side", "top"),
    names: Sequence[str] | None = None,
    panel_size: float = 3.0,
    dpi: float | None = None,
) -> Any:
    """One frame from several orthographic views (front, side, top by default).

    Parameters
    ----------
    positions : (T, J, 3) or (J, 3) float, centimetres, Y up
        Joint positions.
    skeleton : Skeleton or (J,) int parents array
        Hierarchy.
    frame : int
        Frame to draw.
    views : sequence of str
        Names from :data:`VIEWS` (front looks at the face, side from the character's left, top from above).
    names : sequence of str, optional
        Joint names when ``skeleton`` is a parents array.
    panel_size : float
        Panel width and height, inches.
    dpi : float, optional
        Figure resolution.

    Returns
    -------
    matplotlib.figure.Figure
    """
    pos, bones = _prepare(positions, skeleton, names)
    k = _check_frame(frame, len(pos))
    with figure_style():
        fig = _new_figure((panel_size * len(views), panel_size), dpi)
        for i, v in enumerate(views):
            ax = fig.add_subplot(1, len(views), i + 1, projection="3d")
            setup_axes(ax, pos[k : k + 1], view=v, floor=v != "top")
            SkeletonArtist(ax, bones).update(pos[k])
            ax.set_title(str(v))
        fig.subplots_adjust(left=0, right=1, bottom=0, top=0.9, wspace=0)
    return fig


def _default_joints(bones: Bones, names: Sequence[str] | None) -> list[int]:
    if names is not None:
        wanted = [n for n in ("RightHand", "LeftHand", "Head") if n in names]
        if wanted:
            return [list(names).index(n) for n in wanted]
    parents = np.full(bones.n_joints, -1)
    for g in GROUPS:
        parents[bones.pairs[g][:, 1]] = bones.pairs[g][:, 0]
    leaves = np.setdiff1d(np.arange(bones.n_joints), parents)
    return leaves[:5].tolist()


def plot_trajectories(
    positions: Any,
    skeleton: SkeletonLike,
    joints: Sequence[str | int] | None = None,
    *,
    frame: int | None = None,
    view: str | tuple[float, float] = "default",
    names: Sequence[str] | None = None,
    figsize: tuple[float, float] = (5.0, 5.0),
    dpi: float | None = None,
) -> Any:
    """3D paths of chosen joints over the whole clip, over a faint skeleton at one frame.

    Parameters
    ----------
    positions : (T, J, 3) float, centimetres, Y up
        Joint positions.
    skeleton : Skeleton or (J,) int parents array
        Hierarchy.
    joints : sequence of str or int, optional
        Joint names (needs names) or indices; default the wrists and head
        (``RightHand``, ``LeftHand``, ``Head``) when named, else up to 5 leaf joints.
    frame : int, optional
        Frame of the faint skeleton (default the middle frame).
    view : str or (elev, azim)
        Camera.
    names : sequence of str, optional
        Joint names when ``skeleton`` is a parents array.
    figsize, dpi
        Figure size (inches) and resolution.

    Returns
    -------
    matplotlib.figure.Figure
    """
    pos, bones = _prepare(positions, skeleton, names)
    if isinstance(skeleton, Skeleton):
        names = skeleton.names
    if joints is None:
        idx = _default_joints(bones, names)
    else:
        idx = []
        for j in joints:
            if isinstance(j, str):
                if names is None or j not in names:
                    raise KeyError(f"joints: no joint named {j!r} (pass a Skeleton or names=)")
                idx.append(list(names).index(j))
            else:
                if not 0 <= int(j) < bones.n_joints:
                    raise ValueError(f"joints: index {j} is out of range for {bones.n_joints} joints")
                idx.append(int(j))
    k = len(pos) // 2 if frame is None else _check_frame(frame, len(pos))
    with figure_style():
        fig = _new_figure(figsize, dpi)
        ax = fig.add_subplot(projection="3d")
        setup_axes(ax, pos, view=view)
        SkeletonArtist(ax, bones, alpha=0.35).update(pos[k])
        for j in idx:
            path = to_plot_coords(pos[:, j])
            label = names[j] if names is not None else f"joint {j}"
            ax.plot(path[:, 0], path[:, 1], path[:, 2], lw=1.2, label=label)
        ax.legend(loc="upper left", fontsize=8)
    return fig
