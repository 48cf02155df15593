"""The results evaluation (beatlite.train.evaluation) on a small synthetic test set."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from beatlite.data.normalize import Normalizer, Normalizers  # noqa: E402
from beatlite.models import build_model  # noqa: E402
from beatlite.skeleton.beat import beat_skeleton  # noqa: E402
from beatlite.skeleton.directions import positions_to_directions  # noqa: E402
from beatlite.skeleton.kinematics import rest_pose  # noqa: E402
from beatlite.skeleton.ted import (  # noqa: E402
    TED_BONES,
    TED_VECTOR_NAMES,
    beat_to_ted43,
    directions_to_ted_positions,
    euler_to_directions,
    rest_bone_lengths,
)
from beatlite.train.evaluation import (  # noqa: E402
    COLUMNS,
    GROUND_TRUTH,
    GROUND_TRUTH_141,
    evaluate_models,
    write_results,
)
from beatlite.train.testset import EvaluationSet, _in_units, direction_features  # noqa: E402

LENGTHS = (200, 150)


def _rest_directions() -> np.ndarray:
    """(42, 3) TED bone directions of the BEAT rest pose, straight from the rest positions."""
    ted = beat_to_ted43(rest_pose(beat_skeleton())[None])
    return positions_to_directions(ted, np.asarray(TED_BONES))[0]


def _features(windows: np.ndarray) -> np.ndarray:
    """A fixed stand-in extractor: per-window mean and std of the first 3 channels -> (N, 6)."""
    w = np.asarray(windows, np.float64)
    return np.concatenate([w[:, :, :3].mean(1), w[:, :, :3].std(1)], axis=1)


@pytest.fixture(scope="module")
def test_set() -> EvaluationSet:
    rng = np.random.default_rng(0)
    rest = _rest_directions()
    mean = rest.reshape(-1)
    streams, gt, gt141, sems, audios = [], [], [], [], []
    for t in LENGTHS:
        wobble = 0.3 * np.sin(np.arange(t) / 3.0)[:, None, None] * rng.normal(size=(1, 42, 3))
        d = rest + wobble + 0.02 * rng.normal(size=(t, 42, 3))
        d /= np.linalg.norm(d, axis=-1, keepdims=True)
        n = int(t / 15 * 16000)
        audio = (0.01 * rng.normal(size=n)).astype(np.float32)
        audio[:: 16000 // 2] = 0.9  # a click every 0.5 s: audio onsets
        streams.append(
            {
                "pose": np.zeros((t, 141), np.float32),
                "dirvec": (d.reshape(t, -1) - mean).astype(np.float32),
                "audio": audio,
                "mel": np.zeros((n // 512 + 1, 128), np.float32),
                "face": np.zeros((t, 51), np.float32),
                "word": np.zeros(t, np.int64),
                "emotion": np.zeros(t, np.int64),
                "semantic": rng.uniform(size=t).astype(np.float32),
                "speaker": 0,
            }
        )
        gt.append(d)
        gt141.append(d[::-1].copy())
        sems.append(streams[-1]["semantic"].astype(np.float64))
        audios.append(audio)
    norms = Normalizers(Normalizer(np.zeros(141), np.ones(141)), Normalizer(mean, np.ones(126)))
    return EvaluationSet(
        takes=["a", "b"],
        streams=streams,
        gt_directions=gt,
        gt_directions_141=gt141,
        gt_euler=[np.zeros((t, 141)) for t in LENGTHS],
        semantic=sems,
        audio=audios,
        normalizers=norms,
        change_angle=np.full(41, 0.01),
        vocab=("<pad>", "<sos>", "<eos>", "<unk>"),
    )


@pytest.fixture(scope="module")
def results(test_set):
    mean_pose = build_model("mean_pose")
    mean_pose.prepare({"pose": np.zeros((2, 34, 141), np.float32)})  # mean 0 = pose_mean = rest pose
    return evaluate_models([("Mean pose", mean_pose)], test=test_set, extractor=_features)


def test_rows_are_ground_truth_then_models(results):
    assert [r.label for r in results.rows] == [GROUND_TRUTH, GROUND_TRUTH_141, "Mean pose"]
    assert set(results.rows[0].metrics) == set(COLUMNS)
    assert results.get("Mean pose").representation == "euler141"
    with pytest.raises(KeyError, match="no row"):
        results.get("CaMN")


def test_ground_truth_row_closed_forms(results, test_set):
    gt = results.get(GROUND_TRUTH).metrics
    assert gt["FGD"] == pytest.approx(0.0, abs=1e-6)  # identical features
    # every frame is a hit, so paper SRGR = sum of semantic scores / frames
    sem = np.concatenate(test_set.semantic)
    assert gt["SRGR"] == pytest.approx(sem.sum() / sem.size, rel=1e-9)
    assert gt["Diversity"] > 0 and gt["L1div"] > 0


def test_mean_pose_row_closed_forms(results, test_set):
    mp = results.get("Mean pose").metrics
    assert mp["Diversity"] == pytest.approx(0.0, abs=1e-9)  # one constant window, repeated
    assert mp["L1div"] == pytest.approx(0.0, abs=1e-6)  # every frame is the take's mean
    assert mp["BeatAlign"] == 0.0  # a frozen pose has no motion beat
    # the constant window's features: mean = rest - dirvec_mean = 0, std = 0 -> f = 0; FGD to the
    # real features = |mu_real|^2 + tr(Sigma_real) (biased or unbiased covariance: take the max)
    real = direction_features(test_set.gt_directions, test_set, _features)
    low = (real.mean(0) ** 2).sum() + np.trace(np.cov(real.T, bias=True))
    high = (real.mean(0) ** 2).sum() + np.trace(np.cov(real.T))
    assert low - 1e-6 <= mp["FGD"] <= high + 1e-6


def test_windows_are_stride_10_and_pooled(test_set):
    w = direction_features(test_set.gt_directions, test_set, lambda x: x.reshape(len(x), -1))
    # (200 - 34) // 10 + 1 = 17 and (150 - 34) // 10 + 1 = 12 windows
    assert w.shape == (29, 34 * 126)
    third = test_set.gt_directions[0][20:54].reshape(34, -1) - test_set.normalizers.dirvec.mean
    np.testing.assert_allclose(w[2].reshape(34, 126), third, atol=1e-6)
    np.testing.assert_allclose(w[17].reshape(34, 126), test_set.streams[1]["dirvec"][:34], atol=1e-6)


def test_positions_round_trip_and_mirrored_lengths():
    lengths = rest_bone_lengths()
    assert lengths.shape == (42,) and np.all(lengths > 0)
    names = list(TED_VECTOR_NAMES[:42])
    for i, name in enumerate(names):  # the BEAT rest skeleton is left/right symmetric
        if "left" in name:
            j = names.index(name.replace("left", "right"))
            assert lengths[i] == pytest.approx(lengths[j], rel=1e-9), name
    rng = np.random.default_rng(1)
    d = rng.normal(size=(5, 42, 3))
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    pos = directions_to_ted_positions(d, lengths)
    assert pos.shape == (5, 43, 3)
    np.testing.assert_allclose(pos[:, 0], 0.0)  # root at the origin
    np.testing.assert_allclose(positions_to_directions(pos, np.asarray(TED_BONES)), d, atol=1e-9)
    bones = np.asarray(TED_BONES)
    np.testing.assert_allclose(
        np.linalg.norm(pos[:, bones[:, 1]] - pos[:, bones[:, 0]], axis=-1), lengths[None].repeat(5, 0)
    )


def test_euler_to_directions_of_zero_angles_is_the_rest_pose():
    d = euler_to_directions(np.zeros((3, 141)))
    np.testing.assert_allclose(d, np.broadcast_to(_rest_directions(), (3, 42, 3)), atol=1e-9)
    with pytest.raises(ValueError, match=r"\(T, 141\)"):
        euler_to_directions(np.zeros((3, 140)))


def test_seed_streams_are_renormalised_for_other_statistics(test_set):
    stream = test_set.streams[0]
    rng = np.random.default_rng(2)
    dir_mean = test_set.normalizers.dirvec.mean
    have = Normalizers(
        Normalizer(rng.normal(size=141), rng.uniform(1, 3, 141)), Normalizer(dir_mean, np.ones(126))
    )
    want = Normalizers(
        Normalizer(rng.normal(size=141), rng.uniform(1, 3, 141)), Normalizer(dir_mean + 0.1, np.ones(126))
    )
    pose = rng.normal(size=(4, 141))
    out = _in_units({**stream, "pose": pose}, have, want)
    # the same degrees, and the same unit directions, in either normalisation
    np.testing.assert_allclose(
        want.inverse_transform(out["pose"], "euler141"), have.inverse_transform(pose, "euler141"), atol=1e-4
    )
    np.testing.assert_allclose(
        want.inverse_transform(out["dirvec"], "dirvec126"),
        have.inverse_transform(stream["dirvec"], "dirvec126"),
        atol=1e-5,
    )
    assert _in_units(stream, have, have) is stream


def test_written_markdown_and_json(results, tmp_path):
    md, js = write_results(results, tmp_path / "res")
    text = md.read_text()
    table = [line for line in text.splitlines() if line.startswith("|")]
    assert len(table) == 2 + len(results.rows)
    header = table[0]
    positions = [header.index(f"| {name} ") for name in COLUMNS]
    assert positions == sorted(positions)  # metric columns in COLUMNS order
    data = json.loads(js.read_text())
    assert [r["label"] for r in data["rows"]] == [r.label for r in results.rows]
    for row, back in zip(results.rows, data["rows"], strict=True):
        for k, v in row.metrics.items():
            assert back["metrics"][k] is None if not math.isfinite(v) else back["metrics"][k] == v
    assert not list(tmp_path.glob("*.tmp"))


def test_bad_model_entries_are_rejected(test_set):
    with pytest.raises(TypeError, match="models entries"):
        evaluate_models([42], test=test_set, extractor=_features)


def test_table_beat_metrics_equal_the_metrics_functions(test_set, results):
    from beatlite.metrics import beat_align, beat_consistency

    dirs = test_set.gt_directions
    pos = [directions_to_ted_positions(d) for d in dirs]
    expected_ba = beat_align(test_set.audio, 16000, pos, 15, sigma=0.3)
    expected_bc = beat_consistency(
        test_set.audio, 16000, dirs, 15, sigma=0.1, change_angle=test_set.change_angle
    )
    assert np.isfinite(expected_ba) and np.isfinite(expected_bc)
    assert results.value(GROUND_TRUTH, "BeatAlign") == pytest.approx(expected_ba, abs=1e-12)
    assert results.value(GROUND_TRUTH, "BC") == pytest.approx(expected_bc, abs=1e-12)


def test_checkpoints_trained_on_other_data_are_flagged(test_set, tmp_path):
    import dataclasses

    from beatlite.models.testing import fake_windows
    from beatlite.train import TrainConfig, fit

    windows = fake_windows(4)
    windows["pose"][:] = 0.0
    # without statistics in its meta, a checkpoint is compared by data fingerprint
    result = fit(build_model("mean_pose"), windows, TrainConfig(epochs=1, checkpoint=tmp_path / "mp.pt"))
    same = dataclasses.replace(test_set, fingerprint=result.fingerprint)
    res = evaluate_models([str(tmp_path / "mp.pt")], test=same, extractor=_features, ground_truth=False)
    assert not res.rows[0].stale and "†" not in res.to_markdown()
    other = dataclasses.replace(test_set, fingerprint="0000000000000000")
    with pytest.warns(UserWarning, match="other data"):
        res = evaluate_models([str(tmp_path / "mp.pt")], test=other, extractor=_features, ground_truth=False)
    assert res.rows[0].stale and res.rows[0].fingerprint == result.fingerprint
    assert "mp †" in res.to_markdown()
    # with statistics, those decide (a trainer may fingerprint another window dict)
    stats = test_set.normalizers.to_meta()
    fit(build_model("mean_pose"), windows, TrainConfig(epochs=1, checkpoint=tmp_path / "a.pt"), meta=stats)
    res = evaluate_models([str(tmp_path / "a.pt")], test=other, extractor=_features, ground_truth=False)
    assert not res.rows[0].stale
    moved = {**stats, "pose_mean": stats["pose_mean"] + 1.0}
    fit(build_model("mean_pose"), windows, TrainConfig(epochs=1, checkpoint=tmp_path / "b.pt"), meta=moved)
    with pytest.warns(UserWarning, match="other data"):
        res = evaluate_models([str(tmp_path / "b.pt")], test=same, extractor=_features, ground_truth=False)
    assert res.rows[0].stale


def test_evaluate_seeds_collects_each_seeds_row_and_names_missing_checkpoints(
    test_set, tmp_path, monkeypatch
):
    from beatlite.models.testing import fake_windows
    from beatlite.train import TrainConfig, fit
    from beatlite.train import seeds as seeds_module

    paths = {1: tmp_path / "1" / "mean_pose.pt", 2: tmp_path / "2" / "mean_pose.pt"}
    stats = test_set.normalizers.to_meta()
    for seed, path in paths.items():
        windows = fake_windows(4, seed=seed)
        windows["pose"] = np.full_like(windows["pose"], 0.2 * (seed - 1))  # two different frozen poses
        fit(
            build_model("mean_pose"),
            windows,
            TrainConfig(epochs=1, checkpoint=path, progress=False),
            meta=stats,
        )
    monkeypatch.setattr(
        seeds_module, "checkpoint_path", lambda name, seed: tmp_path / str(seed) / f"{name}.pt"
    )
    res = seeds_module.evaluate_seeds(["mean_pose"], seeds=[1, 2], test=test_set, extractor=_features)
    single = [
        evaluate_models([str(p)], test=test_set, extractor=_features, ground_truth=False).rows[0].metrics
        for p in paths.values()
    ]
    assert list(res.values) == [GROUND_TRUTH, GROUND_TRUTH_141, "Mean pose"]
    assert res.values[GROUND_TRUTH]["FGD"] == [pytest.approx(0.0, abs=1e-9)]  # scored once, seed-free
    fgd = [m["FGD"] for m in single]
    assert fgd[0] != fgd[1]
    assert res.values["Mean pose"]["FGD"] == pytest.approx(fgd)
    assert res.mean("Mean pose", "FGD") == pytest.approx(np.mean(fgd))
    assert res.sd("Mean pose", "FGD") == pytest.approx(abs(fgd[0] - fgd[1]) / math.sqrt(2))
    md, js = seeds_module.write_seed_results(res, tmp_path / "seeds")
    assert "±" in md.read_text() and json.loads(js.read_text())["seeds"] == [1, 2]
    with pytest.raises(FileNotFoundError, match=r"3.mean_pose\.pt.*--seeds 3"):
        seeds_module.evaluate_seeds(["mean_pose"], seeds=[1, 3], test=test_set, extractor=_features)
    # missing="skip": the absent seed is a NaN, so value k stays seed k; the first seed must exist
    skip = seeds_module.evaluate_seeds(
        ["mean_pose"], seeds=[1, 3, 2], test=test_set, extractor=_features, missing="skip"
    )
    assert skip.values["Mean pose"]["FGD"][0] == pytest.approx(fgd[0])
    assert math.isnan(skip.values["Mean pose"]["FGD"][1])
    assert skip.values["Mean pose"]["FGD"][2] == pytest.approx(fgd[1])
    assert skip.mean("Mean pose", "FGD") == pytest.approx(np.mean(fgd))
    assert "| 2 |" in skip.to_markdown().splitlines()[-1]  # two seeds counted
    with pytest.raises(FileNotFoundError):
        seeds_module.evaluate_seeds(
            ["mean_pose"], seeds=[3, 1], test=test_set, extractor=_features, missing="skip"
        )


def test_fgd_scorer_equals_the_fgd_column(test_set, results):
    from beatlite.train.testset import fgd_scorer

    mean_pose = build_model("mean_pose")
    mean_pose.prepare({"pose": np.zeros((2, 34, 141), np.float32)})
    score = fgd_scorer(takes=test_set, extractor=_features)
    assert score(mean_pose) == pytest.approx(results.value("Mean pose", "FGD"), rel=1e-9)


def test_a_set_loaded_for_fgd_alone_has_the_full_sets_takes_and_fgd():
    """``load_test_set(fgd_only=True)``, fit's validation set: the same takes, streams and ground truth, so the
    same FGD, without BC's change angle, the mean speed and the onsets (and scoring it is refused)."""
    from beatlite.train.testset import fgd_scorer, load_test_set

    full, fgd_only = load_test_set(split="val"), load_test_set(split="val", fgd_only=True)
    assert fgd_only.takes == full.takes and len(full.takes) > 0
    for a, b in zip(
        full.gt_directions + full.gt_euler, fgd_only.gt_directions + fgd_only.gt_euler, strict=True
    ):
        np.testing.assert_array_equal(a, b)
    for a, b in zip(full.streams, fgd_only.streams, strict=True):
        assert a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a)
    assert (
        full.change_angle.shape == (41,)
        and full.mean_speed.shape == (43,)
        and len(full.audio_beats) == len(full.takes)
    )
    assert fgd_only.change_angle is None and fgd_only.mean_speed is None and fgd_only.audio_beats == []
    with pytest.raises(ValueError, match="fgd_only=False"):
        fgd_only.ground_truth(_features)
    mean_pose = build_model("mean_pose")
    mean_pose.prepare({"pose": np.zeros((2, 34, 141), np.float32)})
    want = fgd_scorer(takes=full, extractor=_features)(mean_pose)
    assert fgd_scorer(takes=fgd_only, extractor=_features)(mean_pose) == want and want > 0


