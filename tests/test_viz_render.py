"""pyvista rendering behind the subprocess probe, and the matplotlib fall-back when rendering is impossible."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import os  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import warnings  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from PIL import Image  # noqa: E402
from test_viz import rest_positions, tiny_skeleton, wave_motion  # noqa: E402

from beatlite.viz import probe, render  # noqa: E402

ABORT = [sys.executable, "-c", "import os; os.abort()"]


@pytest.fixture
def fresh_probe(monkeypatch):
    """Forget cached probe answers and warnings before and after the test; restore the env var."""
    monkeypatch.delenv(probe.ENV_SWITCH, raising=False)
    monkeypatch.setenv(probe.ENV_WINDOW, os.environ.get(probe.ENV_WINDOW, ""))
    probe.probe_offscreen.cache_clear()
    probe._warn_once.cache_clear()
    yield
    probe.probe_offscreen.cache_clear()
    probe._warn_once.cache_clear()


@pytest.fixture(scope="module")
def pyvista_ok():
    """Skip unless the (real) probe finds a working off-screen render window."""
    pytest.importorskip("pyvista")
    status = probe.pyvista_status()
    if not status.ok:
        pytest.skip(f"pyvista cannot render off-screen here: {status.reason}")
    return status


# ------------------------------------------------------------------------------------- the probe
def test_crashing_probe_falls_back_to_matplotlib_with_one_warning(fresh_probe, monkeypatch):
    monkeypatch.setattr(probe, "probe_command", lambda: ABORT)  # SIGABRT, as VTK without GL would
    with pytest.warns(UserWarning, match="using matplotlib instead") as caught:
        img = render.render_frame(wave_motion(), tiny_skeleton(), 3, size=(160, 120))
    assert len(caught) == 1
    message = str(caught[0].message)
    assert "signal 6" in message and "system_deps.sh" in message  # says why and how to fix
    assert img.shape == (120, 160, 3) and img.dtype == np.uint8 and img.std() > 0
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the second call is silent
        img2 = render.render_frame(wave_motion(), tiny_skeleton(), 10, size=(160, 120))
    assert np.abs(img.astype(int) - img2).sum() > 0


def test_probe_reports_each_candidate_and_exit_codes(fresh_probe, monkeypatch):
    monkeypatch.setattr(probe, "probe_command", lambda: [sys.executable, "-c", "import sys; sys.exit(3)"])
    status = probe.probe_offscreen()
    assert not status.ok and status.window_class is None
    assert len(status.tried) == len(probe.candidate_windows())
    assert all("exit code 3" in line for line in status.tried)


def test_probe_times_out(fresh_probe, monkeypatch):
    monkeypatch.setattr(probe, "probe_command", lambda: [sys.executable, "-c", "import time; time.sleep(30)"])
    monkeypatch.setattr(probe, "candidate_windows", lambda: ["vtkEGLRenderWindow"])
    status = probe.probe_offscreen(timeout=0.5)
    assert not status.ok and "no answer within 0.5 s" in status.reason


def test_probe_rejects_blank_images(fresh_probe, monkeypatch):
    blank = 'print(\'{"window": "vtkEGLRenderWindow", "shape": [48, 64, 3], "std": 0.0}\')'
    monkeypatch.setattr(probe, "probe_command", lambda: [sys.executable, "-c", blank])
    monkeypatch.setattr(probe, "candidate_windows", lambda: ["vtkEGLRenderWindow"])
    assert "blank" in probe.probe_offscreen().reason


def test_probe_passes_the_candidate_window_to_the_child(fresh_probe, monkeypatch):
    script = (
        "import os, json; w = os.environ.get('VTK_DEFAULT_OPENGL_WINDOW');"
        "print(json.dumps({'window': w, 'std': 1.0})); raise SystemExit(0 if w == 'vtkOSOpenGLRenderWindow' else 1)"
    )
    monkeypatch.setattr(probe, "probe_command", lambda: [sys.executable, "-c", script])
    monkeypatch.setattr(probe, "candidate_windows", lambda: ["vtkEGLRenderWindow", "vtkOSOpenGLRenderWindow"])
    status = probe.probe_offscreen()
    assert status.ok and status.window_class == "vtkOSOpenGLRenderWindow"
    assert status.tried[0].startswith("vtkEGLRenderWindow: failed")
    assert probe.use_pyvista("auto") is True
    assert os.environ[probe.ENV_WINDOW] == "vtkOSOpenGLRenderWindow"  # set for this (rendering) process


def test_env_switch_off_skips_the_probe(fresh_probe, monkeypatch):
    monkeypatch.setenv(probe.ENV_SWITCH, "off")

    def no_subprocess(*args, **kwargs):
        raise AssertionError("the probe must not run when BEATLITE_PYVISTA=off")

    monkeypatch.setattr(subprocess, "run", no_subprocess)
    with pytest.warns(UserWarning, match="BEATLITE_PYVISTA=off"):
        assert probe.use_pyvista() is False
    assert probe.use_pyvista("matplotlib") is False
    with pytest.raises(ValueError, match="backend"):
        probe.use_pyvista("opengl")


def test_fallback_animation_is_a_gif(fresh_probe, monkeypatch, tmp_path):
    monkeypatch.setenv(probe.ENV_SWITCH, "off")
    with pytest.warns(UserWarning, match="matplotlib"):
        path = render.render_animation(
            wave_motion(12), tiny_skeleton(), tmp_path / "a.gif", fps=15, size=(80, 60)
        )
    with Image.open(path) as gif:
        assert gif.n_frames == 12 and gif.size == (80, 60)


def test_candidates_put_the_users_choice_first(monkeypatch):
    monkeypatch.setenv(probe.ENV_WINDOW, "vtkXOpenGLRenderWindow")
    monkeypatch.delenv("DISPLAY", raising=False)
    cands = probe.candidate_windows()
    assert cands[0] == "vtkXOpenGLRenderWindow"
    if sys.platform.startswith("linux"):
        assert cands[1:] == ["vtkEGLRenderWindow", "vtkOSOpenGLRenderWindow"]


# --------------------------------------------------------------------------------- real renders
def test_pyvista_frame_has_size_content_and_changes(pyvista_ok, tmp_path):
    pos, sk = wave_motion(), tiny_skeleton()
    img0 = render.render_frame(pos, sk, 0, size=(160, 120), backend="pyvista", path=tmp_path / "f.png")
    assert img0.shape == (120, 160, 3) and img0.dtype == np.uint8
    assert img0.std() > 5
    img1 = render.render_frame(pos, sk, 7, size=(160, 120), backend="pyvista")
    assert np.abs(img0.astype(int) - img1).sum() > 0
    assert np.array_equal(np.asarray(Image.open(tmp_path / "f.png"))[..., :3], img0)


def test_pyvista_front_view_puts_the_right_hand_on_the_left(pyvista_ok):
    # colour test: hands are red (#c0392b); in the front view the right hand (x = -45 cm) is left of centre
    pos = rest_positions()
    pos[7] = pos[6]  # fold the left hand onto the left shoulder so only the right hand sticks out
    img = render.render_frame(
        pos, tiny_skeleton(), size=(200, 200), view="front", floor=False, backend="pyvista"
    )
    rgb = img.astype(int)
    red = (rgb[..., 0] > rgb[..., 1] + 50) & (rgb[..., 0] > rgb[..., 2] + 50)
    cols = np.flatnonzero(red.any(axis=0))
    assert cols.size
    # the red that reaches farthest from the image centre (column 100) is on the left: the right hand
    assert 100 - cols.min() > cols.max() - 100 + 20


def test_pyvista_gif_and_mp4(pyvista_ok, tmp_path):
    pos, sk = wave_motion(20), tiny_skeleton()
    gif = render.render_animation(
        pos, sk, tmp_path / "a.gif", fps=30, out_fps=15, size=(96, 64), backend="pyvista"
    )
    with Image.open(gif) as im:
        assert im.n_frames == 10 and im.size == (96, 64)  # 20 frames at 30 fps, every 2nd
        im.seek(0)
        first = np.asarray(im.convert("RGB")).copy()
        im.seek(5)
        assert np.abs(np.asarray(im.convert("RGB")).astype(int) - first).sum() > 0
    if render.ffmpeg_available():
        mp4 = render.render_animation(pos, sk, tmp_path / "a.mp4", fps=30, size=(96, 64), backend="pyvista")
        assert mp4.read_bytes()[4:8] == b"ftyp"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.gif", "a.mp4"][: 1 + render.ffmpeg_available()]


def test_render_checks_its_inputs():
    with pytest.raises(ValueError, match="frame"):
        render.render_frame(wave_motion(3), tiny_skeleton(), 3, backend="matplotlib")
    with pytest.raises(ValueError, match="size"):
        render.render_frame(wave_motion(3), tiny_skeleton(), size=(4, 4), backend="matplotlib")
    with pytest.raises(ValueError, match=r"\.gif or \.mp4"):
        render.render_animation(wave_motion(3), tiny_skeleton(), "x.avi", fps=15, backend="matplotlib")


def test_show_skeleton_outside_a_notebook(fresh_probe, monkeypatch):
    monkeypatch.setenv(probe.ENV_SWITCH, "off")
    with pytest.warns(UserWarning, match="matplotlib"):
        fig = render.show_skeleton(wave_motion(), tiny_skeleton(), 1, size=(200, 100))
    assert fig.get_size_inches().tolist() == [2.0, 1.0]


def test_show_skeleton_with_pyvista_returns_the_image_outside_jupyter(pyvista_ok):
    img = render.show_skeleton(wave_motion(), tiny_skeleton(), 1, size=(120, 90), backend="pyvista")
    assert img.shape == (90, 120, 3) and img.std() > 5


# ------------------------------------------------------------------------- camera, scale and floor
def _display_rows_cols(plotter, points):
    """(N, 2) pixel (column, row from the top) of world points, by VTK's own world -> display transform."""
    ren = plotter.renderer
    h = plotter.window_size[1]
    out = []
    for p in np.asarray(points, dtype=float):
        ren.SetWorldPoint(*p, 1.0)
        ren.WorldToDisplay()
        x, y, _ = ren.GetDisplayPoint()
        out.append((x, h - y))
    return np.array(out)


