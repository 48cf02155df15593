"""Tests of beatlite.viz: style, input checks, matplotlib plots and animations (Agg, headless)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from PIL import Image  # noqa: E402

from beatlite.skeleton.core import Skeleton  # noqa: E402
from beatlite.viz import _inputs, animation, check, face, plot3d, style  # noqa: E402

ROT = ("Xrotation", "Yrotation", "Zrotation")
NAMES = [
    "Hips",
    "Spine",
    "Neck",
    "Head",
    "RightArm",
    "RightHand",
    "LeftArm",
    "LeftHand",
    "RightFoot",
    "LeftFoot",
]
PARENTS = [-1, 0, 1, 2, 1, 4, 1, 6, 0, 0]
OFFSETS = [
    [0, 95, 0],
    [0, 30, 0],
    [0, 25, 0],
    [0, 12, 0],
    [-15, 0, 0],
    [-30, 0, 0],
    [15, 0, 0],
    [30, 0, 0],
    [-10, -95, 0],
    [10, -95, 0],
]


def tiny_skeleton() -> Skeleton:
    return Skeleton(NAMES, PARENTS, OFFSETS, [("Xposition", "Yposition", "Zposition", *ROT)] + [ROT] * 9)


def rest_positions() -> np.ndarray:
    pos = np.zeros((len(NAMES), 3))
    for j, p in enumerate(PARENTS):
        pos[j] = np.array(OFFSETS[j], float) + (pos[p] if p >= 0 else 0.0)
    return pos


def wave_motion(n_frames: int = 30) -> np.ndarray:
    """(T, 10, 3) cm: the rest pose with the right hand waving up and down by up to 25 cm."""
    pos = np.repeat(rest_positions()[None], n_frames, axis=0)
    pos[:, 5, 1] += 25 * np.sin(np.linspace(0, 2 * np.pi, n_frames))
    return pos


def fig_image(fig) -> np.ndarray:
    fig.canvas.draw()
    return np.asarray(fig.canvas.buffer_rgba())[..., :3].copy()


pytestmark = pytest.mark.filterwarnings("ignore:Animation was deleted without rendering:UserWarning")


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


# ----------------------------------------------------------------------------------------- style
def test_figure_style_applies_and_restores_rcparams():
    before = plt.rcParams["axes.spines.top"]
    with style.figure_style(**{"font.size": 17}):
        assert plt.rcParams["font.size"] == 17
        assert plt.rcParams["axes.spines.top"] is False
    assert plt.rcParams["axes.spines.top"] == before
    assert plt.rcParams["font.size"] != 17


def test_save_figure_writes_each_format_atomically(tmp_path):
    fig = plt.figure(figsize=(2, 1))
    ax = fig.add_axes((0, 0, 1, 1))
    ax.imshow(np.arange(6.0).reshape(2, 3), aspect="auto")
    ax.set_axis_off()
    out = style.save_figure(fig, tmp_path / "sub" / "line.png", formats=("png", "svg"), pad_inches=0)
    assert out == [tmp_path / "sub" / "line.png", tmp_path / "sub" / "line.svg"]
    # the style's savefig.dpi = 150 applies outside figure_style too: 2 x 1 inches -> 300 x 150 pixels
    w, h = Image.open(out[0]).size
    assert abs(w - 300) <= 1 and abs(h - 150) <= 1
    assert out[1].read_text().lstrip().startswith("<?xml")
    assert sorted(p.name for p in (tmp_path / "sub").iterdir()) == ["line.png", "line.svg"]  # no temp files


def test_save_figure_rejects_bad_arguments(tmp_path):
    with pytest.raises(TypeError, match="Figure"):
        style.save_figure("not a figure", tmp_path / "x")
    fig = plt.figure()
    with pytest.raises(ValueError, match="formats"):
        style.save_figure(fig, tmp_path / "x", formats=())


# ---------------------------------------------------------------------------------------- inputs
@pytest.mark.parametrize(
    ("name", "group"),
    [
        ("RightHandIndex2", "hands"),
        ("LeftHand", "hands"),
        ("Head", "head"),
        ("HeadEnd", "head"),
        ("Neck1", "head"),
        ("Spine3", "body"),
        ("LeftForeArm", "body"),
        ("RightToeBase", "body"),
    ],
)
def test_joint_group_by_name(name, group):
    assert _inputs.joint_group(name) == group


def test_skeleton_bones_partition_joints_and_bones():
    bones = _inputs.bone_groups(tiny_skeleton())
    # joints: hands = {RightHand, LeftHand}; head = {Neck, Head}; body = the other 6
    assert bones.joints["hands"].tolist() == [5, 7]
    assert bones.joints["head"].tolist() == [2, 3]
    assert len(bones.joints["body"]) == 6
    # every non-root joint owns exactly one bone, coloured by the child
    all_pairs = np.concatenate([bones.pairs[g] for g in _inputs.GROUPS])
    assert sorted(all_pairs[:, 1].tolist()) == list(range(1, 10))
    assert all(PARENTS[c] == p for p, c in all_pairs)
    # a parents array gives the same bones, all in the body group
    plain = _inputs.bone_groups(np.array(PARENTS))
    assert len(plain.pairs["body"]) == 9 and len(plain.pairs["hands"]) == 0


def test_skeleton_bones_rejects_bad_parents():
    with pytest.raises(ValueError, match="parents"):
        _inputs.bone_groups(np.array([-1, 5, 0]))
    with pytest.raises(TypeError, match="parents array"):
        _inputs.bone_groups(np.zeros((2, 2), dtype=int))


def test_check_positions_errors_name_the_shape():
    with pytest.raises(ValueError, match=r"\(T, J, 3\).*\(4, 10, 2\)"):
        _inputs.check_positions(np.zeros((4, 10, 2)))
    with pytest.raises(ValueError, match="9 joints but the skeleton has 10"):
        _inputs.check_positions(np.zeros((4, 9, 3)), 10)
    bad = np.zeros((2, 10, 3))
    bad[1, 3, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        _inputs.check_positions(bad)
    assert _inputs.check_positions(np.zeros((10, 3))).shape == (1, 10, 3)


def test_frame_indices_subsample_to_the_asked_rate():
    # 100 frames at 120 fps played at 15 fps: every 8th frame, 0, 8, ..., 96 -> 13 frames
    assert _inputs.frame_indices(100, 120.0, 15.0).tolist() == list(range(0, 97, 8))
    # 10 frames at 15 fps asked at 30 fps: never faster than recorded -> all frames
    assert _inputs.frame_indices(10, 15.0, 30.0).tolist() == list(range(10))
    assert _inputs.frame_indices(7, 15.0, None).tolist() == list(range(7))


def test_word_at_and_check_words():
    starts, ends, words = _inputs.check_words(([0.0, 1.0, 2.5], [0.8, 2.0, 3.0], ["so", "we", "go"]))
    assert _inputs.word_at(0.5, starts, ends, words) == "so"
    assert _inputs.word_at(0.9, starts, ends, words) == ""  # the gap 0.8-1.0 s
    assert _inputs.word_at(2.0, starts, ends, words) == ""  # ends are exclusive
    assert _inputs.word_at(2.7, starts, ends, words) == "go"
    with pytest.raises(ValueError, match="same length"):
        _inputs.check_words(([0.0], [1.0, 2.0], ["a"]))
    with pytest.raises(ValueError, match="before it starts"):
        _inputs.check_words(([1.0], [0.5], ["a"]))


def test_plot_coords_are_a_rotation_with_height_on_z():
    m = _inputs.to_plot_coords(np.eye(3))  # rows: images of the data x, y, z axes
    assert np.isclose(np.linalg.det(m), 1.0)  # a rotation: no mirror image
    assert m[1].tolist() == [0.0, 0.0, 1.0]  # data up (y) is plot up (z)


# ------------------------------------------------------------------------------------ static plots
def test_plot_frame_renders_expected_size_and_changes_with_the_frame():
    pos = wave_motion()
    fig = plot3d.plot_frame(pos, tiny_skeleton(), 0, figsize=(3, 2), dpi=100)
    img0 = fig_image(fig)
    assert img0.shape == (200, 300, 3)  # 3 x 2 inches at 100 dpi
    assert img0.std() > 5  # not blank
    img1 = fig_image(plot3d.plot_frame(pos, tiny_skeleton(), 7, figsize=(3, 2), dpi=100))
    assert np.abs(img0.astype(int) - img1).sum() > 0


def test_plot_frame_front_view_shows_the_right_hand_on_the_viewers_left():
    from mpl_toolkits.mplot3d import proj3d

    pos = rest_positions()  # right hand at x = -45 cm, left hand at x = +45 cm, both facing +Z
    fig = plot3d.plot_frame(pos, tiny_skeleton(), view="front", figsize=(3, 3), dpi=100)
    ax = fig.axes[0]
    fig.canvas.draw()
    screen_x = []
    for j in (5, 7):
        x, y, z = _inputs.to_plot_coords(pos[j])
        px, py, _ = proj3d.proj_transform(x, y, z, ax.get_proj())
        screen_x.append(ax.transData.transform((px, py))[0])
    assert screen_x[0] < fig.bbox.width / 2 < screen_x[1]


def test_plot_frame_accepts_a_parents_array_and_checks_inputs():
    fig = plot3d.plot_frame(wave_motion(), np.array(PARENTS), 2, figsize=(2, 2), dpi=50)
    assert fig_image(fig).std() > 0
    with pytest.raises(ValueError, match="out of range"):
        plot3d.plot_frame(wave_motion(5), tiny_skeleton(), 5)
    with pytest.raises(ValueError, match="view"):
        plot3d.plot_frame(wave_motion(5), tiny_skeleton(), view="below")


def test_filmstrip_views_and_trajectories_layouts():
    pos, sk = wave_motion(), tiny_skeleton()
    strip = plot3d.plot_filmstrip(pos, sk, n=4, fps=15)
    assert len(strip.axes) == 4
    # frames evenly spaced over 0..29: round(linspace(0, 29, 4)) = 0, 10, 19, 29 -> t = k / 15 s
    assert [ax.get_title() for ax in strip.axes] == ["t = 0.00 s", "t = 0.67 s", "t = 1.27 s", "t = 1.93 s"]
    views = plot3d.plot_views(pos, sk, 3)
    assert [ax.get_title() for ax in views.axes] == ["front", "side", "top"]
    assert [(ax.elev, ax.azim) for ax in views.axes] == [(0, -90), (0, 0), (90, -90)]
    traj = plot3d.plot_trajectories(pos, sk)
    labels = [t.get_text() for t in traj.axes[0].get_legend().get_texts()]
    assert labels == ["RightHand", "LeftHand", "Head"]
    with pytest.raises(KeyError, match="Nose"):
        plot3d.plot_trajectories(pos, sk, joints=["Nose"])


def test_beat_skeleton_joint_groups():
    beat = pytest.importorskip("beatlite.skeleton.beat")
    bones = _inputs.bone_groups(beat.beat_skeleton())
    # reference table: per side RightHand + 23 finger joints (M1-4, R..R4, P..P4, I..I4, T1-4) = 24;
    # head = Neck, Neck1, Head, HeadEnd; body = the other 75 - 48 - 4 = 23
    assert [len(bones.joints[g]) for g in ("body", "hands", "head")] == [23, 48, 4]


# ------------------------------------------------------------------------------------ animations
def _animation(**kwargs):
    pos = wave_motion(30)
    sr = 1000
    audio = np.sin(2 * np.pi * 5 * np.arange(2 * sr) / sr)
    return animation.animate_skeletons(
        {"ground truth": pos, "CaMN": pos[::-1]},
        tiny_skeleton(),
        fps=15,
        timeline=animation.Timeline(audio, sr, audio_beats=[0.2, 0.9], motion_beats=[0.5]),
        words=([0.0, 1.0], [0.5, 1.5], ["hello", "world"]),
        width=300,
        dpi=50,
        **kwargs,
    )


def test_animation_frames_are_in_sync_and_differ():
    anim = _animation(out_fps=5)
    # 30 frames at 15 fps played at 5 fps: frames 0, 3, ..., 27 -> 10 frames, times k * 0.2 s
    assert np.allclose(anim.times, np.arange(10) * 0.2)
    assert anim.fps == pytest.approx(5.0)
    img0, img3 = anim.frame_image(0), anim.frame_image(3)
    # 300 px at 50 dpi: 6 inches, two square 3-inch panels (under the 3.6-inch cap) above the timeline
    assert img0.shape[1] == 300
    assert [ax.get_position().width * 6 for ax in anim.figure.axes[:2]] == pytest.approx([3.0, 3.0])
    assert img0.std() > 5
    assert np.abs(img0.astype(int) - img3).sum() > 0
    caption = anim.figure.texts[-1]
    anim.frame_image(6)  # t = 1.2 s, inside "world" (1.0-1.5 s)
    assert caption.get_text() == "world"
    timeline = anim.figure.axes[2]
    assert np.allclose(timeline.lines[-1].get_xdata(), [1.2, 1.2])  # the cursor follows the clock
    beats = [c for c in timeline.collections if type(c).__name__ == "LineCollection"]
    assert [len(c.get_segments()) for c in beats] == [2, 1]  # 2 audio beats, 1 motion beat
    anim.frame_image(3)  # t = 0.6 s, between words
    assert caption.get_text() == ""


def test_animation_size_is_width_in_pixels_with_square_panels():
    anim = animation.animate_skeletons(wave_motion(6), tiny_skeleton(), fps=15, width=100, dpi=50)
    assert anim.frame_image(0).shape == (100, 100, 3)  # one square 2-inch panel at 50 dpi
    with pytest.raises(TypeError):
        animation.animate_skeletons(wave_motion(6), tiny_skeleton(), fps=15, panel_size=2.0)  # beatlite 0.1


@pytest.fixture
def figure_check_off(monkeypatch):
    monkeypatch.setenv("BEATLITE_FIGURE_CHECK", "off")


#: _animation() is 300 px wide at 50 dpi to keep these tests fast: its 9-pt text is 6 px, which the figure check
#: flags (a warning, or an error under `make test`'s BEATLITE_FIGURE_CHECK=raise): these tests turn it off.
SMALL_FOR_SPEED = pytest.mark.usefixtures("figure_check_off")


@SMALL_FOR_SPEED
def test_animation_gif_round_trip(tmp_path):
    anim = _animation(out_fps=5, max_frames=4)
    path = anim.save_as(tmp_path / "clip.gif")
    with Image.open(path) as gif:
        assert gif.n_frames == 4
        assert gif.info["duration"] == pytest.approx(200, abs=10)  # 1000 ms / 5 fps
        w, h = gif.size
    assert (h, w) == anim.frame_image(0).shape[:2]
    assert [p.name for p in tmp_path.iterdir()] == ["clip.gif"]


@SMALL_FOR_SPEED
def test_animation_mp4_and_html(tmp_path):
    anim = _animation(out_fps=5, max_frames=3)
    if animation.ffmpeg_available():
        data = anim.save_as(tmp_path / "clip.mp4").read_bytes()
        assert data[4:8] == b"ftyp"  # an ISO media file
    html = anim.to_html()
    import re

    shown = anim._repr_html_()  # what JupyterLab displays: the same player, 3 frames
    frames = [sorted(set(re.findall(r"frames\[(\d+)\] = ", h))) for h in (html, shown)]
    assert "<script" in html and "<script" in shown and frames[0] == frames[1] == ["0", "1", "2"]
    assert anim.save_as(tmp_path / "clip.html").read_text().count("<script") >= 1


def test_mp4_without_ffmpeg_says_how_to_fix(tmp_path, monkeypatch):
    monkeypatch.setattr(animation.shutil, "which", lambda name: None)
    anim = _animation(max_frames=2)
    with pytest.raises(RuntimeError, match="ffmpeg"):
        anim.save_as(tmp_path / "clip.mp4")
    with pytest.raises(ValueError, match=r"\.gif"):
        anim.save_as(tmp_path / "clip.avi")
    assert list(tmp_path.iterdir()) == []


def test_animation_face_panels_follow_the_clock():
    rng = np.random.default_rng(0)
    weights = rng.random((120, 51))  # 2 s at 60 fps
    anim = animation.animate_skeletons(
        wave_motion(30),
        tiny_skeleton(),
        fps=15,
        face=animation.FacePanel(weights, fps=60, kind="bars"),
        out_fps=15,
        dpi=40,
    )
    ax_face = anim.figure.axes[-1]
    anim.frame_image(10)  # t = 10 / 15 s -> face frame round(40.0) = 40
    heights = [r.get_height() for r in ax_face.patches]
    assert np.allclose(heights, weights[40, face.most_active(weights, 12)])  # the 12 most active blendshapes
    heat = animation.animate_skeletons(
        wave_motion(30),
        tiny_skeleton(),
        fps=15,
        face=animation.FacePanel(weights, fps=60, kind="heatmap"),
        dpi=40,
    )
    assert heat.frame_image(5).std() > 0
    with pytest.raises(ValueError, match="kind"):
        animation.animate_skeletons(
            wave_motion(3), tiny_skeleton(), 15, face=animation.FacePanel(weights, kind="pie")
        )


def test_animation_rejects_mismatched_inputs():
    with pytest.raises(ValueError, match="labels"):
        animation.animate_skeletons([wave_motion(3)], tiny_skeleton(), 15, labels=["a", "b"])
    with pytest.raises(ValueError, match="audio"):
        animation.animate_skeletons(
            wave_motion(3), tiny_skeleton(), 15, timeline=animation.Timeline(np.zeros((2, 5)))
        )
    with pytest.raises(ValueError, match=r"positions\[0\]"):
        animation.animate_skeletons(np.zeros((3, 4, 3)), tiny_skeleton(), 15)


# ------------------------------------------------------------------------------------------ face
def test_plot_blendshapes_heatmap_and_bars():
    w = np.linspace(0, 1, 60 * 51).reshape(60, 51)
    names = [f"shape{i}" for i in range(51)]
    heat = face.plot_blendshapes(w, names, fps=60, frame=30)
    ax = heat.axes[0]
    assert ax.images[0].get_extent() == [0.0, 1.0, 50.5, -0.5]  # 60 frames / 60 fps = 1 s; row 0 at the top
    assert ax.get_yticklabels()[3].get_text() == "shape3"
    bars = face.plot_blendshapes(w, names, fps=60, kind="bars", frame=2)
    assert np.allclose([r.get_height() for r in bars.axes[0].patches], w[2])
    with pytest.raises(ValueError, match="50 names for 51"):
        face.plot_blendshapes(w, names[:50])
    with pytest.raises(ValueError, match=r"\(T, K\)"):
        face.plot_blendshapes(np.zeros(51))


def test_real_beat_skeleton_file_plots_with_expected_groups(real_samples):
    from beatlite.io import read_bvh

    motion = read_bvh(real_samples / "beat_skeleton_2_scott_0_1_1_frame0.bvh")
    bones = _inputs.bone_groups(motion.skeleton)
    assert [len(bones.joints[g]) for g in ("body", "hands", "head")] == [23, 48, 4]
    img = fig_image(plot3d.plot_frame(motion.positions(), motion.skeleton, figsize=(2, 3), dpi=60))
    assert img.shape == (180, 120, 3) and img.std() > 5


def test_animation_takes_one_skeleton_per_sequence_or_a_parents_list():
    small = np.array([[0.0, 0.0, 0.0], [0.0, 10.0, 0.0], [5.0, 15.0, 0.0]])  # a 3-joint chain
    anim = animation.animate_skeletons(
        [wave_motion(4), np.repeat(small[None], 4, axis=0)], [tiny_skeleton(), [-1, 0, 1]], 15, dpi=30
    )
    assert anim.frame_image(1).std() > 0
    parents_list = animation.animate_skeletons(wave_motion(4), PARENTS, 15, dpi=30)
    assert parents_list.frame_image(0).std() > 0
    with pytest.raises(ValueError, match="skeleton: 3 given for 2"):
        animation.animate_skeletons([wave_motion(2)] * 2, [tiny_skeleton()] * 3, 15)


# ------------------------------------------------------------------ slide-size figures (issue 16)
def ted_parents() -> np.ndarray:
    from beatlite.skeleton.ted import TED43_JOINTS, TED_BONES

    parents = np.full(len(TED43_JOINTS), -1)
    for parent, child in TED_BONES:
        parents[child] = parent
    return parents


def upper_body(n_frames: int = 6) -> np.ndarray:
    """(T, 43, 3) cm: a TED-43 pose built by chaining 10 cm bones straight up from the spine at y = 100."""
    parents = ted_parents()
    pos = np.zeros((43, 3))
    for j in range(43):  # TED_BONES lists parents before children
        if parents[j] >= 0:
            pos[j] = pos[parents[j]] + [0.0, 10.0, 0.0]
    pos[:, 1] += 100.0
    pos[:, 0] = np.arange(43) - 21.0  # spread sideways so the box is not degenerate
    return np.repeat(pos[None], n_frames, axis=0)


def _inside(inner, outer, tol=1.0):
    return (
        inner.x0 >= outer.x0 - tol
        and inner.x1 <= outer.x1 + tol
        and inner.y0 >= outer.y0 - tol
        and (inner.y1 <= outer.y1 + tol)
    )


def test_system_colour_by_name_then_by_position():
    assert style.system_colour("CaMN") == style.system_colour("camn (tiny)") == style.SYSTEM_COLOURS[1]
    assert style.system_colour("HA2G") == style.SYSTEM_COLOURS[2]
    assert style.system_colour("ground truth", 5) == style.SYSTEM_COLOURS[0]
    # a colour no longer depends on the position: the old index is ignored
    assert {style.system_colour("baseline", i) for i in range(6)} == {style.system_colour("baseline")}


#: The course's systems: the ground truth's rows and every shipped recipe's row (baselines included).
def _course_labels(main_rows_only: bool = False) -> list[str]:
    from beatlite.train.recipes import GROUND_TRUTH, GROUND_TRUTH_141, RECIPES

    recipes = [r.label for r in RECIPES.values() if not (main_rows_only and r.overrides)]
    return [GROUND_TRUTH, GROUND_TRUTH_141, *recipes]


#: Labels a user might give their own models (none names a system of the course).
USER_LABELS = [
    "My model",
    "Transformer (ours)",
    "EMAGE",
    "TalkSHOW",
    "baseline v2",
    "Gesture LM",
    "x",
    "DiffStyle",
]


def test_every_system_of_the_course_has_one_fixed_colour_of_its_own():
    """Before: only ground truth, CaMN and HA2G had colours by name; Random clip was green in notebook 07's bars,
    brown in 08's key frames and purple in 09's ranks (colours by position in each figure)."""
    from matplotlib.colors import to_rgb

    named = set(style.NAMED_SYSTEM_COLOURS.values())
    for label in _course_labels():  # ablations ("CaMN w/o text") share their model's colour
        assert style.system_colour(label) in named, label
    main = _course_labels(main_rows_only=True)  # 2 ground-truth rows + 10 recipes' main rows
    colours = {label: style.system_colour(label) for label in main}
    assert len(main) == 12 and len(set(colours.values())) == 12, colours
    # an ablation beside its model, before or after it, takes a lighter shade: the model keeps its colour
    assert (
        style.system_colours(["CaMN w/o text", "CaMN"])[1]
        == style.system_colours(["CaMN", "CaMN w/o text"])[0]
    )
    assert style.system_colours(["HA2G w/o text", "HA2G"])[1] == style.system_colour("HA2G")
    # the three colours the course had before stay
    assert (colours["Ground truth"], colours["CaMN"], colours["HA2G"]) == ("#333333", "#1f77b4", "#ff7f0e")
    rgb = [np.array(to_rgb(c)) for c in colours.values()]  # far apart, not only different hex strings
    assert min(np.abs(a - b).max() for i, a in enumerate(rgb) for b in rgb[i + 1 :]) > 0.1


# Dichromat simulation matrices on linear RGB (Machado, Oliveira & Fernandes 2009, severity 1), and sRGB's D65 matrix.
_DICHROMAT = {
    "protanopia": [
        [0.152286, 1.052583, -0.204868],
        [0.114503, 0.786281, 0.099216],
        [-0.003882, -0.048116, 1.051998],
    ],
    "deuteranopia": [
        [0.367322, 0.860646, -0.227968],
        [0.280085, 0.672501, 0.047413],
        [-0.01182, 0.04294, 0.968881],
    ],
}
_SRGB_TO_XYZ = [[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]]


def _cielab(colour, vision: str = "normal") -> np.ndarray:
    """CIELAB (D65) of a colour as seen with normal vision or, simulated, a dichromat's."""
    from matplotlib.colors import to_rgb

    c = np.array(to_rgb(colour))
    linear = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    if vision != "normal":
        linear = np.clip(np.array(_DICHROMAT[vision]) @ linear, 0.0, 1.0)
    t = np.array(_SRGB_TO_XYZ) @ linear / np.array(_SRGB_TO_XYZ).sum(axis=1)  # over white's XYZ
    f = np.where(t > (6 / 29) ** 3, np.cbrt(t), t / (3 * (6 / 29) ** 2) + 4 / 29)
    return np.array([116 * f[1] - 16, 500 * (f[0] - f[1]), 200 * (f[1] - f[2])])