@pytest.mark.slow
def test_ha2g_code_protocol_is_seeded_and_differs_from_the_deterministic_one():
    from beatlite.paths import checkpoints_dir
    from beatlite.train.testset import SampledProtocol, load_test_set

    if not (checkpoints_dir() / "ha2g_tiny.pt").is_file():
        pytest.skip("no shipped ha2g_tiny checkpoint")
    from beatlite.data.normalize import Normalizers
    from beatlite.train.checkpoint import load_model

    test = load_test_set()
    model, data = load_model("ha2g_tiny")
    norms = Normalizers.from_meta(data["meta"])
    columns = ("FGD", "BC (ha2g)", "Diversity")
    entries = [
        ("sampled", SampledProtocol(model, test.train_speakers, seed=0), norms),
        ("sampled again", SampledProtocol(model, test.train_speakers, seed=0), norms),
        ("deterministic", model, norms),
    ]
    res = evaluate_models(entries, test=test, ground_truth=False, columns=columns)
    assert res.columns == columns and "BC (ha2g)" in res.to_markdown()
    assert res.get("sampled").metrics == res.get("sampled again").metrics  # one seed, one table
    assert res.get("sampled").metrics["FGD"] != res.get("deterministic").metrics["FGD"]
    with pytest.raises(ValueError, match="training speakers"):
        SampledProtocol(model, ())