def _beat_rest(arms_down: float = 0.0):
    """BEAT rest pose (T-pose, cm), each arm turned down by ``arms_down`` degrees about its shoulder."""
    from beatlite.skeleton import beat_skeleton, rest_pose

    sk = beat_skeleton()
    pos = rest_pose(sk)
    for side, sign in (("Right", 1.0), ("Left", -1.0)):
        a = np.radians(sign * arms_down)
        rot = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
        pivot = pos[sk.index(f"{side}Arm")].copy()
        arm = [j for j in range(sk.n_joints) if _descends(sk, j, sk.index(f"{side}Arm"))]
        pos[arm] = (pos[arm] - pivot) @ rot.T + pivot
    return pos, sk


def _descends(sk, j, ancestor):
    while j >= 0:
        if j == ancestor:
            return True
        j = sk.parents[j]
    return False


@pytest.mark.parametrize("view", ["default", "front", "side"])
@pytest.mark.parametrize("size", [(500, 500), (960, 500), (360, 300)])
def test_camera_frames_every_joint_below_the_toolbar(pyvista_ok, view, size):
    from beatlite.viz._inputs import bone_groups

    pos, sk = _beat_rest(arms_down=70.0)
    pos[sk.index("RightHand")] += (-30.0, 40.0, 20.0)  # a gesture: the box is not the rest pose's
    top = render.TRAME_TOOLBAR_PX
    plotter, _ = render._scene(pos[None], bone_groups(sk), size, view, None, None, top=top)
    try:
        plotter.render()
        px = _display_rows_cols(plotter, pos)
    finally:
        plotter.close()
    w, h = size
    margin = 0.02 * h  # frame_camera leaves 4 % of the height around the box; the joints are inside the box
    assert px[:, 0].min() >= margin and px[:, 0].max() <= w - margin
    assert px[:, 1].max() <= h - margin
    head_row = px[sk.index("HeadEnd"), 1] if "HeadEnd" in sk.names else px[:, 1].min()
    assert px[:, 1].min() >= top + margin and head_row >= top + margin  # nothing under the toolbar
    # and the body is not lost in a corner: it spans most of the height (or width) left to it
    span = max((px[:, 1].max() - px[:, 1].min()) / (h - top), (px[:, 0].max() - px[:, 0].min()) / w)
    assert span > 0.6