def test_the_cielab_measure_gives_the_reference_values():
    assert np.allclose(_cielab("white"), [100, 0, 0], atol=1e-6) and np.allclose(
        _cielab("black"), 0, atol=1e-6
    )
    assert np.allclose(_cielab("#ff0000"), [53.24, 80.09, 67.20], atol=0.05)  # sRGB red, published
    for vision in _DICHROMAT:  # a dichromat sees greys as they are (each matrix row sums to 1)
        assert np.allclose(_cielab("#777777", vision), _cielab("#777777"), atol=1e-3)


def test_every_two_named_system_colours_are_clearly_apart():
    """CIELAB ΔE (CIE76) of every two colours of NAMED_SYSTEM_COLOURS: at least 30 with normal vision, where the
    other pairs start at 33.6 (ground truth (141 Euler channels) and random clip; a just noticeable difference is
    2.3); before, A2G-style (#882255) and Joint Embedding-style (#7b4173), two dark purples side by side in notebook
    07's benchmark, were 19.5 apart (9.8 in CIEDE2000). Simulated protanopia and deuteranopia cannot keep twelve
    colours apart: their floor stays 7.5 (HA2G and Mean pose 7.7 for a protanope, Random clip and Trimodal-style 8.3
    for a deuteranope), and Joint Embedding-style stays 30 from every other colour for them too."""
    import itertools

    colours = sorted(set(style.NAMED_SYSTEM_COLOURS.values()))
    joint = style.system_colour("Joint Embedding-style")
    for vision, floor in [("normal", 30.0), ("protanopia", 7.5), ("deuteranopia", 7.5)]:
        for a, b in itertools.combinations(colours, 2):
            distance = float(np.linalg.norm(_cielab(a, vision) - _cielab(b, vision)))
            assert distance >= (30.0 if joint in (a, b) else floor), (vision, a, b, round(distance, 1))