# ------------------------------------------------------------------ reference variants, column tables
def test_reference_variant_columns_closed_forms(test_set):
    mean_pose = build_model("mean_pose")
    mean_pose.prepare({"pose": np.zeros((2, 34, 141), np.float32)})  # Euler 0 everywhere = gt_euler
    keys = ("SRGR (reference)", "FGD (reference)")
    res = evaluate_models([("Mean pose", mean_pose)], test=test_set, extractor=_features, columns=keys)
    # every joint of every frame within 4 degrees: reference SRGR = sum(semantic / 0.165) / frames
    sem = np.concatenate(test_set.semantic)
    expected = sem.sum() / sem.size / 0.165
    assert res.value(GROUND_TRUTH, "SRGR (reference)") == pytest.approx(expected, rel=1e-9)
    assert res.value("Mean pose", "SRGR (reference)") == pytest.approx(expected, rel=1e-9)
    assert res.value(GROUND_TRUTH, "FGD (reference)") == pytest.approx(0.0, abs=1e-6)
    assert set(res.get("Mean pose").metrics) == set(keys) and res.columns == keys


def test_fgd_in_beats_euler_space_closed_form(test_set):
    """FGD (BEAT AE): the extractor reads z-scored 34-frame Euler windows. The mean pose (Euler 0) has
    constant windows, features 0: FGD = |mu_real|^2 + tr(Sigma_real); a direction model has none."""
    import dataclasses

    rng = np.random.default_rng(1)
    euler = [np.cumsum(rng.normal(size=(t, 141)), axis=0) for t in LENGTHS]
    moving = dataclasses.replace(test_set, gt_euler=euler)
    mean_pose = build_model("mean_pose")
    mean_pose.prepare({"pose": np.zeros((2, 34, 141), np.float32)})

    class Still(torch.nn.Module):
        representation, input_keys, target_key, pose_dim, n_pre = "dirvec126", ("dirvec",), "dirvec", 126, 4

        def generate(self, batch):
            return torch.zeros_like(batch["dirvec"])

    key = "FGD (BEAT AE)"
    entries = [("Mean pose", mean_pose), ("Still", Still())]
    res = evaluate_models(
        entries, test=moving, extractor=_features, euler_extractor=_features, columns=(key,)
    )
    assert res.value(GROUND_TRUTH, key) == pytest.approx(0.0, abs=1e-6)
    windows = np.concatenate([[e[s : s + 34] for s in range(0, len(e) - 33, 10)] for e in euler])
    real = _features(windows)  # the normalisers are mean 0, std 1: z-scoring changes nothing here
    low = (real.mean(0) ** 2).sum() + np.trace(np.cov(real.T, bias=True))
    high = (real.mean(0) ** 2).sum() + np.trace(np.cov(real.T))
    # the windows reach the extractor as float32: relative rounding of ~1e-7
    assert low * (1 - 1e-6) <= res.value("Mean pose", key) <= high * (1 + 1e-6)
    assert math.isnan(res.value("Still", key))  # no Euler angles