def test_project_matches_vtk(pyvista_ok):
    from beatlite.viz._inputs import bone_groups

    pos, sk = _beat_rest()
    plotter, _ = render._scene(pos[None], bone_groups(sk), (400, 300), "default", None, None, top=40)
    try:
        plotter.render()
        cam = plotter.camera
        mine = render.project(pos, np.array(cam.position), np.array(cam.focal_point), cam.up, (400, 300))
        np.testing.assert_allclose(mine, _display_rows_cols(plotter, pos), atol=0.5)
    finally:
        plotter.close()


def _ink_rows(img):
    """Rows that hold skeleton pixels: saturated or dark (bones, joints), not white or floor grey."""
    rgb = img.astype(int)
    ink = (rgb.max(axis=-1) - rgb.min(axis=-1) > 40) | (rgb.max(axis=-1) < 150)
    return np.flatnonzero(ink.any(axis=1))


def test_one_box_gives_one_scale_and_a_floor(pyvista_ok):
    from beatlite.skeleton import TED43_JOINTS, TED_BONES, beat_to_ted43

    full, sk = _beat_rest(arms_down=70.0)  # a speaker's pose: taller than wide
    upper = beat_to_ted43(full[None])[0]  # the same body on HA2G's upper-body skeleton, same centimetres
    parents = np.full(len(TED43_JOINTS), -1)
    parents[np.asarray(TED_BONES)[:, 1]] = np.asarray(TED_BONES)[:, 0]
    every = np.concatenate([full, upper])
    box = np.stack([every.min(axis=0), every.max(axis=0)])
    size, kw = (300, 300), dict(view="front", backend="pyvista")
    shared = [
        render.render_frame(p, s, size=size, box=box, floor=False, **kw)
        for p, s in ((full, sk), (upper, parents))
    ]
    heights_px = [np.ptp(_ink_rows(img)) for img in shared]
    heights_cm = [np.ptp(full[:, 1]), np.ptp(upper[:, 1])]  # 177 cm and 90 cm (hands at the hips)
    ratio_px, ratio_cm = heights_px[1] / heights_px[0], heights_cm[1] / heights_cm[0]
    assert ratio_cm < 0.6
    assert abs(ratio_px - ratio_cm) < 0.06, (
        ratio_px,
        ratio_cm,
    )  # one scale (perspective and tube radius aside)
    widths_px = [np.ptp(_ink_rows(img.transpose(1, 0, 2))) for img in shared]  # same shoulders and arms
    assert abs(widths_px[1] / widths_px[0] - 1) < 0.05, widths_px
    own = render.render_frame(
        upper, parents, size=size, floor=False, **kw
    )  # its own box: it fills the picture
    assert np.ptp(_ink_rows(own)) / heights_px[1] > 1.6  # what notebook 08 showed before: HA2G twice as large
    # a floor under every render that shares a box, also under the upper body that has no feet
    for p, s in ((full, sk), (upper, parents)):
        img = render.render_frame(p, s, size=size, box=box, **kw)
        rgb = img.astype(int)
        floor = (np.abs(rgb - 240).max(axis=-1) <= 6).any(axis=1)  # FLOOR_COLOUR #f0f0f0, unlit
        assert render.FLOOR_COLOUR == "#f0f0f0"
        assert floor[_ink_rows(img).max() :].sum() >= 10  # floor rows below the lowest joint
    no_floor = render.render_frame(upper, parents, size=size, **kw)  # alone, an upper body has none
    assert not (np.abs(no_floor.astype(int) - 240).max(axis=-1) <= 6).any()


