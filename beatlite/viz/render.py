"""pyvista renders of skeletons: bones as tubes, joints as spheres; screenshots, GIF/MP4, notebook view.

Each function first asks :func:`beatlite.viz.probe.use_pyvista` whether VTK can
render off-screen here (a subprocess probe, cached per process). When it
cannot, the function warns once (``UserWarning``, saying why and how to fix
it) and returns the same kind of result drawn with matplotlib, so a notebook
kernel never crashes. Pass ``backend="matplotlib"`` to skip pyvista.

Headless machines: see :mod:`beatlite.viz.probe` (EGL first, then OSMesa,
then X/Xvfb) and ``scripts/system_deps.sh``.

Taught in notebooks/08_visualisation_3d.ipynb, section 4 (pyvista: tubes and spheres, rendered off-screen).
"""

from __future__ import annotations

import importlib.util
import subprocess
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from beatlite.viz._files import atomic_target
from beatlite.viz._inputs import GROUPS, Bones, bone_groups, check_fps, check_positions, frame_indices
from beatlite.viz.animation import ffmpeg_available
from beatlite.viz.plot3d import SkeletonLike
from beatlite.viz.probe import use_pyvista
from beatlite.viz.style import GROUP_COLOURS, SLIDE_WIDTH_PX

#: Unit vectors from the scene centre to the camera, and the camera's up vector, of the named views.
CAMERAS: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    "front": ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
    "side": ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
    "top": ((0.0, 1.0, 0.0), (0.0, 0.0, -1.0)),
    "default": ((0.5, 0.25, 0.83), (0.0, 1.0, 0.0)),
}

#: Colour of the floor plane (grid lines are a darker grey).
FLOOR_COLOUR = "#f0f0f0"

#: Height in pixels of the toolbar that pyvista's trame view draws over the top of the 3D view
#: (:func:`show_skeleton` keeps the skeleton below it).
TRAME_TOOLBAR_PX = 64

#: Narrowest trame view in pixels: its toolbar (14 buttons, about 575 px with its left offset) would
#: otherwise draw buttons over each other in a narrow cell; a narrower cell scrolls sideways instead.
TRAME_MIN_WIDTH_PX = 600


def _check_size(size: Any) -> tuple[int, int]:
    try:
        w, h = (int(v) for v in size)
    except (TypeError, ValueError):
        raise TypeError(f"size must be (width, height) in pixels, got {size!r}") from None
    if w < 16 or h < 16:
        raise ValueError(f"size must be at least (16, 16) pixels, got {size!r}")
    return w, h


class _PyvistaSkeleton:
    """Tubes and spheres of one skeleton in a pyvista Plotter, updated in place."""

    def __init__(self, plotter: Any, bones: Bones, first: np.ndarray, radius: float) -> None:
        import pyvista as pv

        self.bones = bones
        self.radius = radius
        self._sphere = pv.Sphere(radius=radius * 1.6, theta_resolution=10, phi_resolution=10)
        self._meshes: dict[str, tuple[Any, Any]] = {}
        for g in GROUPS:
            tubes, balls = self._build(first, g)
            if tubes is not None:
                plotter.add_mesh(tubes, color=GROUP_COLOURS[g], smooth_shading=True)
            if balls is not None:
                plotter.add_mesh(balls, color=GROUP_COLOURS[g], smooth_shading=True)
            self._meshes[g] = (tubes, balls)

    def _build(self, pts: np.ndarray, g: str) -> tuple[Any, Any]:
        import pyvista as pv

        pairs = self.bones.pairs[g]
        joints = self.bones.joints[g]
        scale = 0.6 if g == "hands" else 1.0
        tubes = balls = None
        if len(pairs):
            cells = np.column_stack([np.full(len(pairs), 2), pairs]).ravel()
            tubes = pv.PolyData(pts.copy(), lines=cells).tube(radius=self.radius * scale, n_sides=10)
        if len(joints):
            geom = self._sphere.scale(scale, inplace=False)
            balls = pv.PolyData(pts[joints].copy()).glyph(geom=geom, scale=False, orient=False)
        return tubes, balls

    def update(self, pts: np.ndarray) -> None:
        for g in GROUPS:
            new = self._build(pts, g)
            for old, fresh in zip(self._meshes[g], new):
                if old is not None:
                    old.copy_from(fresh)