def test_direction_rows_have_no_euler_variant(test_set):
    class Still(torch.nn.Module):  # a direction model that repeats the mean direction (dirvec 0)
        representation, input_keys, target_key, pose_dim, n_pre = "dirvec126", ("dirvec",), "dirvec", 126, 4

        def generate(self, batch):
            return torch.zeros_like(batch["dirvec"])

    columns = ("SRGR (reference)", "SRGR")
    res = evaluate_models([("Still", Still())], test=test_set, extractor=_features, columns=columns)
    assert math.isnan(res.value("Still", "SRGR (reference)"))  # BEAT's code needs Euler angles
    assert np.isfinite(res.value("Still", "SRGR"))
    with pytest.raises(ValueError, match="unknown metric"):
        evaluate_models([], test=test_set, extractor=_features, columns=("SRGR (paper)",))


def test_to_markdown_shows_the_chosen_columns_and_names_each_variant(results):
    text = results.to_markdown(["FGD", "BC"])
    lines = text.splitlines()
    assert lines[0] == "| method | FGD ↓ | BC ↑ | gen. s |"
    mean_pose = next(line for line in lines if line.startswith("| Mean pose | "))
    assert len(mean_pose.split("|")) == 6  # label, 2 metrics, seconds
    assert "- **BC**: HA2G beat consistency" in text and "- **SRGR**" not in text
    assert results.to_markdown() == results.to_markdown(results.columns)
    with pytest.raises(ValueError, match="unknown metric"):
        results.to_markdown(["SRGR (paper)"])


