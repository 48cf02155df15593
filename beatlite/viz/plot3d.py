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
from beatlite.viz._inputs import (
    GROUPS,
    Bones,
    bone_groups,
    check_fps,
    check_positions,
    checked_sequences,
    to_plot_coords,
)
from beatlite.viz.style import GROUP_COLOURS, figure_style, legend_outside, system_colours

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
        From :func:`beatlite.viz._inputs.bone_groups`.
    colours : mapping group -> colour, optional
        Defaults to :data:`beatlite.viz.style.GROUP_COLOURS`.
    linewidth : float
        Bone width in points.
    joint_size : float
        Joint marker size in points (0 hides joints).
    alpha : float
        Opacity of bones and joints.

    Examples
    --------
    An animation moves the same six lines (bones and joints of body, hands, head) to each frame; a joint at
    ``(x, y, z)`` is drawn at plot ``(x, -z, y)``:

    >>> import matplotlib.pyplot as plt
    >>> parents = [-1, 0, 1, 1]  # hips, chest, left hand, right hand
    >>> pose = np.array([[0.0, 100, 0], [0, 150, 0], [-40, 140, 10], [40, 140, 10]])  # cm, Y up, facing +Z
    >>> from beatlite.viz._inputs import bone_groups
    >>> fig = plt.figure()
    >>> ax = fig.add_subplot(projection="3d")
    >>> artist = SkeletonArtist(ax, bone_groups(parents))
    >>> artist.update(pose)
    >>> joints = artist.artists[3]  # the body's joints
    >>> len(artist.artists), [np.round(c, 1).tolist()[3] for c in joints.get_data_3d()]  # the right hand
    (6, [40.0, -10.0, 140.0])
    >>> plt.close(fig)
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


def half_extents(positions: np.ndarray | Sequence[np.ndarray], margin: float = 5.0) -> np.ndarray:
    """Half-widths in plot axes that hold every frame: one scale for panels drawn side by side.

    Parameters
    ----------
    positions : (T, J, 3) float or a sequence of such arrays, centimetres, Y up
        Every frame of every panel that must share the scale.
    margin : float
        Extra space around the bounding boxes, centimetres.

    Returns
    -------
    (3,) float64, centimetres
        Half-widths along plot x, y (both the larger ground-plane half-width) and
        z (height). Pass them to :func:`setup_axes` as ``half=`` for every panel: a
        100 cm arm is then equally long in every panel.

    Examples
    --------
    The toy pose spans 80 cm in x, 10 cm in z and 50 cm in height: half-widths 40, 5 and 25 plus the 5 cm
    margin, the ground plane's two made equal (45):

    >>> pose = np.array([[0.0, 100, 0], [0, 150, 0], [-40, 140, 10], [40, 140, 10]])
    >>> half_extents(pose[None]).tolist()
    [45.0, 45.0, 30.0]
    """
    arrays = [positions] if isinstance(positions, np.ndarray) else list(positions)
    half = np.zeros(3)
    for a in arrays:
        pts = to_plot_coords(np.asarray(a, dtype=np.float64).reshape(-1, 3))
        half = np.maximum(half, (pts.max(axis=0) - pts.min(axis=0)) / 2 + margin)
    half = np.maximum(half, 1.0)
    half[:2] = half[:2].max()  # equal scale on the ground plane so turning the camera keeps proportions
    return half


def _draw_floor(ax: Any, centre: np.ndarray, half: np.ndarray, z0: float, n: int = 6) -> None:
    """A grey n x n grid on the plane plot-z = ``z0`` (the floor), as one line."""
    xs = np.linspace(centre[0] - half[0], centre[0] + half[0], n)
    ys = np.linspace(centre[1] - half[1], centre[1] + half[1], n)
    segs = []
    for x in xs:
        segs += [[x, ys[0], z0], [x, ys[-1], z0], [np.nan] * 3]
    for y in ys:
        segs += [[xs[0], y, z0], [xs[-1], y, z0], [np.nan] * 3]
    grid = np.array(segs)
    ax.plot(grid[:, 0], grid[:, 1], grid[:, 2], "-", color="0.75", lw=0.6, zorder=0)