def test_the_same_system_has_the_same_colour_in_every_figure():
    """Two figures with different systems in different orders (notebook 07's ranked bars and points, key frames
    in rows and in columns, an animation's titles) give every label one colour, the one of ``system_colour``."""
    from matplotlib.colors import to_hex

    from beatlite.viz import charts

    seen: dict[str, set[str]] = {}

    def note(label, colour):
        seen.setdefault(label.replace("\n", "").replace("- ", "-"), set()).add(to_hex(colour))

    bars = charts.plot_scores(BENCHMARK_FGD, "FGD").axes[0]
    for handle, label in zip(*bars.get_legend_handles_labels(), strict=True):
        if not label.startswith("_"):
            note(label, handle.patches[0].get_facecolor())
    points = charts.plot_score_scatter(BENCHMARK_FGD, {k: 0.5 for k in BENCHMARK_FGD}, "FGD", "BC").axes[0]
    for handle, label in zip(*points.get_legend_handles_labels(), strict=True):
        note(label, handle.get_facecolor()[0])
    first = ["ground truth", "Mean pose", "Random clip", "S2G-style", "DiffGesture-style", "My model"]
    rows = plot3d.plot_keyframes({k: wave_motion(4) for k in first}, tiny_skeleton(), [0, 2], 15)
    for t in (t for ax in rows.axes for t in ax.texts if t.get_text() in first):
        note(t.get_text(), t.get_color())
    second = ["Trimodal-style", "My model", "Random clip", "CaMN", "A2G-style", "Mean pose", "Other model"]
    cols = plot3d.plot_keyframes(
        {k: wave_motion(4) for k in second}, tiny_skeleton(), [0, 2], 15, systems_in="columns"
    )
    for ax in cols.axes[::2]:
        note(ax.get_title(), ax.title.get_color())
    anim = animation.animate_skeletons({k: wave_motion(4) for k in ["DiffGesture-style", "Random clip"]},
                                       tiny_skeleton(), 15)  # fmt: skip
    for ax in anim.figure.axes:
        if ax.get_title():
            note(ax.get_title(), ax.title.get_color())
    assert {"Random clip", "Mean pose", "My model", "DiffGesture-style", "Trimodal-style"} <= set(seen)
    assert {k: v for k, v in seen.items() if len(v) > 1} == {}  # before: Random clip in 3 colours, ...
    assert all(
        v == {style.system_colour(k)} for k, v in seen.items() if k != "Ground truth (141 Euler channels)"
    )
    plt.close("all")