def test_generated_euler_of_the_mean_pose_is_its_mean_and_directions_are_refused(test_set):
    from beatlite.train.testset import generated_euler

    mean_pose = build_model("mean_pose")
    pose = np.full((2, 34, 141), 0.5, np.float32)  # z-scored mean 0.5 -> 0.5 degrees (std 1, mean 0)
    mean_pose.prepare({"pose": pose})
    euler = generated_euler(mean_pose, test_set)
    assert [e.shape for e in euler] == [(t, 141) for t in LENGTHS]
    # seeded by the first 4 ground-truth frames (0), then the mean pose from frame 4 on
    np.testing.assert_allclose(euler[0][10:], 0.5, atol=1e-6)

    class Still:
        representation = "dirvec126"

    with pytest.raises(ValueError, match="not Euler"):
        generated_euler(Still(), test_set)


class _SeedEcho(torch.nn.Module):
    """A direction model whose every generated frame is its first seed frame: the output reveals its seed."""

    representation, target_key, input_keys, pose_dim, n_pre = "dirvec126", "dirvec", ("dirvec",), 126, 4

    def generate(self, batch):
        return batch["dirvec"][:, :1].expand(-1, 34, -1).clone()


def test_the_per_clip_protocol_seeds_every_clip_with_its_own_ground_truth(test_set):
    from beatlite.train.testset import clip_test_set, generate_takes

    clips = clip_test_set(test_set)
    starts = [(k, s) for k, t in enumerate(LENGTHS) for s in range(0, t - 33, 10)]
    assert clips.takes == [f"{test_set.takes[k]}@{s}" for k, s in starts]
    assert all(len(d) == 34 for d in clips.gt_directions) and len(clips.audio[0]) == int(34 / 15 * 16000)
    directions, _ = generate_takes(_SeedEcho(), clips, None)
    for (k, s), d in zip(starts, directions, strict=True):  # clip k@s: every frame is the take's frame s
        np.testing.assert_allclose(d, np.broadcast_to(test_set.gt_directions[k][s], d.shape), atol=1e-6)
    whole, _ = generate_takes(_SeedEcho(), test_set, None)  # whole takes: the first seed carries on
    np.testing.assert_allclose(whole[0][40], test_set.gt_directions[0][0], atol=1e-6)
    assert np.abs(test_set.gt_directions[0][40] - test_set.gt_directions[0][0]).max() > 1e-3


