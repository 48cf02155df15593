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