def test_a_user_label_never_takes_a_course_colour_and_keeps_its_own():
    named = set(style.NAMED_SYSTEM_COLOURS.values())
    assert not named & set(style.OTHER_SYSTEM_COLOURS)
    for label in USER_LABELS:
        assert style.system_colour(label) in style.OTHER_SYSTEM_COLOURS, label
    mixed = _course_labels(main_rows_only=True) + USER_LABELS  # 8 user labels: more than the 6 user colours
    colours = style.system_colours(mixed)
    assert len(set(colours)) == len(mixed)  # distinct in one figure (lighter shades after six)
    user = dict(zip(USER_LABELS, colours[-len(USER_LABELS) :], strict=True))
    assert not set(user.values()) & named
    # the order of a figure's systems (e.g. ranked by a score) does not change them
    assert style.system_colours(mixed[::-1]) == colours[::-1]
    # a user label alone, or beside the course's systems, keeps the colour of system_colour
    assert style.system_colours(["Ground truth", "CaMN", "My model"])[2] == style.system_colour("My model")
    assert style.system_colours(["My model"]) == [style.system_colour("My model")]


@pytest.mark.parametrize("model", ["camn", "ha2g"])
def test_the_bars_of_an_ablation_study_have_one_colour_each(model):
    """BEAT Table 5 (CaMN and its 7 ablations) or HA2G and its 12 ablations as bars: before, a row after the fourth of
    one system took the third lighter shade again (five CaMN ablations in #e3eef6, nearly white), which
    ``check_figure`` reports and ``BEATLITE_FIGURE_CHECK=raise`` refuses to save."""
    from beatlite.train.recipes import RECIPES
    from beatlite.viz import charts

    labels = [r.label for r in RECIPES.values() if r.model == model]
    assert len(labels) in (8, 13)
    ax = charts.plot_scores({label: 1.0 + i for i, label in enumerate(labels)}, "FGD").axes[0]
    assert check.check_figure(ax.figure) == []
    colours = style.system_colours(labels)
    assert len(set(colours)) == len(labels) and colours[0] == style.system_colour(
        labels[0]
    )  # the model keeps its own
    assert style.system_colours(labels[::-1]) == colours[::-1]
    plt.close("all")


def test_a_user_label_has_the_same_colour_in_every_python_process():
    """The colour comes from a checksum of the name, not from Python's salted ``hash``."""
    import os
    import subprocess
    import sys

    code = f"from beatlite.viz.style import system_colour as c; print([c(x) for x in {USER_LABELS!r}])"
    outputs = set()
    for seed in ("1", "2"):
        env = {**os.environ, "PYTHONHASHSEED": seed}
        proc = subprocess.run(
            [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120
        )
        assert proc.returncode == 0, proc.stderr
        outputs.add(proc.stdout)
    assert outputs == {f"{[style.system_colour(x) for x in USER_LABELS]}\n"}


def test_a_legend_of_every_course_system_and_user_models_passes_the_figure_check():
    fig, ax = plt.subplots()
    labels = _course_labels(main_rows_only=True) + USER_LABELS[:3]
    for i, (label, colour) in enumerate(zip(labels, style.system_colours(labels), strict=True)):
        ax.plot([0, 1], [i, i], color=colour, label=label)
    style.legend_outside(ax)
    assert check.check_figure(fig) == []
    plt.close("all")


def test_legend_outside_does_not_cover_the_data():
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1], label="a")
    fig.canvas.draw()
    for where in ("right", "top"):
        leg = style.legend_outside(ax, where)
        fig.canvas.draw()
        box, axes_box = leg.get_window_extent(), ax.get_window_extent()
        assert box.x0 >= axes_box.x1 - 1 if where == "right" else box.y0 >= axes_box.y1 - 1
    with pytest.raises(ValueError, match="where"):
        style.legend_outside(ax, "inside")
    assert style.legend_outside(plt.subplots()[1]) is None  # nothing labelled: no legend
    plt.close("all")


