"""beatlite.score: scoring a folder of another model's outputs, its checks, intervals and the round trip."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from beatlite.io import FormatError, read_bvh, write_bvh  # noqa: E402
from beatlite.io.motion import Motion  # noqa: E402
from beatlite.metrics.scoring import METRICS, GroundTruth, Takes  # noqa: E402
from beatlite.paths import checkpoints_dir  # noqa: E402
from beatlite.score import (  # noqa: E402
    ScoreInputError,
    ScoreWarning,
    bootstrap_intervals,
    export_checkpoint_takes,
    export_ground_truth,
    main,
    match_predictions,
    mean_interval,
    read_prediction,
    score_folder,
    self_check,
)
from beatlite.skeleton.beat import JOINT_SUBSETS, beat_skeleton  # noqa: E402
from beatlite.skeleton.core import Skeleton  # noqa: E402
from beatlite.skeleton.rotations import euler_to_matrix, matrix_to_euler  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
KEYS = list(METRICS)
REPRESENTATIVE = ("camn_tiny", "ha2g_tiny", "mean_pose")  # an Euler model, a direction model, a baseline


@pytest.fixture(scope="module")
def test_set():
    from beatlite.score import load_split

    return load_split(REPO / "data_samples", "test")


@pytest.fixture(scope="module")
def library(test_set):
    """The in-library numbers: evaluate_models' rows (ground truth and the representative checkpoints)."""
    from beatlite.train.evaluation import evaluate_models

    missing = [n for n in REPRESENTATIVE if not (checkpoints_dir() / f"{n}.pt").is_file()]
    if missing:
        pytest.skip(f"checkpoints {missing} not shipped")
    return evaluate_models(list(REPRESENTATIVE), test=test_set, columns=KEYS)


@pytest.fixture(scope="module")
def truth_files(test_set, tmp_path_factory):
    """The test split's own motion as {stem}.bvh files (15 fps, 228 channels)."""
    out = tmp_path_factory.mktemp("truth")
    export_ground_truth(test_set, out)
    return out


def _assert_same_scores(
    got: dict[str, float], want: dict[str, float], label: str, atol: float = 1e-8
) -> None:
    """Equal to rtol 1e-6; ``atol`` for values that are 0 by definition (a constant pose's L1div is 2e-9 of
    round-off; the ground truth's own MPJPE is 2e-7 cm of its float32 storage)."""
    for key in KEYS:
        a, b = got[key], want[key]
        if np.isnan(b):
            assert np.isnan(a), (label, key, a)
        else:
            np.testing.assert_allclose(a, b, rtol=1e-6, atol=atol, err_msg=f"{label} {key}")


def _run_cli(*args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(REPO), "BEATLITE_THREADS": "1"}
    return subprocess.run(
        [sys.executable, "-m", "beatlite.score", *args], capture_output=True, text=True, env=env, cwd=REPO
    )


# ----------------------------------------------------------------------------- self-check
def test_self_check_gives_zero_fgd_and_the_ground_truths_own_values(test_set, library):
    result = self_check(test=test_set)
    values = result.evaluation.values()
    assert values["FGD"] < 1e-6 and values["FGD (reference)"] < 1e-6 and values["FGD (BEAT AE)"] < 1e-6
    assert values["PCK"] == 1.0 and values["MPJPE"] < 1e-4
    key, gap = result.info["self_check"]["largest_gap"]
    assert gap < 1e-6 and f"{gap:.2g} ({key};" in result.to_markdown()
    # the ground truth's values as the in-library results table computes them (its "Ground truth" row)
    _assert_same_scores(values, library.get("Ground truth").metrics, "self-check", atol=1e-6)
    _assert_same_scores(result.truth.values(), library.get("Ground truth").metrics, "ground truth column")


def test_import_does_not_import_torch():
    code = "import sys, beatlite.score; assert 'torch' not in sys.modules, 'torch imported'"
    subprocess.run([sys.executable, "-c", code], check=True, env={**os.environ, "PYTHONPATH": str(REPO)})


def test_a_split_loaded_directly_names_its_data_folder(test_set):
    """``score_folder(..., test=load_test_set(index))`` names the data folder like ``load_split`` does (its caption
    said "the `test` split of ``")."""
    from beatlite.data.index import index_folder
    from beatlite.train.testset import load_test_set

    direct = load_test_set(index_folder(REPO / "data_samples"))
    assert direct.folder == test_set.folder == str((REPO / "data_samples").resolve())
    result = self_check(test=direct, metrics=["PCK"])
    assert result.info["data"] == "data_samples"  # relative to the repository (paths.shareable)
    assert "split of `data_samples`" in result.to_markdown()


def test_a_report_names_no_folder_of_the_machine_that_wrote_it(test_set, truth_files, tmp_path):
    """The JSON and Markdown reports name the predictions, the data folder and the FGD extractor without the
    writer's folders (before: absolute paths such as ``/home/alice/outputs``, naming the home folder and user):
    by their names, or as given when relative; the sha256 values identify them."""
    import dataclasses
    import hashlib

    home = tmp_path / "home" / "alice"
    pred, extractor = home / "outputs", home / "my_fgd.pt"
    shutil.copytree(truth_files, pred)
    shutil.copy(checkpoints_dir() / "fgd_dirvec.pt", extractor)
    elsewhere = dataclasses.replace(test_set, folder=str(home / "beat_english"))  # data in the home folder
    result = score_folder(pred, test=elsewhere, metrics=["PCK"], extractor=extractor)
    assert (result.info["pred"], result.info["data"], result.info["extractor"]) == (
        "outputs",
        "beat_english",
        "my_fgd.pt",
    )
    for text in (json.dumps(result.to_dict()), result.to_markdown()):
        assert str(tmp_path) not in text and "alice" not in text, text
    digest = hashlib.sha256((checkpoints_dir() / "fgd_dirvec.pt").read_bytes()).hexdigest()
    assert result.info["extractor_sha256"] == digest[:16]  # the extractor stays identified


# ----------------------------------------------------------------------------- round trip
@pytest.mark.parametrize("name", REPRESENTATIVE)
def test_exported_then_scored_equals_the_in_library_evaluation(name, test_set, library, tmp_path):
    files = export_checkpoint_takes(name, tmp_path, test=test_set)
    assert [f.name.split(".")[0] for f in files] == list(test_set.takes)
    if library.get(name).representation == "euler141":
        motion = read_bvh(files[0])
        assert motion.fps == 15 and motion.skeleton.same_topology(beat_skeleton())
    else:
        assert files[0].suffix == ".npy" and np.load(files[0]).shape[1:] == (42, 3)
    result = score_folder(tmp_path, test=test_set)
    _assert_same_scores(result.evaluation.values(), library.get(name).metrics, name)