def test_written_tables_name_no_folder_of_the_machine_that_wrote_them(test_set, tmp_path, monkeypatch):
    """The results tables and the seed table record the FGD extractor, each seed's checkpoints and a row's source
    without the writer's folders (before: absolute paths such as ``/home/alice/...``, naming the home folder and
    user): relative to the build folder, else by the file's name."""
    from beatlite.models.testing import fake_windows
    from beatlite.train import TrainConfig, fit
    from beatlite.train import seeds as seeds_module

    home = tmp_path / "home" / "alice"
    monkeypatch.setenv("BEATLITE_BUILD", str(home / "build"))
    path = home / "build" / "seeds" / "1" / "mean_pose.pt"
    config = TrainConfig(epochs=1, checkpoint=path, progress=False)
    fit(build_model("mean_pose"), fake_windows(4, seed=1), config, meta=test_set.normalizers.to_meta())
    monkeypatch.setattr(
        seeds_module,
        "checkpoint_path",
        lambda name, seed: home / "build" / "seeds" / str(seed) / f"{name}.pt",
    )

    class Extractor:  # the stand-in features, loaded from a file of the home folder
        meta = {"path": str(home / "fgd_dirvec.pt")}

        def __call__(self, windows: np.ndarray) -> np.ndarray:
            return _features(windows)

    seed_table = seeds_module.evaluate_seeds(["mean_pose"], seeds=[1], test=test_set, extractor=Extractor())
    table = evaluate_models([str(path)], test=test_set, extractor=Extractor(), ground_truth=False)
    assert seed_table.info["checkpoints"] == {"mean_pose": ["$BEATLITE_BUILD/seeds/1/mean_pose.pt"]}
    assert table.info["extractor"] == seed_table.info["extractor"] == "fgd_dirvec.pt"
    assert table.to_dict()["rows"][0]["source"] == "$BEATLITE_BUILD/seeds/1/mean_pose.pt"
    written = [
        *seeds_module.write_seed_results(seed_table, tmp_path / "seeds"),
        *write_results(table, tmp_path / "r"),
    ]
    for file in written:
        text = file.read_text()
        assert str(tmp_path) not in text and "alice" not in text, (file.name, text)