def test_ted43_parents_get_named_groups_and_no_feet():
    bones = _inputs.bone_groups(ted_parents())
    # TED-43: 2 wrists + 30 finger joints are hands; neck, nose, 2 eyes, 2 ears are head; spine,
    # 2 shoulders, 2 elbows are body (module docstring of beatlite.skeleton.ted)
    assert [len(bones.joints[g]) for g in ("body", "hands", "head")] == [5, 32, 6]
    assert not bones.has_feet
    assert _inputs.bone_groups(tiny_skeleton()).has_feet  # RightFoot, LeftFoot
    assert not _inputs.bone_groups(np.array(PARENTS)).has_feet  # unnamed: do not guess a floor
    assert _inputs.joint_group("right_wrist") == "hands" and _inputs.joint_group("left_ear") == "head"


def _floor_lines(ax):
    return [ln for ln in ax.lines if ln.get_color() == "0.75"]


def test_no_floor_under_an_upper_body():
    standing = plot3d.plot_frame(wave_motion(2), tiny_skeleton())
    assert len(_floor_lines(standing.axes[0])) == 1
    upper = plot3d.plot_frame(upper_body(2), ted_parents())
    assert _floor_lines(upper.axes[0]) == []
    forced = plot3d.plot_frame(upper_body(2), ted_parents(), floor=True)
    assert len(_floor_lines(forced.axes[0])) == 1
    plt.close("all")


def test_keyframes_share_one_scale_and_colour_rows_by_system():
    fig = plot3d.plot_keyframes(
        {"ground truth": wave_motion(10), "HA2G": upper_body(10)},
        [tiny_skeleton(), ted_parents()],
        [0, 5],
        15,
    )
    assert len(fig.axes) == 4
    spans = {tuple(np.round([np.diff(ax.get_xlim())[0], np.diff(ax.get_zlim())[0]], 6)) for ax in fig.axes}
    assert len(spans) == 1  # the same box in cm in every panel
    assert [ax.get_title() for ax in fig.axes[:2]] == ["t = 0.0 s", "t = 0.3 s"]
    row_labels = {t.get_text(): t.get_color() for ax in fig.axes for t in ax.texts}
    assert row_labels == {"ground truth": style.SYSTEM_COLOURS[0], "HA2G": style.SYSTEM_COLOURS[2]}
    assert _floor_lines(fig.axes[0]) and not _floor_lines(fig.axes[2])  # floor only under the standing body
    plt.close("all")


def test_keyframes_of_many_systems_fit_a_slide_in_columns():
    """Eleven systems as rows of six key frames made a figure 1.8 times as tall as wide (notebook 08's every
    system: 1004 x 1798 px, shown on a 16:10 slide at a third of its size, its labels 5 px high); as columns it is
    wider than tall, each label above its column and no wider than it."""
    labels = ["ground truth", "Mean pose", "Joint Embedding-style", "DiffGesture-style", "CaMN", "HA2G"]
    labels += [f"Baseline {i}-style" for i in range(5)]
    systems = {label: wave_motion(10) for label in labels}
    rows = plot3d.plot_keyframes(systems, tiny_skeleton(), [0, 2, 4, 5, 7, 9], 15)
    assert rows.get_figheight() > 1.5 * rows.get_figwidth()  # what the notebook drew before
    fig = plot3d.plot_keyframes(
        systems, tiny_skeleton(), [0, 2, 4, 5, 7, 9], 15, systems_in="columns", panel_size=1.2
    )
    width, height = fig.get_size_inches()
    assert width > 1.6 * height and height * 16 / 10 < width  # fits a 16:10 frame by its width
    assert len(fig.axes) == 11 * 6
    tops = fig.axes[::6]  # each system's column, top panel first
    assert [ax.get_title().replace("\n", " ").replace("- ", "-") for ax in tops] == labels
    assert [ax.title.get_color() for ax in tops[:6:4]] == [style.SYSTEM_COLOURS[0], style.SYSTEM_COLOURS[1]]
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    for ax in tops:
        title, panel = ax.title.get_window_extent(renderer), ax.get_window_extent(renderer)
        assert title.width <= panel.width and title.y0 >= panel.y1 - 2  # within its column, above it
    times = [t.get_text() for t in fig.axes[0].texts] + [
        t.get_text() for ax in fig.axes[1:6] for t in ax.texts
    ]
    assert times == ["t = 0.0 s", "t = 0.1 s", "t = 0.3 s", "t = 0.3 s", "t = 0.5 s", "t = 0.6 s"]
    spans = {tuple(np.round([np.diff(ax.get_xlim())[0], np.diff(ax.get_zlim())[0]], 6)) for ax in fig.axes}
    assert len(spans) == 1  # one scale, as in rows
    assert check.check_figure(fig) == [] == check.check_figure(fig, dpi=100, fit=check.SLIDE_FIGURE_BOX)
    small = check.check_figure(rows, dpi=100, fit=check.SLIDE_FIGURE_BOX)  # on a slide, at ~40 % of its size
    assert small and all("shown at" in str(p) for p in small)
    with pytest.raises(ValueError, match="systems_in"):
        plot3d.plot_keyframes(systems, tiny_skeleton(), [0], 15, systems_in="diagonal")
    plt.close("all")


def test_annotation_legend_lists_only_the_gesture_types_it_draws():
    """A segment's bar is its score high: '00_nogesture' (score 0) drew nothing, yet had a legend swatch of its own
    (notebook 01's timeline), a colour to look for that is nowhere in the figure."""
    from beatlite.io.emotion import EmotionSegment
    from beatlite.io.semantic import SemanticSegment
    from beatlite.viz import figures

    semantic = [
        SemanticSegment("00_nogesture", 0.0, 0.7, 0.7, 0.0, ""),
        SemanticSegment("02_deictic_l", 0.7, 2.3, 1.6, 0.3, "my"),
        SemanticSegment("00_nogesture", 2.3, 2.5, 0.2, 0.0, ""),
        SemanticSegment("01_beat_align", 2.5, 4.0, 1.5, 0.1, ""),
    ]
    frames = np.repeat([0.0, 0.3, 0.0, 0.1], 15)
    fig = figures.plot_annotations([EmotionSegment("neutral", 0.0, 4.0, 4.0, 0)], semantic, frames, 15, 4.0)
    legend = fig.axes[1].get_legend()
    assert [t.get_text() for t in legend.get_texts()] == ["01_beat_align", "02_deictic_l"]
    bars = {
        (round(p.get_x(), 3), tuple(p.get_facecolor())) for p in fig.axes[1].patches if p.get_height() > 0
    }
    assert {c for _, c in bars} == {
        tuple(h.get_facecolor()) for h in legend.legend_handles
    }  # each swatch drawn
    assert check.check_figure(fig) == []
    silent = figures.plot_annotations([], semantic[:1], np.zeros(15), 15, 1.0)  # nothing scores: as before
    assert [t.get_text() for t in silent.axes[1].get_legend().get_texts()] == ["00_nogesture"]
    plt.close("all")