def test_the_clips_protocol_exports_and_scores_ha2g_evaluator_clips(test_set, tmp_path):
    """``--protocol clips``: one 34-frame prediction {stem}@{start} per window, each generated from its own seed
    frames, scores as evaluate_models on clip_test_set; the ground truth's clips self-check to FGD 0."""
    from beatlite.score import load_split
    from beatlite.train.evaluation import evaluate_models
    from beatlite.train.testset import clip_test_set

    clips = load_split(REPO / "data_samples", protocol="clips")
    assert clips.takes == clip_test_set(test_set).takes and clips.folder == test_set.folder
    starts = [int(t.partition("@")[2]) for t in clips.takes if t.startswith(test_set.takes[0] + "@")]
    assert starts == list(range(0, test_set.gt_directions[0].shape[0] - 33, 10))
    keys = ["FGD", "BC (ha2g)", "BC (ha2g published)", "Diversity (ha2g)", "SRGR"]
    want = evaluate_models(["ha2g_tiny"], test=clips, columns=keys).get("ha2g_tiny").metrics
    out = tmp_path / "clips"
    r = _run_cli(
        str(out), "--export", "ha2g_tiny", "--protocol", "clips", "--data", str(REPO / "data_samples")
    )
    assert r.returncode == 0, r.stderr
    assert sorted(p.name.split(".")[0] for p in out.iterdir()) == sorted(clips.takes)
    assert all(np.load(p).shape == (34, 42, 3) for p in out.iterdir())
    got = score_folder(out, test=clips, metrics=keys).evaluation.values()
    for key in keys:
        np.testing.assert_allclose(got[key], want[key], rtol=1e-6, err_msg=key)
    truth = self_check(test=clips, metrics=["FGD", "PCK"]).evaluation.values()
    assert truth["FGD"] < 1e-6 and truth["PCK"] == 1.0


def test_an_euler_model_exported_as_npy_scores_the_same(test_set, library, tmp_path):
    files = export_checkpoint_takes("camn_tiny", tmp_path, test=test_set, format="npy")
    assert np.load(files[0], allow_pickle=False).shape[1:] == (141,)
    _assert_same_scores(
        score_folder(tmp_path, test=test_set).evaluation.values(), library.get("camn_tiny").metrics, "npy"
    )


@pytest.mark.slow
def test_every_shipped_checkpoint_round_trips(test_set, tmp_path):
    from beatlite.train.evaluation import evaluate_models
    from beatlite.train.recipes import RECIPES

    names = [n for n in RECIPES if (checkpoints_dir() / f"{n}.pt").is_file()]
    if not names:
        pytest.skip("no shipped checkpoints")
    res = evaluate_models(names, test=test_set, columns=KEYS, ground_truth=False)
    for name in names:
        folder = tmp_path / name
        export_checkpoint_takes(name, folder, test=test_set)
        _assert_same_scores(
            score_folder(folder, test=test_set).evaluation.values(), res.get(name).metrics, name
        )


# ----------------------------------------------------------------------------- conversions
def test_a_bvh_at_30_fps_is_resampled_to_the_takes_frames(test_set):
    """The corpus' own 30 fps BVH of a test take reads as the take's 15 fps ground truth."""
    stem = test_set.takes[0]
    pred = read_prediction(REPO / "data_samples" / f"{stem}.bvh.gz")
    n = len(test_set.gt_directions[0])
    assert pred.n_frames >= n and "30 fps -> 15 fps" in pred.form
    np.testing.assert_allclose(pred.directions[:n], test_set.gt_directions[0], atol=1e-5)  # GT is float32
    np.testing.assert_allclose(pred.euler[:n], test_set.gt_euler[0], atol=1e-9)


def _reordered(motion: Motion, order: str) -> Motion:
    """The same motion with every joint's rotation channels in ``order`` (scipy does the conversion)."""
    from scipy.spatial.transform import Rotation

    skel = motion.skeleton
    channels, out = [], []
    for j in range(skel.n_joints):
        cols = skel.rotation_channel_indices(j)
        angles = Rotation.from_euler(skel.rotation_order(j), motion.channels[:, cols], degrees=True)
        pos = skel.position_channel_indices(j)
        channels.append(tuple(skel.channels[j][: len(pos)]) + tuple(f"{a}rotation" for a in order))
        out += [motion.channels[:, pos], angles.as_euler(order, degrees=True)]
    return Motion(
        Skeleton(skel.names, skel.parents, skel.offsets, tuple(channels)), np.hstack(out), motion.fps
    )


def _without(motion: Motion, words: tuple[str, ...]) -> Motion:
    """The motion on the skeleton without the joints whose names hold one of ``words``."""
    skel = motion.skeleton
    keep = [j for j, n in enumerate(skel.names) if not any(w in n for w in words)]
    new = {j: i for i, j in enumerate(keep)}
    parents = np.array([new.get(int(skel.parents[j]), -1) for j in keep])  # a dropped root: the child is root
    cols = np.concatenate(
        [np.arange(s, s + len(skel.channels[j])) for j, s in enumerate(skel.channel_starts) if j in new]
    )
    sub = Skeleton(
        tuple(skel.names[j] for j in keep), parents, skel.offsets[keep], tuple(skel.channels[j] for j in keep)
    )
    return Motion(sub, motion.channels[:, cols], motion.fps)


def test_another_channel_order_and_a_joint_subset_read_as_the_same_directions(
    truth_files, test_set, tmp_path
):
    stem = test_set.takes[1]
    motion = read_bvh(truth_files / f"{stem}.bvh")
    motion.channels[:, 3:6] += 10.0  # a root rotation, so the conversion of the root is exercised too
    write_bvh(tmp_path / "xyz.bvh", motion, precision=12)
    reference = read_prediction(tmp_path / "xyz.bvh")
    write_bvh(tmp_path / "zxy.bvh", _reordered(motion, "ZXY"), precision=12)
    write_bvh(tmp_path / "upper.bvh", _without(motion, ("UpLeg", "Leg", "Foot", "Toe")), precision=12)
    for name in ("zxy.bvh", "upper.bvh"):
        pred = read_prediction(tmp_path / name)
        np.testing.assert_allclose(pred.directions, reference.directions, atol=1e-9, err_msg=name)
        np.testing.assert_allclose(pred.euler, reference.euler, atol=1e-7, err_msg=name)
    # without Hips (root Spine) the body's rotation is BEAT's rest: as the file with the root rotation zeroed
    write_bvh(
        tmp_path / "no_hips.bvh", _without(motion, ("Hips", "UpLeg", "Leg", "Foot", "Toe")), precision=12
    )
    motion.channels[:, :6] = 0.0
    write_bvh(tmp_path / "rest_root.bvh", motion, precision=12)
    np.testing.assert_allclose(
        read_prediction(tmp_path / "no_hips.bvh").directions, read_prediction(tmp_path / "rest_root.bvh").directions,
        atol=1e-9,
    )  # fmt: skip