def _check_box(box: Any) -> np.ndarray | None:
    if box is None:
        return None
    try:
        arr = np.asarray(box, dtype=np.float64)
    except (TypeError, ValueError):
        arr = np.zeros(0)
    if arr.shape != (2, 3) or not np.all(np.isfinite(arr)) or np.any(arr[1] < arr[0]):
        raise ValueError(f"box must be [[x0, y0, z0], [x1, y1, z1]] cm with x0 <= x1 etc., got {box!r}")
    return arr


def project(
    points: np.ndarray,
    position: np.ndarray,
    focal: np.ndarray,
    up: Sequence[float],
    size: tuple[int, int],
    view_angle: float = 30.0,
) -> np.ndarray:
    """(N, 3) world points -> (N, 2) pixel (column, row) of a perspective camera, row 0 at the top.

    Parameters
    ----------
    points : (N, 3) float
        World points (centimetres for beatlite's scenes).
    position, focal : (3,) float
        Camera position and the point it looks at (same units).
    up : (3,) float
        The camera's up direction (made orthogonal to the viewing direction).
    size : (width, height)
        Image size in pixels.
    view_angle : float
        Vertical field of view in degrees, as in VTK.

    Returns
    -------
    (N, 2) float64
        Pixel column and row (fractional; row 0 at the top).

    Examples
    --------
    A 100 x 100 image with a 90-degree field of view: at 10 cm in front of the camera the image spans +-10 cm,
    so the focal point lands at the centre (50, 50), 1 cm to the right 5 px right, 5 cm up 25 px up:

    >>> points = np.array([[0.0, 0, 0], [1, 0, 0], [0, 5, 0]])
    >>> pixels = project(points, np.array([0.0, 0, 10]), np.zeros(3), (0, 1, 0), (100, 100), view_angle=90)
    >>> np.round(pixels, 6).tolist()
    [[50.0, 50.0], [55.0, 50.0], [50.0, 25.0]]
    """
    w, h = size
    back = np.asarray(position, dtype=np.float64) - focal
    back /= np.linalg.norm(back)
    up_v = np.asarray(up, dtype=np.float64) - back * (np.asarray(up, dtype=np.float64) @ back)
    up_v /= np.linalg.norm(up_v)
    right = np.cross(up_v, back)
    rel = np.asarray(points, dtype=np.float64).reshape(-1, 3) - position
    depth = -(rel @ back)
    t = np.tan(np.radians(view_angle) / 2)
    ndc_x = (rel @ right) / depth / (t * w / h)
    ndc_y = (rel @ up_v) / depth / t
    return np.column_stack([(ndc_x + 1) * w / 2, (1 - ndc_y) * h / 2])