def test_annotation_legend_gives_every_gesture_type_its_own_colour():
    """BEAT's ten scoring types and the two its files may also hold (``habit``, ``need_cut``): twelve types drawn,
    twelve colours in the legend (tab10 alone gave 'habit' the colour of '01_beat_align' and 'need_cut' that of
    '02_deictic_l')."""
    from beatlite.io.emotion import EmotionSegment
    from beatlite.io.semantic import SemanticSegment
    from beatlite.viz import figures

    types = [f"{i:02d}_type" for i in range(1, 11)] + ["habit", "need_cut"]
    semantic = [SemanticSegment(t, 2.0 * i, 2.0 * i + 1.5, 1.5, 0.5) for i, t in enumerate(types)]
    fig = figures.plot_annotations(
        [EmotionSegment("neutral", 0.0, 24.0, 24.0, 0)], semantic, np.zeros(24 * 15), 15, 24.0
    )
    legend = fig.axes[1].get_legend()
    assert [t.get_text() for t in legend.get_texts()] == types
    colours = [tuple(h.get_facecolor()) for h in legend.legend_handles]
    assert len(set(colours)) == len(types), colours
    plt.close("all")


def test_beat_curves_take_onsets_and_beats_as_lists():
    """Times as plain lists, as elsewhere in the viz API: ``onsets`` raised "'>=' not supported between instances
    of 'list' and 'float'". Only the onsets inside ``t_range`` draw a line, on every panel."""
    from beatlite.viz import figures

    speed = np.abs((np.arange(90) / 15) % 1.0 - 0.5) * 80  # 6 s at 15 fps
    curves = {"speed": (speed, [0.5, 1.5], "cm/s")}
    fig = figures.plot_beat_curves(np.zeros(6000), 1000, [1.0, 2.0, 7.0], curves, 15, t_range=(0.0, 6.0))
    for ax in fig.axes:
        onset_lines = [line for line in ax.lines if list(line.get_xdata()) in ([1.0, 1.0], [2.0, 2.0])]
        assert len(onset_lines) == 2
        assert not [line for line in ax.lines if list(line.get_xdata()) == [7.0, 7.0]]  # outside t_range
    plt.close(fig)


def _slide_animation(**kwargs):
    sr = 1000
    audio = np.sin(2 * np.pi * 5 * np.arange(2 * sr) / sr)
    face = np.zeros((30, 5))
    face[:, 3] = np.linspace(0, 1, 30)  # the only blendshape that moves
    face[:, 1] = 0.5  # constant
    return animation.animate_skeletons(
        {"CaMN": wave_motion(30), "HA2G": upper_body(30)},
        [tiny_skeleton(), ted_parents()],
        fps=15,
        timeline=animation.Timeline(audio, sr, audio_beats=[0.2, 0.9], motion_beats=[0.5]),
        words=([0.0, 1.0], [0.5, 1.5], ["hello", "world"]),
        face=animation.FacePanel(face, ["a", "b", "c", "d", "e"], top=2),
        **kwargs,
    )


def test_animation_is_slide_size_with_one_scale_and_readable_panels():
    anim = _slide_animation(dpi=100)
    img = anim.frame_image(0)
    assert img.shape[1] == 960  # default width, pixels
    fig = anim.figure
    sk = [ax for ax in fig.axes if ax.name == "3d"]
    assert np.diff(sk[0].get_zlim()) == pytest.approx(np.diff(sk[1].get_zlim()))  # one scale
    assert [ax.get_title() for ax in sk] == ["CaMN", "HA2G"]
    assert [ax.title.get_color() for ax in sk] == [style.SYSTEM_COLOURS[1], style.SYSTEM_COLOURS[2]]
    assert _floor_lines(sk[0]) and not _floor_lines(sk[1])
    timeline, face_ax = fig.axes[2], fig.axes[3]
    # the face rows are the 2 most variable blendshapes, by name, in their order: b (constant) and d
    # have std 0 and > 0; a, c, e are all zero, so the stable sort keeps the first of them: a
    assert [t.get_text() for t in face_ax.get_yticklabels()] == ["a", "d"]
    anim.frame_image(18)  # 15 fps played at 15 fps: t = 1.2 s, the caption reads "world"
    renderer = fig.canvas.get_renderer()
    caption = fig.texts[-1]
    assert caption.get_text() == "world"
    assert caption.get_window_extent(renderer).y0 > timeline.get_tightbbox(renderer).y1  # above the timeline
    legend = timeline.get_legend().get_window_extent(renderer)
    assert legend.x0 >= timeline.get_window_extent(renderer).x1 - 1  # legend right of the data
    assert timeline.get_xlabel() == "time (s)" and timeline.get_ylabel() == "amplitude"


def test_face_panel_and_timeline_check_their_inputs():
    with pytest.raises(ValueError, match="timeline"):
        animation.Timeline().checked()
    with pytest.raises(ValueError, match="kind"):
        animation.FacePanel(np.zeros((3, 2)), kind="pie").checked(15)
    checked = animation.FacePanel(np.zeros((3, 2)), top=None).checked(15)
    assert checked.names == ["blendshape 0", "blendshape 1"] and checked.fps == 15
    with pytest.raises(TypeError, match="unexpected keyword"):
        animation.animate_skeletons(wave_motion(3), tiny_skeleton(), 15, colour="red")


def test_blendshape_heatmap_labels_every_row_by_name_at_a_readable_height():
    w = np.zeros((20, 51))
    w[:, 7] = np.linspace(0, 1, 20)
    names = [f"shape{k}" for k in range(51)]
    fig = face.plot_blendshapes(w, names, fps=60)
    ax = fig.axes[0]
    assert [t.get_text() for t in ax.get_yticklabels()] == names  # first name at the top row
    assert ax.get_ylim()[0] > ax.get_ylim()[1]  # origin upper
    assert fig.get_figheight() >= 51 * face.ROW_INCHES
    top = face.plot_blendshapes(w, names, fps=60, top=3)
    assert "shape7" in [t.get_text() for t in top.axes[0].get_yticklabels()]
    assert face.most_active(w, 1).tolist() == [7]
    plt.close("all")


def test_history_values_and_training_curves_label_every_panel():
    from beatlite.viz import charts

    history = [{"epoch": e, "train": {"rec": 1.0 / (e + 1)}, **({"val_score": 10.0 - e} if e % 2 else {})}
               for e in range(4)]  # fmt: skip
    epochs, values = charts.history_values(history, "val_score")
    assert epochs.tolist() == [1.0, 3.0] and values.tolist() == [9.0, 7.0]
    fig = charts.plot_training_curves(
        history,
        {"loss (Huber)": {"train": "train.rec"}, "FGD": {"val": "val_score"}, "adv": {"g": "train.adv"}},
    )
    assert [ax.get_ylabel() for ax in fig.axes] == ["loss (Huber)", "FGD", "adv"]
    assert [len(ax.lines) for ax in fig.axes] == [1, 1, 0]
    assert fig.axes[2].texts[0].get_text() == "not logged in this run"  # no empty box without a word
    plt.close("all")


def test_score_bars_cut_an_outlier_and_scatter_labels_stay_inside():
    from beatlite.viz import charts

    fgd = {"CaMN": 1.0, "HA2G": 2.0, "mean pose": 25.0}
    ax = charts.plot_scores(fgd, "FGD").axes[0]
    # 25 > 3 x 2 (the median): the axis ends at 1.4 x 2, the bar stops at 1.12 x 2, cut, its value written
    assert ax.get_xlim()[1] == pytest.approx(2.0 * 1.4)
    assert max(p.get_width() for p in ax.patches) == pytest.approx(2.0 * 1.12)
    assert any("25 (cut)" in t.get_text() for t in ax.texts)
    plain = charts.plot_scores({"a": 1.0, "b": 2.0}, "FGD").axes[0]
    assert plain.get_xlim()[1] == pytest.approx(2.0 * 1.12)
    with pytest.raises(ValueError, match="finite"):
        charts.plot_scores({"a": np.nan}, "FGD")
    fig = charts.plot_score_scatter(
        {"CaMN": 1.0, "HA2G": 2.0, "a long model name": 9.0}, {"CaMN": 0.4, "HA2G": 0.5, "a long model name": 0.3},
        "FGD", "BC"
    )  # fmt: skip
    fig.canvas.draw()
    ax = fig.axes[0]
    renderer = fig.canvas.get_renderer()
    labels = [t for t in ax.texts if t.get_text()]
    assert len(labels) == 3 and all(_inside(t.get_window_extent(renderer), ax.get_window_extent(renderer))
                                    for t in labels)  # fmt: skip
    plt.close("all")