def test_another_skeleton_is_refused_naming_file_and_field(real_samples):
    path = real_samples / "dataset-1_bye_normal_001.bvh"
    with pytest.raises(FormatError) as info:
        read_prediction(path)
    assert info.value.field == "HIERARCHY" and info.value.path == path
    assert "not BEAT's skeleton" in str(info.value) and "\n" not in str(info.value)


def test_npy_representations(test_set, tmp_path):
    from beatlite.skeleton.ted import euler_to_directions

    d, e = test_set.gt_directions[0], test_set.gt_euler[0]
    np.save(tmp_path / "d126.npy", d.reshape(len(d), 126))
    np.save(tmp_path / "e141.npy", e)
    np.testing.assert_allclose(read_prediction(tmp_path / "d126.npy").directions, d, atol=1e-12)
    pred = read_prediction(tmp_path / "e141.npy")
    np.testing.assert_array_equal(pred.euler, e)
    np.testing.assert_allclose(pred.directions, euler_to_directions(e), atol=1e-12)
    np.save(tmp_path / "long.npy", 2.0 * d)  # not unit: normalised with a warning
    with pytest.warns(ScoreWarning, match="not unit vectors"):
        np.testing.assert_allclose(read_prediction(tmp_path / "long.npy").directions, d, atol=1e-12)


@pytest.mark.parametrize(
    ("array", "field"),
    [
        (np.zeros((40, 40)), "shape"),
        (np.full((40, 141), np.nan), "values"),
        (np.array([{"a": 1}], dtype=object), "dtype"),  # a pickled object: refused, never unpickled
        (np.zeros((40, 42, 3)), "values"),  # zero direction vectors
    ],
)
def test_bad_npy_files_are_format_errors(array, field, tmp_path):
    path = tmp_path / "bad.npy"
    np.save(path, array, allow_pickle=True)
    with pytest.raises(FormatError) as info:
        read_prediction(path)
    assert info.value.field == field and info.value.path == path


def test_npy_files_whose_header_or_values_cannot_be_read_are_format_errors(tmp_path):
    import gzip
    import io

    header = io.BytesIO()  # a header claiming 10^11 frames in a 250 kB file: refused before allocating 113 TB
    np.lib.format.write_array_header_1_0(
        header, {"descr": "<f8", "fortran_order": False, "shape": (10**11, 141)}
    )
    (tmp_path / "huge.npy").write_bytes(header.getvalue() + bytes(250_000))
    np.save(tmp_path / "long.npy", np.ones((40, 42, 3)) * 1e200)  # finite, but its norms overflow
    np.save(tmp_path / "plain.npy", np.ones((40, 141)))
    (tmp_path / "gz.npy").write_bytes(gzip.compress((tmp_path / "plain.npy").read_bytes()))
    cases = {"huge": ("shape", "needs 112800000000000 bytes, the file holds 250000"),
             "long": ("values", "too long to normalise"), "gz": (None, "gzip")}  # fmt: skip
    for name, (field, text) in cases.items():
        with pytest.raises(FormatError) as info:
            read_prediction(tmp_path / f"{name}.npy")
        assert info.value.field == field and text in str(info.value), (name, str(info.value))


def _rewritten(src: Path, dst: Path, change: Any) -> None:
    """Every BVH of ``src`` written to ``dst`` with ``change(skeleton, channels)`` applied."""
    dst.mkdir()
    for path in sorted(src.glob("*.bvh")):
        m = read_bvh(path)
        write_bvh(dst / path.name, Motion(*change(m.skeleton, m.channels.copy()), m.fps), precision=12)


def test_euler_angles_written_from_matrices_score_as_the_ground_truth(truth_files, test_set, tmp_path):
    """A model that writes its rotations through matrices (scipy's as_euler) puts every joint on |Y| <= 90° in
    (-180, 180], where the ground truth's tracks are continuous: the same motion must score as the ground truth in
    the Euler metrics too (before: FGD (BEAT AE) 5.5e7, the reference L1div 472 against 311)."""

    def principal(skel: Skeleton, ch: np.ndarray) -> tuple[Skeleton, np.ndarray]:
        for j in range(skel.n_joints):
            cols = skel.rotation_channel_indices(j)
            ch[:, cols] = matrix_to_euler(euler_to_matrix(ch[:, cols], "XYZ"), "XYZ")
        for name in JOINT_SUBSETS["spine_neck_141"][3:5]:  # and 360° turns of two joints, every other frame
            ch[::2, skel.rotation_channel_indices(skel.index(name))] += 360.0
        return skel, ch

    _rewritten(truth_files, tmp_path / "pred", principal)
    keys = ["FGD (BEAT AE)", "SRGR (reference)", "L1div (reference)", "MPJPE"]
    with pytest.warns(ScoreWarning, match="on the ground truth's representation"):
        result = score_folder(tmp_path / "pred", test=test_set, metrics=keys)
    n_frames = sum(len(d) for d in test_set.gt_directions)
    assert n_frames < result.info["euler_rewritten"] < 47 * n_frames  # the turns, and some other branches
    got, own = result.evaluation.values(), result.truth.values()
    assert got["FGD (BEAT AE)"] < 1e-6 and got["MPJPE"] < 1e-4
    for key in ("SRGR (reference)", "L1div (reference)"):
        assert got[key] == pytest.approx(own[key], rel=1e-6), key
    plain = score_folder(
        truth_files, test=test_set, metrics=keys[:1]
    )  # already the truth's angles: untouched
    assert plain.info["euler_rewritten"] == 0


def test_a_frozen_prediction_half_a_turn_from_the_truth_stays_frozen(test_set, tmp_path):
    """Each take's first frame held, one channel set 180° from the ground truth's median: the truth swings to
    either side of it, so frame-by-frame nearest angles would alternate between two 360° offsets (a reviewer
    measured L1div 70.3 for this frozen system); anchored at the first frame and kept continuous, it stays
    frozen: L1div 0."""
    channel = int(np.argmax(np.concatenate(test_set.gt_euler).std(axis=0)))
    for stem, truth in zip(test_set.takes, test_set.gt_euler, strict=True):
        frozen = np.repeat(truth[:1], len(truth), axis=0)
        frozen[:, channel] = np.median(truth[:, channel]) + 180.0
        np.save(tmp_path / f"{stem}.npy", frozen)
    result = score_folder(tmp_path, test=test_set, metrics=["L1div (reference)", "L1div"])
    assert result.evaluation.get("L1div (reference)").value == pytest.approx(0.0, abs=1e-9)