def test_box_is_checked():
    with pytest.raises(ValueError, match="box"):
        render.render_frame(wave_motion(3), tiny_skeleton(), box=[[0, 0, 0], [1, 1]], backend="matplotlib")
    with pytest.raises(ValueError, match="box"):
        render.render_frame(
            wave_motion(3), tiny_skeleton(), box=[[0, 0, 0], [-1, 1, 1]], backend="matplotlib"
        )


def test_show_skeleton_trame_view_fills_the_cell_and_frames_the_body(pyvista_ok, monkeypatch):
    import pyvista as pv

    from beatlite.viz._inputs import bone_groups

    seen = {}

    def fake_show(plotter, **kwargs):  # what pyvista's trame backend would receive
        seen.update(kwargs, camera=plotter.camera.copy())
        plotter.close()

    monkeypatch.setattr(pv.Plotter, "show", fake_show)
    monkeypatch.setattr(render, "_in_notebook", lambda: True)
    pos, sk = _beat_rest()
    render.show_skeleton(pos, sk, size=(960, 500), jupyter_backend="trame", backend="pyvista")
    assert seen["jupyter_backend"] == "trame"
    assert seen["jupyter_kwargs"] == {"width": "max(100%, 600px)", "height": "500px"}
    for width in (500, 800, 1200):  # the cell's width is unknown: the body fits any at least 500 px wide
        plotter, _ = render._scene(pos[None], bone_groups(sk), (width, 500), "default", None, None)
        try:
            plotter.camera = seen["camera"]
            plotter.render()
            px = _display_rows_cols(plotter, pos)
        finally:
            plotter.close()
        assert px[:, 0].min() > 0 and px[:, 0].max() < width
        assert px[:, 1].min() > render.TRAME_TOOLBAR_PX and px[:, 1].max() < 500