def frame_camera(
    box: np.ndarray,
    view: str,
    size: tuple[int, int],
    *,
    view_angle: float = 30.0,
    top: int = 0,
    margin: float = 0.04,
) -> tuple[np.ndarray, np.ndarray, tuple[float, float, float]]:
    """Camera position, focal point and up vector that show every point of ``box`` inside the image.

    The camera looks along the named view at the box's centre, moved up so that the centre lands
    in the middle of the image area below a band of ``top`` pixels (a toolbar drawn over the
    view); its distance is the smallest at which the 8 corners of the box project inside that
    area, leaving ``margin`` (a fraction of the image height) on every side. Renders that share
    a box share one camera, hence one scale (cm per pixel).

    Parameters
    ----------
    box : (2, 3) float, centimetres
        Corners ``[lo, hi]`` of what must be seen.
    view : {"default", "front", "side", "top"}
        Direction the camera looks from (:data:`CAMERAS`).
    size : (width, height)
        Image size in pixels.
    view_angle : float
        Vertical field of view, degrees (VTK's default 30).
    top : int
        Pixels at the top of the image kept free (trame's toolbar: :data:`TRAME_TOOLBAR_PX`).
    margin : float
        Free border on every side, as a fraction of the height.

    Returns
    -------
    position, focal_point : (3,) float
        Camera position and the point it looks at, centimetres.
    up : (3,) float tuple
        The view's up vector.

    Examples
    --------
    A 180 cm tall box seen from the front: the camera is on the +z axis level with its centre, and its height
    sets the distance, so its corners reach the 4 % margin of the 720 px height (28.8 px) at top and bottom:

    >>> box = np.array([[-50.0, 0, -10], [50, 180, 10]])
    >>> position, focal, up = frame_camera(box, "front", (960, 720))
    >>> focal.tolist(), position[:2].tolist(), up
    ([0.0, 90.0, 0.0], [0.0, 90.0], (0.0, 1.0, 0.0))
    >>> corners = np.array([[x, y, z] for x in box[:, 0] for y in box[:, 1] for z in box[:, 2]])
    >>> rows = project(corners, position, focal, up, (960, 720))[:, 1]
    >>> round(float(rows.min()), 1), round(float(rows.max()), 1)
    (28.8, 691.2)
    """
    if view not in CAMERAS:
        raise ValueError(f"view must be one of {sorted(CAMERAS)}, got {view!r}")
    w, h = size
    direction, up = CAMERAS[view]
    d = np.asarray(direction, dtype=np.float64) / np.linalg.norm(direction)
    centre = box.mean(axis=0)
    corners = np.array([[box[i, 0], box[j, 1], box[k, 2]] for i in (0, 1) for j in (0, 1) for k in (0, 1)])
    up_v = np.asarray(up, dtype=np.float64) - d * (np.asarray(up, dtype=np.float64) @ d)
    up_v /= np.linalg.norm(up_v)
    t = np.tan(np.radians(view_angle) / 2)
    pad = margin * h
    size_cm = max(float(np.linalg.norm(box[1] - box[0])), 1.0)

    def place(dist: float) -> tuple[np.ndarray, np.ndarray]:
        focal = centre + up_v * (top / h) * t * dist  # look above the centre: it drops to the area's middle
        return focal + d * dist, focal

    def fits(dist: float) -> bool:
        position, focal = place(dist)
        px = project(corners, position, focal, up, size, view_angle)
        return bool(
            np.all(px[:, 0] >= pad) and np.all(px[:, 0] <= w - pad)
            and np.all(px[:, 1] >= top + pad) and np.all(px[:, 1] <= h - pad)
        )  # fmt: skip

    # start just outside the box's bounding sphere (every corner in front), double until it fits
    near = far = 0.51 * size_cm
    while not fits(far):
        near, far = far, far * 2
    for _ in range(40):  # bisection to a fraction of a millimetre
        mid = (near + far) / 2
        near, far = (near, mid) if fits(mid) else (mid, far)
    position, focal = place(far)
    return position, focal, up


def _scene(
    positions: np.ndarray,
    bones: Bones,
    size: tuple[int, int],
    view: str,
    floor: bool | None,
    radius: float | None,
    box: np.ndarray | None = None,
    top: int = 0,
) -> tuple[Any, _PyvistaSkeleton]:
    import pyvista as pv

    if view not in CAMERAS:
        raise ValueError(f"view must be one of {sorted(CAMERAS)}, got {view!r}")
    pts = positions.reshape(-1, 3)
    if box is None:
        box = np.stack([pts.min(axis=0), pts.max(axis=0)])
        draw_floor = bones.has_feet if floor is None else floor
    else:  # a box shared by several renders: one world, so one floor under all of them
        draw_floor = True if floor is None else floor
    lo, hi = box
    extent = float(np.max(hi - lo)) or 1.0
    r = radius if radius is not None else max(extent / 120.0, 0.2)
    plotter = pv.Plotter(off_screen=True, window_size=size)
    plotter.set_background("white")
    shown = box
    if draw_floor:  # a square under the box with a rim of 10 % of its size; the camera shows all of it
        centre = (lo + hi) / 2
        side = float(max(hi[0] - lo[0], hi[2] - lo[2])) + 0.2 * extent
        plane = pv.Plane(
            center=(centre[0], lo[1] - r, centre[2]),
            direction=(0, 1, 0),
            i_size=side,
            j_size=side,
            i_resolution=6,
            j_resolution=6,
        )
        plotter.add_mesh(plane, color=FLOOR_COLOUR, show_edges=True, edge_color="#c8c8c8", lighting=False)
        half = np.array([side / 2, 0.0, side / 2])
        shown = np.stack([np.minimum(lo, centre - half), np.maximum(hi, centre + half)])
        shown[0, 1] = lo[1] - r
    skel = _PyvistaSkeleton(plotter, bones, positions[0], r)
    position, focal, up = frame_camera(shown, view, size, view_angle=plotter.camera.view_angle, top=top)
    plotter.camera.focal_point = tuple(focal)
    plotter.camera.position = tuple(position)
    plotter.camera.up = up
    return plotter, skel