def test_a_rotated_root_above_hips_turns_the_body(truth_files, test_set, tmp_path):
    """A root joint above Hips (e.g. a Z-up to Y-up correction) turns the whole body: read as the same turn on
    Hips. A root at rest changes nothing."""
    stem = test_set.takes[0]
    m = read_bvh(truth_files / f"{stem}.bvh")
    skel, zxy = m.skeleton, ("Zrotation", "Xrotation", "Yrotation")
    above = Skeleton(("Reference", *skel.names), np.concatenate([[-1], np.asarray(skel.parents) + 1]),
                     np.vstack([[0.0, 0.0, 0.0], skel.offsets]), (zxy, *skel.channels))  # fmt: skip
    for turn in (0.0, 90.0):
        rows = np.hstack([np.tile([turn, 0.0, 0.0], (m.n_frames, 1)), m.channels])  # Z by `turn` degrees
        write_bvh(tmp_path / "above.bvh", Motion(above, rows, m.fps), precision=12)
        on_hips = m.channels.copy()
        hips = skel.rotation_channel_indices(0)
        rz = euler_to_matrix(np.array([turn, 0.0, 0.0]), "ZXY")
        on_hips[:, hips] = matrix_to_euler(rz @ euler_to_matrix(on_hips[:, hips], "XYZ"), "XYZ")
        write_bvh(tmp_path / "hips.bvh", Motion(skel, on_hips, m.fps), precision=12)
        with pytest.warns(ScoreWarning, match="Reference"):
            got = read_prediction(tmp_path / "above.bvh")
        want = read_prediction(tmp_path / "hips.bvh")
        np.testing.assert_allclose(got.directions, want.directions, atol=1e-9, err_msg=f"{turn}°")
        if turn == 0.0:
            np.testing.assert_allclose(got.directions, test_set.gt_directions[0], atol=1e-5)
        else:
            assert np.abs(got.directions - test_set.gt_directions[0]).max() > 0.5  # turned, not ignored


def test_match_predictions_skips_hidden_files_and_lists_the_rest(tmp_path):
    names = [
        "a.bvh",
        "b.BVH",
        "._a.bvh",
        "._c.bvh",
        ".DS_Store",
        "model.bvh",
        "model.npy",
        "c.bvh.bak",
        "x.txt",
    ]
    for name in names:
        (tmp_path / name).write_bytes(b"")
    files, missing, extra = match_predictions(tmp_path, ["a", "b", "c"])
    assert {k: p.name for k, p in files.items()} == {"a": "a.bvh", "b": "b.BVH"} and missing == ["c"]
    assert extra == ["c.bvh.bak", "model.bvh", "model.npy", "x.txt"]  # two of a stem of no take: no error
    (tmp_path / "a.npy").write_bytes(b"")
    with pytest.raises(ScoreInputError, match="several predictions"):
        match_predictions(tmp_path, ["a", "b", "c"])


def test_cli_mistakes_are_one_error_line(truth_files, tmp_path, capsys):
    data = str(REPO / "data_samples")
    (tmp_path / "empty").mkdir()
    (tmp_path / "a_folder").mkdir()
    cases = {
        "--json a folder": (
            [str(truth_files), "--data", data, "--json", str(tmp_path / "a_folder")],
            "--json",
        ),
        "--md in no folder": (
            [str(truth_files), "--data", data, "--md", str(tmp_path / "no" / "x.md")],
            "--md",
        ),
        "--bootstrap -1": ([str(truth_files), "--data", data, "--bootstrap", "-1"], "--bootstrap -1"),
        "no such split": ([str(truth_files), "--data", data, "--split", "nosuch"], "'nosuch' split"),
        "nothing to score": (
            [str(tmp_path / "empty"), "--data", data, "--allow-missing"],
            "any of the 8 takes",
        ),
        # a rate below a BVH's 1 fps asked for 1e301 frames: a bare ValueError or ZeroDivisionError before
        "--pred-fps 1e-300": (
            [str(truth_files), "--data", data, "--pred-fps", "1e-300"],
            "from 1 to 100000 fps",
        ),
        "--pred-fps 0": ([str(truth_files), "--data", data, "--pred-fps", "0"], "pred_fps 0.0"),
    }
    for label, (argv, text) in cases.items():
        assert main(argv) == 2, label
        err = capsys.readouterr().err.strip().splitlines()
        errors = [line for line in err if line.startswith("error: ")]
        assert len(errors) == 1 and text in errors[0] and "Traceback" not in "\n".join(err), (label, err)


def test_exporting_a_hostile_checkpoint_is_one_error_line_naming_the_field(tmp_path, capsys):
    """docs/architecture.md promises one ``error:`` line and exit 2; before, each of these ended in a traceback
    (AttributeError, write_bvh's ValueError, Normalizer's ValueError, _check_vocab's ValueError)."""
    import torch

    from beatlite.train.checkpoint import load_checkpoint, save_checkpoint

    base = load_checkpoint(checkpoints_dir() / "camn_tiny.pt")
    nan = {
        k: torch.full_like(v, float("nan")) if v.is_floating_point() else v for k, v in base["state"].items()
    }
    cases = {
        "state a list": ({**base, "state": [1, 2]}, "field 'state'"),
        "NaN weights": ({**base, "state": nan}, "field 'state'"),
        "bad statistics": ({**base, "meta": {**base["meta"], "pose_std": np.zeros(3)}}, "field 'meta'"),
        "another vocabulary": ({**base, "meta": {**base["meta"], "vocab": ["a", "b"]}}, "field 'meta.vocab'"),
    }
    data = str(REPO / "data_samples")
    for label, (payload, text) in cases.items():
        path = save_checkpoint(tmp_path / f"{label.replace(' ', '_')}.pt", payload)
        assert main([str(tmp_path / "out"), "--export", str(path), "--data", data]) == 2, label
        err = capsys.readouterr().err.strip().splitlines()
        errors = [line for line in err if line.startswith("error: ")]
        assert len(errors) == 1 and str(path) in errors[0] and text in errors[0], (label, err)
        assert "Traceback" not in "\n".join(err) and not list((tmp_path / "out").glob("*.bvh")), label


# ----------------------------------------------------------------------------- the folder
def test_trimmed_and_extended_predictions_are_scored_on_the_overlap(truth_files, test_set, tmp_path):
    folder = tmp_path / "pred"
    shutil.copytree(truth_files, folder)
    short, long = test_set.takes[2], test_set.takes[3]
    m = read_bvh(folder / f"{short}.bvh")
    write_bvh(folder / f"{short}.bvh", Motion(m.skeleton, m.channels[:-20], m.fps), precision=12)
    m = read_bvh(folder / f"{long}.bvh")
    write_bvh(
        folder / f"{long}.bvh",
        Motion(m.skeleton, np.vstack([m.channels, m.channels[:7]]), m.fps),
        precision=12,
    )
    with pytest.warns(ScoreWarning) as record:
        result = score_folder(folder, test=test_set)
    messages = [str(w.message) for w in record]
    assert any(short in s and "20 more" in s for s in messages) and any(
        long in s and "last 7" in s for s in messages
    )
    values = result.evaluation.values()
    assert values["PCK"] == 1.0 and values["MPJPE"] < 1e-4 and values["FGD"] < 1e-6  # frames stay aligned
    assert result.info["trimmed"] == {short: -20, long: 7}
    assert result.info["frames"] == sum(len(d) for d in test_set.gt_directions) - 20