def setup_axes(
    ax: Any,
    positions: np.ndarray | Sequence[np.ndarray],
    *,
    view: str | tuple[float, float] = "default",
    floor: bool = True,
    axis_off: bool = True,
    margin: float = 5.0,
    half: np.ndarray | None = None,
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
        Pass ``bones.has_feet``: a floor under an upper body (no legs) makes its
        lowest hand look like it rests on the ground.
    axis_off : bool
        Hide panes, ticks and labels.
    margin : float
        Extra space around the bounding box, centimetres.
    half : (3,) float, optional
        Half-widths of the box in plot axes, centimetres (:func:`half_extents` of
        every panel, for one scale across panels; the box is then aligned on the
        highest joint, so heads line up); default: this axes' own data, centred.

    Examples
    --------
    The limits are the box of :func:`half_extents` around the middle of the data (plot axes x, -z, y): heights
    100 to 150 cm give z limits ``125 ± 30``; ``"side"`` looks along the character's x axis:

    >>> import matplotlib.pyplot as plt
    >>> parents = [-1, 0, 1, 1]  # hips, chest, left hand, right hand
    >>> pose = np.array([[0.0, 100, 0], [0, 150, 0], [-40, 140, 10], [40, 140, 10]])  # cm, Y up, facing +Z
    >>> fig = plt.figure()
    >>> ax = fig.add_subplot(projection="3d")
    >>> setup_axes(ax, pose[None], view="side")
    >>> [float(v) for v in ax.get_zlim()], [float(v) for v in ax.get_xlim()], (ax.elev, ax.azim)
    ([95.0, 155.0], [-45.0, 45.0], (0.0, 0.0))
    >>> plt.close(fig)
    """
    arrays = [positions] if isinstance(positions, np.ndarray) else list(positions)
    pts = to_plot_coords(np.concatenate([np.asarray(a, dtype=np.float64).reshape(-1, 3) for a in arrays]))
    centre = (pts.min(axis=0) + pts.max(axis=0)) / 2
    if half is None:
        half = half_extents(arrays, margin)
    else:  # a shared box: align the tops (heads) of the panels, so an upper body sits where a full body's does
        half = np.asarray(half, dtype=np.float64)
        centre[2] = pts[:, 2].max() + margin - half[2]
    ax.set_xlim(centre[0] - half[0], centre[0] + half[0])
    ax.set_ylim(centre[1] - half[1], centre[1] + half[1])
    ax.set_zlim(centre[2] - half[2], centre[2] + half[2])
    ax.set_box_aspect(tuple(half), zoom=1.15)
    elev, azim = _view_angles(view)
    ax.view_init(elev=elev, azim=azim)
    if isinstance(view, str) and view in VIEWS:
        ax.set_proj_type("ortho")
    if floor:
        _draw_floor(ax, centre, half, pts[:, 2].min())
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
    bones = bone_groups(skeleton, names)
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
    floor: bool | None = None,
    title: str | None = None,
    names: Sequence[str] | None = None,
    figsize: tuple[float, float] = (6.4, 6.4),
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
    floor : bool, optional
        Draw the floor grid; default only under a skeleton with feet (no floor under
        an upper body such as HA2G's TED-43).
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

    Examples
    --------
    A clip of 10 frames in which the right hand rises 2 cm per frame; the last frame (``-1``) has it at
    140 + 18 = 158 cm, drawn at plot height 158:

    >>> import matplotlib.pyplot as plt
    >>> parents = [-1, 0, 1, 1]  # hips, chest, left hand, right hand
    >>> pose = np.array([[0.0, 100, 0], [0, 150, 0], [-40, 140, 10], [40, 140, 10]])  # cm, Y up, facing +Z
    >>> clip = np.repeat(pose[None], 10, axis=0)
    >>> clip[:, 3, 1] += 2.0 * np.arange(10)
    >>> fig = plot_frame(clip, parents, frame=-1, view="front")
    >>> x, minus_z, height = fig.axes[0].lines[1].get_data_3d()  # the body's joints
    >>> np.round(height, 1).tolist()
    [100.0, 150.0, 140.0, 158.0]
    >>> plt.close(fig)
    """
    pos, bones = _prepare(positions, skeleton, names)
    k = _check_frame(frame, len(pos))
    with figure_style():
        if ax is None:
            fig = _new_figure(figsize, dpi)
            ax = fig.add_subplot(projection="3d")
        setup_axes(ax, pos[k : k + 1], view=view, floor=bones.has_feet if floor is None else floor)
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

    Examples
    --------
    Four frames evenly spaced over 10 are frames 0, 3, 6 and 9: at 15 fps, 0.2 s apart:

    >>> import matplotlib.pyplot as plt
    >>> parents = [-1, 0, 1, 1]  # hips, chest, left hand, right hand
    >>> pose = np.array([[0.0, 100, 0], [0, 150, 0], [-40, 140, 10], [40, 140, 10]])  # cm, Y up, facing +Z
    >>> fig = plot_filmstrip(np.repeat(pose[None], 10, axis=0), parents, n=4, fps=15)
    >>> [ax.get_title() for ax in fig.axes]
    ['t = 0.00 s', 't = 0.20 s', 't = 0.40 s', 't = 0.60 s']
    >>> plt.close(fig)
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
            setup_axes(ax, shown, view=view, floor=bones.has_feet)
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

    Examples
    --------
    One panel per view, its camera the angles ``(elev, azim)`` of :data:`VIEWS`:

    >>> import matplotlib.pyplot as plt
    >>> parents = [-1, 0, 1, 1]  # hips, chest, left hand, right hand
    >>> pose = np.array([[0.0, 100, 0], [0, 150, 0], [-40, 140, 10], [40, 140, 10]])  # cm, Y up, facing +Z
    >>> fig = plot_views(pose, parents)
    >>> [(ax.get_title(), (ax.elev, ax.azim) == VIEWS[ax.get_title()]) for ax in fig.axes]
    [('front', True), ('side', True), ('top', True)]
    >>> plt.close(fig)
    """
    pos, bones = _prepare(positions, skeleton, names)
    k = _check_frame(frame, len(pos))
    with figure_style():
        fig = _new_figure((panel_size * len(views), panel_size), dpi)
        for i, v in enumerate(views):
            ax = fig.add_subplot(1, len(views), i + 1, projection="3d")
            setup_axes(ax, pos[k : k + 1], view=v, floor=v != "top" and bones.has_feet)
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


def _joint_indices(joints: Sequence[str | int], names: Sequence[str] | None, n_joints: int) -> list[int]:
    """Joint indices of names (needs ``names``) or of in-range integers."""
    idx = []
    for j in joints:
        if isinstance(j, str):
            if names is None or j not in names:
                raise KeyError(f"joints: no joint named {j!r} (pass a Skeleton or names=)")
            idx.append(list(names).index(j))
        elif 0 <= int(j) < n_joints:
            idx.append(int(j))
        else:
            raise ValueError(f"joints: index {j} is out of range for {n_joints} joints")
    return idx


def plot_trajectories(
    positions: Any,
    skeleton: SkeletonLike,
    joints: Sequence[str | int] | None = None,
    *,
    frame: int | None = None,
    view: str | tuple[float, float] = "default",
    names: Sequence[str] | None = None,
    figsize: tuple[float, float] = (6.4, 6.4),
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

    Examples
    --------
    With joint names, the default paths are the hands' (and the head's, when there is one); the right hand's
    path rises 2 cm per frame:

    >>> import matplotlib.pyplot as plt
    >>> parents = [-1, 0, 1, 1]  # hips, chest, left hand, right hand
    >>> pose = np.array([[0.0, 100, 0], [0, 150, 0], [-40, 140, 10], [40, 140, 10]])  # cm, Y up, facing +Z
    >>> clip = np.repeat(pose[None], 5, axis=0)
    >>> clip[:, 3, 1] += 2.0 * np.arange(5)
    >>> fig = plot_trajectories(clip, parents, names=["Hips", "Chest", "LeftHand", "RightHand"])
    >>> ax = fig.axes[0]
    >>> labels = ax.get_legend_handles_labels()[1]
    >>> path = ax.lines[-len(labels) + labels.index("RightHand")]
    >>> labels, path.get_data_3d()[2].tolist()
    (['RightHand', 'LeftHand'], [140.0, 142.0, 144.0, 146.0, 148.0])
    >>> plt.close(fig)
    """
    pos, bones = _prepare(positions, skeleton, names)
    if isinstance(skeleton, Skeleton):
        names = skeleton.names
    idx = _default_joints(bones, names) if joints is None else _joint_indices(joints, names, bones.n_joints)
    k = len(pos) // 2 if frame is None else _check_frame(frame, len(pos))
    with figure_style():
        fig = _new_figure(figsize, dpi)
        ax = fig.add_subplot(projection="3d")
        setup_axes(ax, pos, view=view, floor=bones.has_feet)
        SkeletonArtist(ax, bones, alpha=0.35).update(pos[k])
        for j in idx:
            path = to_plot_coords(pos[:, j])
            label = names[j] if names is not None else f"joint {j}"
            ax.plot(path[:, 0], path[:, 1], path[:, 2], lw=1.2, label=label)
        legend_outside(ax, "right")
    return fig


def _keyframe_row(
    axes: list[Any], pos: np.ndarray, bones: Bones, frames: list[int], view: Any, half: Any
) -> None:
    """One system's key frames, one per axes, in the shared box ``half``."""
    for ax, k in zip(axes, frames):
        setup_axes(ax, pos[frames], view=view, floor=bones.has_feet, half=half)
        SkeletonArtist(ax, bones, linewidth=1.5, joint_size=1.5).update(pos[k])


def plot_keyframes(
    systems: Mapping[str, Any],
    skeletons: SkeletonLike | Sequence[SkeletonLike],
    frames: Sequence[int],
    fps: float,
    *,
    view: str | tuple[float, float] = "front",
    panel_size: float = 1.6,
    systems_in: str = "rows",
) -> Any:
    """Key frames of several systems, one row each, on one scale (HA2G Fig. 2, BEAT Fig. 3b).

    Every panel has the same box size in centimetres (:func:`half_extents` of
    all rows), so a shorter skeleton (HA2G's TED-43 upper body) looks shorter
    rather than zoomed in; joint groups have the same colours in every row,
    the row label the system's colour (:func:`beatlite.viz.style.system_colours`: by name, the same in every figure),
    and a floor is drawn only under skeletons that have feet.

    Parameters
    ----------
    systems : mapping label -> (T_i, J_i, 3) float, centimetres, Y up
        Joint positions of each system at ``fps``, e.g. ``{"ground truth": gt, "CaMN": a, "HA2G": b}``.
    skeletons : Skeleton or (J,) parents array, or a sequence of them (one per system)
        Hierarchy of each row (HA2G's TED-43 parents array is recognised by name).
    frames : sequence of int
        Frame indices (columns), the same for every row.
    fps : float
        Frame rate; columns are titled with the time in seconds.
    view : str or (elev, azim)
        Camera of every panel (``"front"``: the character faces us).
    panel_size : float
        Width and height of a panel, inches (6 columns x 1.6 in = 9.6 in: 1440 px saved at 150 dpi).
    systems_in : {"rows", "columns"}
        ``"columns"``: one column per system (its label above it, wrapped to the column's width) and one row
        per key frame (its time on the left), for many systems: eleven rows of six frames are 1.8 times as
        tall as wide, shown on a 16:10 slide at a third of their size, eleven columns of six frames fit it.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> fig = plot_keyframes({"ground truth": gt, "CaMN": camn}, skeleton, [0, 15, 30], fps=15)  # doctest: +SKIP
    """
    if systems_in not in ("rows", "columns"):
        raise ValueError(f"systems_in must be 'rows' or 'columns', got {systems_in!r}")
    labels = list(systems)
    seqs, bones = checked_sequences(list(systems.values()), skeletons, "systems")
    frames = [_check_frame(f, min(len(p) for p in seqs), "frames") for f in frames]
    if not frames:
        raise ValueError("frames must list at least one frame, got an empty sequence")
    fps = check_fps(fps)
    half = half_extents([p[frames] for p in seqs])
    if systems_in == "columns":
        return _keyframe_columns(labels, seqs, bones, frames, fps, view, panel_size, half)
    with figure_style():
        fig = _new_figure((panel_size * len(frames) + 0.4, panel_size * len(seqs) + 0.3), None)
        fig.subplots_adjust(
            left=0.4 / fig.get_figwidth(), right=1, bottom=0, top=1 - 0.3 / fig.get_figheight()
        )
        colours = system_colours(labels)
        for row, (label, pos, b) in enumerate(zip(labels, seqs, bones)):
            axes = [fig.add_subplot(len(seqs), len(frames), row * len(frames) + col + 1, projection="3d")
                    for col in range(len(frames))]  # fmt: skip
            _keyframe_row(axes, pos, b, frames, view, half)
            axes[0].text2D(-0.06, 0.5, label, transform=axes[0].transAxes, rotation=90, va="center", ha="right",
                           color=colours[row], fontsize=11, fontweight="bold")  # fmt: skip
        for ax, k in zip(fig.axes, frames):
            ax.set_title(f"t = {k / fps:.1f} s", fontsize=10)
        fig.subplots_adjust(wspace=0, hspace=0)
    return fig


def _keyframe_columns(
    labels: list[str],
    seqs: list[np.ndarray],
    bones: list[Bones],
    frames: list[int],
    fps: float,
    view: Any,
    panel_size: float,
    half: Any,
) -> Any:
    """:func:`plot_keyframes` with one column per system and one row per key frame."""
    import textwrap

    chars = max(6, int(panel_size * 72 / (11 * 0.62)))  # 11-pt bold characters across a column
    titles = [
        "\n".join(textwrap.wrap(label.replace("-", "- "), chars)).replace("- ", "-") for label in labels
    ]
    top = 0.2 + 0.2 * max(t.count("\n") + 1 for t in titles)
    with figure_style():
        fig = _new_figure((panel_size * len(seqs) + 0.4, panel_size * len(frames) + top), None)
        fig.subplots_adjust(
            left=0.4 / fig.get_figwidth(), right=1, bottom=0, top=1 - top / fig.get_figheight()
        )
        colours = system_colours(labels)
        for col, (title, colour, pos, b) in enumerate(zip(titles, colours, seqs, bones)):
            axes = [fig.add_subplot(len(frames), len(seqs), row * len(seqs) + col + 1, projection="3d")
                    for row in range(len(frames))]  # fmt: skip
            _keyframe_row(axes, pos, b, frames, view, half)
            axes[0].set_title(title, color=colour, fontsize=11, fontweight="bold")
            if col == 0:
                for ax, k in zip(axes, frames):
                    ax.text2D(-0.06, 0.5, f"t = {k / fps:.1f} s", transform=ax.transAxes, rotation=90,
                              va="center", ha="right", fontsize=10)  # fmt: skip
        fig.subplots_adjust(wspace=0, hspace=0)
    return fig


def _level_panel(
    ax: Any,
    pts: np.ndarray,
    bones: np.ndarray,
    shown: Sequence[int],
    new: set[int],
    box: np.ndarray,
    ghost: Sequence[int] = (),
) -> None:
    """2D bones (``pts`` already projected) inside ``box`` ((2, 2): min, max): new ones thick red, earlier grey;
    ``ghost`` bones (not in this level yet) dotted and light, so a panel without bones still shows where they go."""
    for b in ghost:
        xy = pts[bones[b]]
        ax.plot(xy[:, 0], xy[:, 1], ":", lw=0.9, color="0.75")
    for b in shown:
        xy = pts[bones[b]]
        ax.plot(xy[:, 0], xy[:, 1], "-o", ms=2.5, lw=2.2 if b in new else 1.0,
                color=GROUP_COLOURS["hands"] if b in new else "0.6")  # fmt: skip
    if len(ghost) and not len(shown):
        ax.text(0.5, 0.02, "none of these bones yet", transform=ax.transAxes, ha="center", va="bottom",
                color="0.4", fontsize=9)  # fmt: skip
    ax.set_xlim(box[0, 0], box[1, 0])
    ax.set_ylim(box[0, 1], box[1, 1])
    ax.set_aspect("equal")
    ax.set_axis_off()


def _box(pts: np.ndarray, margin: float = 0.06) -> np.ndarray:
    """(2, 2) min/max corners of 2D points, with a margin (fraction of the larger side)."""
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    pad = margin * float(max(hi - lo)) + 1e-6
    return np.stack([lo - pad, hi + pad])


def _subtree(bones: np.ndarray, root: int) -> set[int]:
    """Indices of the bones below joint ``root`` (its descendants' bones)."""
    below, found = {root}, set()
    for _ in range(len(bones)):
        for b, (p, c) in enumerate(bones):
            if p in below and b not in found:
                found.add(b)
                below.add(int(c))
    return found


def _level_views(pos: np.ndarray, bones: np.ndarray, root: int | None) -> list[tuple[np.ndarray, set[int]]]:
    """(2D points, bones shown) of each panel row: the body from the front, then the subtree of ``root`` from above."""
    views = [(pos[:, [0, 1]], set(range(len(bones))))]  # front: x right, y up
    if root is not None:  # above, around the root joint: x right, +z (forward) down
        views.append(((pos - pos[root])[:, [0, 2]] * [1, -1], _subtree(bones, root)))
    return views


def _check_bones(bones: Any, n_joints: int) -> np.ndarray:
    bones = np.asarray(bones, dtype=np.int64).reshape(-1, 2)
    if bones.size == 0 or bones.min() < 0 or bones.max() >= n_joints:
        raise ValueError(f"bones must be (B, 2) joint indices below {n_joints}, got shape {bones.shape}")
    return bones


def _levels_title(root: int | None, names: Sequence[str] | None) -> str:
    title = "bones each level adds (red) to the earlier ones (grey)"
    if root is None:
        return title
    return f"{title}; below the levels that reach it: the bones below {names[root] if names else root}, from above"


def plot_bone_levels(
    positions: Any,
    bones: Any,
    levels: Sequence[Sequence[int]],
    *,
    names: Sequence[str] | None = None,
    zoom: str | int | None = None,
    ncols: int = 3,
) -> Any:
    """What each level of a bone hierarchy adds (HA2G's 6 levels, Sec. 3.2): new bones red, earlier ones grey.

    One panel per level: the body from the front; with ``zoom``, a second panel
    shows the bones below that joint (e.g. the right hand) from above, enlarged,
    for the rows of levels that reach it (HA2G: levels 4-6; no row of three
    empty panels for levels 1-3). A zoom panel of a level without those bones, in
    a row drawn for the others, shows them dotted and light ("none of these bones
    yet"). Panels are tight around the bones (equal aspect, no empty axes).

    Parameters
    ----------
    positions : (J, 3) float, centimetres, Y up
        One pose (e.g. the rest pose on TED-43).
    bones : (B, 2) int
        (parent, child) joint index of each bone.
    levels : sequence of sequence of int
        Bone indices of each level (cumulative, like ``beatlite.skeleton.ted.HA2G_LEVELS``).
    names : sequence of str, optional
        Joint names (needed when ``zoom`` is a name).
    zoom : str or int, optional
        Joint whose subtree gets an enlarged top view (e.g. ``"right_wrist"``).
    ncols : int
        Levels per row of the figure.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    Two cumulative levels of the toy skeleton's three bones (the spine, then both arms); a level's title counts
    its bones and their 3 coordinates each:

    >>> import matplotlib.pyplot as plt
    >>> pose = np.array([[0.0, 100, 0], [0, 150, 0], [-40, 140, 10], [40, 140, 10]])
    >>> fig = plot_bone_levels(pose, [[0, 1], [1, 2], [1, 3]], [[0], [0, 1, 2]])
    >>> [ax.get_title() for ax in fig.axes]
    ['level 1: 1 bone, 3 dims', 'level 2: 3 bones, 9 dims']
    >>> plt.close(fig)
    """
    pos = check_positions(positions)[0]
    bones = _check_bones(bones, len(pos))
    root = None if zoom is None else _joint_indices([zoom], names, len(pos))[0]
    views = _level_views(pos, bones, root)
    boxes = [_box(pts[np.unique(bones[sorted(keep)])]) for pts, keep in views]
    col_w = 9.6 / ncols
    heights = [min(col_w * float(np.ptp(b[:, 1]) / np.ptp(b[:, 0])), 1.5) for b in boxes]
    blocks = [list(range(k, min(k + ncols, len(levels)))) for k in range(0, len(levels), ncols)]
    # a row of views is drawn for a block of levels only when one of them has bones in that view (HA2G: the hand
    # gets its first bones at level 4, so levels 1-3 have no hand row instead of three empty panels)
    rows = [(block, v) for block in blocks for v, (_, keep) in enumerate(views)
            if any(set(levels[k]) & keep for k in block)]  # fmt: skip
    with figure_style():
        fig = _new_figure((9.6, sum(heights[v] + 0.35 for _, v in rows) + 0.5), None)
        grid = fig.add_gridspec(
            len(rows), ncols, height_ratios=[heights[v] for _, v in rows], hspace=0.2, wspace=0.05
        )
        for r, (block, v) in enumerate(rows):
            pts, keep = views[v]
            for col, k in enumerate(block):
                previous = set(levels[k - 1]) if k else set()
                ax = fig.add_subplot(grid[r, col])
                shown = sorted(set(levels[k]) & keep)
                _level_panel(ax, pts, bones, shown, (set(levels[k]) - previous) & keep, boxes[v],
                             ghost=sorted(keep) if not shown else ())  # fmt: skip
                if v == 0:
                    ax.set_title(
                        f"level {k + 1}: {len(levels[k])} bone{'s' * (len(levels[k]) != 1)}, {3 * len(levels[k])} dims",
                        fontsize=10,
                    )
                else:
                    below = names[root] if names else root
                    ax.set_title(f"level {k + 1}: below {below}, from above", fontsize=9, color="0.3")
        fig.suptitle(_levels_title(root, names), fontsize=11)
    return fig