def test_matplotlib_fallback_honours_the_box():
    from beatlite.skeleton import TED43_JOINTS, TED_BONES, beat_to_ted43

    full, sk = _beat_rest(arms_down=70.0)
    upper = beat_to_ted43(full[None])[0]
    parents = np.full(len(TED43_JOINTS), -1)
    parents[np.asarray(TED_BONES)[:, 1]] = np.asarray(TED_BONES)[:, 0]
    box = np.stack([full.min(axis=0), full.max(axis=0)])
    kw = dict(size=(200, 240), view="front", floor=False, backend="matplotlib")
    heights = [
        np.ptp(_ink_rows(render.render_frame(p, s, box=box, **kw))) for p, s in ((full, sk), (upper, parents))
    ]
    ratio_cm = np.ptp(upper[:, 1]) / np.ptp(full[:, 1])  # 0.51
    assert abs(heights[1] / heights[0] - ratio_cm) < 0.08, (heights, ratio_cm)


def test_trame_vtklocal_downloads_nothing(monkeypatch, tmp_path):
    """The interactive extra's trame-vtklocal fetches VTK's WebAssembly bundle when a trame server starts;
    beatlite's views do not use it, and no_wasm_download() makes its registration copy from an empty folder."""
    wasm = pytest.importorskip("trame_vtklocal.module.wasm")  # only with the `interactive` extra
    from beatlite.viz.render import no_wasm_download

    fetched = []

    async def fake_setup(dest, url):  # what would download
        fetched.append(url)

    monkeypatch.setattr(wasm, "setup_wasm_directory", fake_setup)
    monkeypatch.delenv("VTK_WASM_DIR_OVERRIDE", raising=False)
    folder = no_wasm_download()
    assert __import__("os").listdir(folder) == []
    wasm.register_wasm(str(tmp_path / "serve"))
    assert fetched == []
    monkeypatch.delenv("VTK_WASM_DIR_OVERRIDE")
    wasm.register_wasm(str(tmp_path / "serve2"))  # without it: the download the test guards against
    assert len(fetched) == 1 and fetched[0].startswith("https://")