def test_missing_takes_are_an_error_unless_allowed(truth_files, test_set, tmp_path):
    folder = tmp_path / "pred"
    shutil.copytree(truth_files, folder)
    (folder / f"{test_set.takes[0]}.bvh").unlink()
    with pytest.raises(ScoreInputError, match=test_set.takes[0]):
        score_folder(folder, test=test_set)
    with pytest.warns(ScoreWarning, match="scored without them"):
        result = score_folder(folder, test=test_set, allow_missing=True, metrics=["FGD", "PCK"])
    assert result.info["takes"] == list(test_set.takes[1:]) and result.evaluation.get("PCK").value == 1.0


def test_cli_refuses_a_bad_folder_with_one_line_per_problem(truth_files, test_set, real_samples, tmp_path):
    folder = tmp_path / "pred"
    shutil.copytree(truth_files, folder)
    missing, truncated, other = test_set.takes[0], test_set.takes[1], test_set.takes[2]
    (folder / f"{missing}.bvh").unlink()
    shutil.copy(folder / f"{truncated}.bvh", folder / "30_katya_0_1_1.bvh")  # a take of no split: extra
    m = read_bvh(folder / f"{truncated}.bvh")
    write_bvh(folder / f"{truncated}.bvh", Motion(m.skeleton, m.channels[:-15], m.fps), precision=12)
    shutil.copy(real_samples / "dataset-1_bye_normal_001.bvh", folder / f"{other}.bvh")
    r = _run_cli(str(folder), "--data", str(REPO / "data_samples"))
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert "Traceback" not in r.stderr and all(line.startswith(("error: ", "warning: ")) for line in lines), (
        r.stderr
    )
    errors = [line for line in lines if line.startswith("error: ")]
    assert len(errors) == 2, r.stderr
    assert any(missing in e and "no prediction" in e for e in errors), r.stderr
    assert any(f"{other}.bvh" in e and "HIERARCHY" in e for e in errors), r.stderr
    assert sum("30_katya_0_1_1.bvh" in line and "ignored" in line for line in lines) == 1, r.stderr
    assert sum(f"{truncated}.bvh" in line and "15 more" in line for line in lines) == 1, r.stderr


def test_predictions_that_crashed_the_scorer_are_one_error_line_each(truth_files, test_set, tmp_path):
    """Each raised a bare exception through `python -m beatlite.score` (a traceback, exit 1): a (0, 42, 3) .npy
    (ValueError: zero-size array), a .npy header numpy's tokenizer cannot read (tokenize.TokenError), and a .bvh
    or BEAT2 .npz whose root lies 1e30 cm away (ValueError: zero-length bones). Now one FormatError line each."""
    from beatlite.io.smplx import SMPLXMotion, write_smplx

    folder = tmp_path / "pred"
    shutil.copytree(truth_files, folder)
    empty, header, far, far_npz = test_set.takes[:4]
    for stem in (empty, header, far_npz):
        (folder / f"{stem}.bvh").unlink()
    np.save(folder / f"{empty}.npy", np.zeros((0, 42, 3)))
    text = b"{'descr': '<f8', 'fortran_order': False, 'shape': (".ljust(117) + b"\n"  # an unclosed tuple
    (folder / f"{header}.npy").write_bytes(b"\x93NUMPY\x01\x00" + len(text).to_bytes(2, "little") + text)
    m = read_bvh(folder / f"{far}.bvh")
    channels = m.channels.copy()
    channels[:, :3] = 1e30  # the root position, cm
    write_bvh(folder / f"{far}.bvh", Motion(m.skeleton, channels, m.fps))
    write_smplx(folder / f"{far_npz}.npz", SMPLXMotion(np.zeros((40, 165)), np.full((40, 3), 1e28), 30))
    expected = {
        f"{empty}.npy": ("shape", "no frames"),
        f"{header}.npy": (None, "not a readable .npy header"),
        f"{far}.bvh": ("values", "zero-length bones"),
        f"{far_npz}.npz": ("values", "zero-length bones"),
    }
    for name, (field, text) in expected.items():
        with pytest.raises(FormatError, match=text) as info:
            read_prediction(folder / name)
        assert info.value.field == field and info.value.path == folder / name
    for shape in ((0, 126), (0, 141)):  # 0 frames of the other forms
        np.save(folder / "x.npy", np.zeros(shape))
        with pytest.raises(FormatError, match="no frames"):
            read_prediction(folder / "x.npy")
    (folder / "x.npy").unlink()
    r = _run_cli(str(folder), "--data", str(REPO / "data_samples"))
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    errors = [line for line in r.stderr.splitlines() if line.startswith("error: ")]
    assert len(errors) == 4 and all(any(n in e for e in errors) for n in expected), r.stderr


def test_cli_writes_the_table_and_json(truth_files, tmp_path):
    out = tmp_path / "scores.json"
    r = _run_cli(str(truth_files), "--data", str(REPO / "data_samples"), "--metrics", "FGD", "SRGR",
                 "--json", str(out), "--md", str(tmp_path / "scores.md"), "--bootstrap", "20")  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "| FGD ↓ |" in r.stdout and "**SRGR**: BEAT eq. 11" in r.stdout and "sha256" in r.stdout
    data = json.loads(out.read_text())
    assert set(data["metrics"]) == {"FGD", "SRGR"} and data["info"]["beatlite_version"]
    assert len(data["info"]["extractor_sha256"]) == 16 and len(data["metrics"]["SRGR"]["interval"]) == 2
    assert (tmp_path / "scores.md").read_text().strip() == r.stdout.strip()


# ----------------------------------------------------------------------------- bootstrap
def test_bootstrap_of_two_takes_spans_their_own_values():
    """Two takes: a draw is (a, a), (a, b), (b, a) or (b, b), each 1/4 likely, so with enough draws the 2.5th and
    97.5th percentiles of a frame-weighted MPJPE are the two takes' own MPJPEs."""
    rng = np.random.default_rng(0)
    real = [rng.normal(size=(50, 3, 3)), rng.normal(size=(40, 3, 3))]
    gen = [real[0] + 1.0, real[1] + rng.normal(size=(40, 3, 3))]
    own = [float(np.linalg.norm(g - t, axis=-1).mean()) for g, t in zip(gen, real, strict=True)]
    truth = GroundTruth(Takes(positions=real))
    low, high = bootstrap_intervals(Takes(positions=gen), truth, ["MPJPE"], n=400, seed=3)["MPJPE"]
    assert low == pytest.approx(min(own), rel=1e-12) and high == pytest.approx(max(own), rel=1e-12)