def _mpl_frame_image(
    positions: np.ndarray,
    skeleton: SkeletonLike,
    frame: int,
    size: tuple[int, int],
    view: str,
    floor: bool | None,
    box: np.ndarray | None = None,
) -> np.ndarray:
    import matplotlib.pyplot as plt
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from beatlite.viz.plot3d import SkeletonArtist, setup_axes
    from beatlite.viz.style import STYLE

    w, h = size
    with plt.rc_context(dict(STYLE)):
        fig = Figure(figsize=(w / 100, h / 100), dpi=100)
        canvas = FigureCanvasAgg(fig)
        ax = fig.add_axes((0, 0, 1, 1), projection="3d")
        bones = bone_groups(skeleton)
        if box is None:
            setup_axes(ax, positions, view=view, floor=bones.has_feet if floor is None else floor)
        else:  # the box's corners join the limits, and the floor is under them
            setup_axes(ax, [positions, box[None]], view=view, floor=True if floor is None else floor)
        SkeletonArtist(ax, bones).update(positions[frame])
        canvas.draw()
        img = np.asarray(canvas.buffer_rgba())[..., :3].copy()
    return img


def render_frame(
    positions: Any,
    skeleton: SkeletonLike,
    frame: int = 0,
    *,
    size: Sequence[int] = (SLIDE_WIDTH_PX, 720),
    view: str = "default",
    floor: bool | None = None,
    radius: float | None = None,
    box: Any = None,
    path: str | Path | None = None,
    backend: str = "auto",
) -> np.ndarray:
    """Render one frame off-screen (pyvista tubes and spheres; matplotlib when pyvista cannot render).

    Parameters
    ----------
    positions : (T, J, 3) or (J, 3) float, centimetres, Y up
        Joint positions.
    skeleton : Skeleton or (J,) int parents array
        Hierarchy (a Skeleton's names colour body, hands and head).
    frame : int
        Frame to render.
    size : (width, height)
        Image size in pixels (default 960 x 720, slide size).
    view : {"default", "front", "side", "top"}
        Camera.
    floor : bool, optional
        Draw a floor plane under the lowest joint (under ``box`` when given); default: always with
        ``box``, else only for a skeleton with feet (under an upper body alone the floor would meet
        the lowest hand, and the side view would look like a figure crawling on the ground).
    radius : float, optional
        Bone tube radius, centimetres (default: 1/120 of the scene size).
    box : (2, 3) float, optional
        Corners ``[[x0, y0, z0], [x1, y1, z1]]`` (cm) of the region the camera frames, the floor
        lies under (at ``y0``) and the bone radius scales with; default the skeleton's own bounding
        box. Renders of several systems that share one box share one camera and one scale: an
        upper body (HA2G's TED-43) is then as large as the upper half of a full body, instead of
        filling the picture on its own.
    path : str or Path, optional
        Also write the image there (PNG), atomically.
    backend : {"auto", "pyvista", "matplotlib"}
        Renderer; ``"auto"``/``"pyvista"`` fall back to matplotlib with one warning.

    Returns
    -------
    (height, width, 3) uint8 ndarray
        The RGB image.

    Examples
    --------
    The image has the size asked, as (rows, columns, RGB); here drawn by matplotlib, as where pyvista cannot
    render:

    >>> parents = [-1, 0, 1, 1]  # hips, chest, left hand, right hand
    >>> pose = np.array([[0.0, 100, 0], [0, 150, 0], [-40, 140, 10], [40, 140, 10]])  # cm, Y up
    >>> image = render_frame(pose, parents, size=(160, 120), backend="matplotlib")
    >>> image.shape, image.dtype
    ((120, 160, 3), dtype('uint8'))
    """
    bones = bone_groups(skeleton)
    pos = check_positions(positions, bones.n_joints)
    if (
        isinstance(frame, bool)
        or not isinstance(frame, int | np.integer)
        or not -len(pos) <= frame < len(pos)
    ):
        raise ValueError(f"frame={frame!r} is not a frame index for {len(pos)} frames")
    frame = int(frame) % len(pos)
    w, h = _check_size(size)
    box = _check_box(box)
    if use_pyvista(backend):
        plotter, skel = _scene(pos[frame : frame + 1], bones, (w, h), view, floor, radius, box)
        try:
            img = np.asarray(plotter.screenshot(return_img=True))[..., :3].copy()
        finally:
            plotter.close()
    else:
        img = _mpl_frame_image(pos, skeleton, frame, (w, h), view, floor, box)
    if path is not None:
        from matplotlib.image import imsave

        with atomic_target(path) as tmp:
            imsave(tmp, img, format="png")
    return img