#: Notebook 07's one-run FGD column, best first (the mean pose's 25.3 used to set the axis: CaMN vs HA2G in an eighth).
BENCHMARK_FGD = {"Ground truth": 0.0, "Ground truth (141 Euler channels)": 0.0411, "CaMN": 2.97, "HA2G": 3.92,
                 "Random clip": 4.22, "DiffGesture-style": 4.81, "S2G-style": 4.86, "Trimodal-style": 5.31,
                 "A2G-style": 8.0, "Seq2Seq-style": 8.35, "Joint Embedding-style": 10.4, "Mean pose": 25.3}  # fmt: skip


def test_score_bars_of_the_benchmark_cut_only_the_mean_pose_and_give_every_row_its_colour():
    from matplotlib.colors import to_hex

    from beatlite.viz import charts, check

    ax = charts.plot_scores(BENCHMARK_FGD, "FGD").axes[0]
    # median of the 11 positive values 4.86, 3 x 4.86 = 14.6: only 25.3 is cut; the axis ends at 1.4 x 10.4
    assert ax.get_xlim()[1] == pytest.approx(1.4 * 10.4)
    assert [t.get_text().strip() for t in ax.texts if "cut" in t.get_text()] == ["25.3 (cut)"]
    assert (3.92 - 2.97) / ax.get_xlim()[1] > 0.06  # the CaMN-HA2G gap: 1/15 of the axis, was 1/30
    colours = {to_hex(p.get_facecolor()) for p in ax.patches}
    assert len(colours) == len(BENCHMARK_FGD)  # 12 rows, 12 colours (Random clip and Mean pose shared one)
    assert check.check_figure(ax.figure) == []
    plt.close("all")


def test_score_scatter_ties_a_label_that_is_not_beside_its_point():
    from matplotlib.text import Text

    from beatlite.viz import charts

    bc = dict(
        zip(BENCHMARK_FGD, [0.665, 0.67, 0.727, 0.786, 0.51, 0.79, 0.815, 0.75, 0.75, 0.26, 0.125, np.nan])
    )
    fig, ax = plt.subplots(figsize=(5.5, 4.6), layout="constrained")
    ax.set_title("closeness to the data vs synchrony")
    charts.plot_score_scatter(BENCHMARK_FGD, bc, "FGD", "BC", ax=ax)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    assert len(ax.texts) == 11  # the mean pose has no BC
    for note in ax.texts:
        box = Text.get_window_extent(note, renderer)
        point = ax.transData.transform((BENCHMARK_FGD[note.get_text()], bc[note.get_text()]))
        gap = max(box.x0 - point[0], point[0] - box.x1, box.y0 - point[1], point[1] - box.y1, 0.0)
        # beside its point (within 12 points) or tied to it by a visible line
        assert gap <= 12 * fig.dpi / 72 or note.arrow_patch.get_visible(), (note.get_text(), gap)
    plt.close("all")


def test_effects_draw_the_paper_bars_beside_ours_with_error_bars():
    from matplotlib.container import BarContainer, ErrorbarContainer

    from beatlite.viz import charts

    fig = charts.plot_effects(["a", "b"], [10.0, 20.0], [-5.0, 3.0], [1.0, 2.0], "FGD change (%)")
    (ax,) = fig.axes
    bars = [c for c in ax.containers if isinstance(c, BarContainer)]
    assert [p.get_height() for p in bars[0]] == [10.0, 20.0]  # the paper's, no error bar
    assert [p.get_height() for p in bars[1]] == [-5.0, 3.0]
    (errors,) = [c for c in ax.containers if isinstance(c, ErrorbarContainer)]
    spans = [np.ptp(seg[:, 1]) for seg in errors.lines[2][0].get_segments()]
    assert spans == pytest.approx([2.0, 4.0])  # +- the half-lengths given
    assert ax.get_ylabel() == "FGD change (%)" and [t.get_text() for t in ax.get_xticklabels()] == ["a", "b"]
    with pytest.raises(ValueError, match="same length"):
        charts.plot_effects(["a"], [1.0, 2.0], [1.0], [1.0], "x")
    plt.close("all")


def test_signals_label_the_axes_keep_the_legend_outside_and_cut_one_large_swing():
    from beatlite.viz import charts

    t = np.arange(150) / 15
    swing = np.where(np.abs(t - 1.0) < 0.2, 100.0, 0.0)  # one 100 cm/s swing before speech
    speed = 5.0 + 5.0 * np.sin(2 * np.pi * t) + swing
    fig = charts.plot_signals(t, {"wrist": speed}, "wrist speed (cm/s)", events={"onsets": [2.0, 3.0]},
                              markers={"wrist": [2.75]}, clip_quantile=0.9)  # fmt: skip
    ax = fig.axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("time (s)", "wrist speed (cm/s)")
    cut = 1.2 * np.quantile(speed, 0.9)  # the y axis ends near the sine's range, not at 105
    assert ax.get_ylim()[1] == pytest.approx(cut + 0.05 * (cut - speed.min()))
    assert any("cut" in txt.get_text() for txt in ax.texts)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    assert ax.get_legend().get_window_extent(renderer).x0 >= ax.get_window_extent(renderer).x1 - 1
    assert [txt.get_text() for txt in ax.get_legend().get_texts()] == ["wrist", "onsets"]
    with pytest.raises(ValueError, match="curves"):
        charts.plot_signals(t, {"short": speed[:10]}, "x")
    fig = charts.plot_signals(t, {"a": speed, "b": speed}, "score", xlabel="motion shifted by (s)", title="T",
                              styles={"b": {"ls": "--"}})  # fmt: skip
    ax = fig.axes[0]
    assert (ax.get_xlabel(), ax.get_title()) == ("motion shifted by (s)", "T")
    assert [ln.get_linestyle() for ln in ax.lines if ln.get_label() in ("a", "b")] == ["-", "--"]
    plt.close("all")


def test_waveform_has_an_amplitude_axis_and_the_words_of_the_window():
    from beatlite.viz import charts

    sr = 1000
    y = 0.5 * np.sin(2 * np.pi * 50 * np.arange(3 * sr) / sr)
    words = ([0.2, 1.0, 2.5], [0.6, 1.4, 2.9], ["one", "two", "three"])
    y[int(2.5 * sr)] = 1.0  # a click after the window shown
    ax = charts.plot_waveform(y, sr, words=words, onsets={"onsets": [0.2]}, xlim=(0, 2), title="t").axes[0]
    assert ax.get_ylabel() == "amplitude (full scale = 1)" and ax.get_xlabel() == "time (s)"
    assert [t.get_text() for t in ax.texts] == ["one", "two"]  # "three" starts after the 2 s shown
    assert ax.get_xlim() == (0.0, 2.0) and ax.get_title() == "t"
    assert ax.get_ylim() == pytest.approx((-1.05 * 0.5, 1.45 * 0.5), rel=1e-3)  # the click sets no scale
    assert ax.lines[0].get_xdata().max() <= 2.0 + 1.0 / sr  # only the window's samples are drawn
    plt.close("all")


def test_log_mel_spans_its_frames_in_seconds_with_its_bands_and_events():
    """M frames at ``frame_rate`` span M / frame_rate seconds; B bands are labelled 0..B-1; each event is one line;
    the colour bar says the level's reference; a 1-D input is refused."""
    from beatlite.viz import charts

    mel = np.linspace(-80.0, 0.0, 70 * 128).reshape(70, 128)
    fig = charts.plot_log_mel(mel, 31.25, events=[0.5, 1.0], title="t")
    ax, bar = fig.axes
    assert ax.images[0].get_extent() == [0.0, 70 / 31.25, 0, 128] and ax.get_xlim() == (0.0, 70 / 31.25)
    assert (
        ax.get_ylabel() == "mel band (index, 0-127)"
        and ax.get_xlabel() == "time (s)"
        and ax.get_title() == "t"
    )
    assert sorted(line.get_xdata()[0] for line in ax.lines) == [0.5, 1.0]
    assert bar.get_ylabel() == "level (dB, 0 = the take's peak)"
    np.testing.assert_array_equal(ax.images[0].get_array(), mel.T)  # bands up, time across
    assert charts.plot_log_mel(mel, 31.25, xlim=(0, 1)).axes[0].get_xlim() == (0.0, 1.0)
    with pytest.raises(ValueError, match="non-empty"):
        charts.plot_log_mel(np.zeros(70), 31.25)
    plt.close("all")