def test_mean_interval_is_bootstrap_intervals_on_per_take_values():
    """``mean_interval`` (the reference of notebook 09's exercise 3) is what ``bootstrap_intervals`` gives a mean
    over takes: takes of equal length make the frame-weighted MPJPE the mean of the per-take MPJPEs, so the same
    seed draws the same takes and gives the same interval. Two values: a resample's mean is a, (a + b) / 2 or b,
    each end 1/4 likely, so the 2.5th and 97.5th percentiles are the values themselves."""
    rng = np.random.default_rng(1)
    real = [rng.normal(size=(40, 3, 3)) for _ in range(6)]
    gen = [t + rng.normal(scale=0.2 * (k + 1), size=t.shape) for k, t in enumerate(real)]
    per_take = [float(np.linalg.norm(g - t, axis=-1).mean()) for g, t in zip(gen, real, strict=True)]
    truth = GroundTruth(Takes(positions=real))
    want = bootstrap_intervals(Takes(positions=gen), truth, ["MPJPE"], n=300, seed=4)["MPJPE"]
    np.testing.assert_allclose(mean_interval(per_take, 300, 4), want, rtol=1e-12)
    assert mean_interval([3.0, 7.0], 400, 0).tolist() == [3.0, 7.0]
    narrow, wide = mean_interval(per_take, 300, 4, level=0.5), mean_interval(per_take, 300, 4)
    assert wide[0] <= narrow[0] <= narrow[1] <= wide[1]
    with pytest.raises(ValueError, match="non-empty 1-D"):
        mean_interval([], 10)


def test_bootstrap_resamples_that_cannot_score_a_metric_are_left_out_and_counted():
    """Takes of 20, 80 and 90 frames: the first has no window, so a resample drawing only it has no FGD (was: the
    whole bootstrap failed, "needs at least 2 samples"); one take without audio beats: BeatAlign likewise (was
    (nan, nan)). A resample draws only take 0 with probability (1/3)^3 = 1/27."""
    from beatlite.data.windows import window_starts

    rng = np.random.default_rng(8)
    real = [np.cumsum(rng.normal(size=(n, 43, 3)) * 0.3, axis=0) for n in (20, 80, 90)]
    n_windows = sum(len(window_starts(len(p))) for p in real)
    truth = GroundTruth(Takes(positions=real, features=rng.normal(size=(n_windows, 16))),
                        audio_beats=[np.array([]), np.array([1.0, 2.0, 4.0]), np.array([0.5, 3.0])])  # fmt: skip
    gen = Takes(positions=[p + 1.0 for p in real], features=rng.normal(size=(n_windows, 16)))
    with pytest.warns(ScoreWarning) as record:
        out = bootstrap_intervals(gen, truth, ["FGD", "BeatAlign", "MPJPE"], n=300, seed=0)
    messages = " ".join(str(w.message) for w in record)
    fgd_missing = int(re.search(r"(\d+) of 300 resamples gave no FGD", messages).group(1))
    assert 0 < fgd_missing < 40  # binomial(300, 1/27): mean 11, sd 3.3
    assert "no BeatAlign" in messages and "no MPJPE" not in messages
    assert all(np.isfinite(out[k]).all() for k in out) and out["MPJPE"][0] < out["MPJPE"][1]
    one = GroundTruth(
        Takes(positions=real[1:2], features=truth.takes.features[:5]), audio_beats=truth.audio_beats[1:2]
    )
    one_gen = Takes(positions=gen.positions[1:2], features=gen.features[:5])
    with pytest.warns(ScoreWarning, match="at least 2 takes"):  # one take: every resample is that take
        assert bootstrap_intervals(one_gen, one, ["MPJPE"], n=10) == {}


def test_bootstrap_intervals_are_seeded_and_contain_the_estimate(test_set, tmp_path):
    export_checkpoint_takes("camn_tiny", tmp_path, test=test_set)
    keys = ["FGD", "SRGR", "BeatAlign", "BC", "Diversity", "L1div"]
    a = score_folder(tmp_path, test=test_set, metrics=keys, bootstrap=30, seed=1)
    b = score_folder(tmp_path, test=test_set, metrics=keys, bootstrap=30, seed=1)
    c = score_folder(tmp_path, test=test_set, metrics=keys, bootstrap=30, seed=2)
    assert a.intervals == b.intervals and a.intervals != c.intervals
    for key in keys:
        low, high = a.intervals[key]
        assert low <= a.evaluation.get(key).value <= high, (key, low, a.evaluation.get(key).value, high)


def test_an_extractor_of_another_space_is_refused(truth_files, test_set):
    path = checkpoints_dir() / "fgd_euler141.pt"
    if not path.is_file():
        pytest.skip("no shipped Euler extractor")
    with pytest.raises(ScoreInputError, match="'pose' space"):
        score_folder(truth_files, test=test_set, metrics=["FGD"], extractor=path)


def test_a_too_short_prediction_and_an_incomplete_smplx_npz_are_refused_one_line_each(
    truth_files, test_set, tmp_path
):
    folder = tmp_path / "pred"
    shutil.copytree(truth_files, folder)
    short, smplx = test_set.takes[0], test_set.takes[1]
    m = read_bvh(folder / f"{short}.bvh")
    write_bvh(folder / f"{short}.bvh", Motion(m.skeleton, m.channels[:20], m.fps), precision=12)
    (folder / f"{smplx}.bvh").unlink()
    np.savez(folder / f"{smplx}.npz", poses=np.zeros((10, 165)))
    with pytest.raises(ScoreInputError) as info:
        score_folder(folder, test=test_set)
    lines = info.value.lines
    assert len(lines) == 2 and all("\n" not in line for line in lines), lines
    assert any(short in line and "20 frames" in line and "34-frame window" in line for line in lines), lines
    assert any(f"{smplx}.npz" in line and "no 'trans' array" in line for line in lines), lines


def test_emage_audio_beats_leave_out_two_seconds_at_both_ends():
    """Clicks at 1, 3, 5 and 7.5 s of an 8 s take: EMAGE scores 2 s to 6 s, so the onsets at 3 and 5 s remain,
    reported 1 and 3 s after the cut (librosa reports each click about 0.032 s late, one hop of 512 at 16 kHz)."""
    from beatlite.metrics.alignment import emage_audio_beats

    sr = 16000
    audio = np.zeros(8 * sr, np.float32)
    audio[[1 * sr, 3 * sr, 5 * sr, int(7.5 * sr)]] = 1.0
    beats = emage_audio_beats(audio, sr, n_frames=120, fps=15)
    nearest = np.abs(beats[:, None] - np.array([1.0, 3.0])[None]).min(axis=1)
    assert len(beats) >= 2 and nearest.max() < 0.05, beats  # librosa may report a click twice, 32 ms apart
    assert np.abs(beats - 1.0).min() < 0.05 and np.abs(beats - 3.0).min() < 0.05, beats