def _pipe_to_ffmpeg(frames: Any, path: Path, fps: float, size: tuple[int, int]) -> None:
    w, h = size
    cmd = [
        "ffmpeg", "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{w}x{h}",
        "-r", f"{fps:g}", "-i", "-", "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264",
        "-pix_fmt", "yuv420p", str(path),
    ]  # fmt: skip
    proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stderr=subprocess.PIPE)
    assert proc.stdin is not None
    try:
        for img in frames:
            proc.stdin.write(np.ascontiguousarray(img[..., :3], dtype=np.uint8).tobytes())
    finally:
        proc.stdin.close()
        err = proc.stderr.read().decode(errors="replace") if proc.stderr else ""
        rc = proc.wait()
    if rc != 0:
        raise RuntimeError(f"ffmpeg failed writing {path} (exit code {rc}): {err.strip()[-300:]}")


def render_animation(
    positions: Any,
    skeleton: SkeletonLike,
    path: str | Path,
    *,
    fps: float,
    out_fps: float | None = 15.0,
    size: Sequence[int] = (SLIDE_WIDTH_PX, 720),
    view: str = "default",
    floor: bool | None = None,
    radius: float | None = None,
    box: Any = None,
    backend: str = "auto",
) -> Path:
    """Render a clip to ``.gif`` (``plotter.open_gif``) or ``.mp4`` (ffmpeg), atomically.

    Parameters
    ----------
    positions : (T, J, 3) float, centimetres, Y up
        Joint positions at ``fps``.
    skeleton : Skeleton or (J,) int parents array
        Hierarchy.
    path : str or Path
        Output file, ``.gif`` or ``.mp4``.
    fps : float
        Frame rate of ``positions``.
    out_fps : float or None
        Playback rate; frames are subsampled to it (``None``: all frames).
    size : (width, height)
        Frame size in pixels (default 960 x 720, slide size).
    view : {"default", "front", "side", "top"}
        Camera (fixed for the whole clip).
    floor : bool, optional
        Draw a floor plane; default with ``box``, else only for a skeleton with feet.
    radius : float, optional
        Bone radius, centimetres.
    box : (2, 3) float, optional
        Corners ``[[x0, y0, z0], [x1, y1, z1]]`` (cm) of the region the camera frames, the floor
        lies under (at ``y0``) and the bone radius scales with; default the bounding box of every
        frame. Renders of several systems that share one box share one camera and one scale: an
        upper body (HA2G's TED-43) is then as large as the upper half of a full body, instead of
        filling the picture on its own.
    backend : {"auto", "pyvista", "matplotlib"}
        Renderer; ``"auto"``/``"pyvista"`` fall back to matplotlib with one warning.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ValueError
        ``path`` does not end in ``.gif`` or ``.mp4``.
    RuntimeError
        ``.mp4`` without ffmpeg on ``PATH``.

    Examples
    --------
    Four frames of a rising hand at 15 fps, played at 15 fps: a GIF of four frames of the size asked (here drawn
    by matplotlib):

    >>> import tempfile
    >>> from PIL import Image
    >>> parents = [-1, 0, 1, 1]  # hips, chest, left hand, right hand
    >>> pose = np.array([[0.0, 100, 0], [0, 150, 0], [-40, 140, 10], [40, 140, 10]])  # cm, Y up
    >>> clip = np.repeat(pose[None], 4, axis=0)
    >>> clip[:, 3, 1] += 5.0 * np.arange(4)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     gif = Image.open(render_animation(clip, parents, Path(tmp) / "clip.gif", fps=15, size=(320, 240),
    ...                                       backend="matplotlib"))
    ...     gif.n_frames, gif.size
    (4, (320, 240))
    """
    bones = bone_groups(skeleton)
    pos = check_positions(positions, bones.n_joints)
    fps = check_fps(fps)
    w, h = _check_size(size)
    box = _check_box(box)
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise ValueError(f"path must end in .gif or .mp4, got {path.name!r}")
    if suffix == ".mp4" and not ffmpeg_available():
        raise RuntimeError(
            f"cannot write {path}: MP4 export needs the ffmpeg program on PATH "
            "(Debian/Ubuntu: `sudo apt-get install ffmpeg`), or save as .gif"
        )
    idx = frame_indices(len(pos), fps, out_fps)
    play_fps = fps if len(idx) < 2 else fps / float(np.mean(np.diff(idx)))
    if not use_pyvista(backend):
        from beatlite.viz.animation import animate_skeletons

        anim = animate_skeletons(pos, skeleton, fps, out_fps=out_fps, view=view, width=w, dpi=100)
        anim.figure.set_size_inches(w / 100, h / 100)
        return anim.save_as(path)
    plotter, skel = _scene(pos, bones, (w, h), view, floor, radius, box)
    try:
        with atomic_target(path) as tmp:
            if suffix == ".gif":
                plotter.open_gif(str(tmp), fps=play_fps)
                for k in idx:
                    skel.update(pos[k])
                    plotter.write_frame()
            else:

                def frames() -> Any:
                    for k in idx:
                        skel.update(pos[k])
                        plotter.render()
                        yield plotter.screenshot(return_img=True)

                _pipe_to_ffmpeg(frames(), tmp, play_fps, (w, h))
            plotter.close()
    finally:
        plotter.close()
    return path