def test_blendshape_curves_show_the_most_active_not_the_flat_ones():
    w = np.zeros((120, 4))
    w[:, 2] = 0.5 + 0.5 * np.sin(np.arange(120) / 10)
    w[:, 0] = np.linspace(0, 0.2, 120)
    fig = face.plot_blendshape_curves(w, ["a", "b", "c", "d"], fps=60, top=2)
    ax = fig.axes[0]
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["a", "c"]
    assert ax.get_ylabel() == "weight (0-1)"
    assert ax.lines[0].get_xdata()[-1] == pytest.approx(119 / 60)  # seconds
    plt.close("all")


def test_bone_levels_mark_the_new_bones_of_each_level_on_shared_limits():
    from beatlite.skeleton import ted
    from beatlite.viz import check

    pose = upper_body(1)[0]
    levels = ted.HA2G_LEVELS
    fig = plot3d.plot_bone_levels(pose, ted.TED_BONES, levels, names=ted.TED43_JOINTS, zoom="right_wrist")
    # rows: levels 1-3 (body), levels 4-6 (body), levels 4-6 (right hand): the right hand's 15 finger bones
    # arrive in levels 4-6, so levels 1-3 get no hand row (it was three panels saying "no bones here yet")
    assert len(fig.axes) == 9
    body, hands = fig.axes[:6], fig.axes[6:]
    red = style.GROUP_COLOURS["hands"]
    for k, ax in enumerate(body):  # thick red lines = the bones this level adds (levels are cumulative)
        added = len(levels[k]) - (len(levels[k - 1]) if k else 0)
        assert sum(line.get_color() == red for line in ax.lines) == added
    assert len({(ax.get_xlim(), ax.get_ylim()) for ax in body}) == 1  # one scale for every level
    assert [ax.get_title()[:8] for ax in hands] == ["level 4:", "level 5:", "level 6:"]
    assert [len(ax.lines) for ax in hands] == [5, 10, 15]  # 5 finger bones per level
    assert check.check_figure(fig) == []  # no empty panel
    # two levels a row: the row of levels 3-4 has hand bones only in level 4; level 3's hand panel shows the
    # 15 bones to come, dotted, instead of nothing
    fig = plot3d.plot_bone_levels(
        pose, ted.TED_BONES, levels, names=ted.TED43_JOINTS, zoom="right_wrist", ncols=2
    )
    assert len(fig.axes) == 10
    ghost = fig.axes[4]
    assert ghost.get_title().startswith("level 3:") and [t.get_text() for t in ghost.texts] == [
        "none of these bones yet"
    ]
    assert len(ghost.lines) == 15 and all(line.get_linestyle() == ":" for line in ghost.lines)
    assert check.check_figure(fig) == []
    plt.close("all")


def test_inline_player_resolution_and_format_are_chosen_per_call():
    anim = animation.animate_skeletons(wave_motion(4), tiny_skeleton(), 15, max_frames=2)
    small, large = anim.to_html(dpi=20), anim.to_html(dpi=80)  # a second call is not the cached first one
    assert len(small) < len(large)
    assert "data:image/jpeg" in anim.to_html(dpi=20, frame_format="jpeg")
    assert "data:image/png" in small


def test_inline_player_text_is_checked_at_the_size_it_is_shown(monkeypatch):
    """Notebooks 05 and 08 embedded their players at dpi=60 (576 px): 9-pt ticks and legends 7.5 px high."""
    from beatlite.viz import check

    timeline = animation.Timeline(np.zeros(16000), 16000, np.array([0.5]), np.array([1.0]))
    anim = animation.animate_skeletons({"ground truth": wave_motion(4), "CaMN": wave_motion(4)}, tiny_skeleton(), 15,
                                       timeline=timeline, max_frames=2)  # fmt: skip
    problems = check.check_figure(anim.figure, dpi=60)
    assert problems and {p.kind for p in problems} == {"small text"}
    assert any("'audio beats' is 7.5 px" in p.detail for p in problems)  # 9 pt x 60 / 72
    assert check.check_figure(anim.figure, dpi=80) == []  # 768 px: 9 pt = 10 px
    monkeypatch.setenv("BEATLITE_FIGURE_CHECK", "raise")
    with pytest.raises(check.FigureError, match="to_html\\(dpi=60\\)"):
        anim.to_html(dpi=60)
    html = anim.to_html(dpi=80, frame_format="jpeg")
    assert "data:image/jpeg" in html
    first = anim.frame_image(0)
    assert first.shape[1] == 960  # the check drew the figure at its own size; the player restarts at frame 0
    plt.close("all")


def test_score_scatter_labels_of_close_points_do_not_overlap():
    from beatlite.viz import charts

    x = {"Ground truth": 0.0, "Ground truth (141 Euler channels)": 0.04, "CaMN": 3.0, "HA2G": 3.1}
    y = {"Ground truth": 0.66, "Ground truth (141 Euler channels)": 0.67, "CaMN": 0.73, "HA2G": 0.74}
    fig = charts.plot_score_scatter(x, y, "FGD", "BC")
    fig.canvas.draw()
    boxes = [t.get_window_extent() for t in fig.axes[0].texts]
    assert len(boxes) == 4
    for i in range(4):
        for j in range(i + 1, 4):
            assert not boxes[i].overlaps(boxes[j]), (
                fig.axes[0].texts[i].get_text(),
                fig.axes[0].texts[j].get_text(),
            )


def test_score_scatter_labels_cover_no_marker_and_stay_inside():
    """Notebook 07's crowded corner: HA2G, S2G and Trimodal within 1.4 FGD and 0.03 BC of each other
    (a label written beside its point crossed the next marker before)."""
    from beatlite.viz import charts

    names = ["CaMN", "HA2G", "S2G-style", "Trimodal-style", "A2G-style", "Mean"]
    x = dict(zip(names, [2.97, 3.92, 4.86, 5.31, 8.0, 0.0], strict=True))
    y = dict(zip(names, [0.727, 0.786, 0.815, 0.784, 0.75, 0.66], strict=True))
    fig = charts.plot_score_scatter(x, y, "FGD", "BC")
    fig.canvas.draw()
    ax = fig.axes[0]
    labels = [t.get_window_extent() for t in ax.texts]
    points = ax.transData.transform(np.column_stack([list(x.values()), list(y.values())]))
    assert len(labels) == len(x)
    for text, box in zip(ax.texts, labels, strict=True):
        assert _inside(box, ax.get_window_extent()), text.get_text()
        # no marker centre under a label, and no other label overlapping it
        assert not any(box.contains(px, py) for px, py in points), text.get_text()
        assert sum(box.overlaps(other) for other in labels) == 1, text.get_text()
    plt.close("all")


def _figures_made_outside_the_style(notebook: str) -> list[str]:
    """Calls of a notebook that make a figure (``plt.subplots``, ``plt.figure``, ``plt.subplot_mosaic``) outside a
    ``with bl.viz.figure_style():`` block, as ``"cell N: call"``."""
    import ast
    import json
    from pathlib import Path

    nb = json.loads((Path(__file__).resolve().parents[1] / "notebooks" / notebook).read_text())
    found = []
    for i, cell in enumerate(nb["cells"]):
        if cell["cell_type"] != "code":
            continue
        lines = "".join(cell["source"]).splitlines()
        tree = ast.parse("\n".join(line for line in lines if not line.lstrip().startswith(("%", "!"))))
        styled = {
            id(node)
            for block in ast.walk(tree)
            if isinstance(block, ast.With) and any("figure_style" in ast.unparse(w) for w in block.items)
            for node in ast.walk(block)
        }
        for node in ast.walk(tree):
            name = ast.unparse(node.func) if isinstance(node, ast.Call) else ""
            if name in ("plt.subplots", "plt.figure", "plt.subplot_mosaic") and id(node) not in styled:
                found.append(f"cell {i}: {name}")
    return found


def test_notebook_09_makes_its_figures_in_the_beatlite_style():
    """Notebook 09's four figures are drawn inside ``bl.viz.figure_style()`` (fonts, grid, spines, the style's
    colours), as the library's plot functions draw theirs (before: matplotlib's defaults, its one-series curves in
    CaMN's blue)."""
    assert _figures_made_outside_the_style("09_scoring.ipynb") == []