def test_bvh_rows_under_another_rate_s_frame_time_are_refused_and_scored_with_pred_fps(
    truth_files, test_set, tmp_path
):
    """BEAT's code writes its 15 fps results under the 120 fps template's ``Frame Time: 0.008333``. Before, a file
    whose Frame Time says twice its rows' rate was read as half the take and scored against the take's first half
    (the exact ground truth got FGD 3.7, MPJPE 11.9 cm, with a trimming warning only), and one at 120 fps was
    refused as shorter than a window. Now both are one error line naming the file and 'Frame Time' and the rate
    that spans the take; ``pred_fps=15`` scores them as the ground truth they are."""
    folder = tmp_path / "pred"
    shutil.copytree(truth_files, folder)
    changed = {test_set.takes[0]: "0.008333", test_set.takes[1]: "0.033333"}  # 120 and 30 fps
    for stem, frame_time in changed.items():
        path = folder / f"{stem}.bvh"
        path.write_text(path.read_text().replace("Frame Time: 0.066667", f"Frame Time: {frame_time}"))
    with pytest.raises(ScoreInputError) as info:
        score_folder(folder, test=test_set, metrics=["MPJPE"])
    lines = info.value.lines
    assert len(lines) == 2, lines
    for stem, line in zip(changed, lines, strict=True):
        frames = len(test_set.gt_directions[test_set.takes.index(stem)])
        assert f"{stem}.bvh" in line and "'Frame Time'" in line and f"{frames} rows" in line, line
        assert "at 15 fps they would span it" in line and "--pred-fps" in line, line
    result = score_folder(folder, test=test_set, metrics=["FGD", "PCK", "MPJPE"], pred_fps=15)
    values = result.evaluation.values()
    assert values["PCK"] == 1.0 and values["MPJPE"] < 1e-4 and values["FGD"] < 1e-6  # the ground truth itself
    assert result.info["pred_fps"] == 15 and "--pred-fps" in result.to_markdown()
    assert result.info["trimmed"] == {}


def test_npy_rows_at_another_rate_are_refused_and_resampled_with_pred_fps(test_set, tmp_path):
    """A ``.npy`` states no rate: before, one of 30 fps rows (BEAT2's rate) was refused with "resample it to 15 fps"
    and ``--pred-fps`` did not apply to it. Now the refusal names the 30 fps at which its rows span the take, and
    ``pred_fps=30`` decimates them: every even row is the ground truth, every odd row noise that must not be read,
    so the scores are those of the ground truth's rows saved at 15 fps."""
    rng = np.random.default_rng(0)
    folder, at_15 = tmp_path / "pred", tmp_path / "at_15"
    folder.mkdir(), at_15.mkdir()
    for k, stem in enumerate(test_set.takes):
        truth = test_set.gt_euler[k] if k % 2 else test_set.gt_directions[k]  # both representations
        rows = np.repeat(truth, 2, axis=0)
        rows[1::2] += rng.normal(scale=30.0, size=rows[1::2].shape)
        np.save(folder / f"{stem}.npy", rows)
        np.save(at_15 / f"{stem}.npy", truth)
    with pytest.raises(ScoreInputError) as info:
        score_folder(folder, test=test_set, metrics=["MPJPE"])
    assert len(info.value.lines) == len(test_set.takes), info.value.lines
    for stem, line in zip(test_set.takes, info.value.lines, strict=True):
        assert f"{stem}.npy" in line and "'shape'" in line and "at 30 fps they would span it" in line, line
        assert "--pred-fps" in line, line
    with pytest.warns(
        ScoreWarning
    ):  # the noisy odd direction rows are not unit vectors; the Euler metrics skipped
        result = score_folder(folder, test=test_set, metrics=["FGD", "PCK", "MPJPE"], pred_fps=30)
        want = score_folder(at_15, test=test_set, metrics=["FGD", "PCK", "MPJPE"]).evaluation.values()
    got = result.evaluation.values()
    for key in want:  # the same rows, the same arithmetic
        np.testing.assert_allclose(got[key], want[key], rtol=1e-12, atol=0, err_msg=key)
    assert result.info["trimmed"] == {} and "npy euler (T, 141) 30 fps -> 15 fps" in str(result.info["files"])


def test_a_bvh_with_vast_values_at_another_rate_reads_finite_or_is_a_format_error(tmp_path):
    # Resampled from 20 to 15 fps (resample_frames): a rotation flipping between +-1.7e308 degrees reads
    # as its reduction mod 360 (finite directions, no overflow warning); a root flipping between +-1.7e308
    # cm leaves every bone with zero length, a FormatError (it was NaN directions and RuntimeWarnings).
    from beatlite.skeleton.beat import subset_columns

    skeleton = beat_skeleton()
    column = int(subset_columns(skeleton, "spine_neck_141")[7])
    for name, col, flip in (("turn.bvh", column, None), ("root.bvh", 0, "zero-length")):
        channels = np.zeros((8, skeleton.n_channels))
        channels[::2, col], channels[1::2, col] = -1.7e308, 1.7e308
        write_bvh(tmp_path / name, Motion(skeleton, channels, 20.0))
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            if flip is None:
                got = read_prediction(tmp_path / name)
                assert np.isfinite(got.directions).all() and np.isfinite(got.euler).all()
                want = int(1.7e308) % 360 + ((int(-1.7e308) % 360 - int(1.7e308) % 360 + 180) % 360 - 180) / 3
                assert abs((got.euler[1, 7] - want + 180.0) % 360.0 - 180.0) < 1e-9  # row 4/3
            else:
                with pytest.raises(FormatError, match="values too large to give directions"):
                    read_prediction(tmp_path / name)