def notebook_backend() -> str:
    """pyvista's Jupyter backend for :func:`show_skeleton`: ``"trame"`` (interactive) or ``"static"``.

    ``"trame"`` in a live kernel (:func:`beatlite.notebook.interactive`: not under ``make run`` /
    ``make test``, which set ``BEATLITE_INTERACTIVE=off``) with the ``interactive`` extra installed
    (``trame-pyvista`` and ``ipywidgets``: ``pip install -e ".[interactive]"``, done by ``make lab``);
    ``"static"`` (a PNG) otherwise.

    Examples
    --------
    >>> notebook_backend()  # a plain Python process (or BEATLITE_INTERACTIVE=off) is not a live kernel
    'static'
    """
    from beatlite.notebook import interactive

    if not interactive():
        return "static"
    needed = ("trame_pyvista", "ipywidgets")
    return "trame" if all(importlib.util.find_spec(m) is not None for m in needed) else "static"


def show_skeleton(
    positions: Any,
    skeleton: SkeletonLike,
    frame: int = 0,
    *,
    size: Sequence[int] = (SLIDE_WIDTH_PX, 500),
    view: str = "default",
    box: Any = None,
    jupyter_backend: str | None = None,
    backend: str = "auto",
) -> Any:
    """Show one frame in a notebook: an interactive view in a live kernel that has trame, else an image.

    Parameters
    ----------
    positions : (T, J, 3) or (J, 3) float, centimetres, Y up
        Joint positions.
    skeleton : Skeleton or (J,) int parents array
        Hierarchy.
    frame : int
        Frame to show.
    size : (width, height)
        Pixels of the image. The trame view is as wide as the notebook cell (at least
        :data:`TRAME_MIN_WIDTH_PX`) and ``height`` pixels high; its camera keeps the whole skeleton below the toolbar that trame draws over the top
        :data:`TRAME_TOOLBAR_PX` pixels (in any cell at least ``height`` pixels wide).
    view : {"default", "front", "side", "top"}
        Initial camera.
    box : (2, 3) float, optional
        Region the camera frames, as in :func:`render_frame`.
    jupyter_backend : str, optional
        pyvista's Jupyter backend (default :func:`notebook_backend`: ``"trame"`` in a live JupyterLab
        kernel with the ``interactive`` extra, ``"static"`` under ``make run`` / ``make test``).
    backend : {"auto", "pyvista", "matplotlib"}
        ``"matplotlib"`` (or a failed probe, with one warning) returns a matplotlib figure.

    Returns
    -------
    object
        In a notebook, what ``Plotter.show`` returns (it displays a trame widget or a
        static image); outside a notebook the ``(H, W, 3) uint8`` image; a matplotlib
        Figure when pyvista cannot render.

    Examples
    --------
    With matplotlib (``backend="matplotlib"``, or where pyvista cannot render) the view is a figure of the size
    asked, 100 px per inch:

    >>> import matplotlib.pyplot as plt
    >>> parents = [-1, 0, 1, 1]  # hips, chest, left hand, right hand
    >>> pose = np.array([[0.0, 100, 0], [0, 150, 0], [-40, 140, 10], [40, 140, 10]])  # cm, Y up
    >>> fig = show_skeleton(pose, parents, size=(320, 240), backend="matplotlib")
    >>> type(fig).__name__, fig.get_size_inches().tolist()
    ('Figure', [3.2, 2.4])
    >>> plt.close(fig)
    """
    bones = bone_groups(skeleton)
    pos = check_positions(positions, bones.n_joints)
    w, h = _check_size(size)
    box = _check_box(box)
    if not -len(pos) <= int(frame) < len(pos):
        raise ValueError(f"frame={frame!r} is not a frame index for {len(pos)} frames")
    if not use_pyvista(backend):
        from beatlite.viz.plot3d import plot_frame

        return plot_frame(pos, skeleton, int(frame), view=view, figsize=(w / 100, h / 100))
    k = int(frame) % len(pos)
    if not _in_notebook():
        plotter, _ = _scene(pos[k : k + 1], bones, (w, h), view, None, None, box)
        try:
            return np.asarray(plotter.screenshot(return_img=True))[..., :3].copy()
        finally:
            plotter.close()
    jb = jupyter_backend or notebook_backend()
    if jb != "trame":
        plotter, _ = _scene(pos[k : k + 1], bones, (w, h), view, None, None, box)
        return plotter.show(jupyter_backend=jb)
    # trame: the view fills the cell's width, unknown here. VTK's view angle is vertical, so framing
    # for a square view fits every view at least as wide as it is high.
    plotter, _ = _scene(pos[k : k + 1], bones, (h, h), view, None, None, box, top=TRAME_TOOLBAR_PX)
    width = (
        f"max(100%, {TRAME_MIN_WIDTH_PX}px)"  # the cell's width, never so narrow that the toolbar overlaps
    )
    no_wasm_download()
    return plotter.show(jupyter_backend="trame", jupyter_kwargs={"width": width, "height": f"{h}px"})