def test_npy_directions_between_rows_are_normalised_interpolations(tmp_path):
    """20 fps rows -> 15 fps: output frame i is row position 4i/3. A bone turning at a constant rate in the x-y plane
    (10 degrees per row) is, between rows a and a+10° at weight w, the normalised sum (1-w)u(a) + w u(a+10°):
    at the angle a + atan2(w sin 10°, 1 - w + w cos 10°) (closed form), of norm 1. Halfway between two rows where a
    bone turns by 180° it has no direction: a FormatError naming the rows."""
    from beatlite.score import read_prediction

    rows = 13
    angle = np.deg2rad(10.0 * np.arange(rows))
    d = np.zeros((rows, 42, 3))
    d[..., 0], d[..., 1] = np.cos(angle)[:, None], np.sin(angle)[:, None]
    np.save(tmp_path / "turn.npy", d)
    got = read_prediction(tmp_path / "turn.npy", fps=20).directions
    pos = np.arange(len(got)) * 4 / 3
    a, w, step = np.floor(pos + 1e-9), pos - np.floor(pos + 1e-9), np.deg2rad(10.0)
    want = np.deg2rad(10.0 * a) + np.arctan2(w * np.sin(step), 1 - w + w * np.cos(step))
    assert len(got) == 10  # positions 0, 4/3, ..., 12 inside the 13 rows
    np.testing.assert_allclose(
        np.arctan2(got[..., 1], got[..., 0]), np.repeat(want[:, None], 42, 1), atol=1e-12
    )
    np.testing.assert_allclose(np.linalg.norm(got, axis=-1), 1.0, atol=1e-12)
    huge = np.zeros((4, 141))
    huge[::2, 7], huge[1::2, 7] = -1.7e308, 1.7e308  # finite, but their difference is not
    np.save(tmp_path / "huge.npy", huge)
    big = read_prediction(tmp_path / "huge.npy", fps=20)  # reduced mod 360 (resample_frames), then turned
    assert np.isfinite(big.directions).all()
    ra, rb = int(-1.7e308) % 360, int(1.7e308) % 360  # 15 fps frame 1 is row 4/3: a third from row 1 to row 2
    want = rb + ((ra - rb + 180) % 360 - 180) / 3
    assert abs((big.euler[1, 7] - want + 180.0) % 360.0 - 180.0) < 1e-9
    for fps in (1e-300, 5e-324, 0.5, 2e5, float("nan")):  # outside a BVH Frame Time's 1 to 100,000 fps
        with pytest.raises(ValueError, match="from 1 to 100000 fps"):
            read_prediction(tmp_path / "turn.npy", fps=fps)
    d[2, 5] = -d[1, 5]  # bone 5 flips between rows 1 and 2; at 22.5 fps, 15 fps frame 1 is row 1.5, halfway
    np.save(tmp_path / "flip.npy", d)
    with pytest.raises(FormatError, match=r"bone 5 turns by 180 degrees between rows 1 and 2") as info:
        read_prediction(tmp_path / "flip.npy", fps=22.5)
    assert info.value.field == "values"


@pytest.mark.filterwarnings(
    "error::RuntimeWarning", "ignore::beatlite.score.ScoreWarning"
)  # (not unit: normalised)
def test_random_npy_files_at_random_rates_read_or_are_format_errors(tmp_path):
    """400 random .npy files (the three shapes and others, 1 to 60 rows, values from 1e-300 to 1e308, NaN, zeros,
    antipodal neighbours) read at random rates: each gives finite unit directions (and finite Euler channels) or a
    FormatError; no other exception, no non-finite value."""
    from beatlite.score import read_prediction

    rng = np.random.default_rng(28)
    shapes = [(42, 3), (126,), (141,), (42, 2), (140,), ()]
    for i in range(400):
        rows, shape = int(rng.integers(1, 60)), shapes[int(rng.integers(len(shapes)))]
        with np.errstate(over="ignore"):  # some become inf: refused as not finite
            x = rng.normal(size=(rows, *shape)) * 10.0 ** rng.integers(-300, 309)
        kind = rng.integers(6)
        if kind == 0:
            x.flat[int(rng.integers(x.size))] = np.nan
        elif kind == 1:
            x[int(rng.integers(rows))] = 0.0
        elif kind == 2 and rows > 1:
            x[1::2] = -x[:-1:2][: len(x[1::2])]  # every odd row the negation of the even row before it
        np.save(tmp_path / "x.npy", x)
        fps = [None, 15.0, 30.0, 20.0, 22.5, 7.5, 120.0][int(rng.integers(7))]
        try:
            pred = read_prediction(tmp_path / "x.npy", fps=fps)
        except FormatError:
            continue
        assert np.isfinite(pred.directions).all(), (i, shape, fps)
        np.testing.assert_allclose(np.linalg.norm(pred.directions, axis=-1), 1.0, atol=1e-9, err_msg=str(i))
        assert pred.euler is None or np.isfinite(pred.euler).all(), (i, shape, fps)


def test_predictions_named_in_another_case_or_as_beat_and_emage_write_them_are_matched(tmp_path):
    """BEAT's test code names a take's result ``res_{take}.bvh``, EMAGE's ``res_{take}.npz`` beside
    ``gt_{take}.npz``; before, such a folder (and one of ``2_Scott_0_1_1.BVH``) matched no take ('no prediction for
    8 of the 8 takes')."""
    takes = ["2_scott_0_1_1", "4_lawrence_0_65_65", "6_carla_0_87_87", "8_catherine_0_103_103"]
    names = [
        "res_2_scott_0_1_1.npz",
        "gt_2_scott_0_1_1.npz",
        "4_Lawrence_0_65_65.BVH",
        "RES_6_carla_0_87_87.bvh",
    ]
    names += ["8_catherine_0_103_103_generated.bvh"]
    for name in names:
        (tmp_path / name).write_bytes(b"")
    files, missing, extra = match_predictions(tmp_path, takes)
    assert {t: p.name for t, p in files.items()} == dict(zip(takes[:3], names[:1] + names[2:4], strict=True))
    assert missing == takes[3:] and extra == ["8_catherine_0_103_103_generated.bvh", "gt_2_scott_0_1_1.npz"]
    (tmp_path / "2_scott_0_1_1.bvh").write_bytes(b"")
    with pytest.raises(
        ScoreInputError, match=r"2_scott_0_1_1: several predictions \(2_scott_0_1_1.bvh, res_"
    ):
        match_predictions(tmp_path, takes)


def test_a_folder_of_res_files_scores_and_a_misnamed_file_is_named(truth_files, test_set, tmp_path):
    """A folder of res_{take}.bvh scores as its files; a file that only holds a take's name is named in the error."""
    folder = tmp_path / "pred"
    folder.mkdir()
    for stem in test_set.takes:
        shutil.copy(truth_files / f"{stem}.bvh", folder / f"res_{stem}.bvh")
    result = score_folder(folder, test=test_set, metrics=["PCK", "MPJPE"])
    assert result.evaluation.values()["PCK"] == 1.0 and result.evaluation.values()["MPJPE"] < 1e-4
    stem = test_set.takes[0]
    (folder / f"res_{stem}.bvh").rename(folder / f"{stem}_generated.bvh")
    with (
        pytest.warns(ScoreWarning, match="ignored"),
        pytest.raises(ScoreInputError, match=rf"no prediction for 1 of the 8 takes.*{stem}_generated\.bvh"),
    ):
        score_folder(folder, test=test_set, metrics=["PCK"])