def no_wasm_download() -> str:
    """Point trame-vtklocal at an empty VTK WebAssembly folder (``$VTK_WASM_DIR_OVERRIDE``, unless set already).

    ``trame-pyvista`` needs ``trame-vtklocal``, which downloads VTK's WebAssembly bundle from gitlab.kitware.com
    when its first trame server starts, for client-side rendering. beatlite's views are rendered by the kernel's
    VTK and do not use it; with the folder set, nothing is downloaded (offline, the attempt printed a traceback
    in the cell). Returns the folder (a temporary one of this process).

    Examples
    --------
    A folder already set is kept:

    >>> import os
    >>> from unittest import mock
    >>> with mock.patch.dict(os.environ, {"VTK_WASM_DIR_OVERRIDE": "/opt/vtk-wasm"}):
    ...     no_wasm_download()
    '/opt/vtk-wasm'
    """
    import os
    import tempfile

    if not os.environ.get("VTK_WASM_DIR_OVERRIDE"):
        os.environ["VTK_WASM_DIR_OVERRIDE"] = tempfile.mkdtemp(prefix="beatlite-no-vtk-wasm-")
    return os.environ["VTK_WASM_DIR_OVERRIDE"]


def _in_notebook() -> bool:
    """True inside a Jupyter kernel (IPython's ZMQ shell)."""
    import sys

    ipython = sys.modules.get("IPython")
    shell = ipython.get_ipython() if ipython is not None else None
    return shell is not None and type(shell).__name__ == "ZMQInteractiveShell"
