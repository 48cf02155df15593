"""BEAT2 / SMPL-X: the .npz reader and writer, forward kinematics, retargeting to and from BEAT, BEAT2 folders."""

from __future__ import annotations

import io
import re
import shutil
import zipfile
from pathlib import Path

import numpy as np
import pytest
from zipdamage import flag_every_member

from beatlite.io import FormatError, load_take
from beatlite.io.smplx import SMPLXMotion, read_beat2_split, read_smplx, write_smplx
from beatlite.paths import repo_root
from beatlite.skeleton.rotations import axis_angle_to_matrix
from beatlite.skeleton.smplx import (
    BEAT_COUNTERPARTS,
    SMPLX_JOINTS,
    SMPLX_PARENTS,
    angular_speed,
    approximate_rest,
    beat_to_smplx,
    bone_direction_errors,
    rest_from_model,
    smplx_forward_kinematics,
    smplx_to_beat,
)

SAMPLES = repo_root() / "data_samples"


def _beat2_like(n: int = 40, seed: int = 0) -> dict[str, np.ndarray]:
    """The arrays of a BEAT2 file as PantoMatrix's beat_format_save writes them (keys, dtypes, shapes)."""
    rng = np.random.default_rng(seed)
    return {
        "betas": rng.normal(size=300).astype(np.float32),
        "poses": rng.normal(scale=0.3, size=(n, 165)).astype(np.float32),
        "expressions": rng.normal(size=(n, 100)).astype(np.float32),
        "trans": rng.normal(scale=0.1, size=(n, 3)).astype(np.float32),
        "model": np.array("smplx2020"),
        "gender": np.array("neutral"),
        "mocap_frame_rate": np.array(30),
    }


def _save(path: Path, arrays: dict, **kw) -> Path:
    np.savez(path, **arrays, **kw)
    return path


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle in radians between rotation matrices (robust near 0 and pi)."""
    d = np.swapaxes(a, -1, -2) @ b
    cos = (np.trace(d, axis1=-2, axis2=-1) - 1) / 2
    sin = np.linalg.norm(np.stack([d[..., 2, 1] - d[..., 1, 2], d[..., 0, 2] - d[..., 2, 0],
                                   d[..., 1, 0] - d[..., 0, 1]], -1), axis=-1) / 2  # fmt: skip
    return np.arctan2(sin, cos)


# --------------------------------------------------------------------------------------------- reading
def test_read_smplx_reads_a_file_written_like_beat2s(tmp_path):
    arrays = _beat2_like()
    m = read_smplx(_save(tmp_path / "2_scott_0_1_1.npz", arrays))
    assert m.poses.shape == (40, 55, 3) and m.fps == 30.0 and (m.model, m.gender) == ("smplx2020", "neutral")
    np.testing.assert_array_equal(m.poses.reshape(40, 165), arrays["poses"].astype(np.float64))
    np.testing.assert_array_equal(m.trans, arrays["trans"].astype(np.float64))
    np.testing.assert_array_equal(m.betas, arrays["betas"].astype(np.float64))
    assert m.expressions.shape == (40, 100)


def test_write_then_read_round_trips_in_float32(tmp_path):
    a = _beat2_like(seed=1)
    motion = SMPLXMotion(a["poses"].reshape(-1, 55, 3), a["trans"], 30, a["betas"], a["expressions"])
    write_smplx(tmp_path / "t.npz", motion)
    back = read_smplx(tmp_path / "t.npz")
    np.testing.assert_array_equal(back.poses, motion.poses)  # float32 values survive exactly
    with np.load(tmp_path / "t.npz") as z:
        assert set(z.files) == set(a) and all(z[k].dtype == a[k].dtype for k in ("poses", "trans", "betas"))
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


def _malformed(tmp_path: Path) -> dict[str, tuple[Path, str]]:
    """Ten malformed files (and what each error must name)."""
    a = _beat2_like(n=10)
    out = {}
    p = tmp_path / "lfs.npz"
    p.write_text("version https://git-lfs.github.com/spec/v1\noid sha256:ab\nsize 12\n")
    out["lfs pointer"] = (p, "Git-LFS")
    p = tmp_path / "text.npz"
    p.write_text("poses,trans\n1,2\n")
    out["a csv named .npz"] = (p, "not an .npz")
    out["no poses"] = (_save(tmp_path / "nop.npz", {k: v for k, v in a.items() if k != "poses"}), "'poses'")
    out["no frame rate"] = (
        _save(tmp_path / "nofps.npz", {k: v for k, v in a.items() if k != "mocap_frame_rate"}),
        "mocap_frame_rate",
    )
    out["164 columns"] = (_save(tmp_path / "w.npz", {**a, "poses": a["poses"][:, :164]}), "field 'poses'")
    nan = a["trans"].copy()
    nan[3, 1] = np.nan
    out["NaN in trans"] = (
        _save(tmp_path / "nan.npz", {**a, "trans": nan}),
        "non-finite value at index [3, 1]",
    )
    obj = np.empty(2, dtype=object)
    obj[:] = [{"x": 1}, None]
    out["pickled object array"] = (_save(tmp_path / "obj.npz", {**a, "betas": obj}), "pickled object array")
    out["trans of another length"] = (
        _save(tmp_path / "len.npz", {**a, "trans": a["trans"][:-1]}),
        "field 'trans'",
    )
    out["zero frame rate"] = (
        _save(tmp_path / "zero.npz", {**a, "mocap_frame_rate": np.array(0)}),
        "frame rate 0 fps is outside 1..100000 fps",
    )
    out["a frame rate below a BVH's"] = (  # resampled to 15 fps it would be 1,500 times as long: unbounded
        _save(tmp_path / "slow.npz", {**a, "mocap_frame_rate": np.array(0.01)}),
        "field 'mocap_frame_rate': frame rate 0.01 fps",
    )
    good = _save(tmp_path / "good.npz", a).read_bytes()
    p = tmp_path / "cut.npz"
    p.write_bytes(good[: len(good) // 2])
    out["truncated download"] = (p, "cut.npz")
    return out


def test_read_smplx_gives_one_format_error_per_malformed_file(tmp_path):
    cases = _malformed(tmp_path)
    assert len(cases) == 11
    for name, (path, expected) in cases.items():
        with pytest.raises(FormatError) as err:
            read_smplx(path)
        message = str(err.value)
        assert path.name in message and expected in message, (name, message)
        assert "\n" not in message, (name, message)


@pytest.mark.parametrize(
    "key, value",
    [
        ("mocap_frame_rate", np.array(0.5)),
        ("expressions", np.zeros((7, 100), np.float32)),
        ("poses", np.full((5, 165), np.nan, np.float32)),
        ("betas", np.arange(600, dtype=np.float32).reshape(2, 300)),
        ("trans", np.full((5, 3), 1e39)),  # finite in float64, inf in the float32 file
    ],
)
def test_what_read_smplx_refuses_smplx_motion_or_write_smplx_refuses(tmp_path, key, value):
    """write_smplx wrote files read_smplx refuses (fps 0.5, expressions of another length, NaN poses, per-frame
    betas that differ, trans beyond float32): each is now refused before a file is written."""
    arrays = {**_beat2_like(n=5), key: value}
    with np.errstate(over="ignore"):  # the file as the writer would write it (float32)
        raw = {k: v.astype(np.float32) if k == "trans" else v for k, v in arrays.items()}
    with pytest.raises(FormatError, match=f"field '{key}'"):  # the oracle: the reader refuses the file
        read_smplx(_save(tmp_path / "raw.npz", raw))
    path = tmp_path / "written.npz"
    args = [
        arrays["poses"],
        arrays["trans"],
        arrays["mocap_frame_rate"],
        arrays["betas"],
        arrays["expressions"],
    ]
    field = "fps" if key == "mocap_frame_rate" else key
    with pytest.raises(ValueError, match=rf"^(SMPLXMotion|write_smplx: .*written\.npz): {field}\b"):
        write_smplx(path, SMPLXMotion(*args))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["raw.npz"]


def test_write_smplx_refuses_a_motion_changed_after_it_was_made(tmp_path):
    motion = SMPLXMotion(np.zeros((5, 55, 3)), np.zeros((5, 3)), fps=30)
    motion.fps = 0.5
    with pytest.raises(ValueError, match="mocap_frame_rate as written .*0.5 fps is outside 1..100000"):
        write_smplx(tmp_path / "a.npz", motion)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("shape", [(5, 3, 55), (5 * 165,), (5, 5, 33), (5, 1, 165)])
def test_smplx_motion_takes_poses_as_t_165_or_t_55_3_only(shape):
    """Any array of 5 * 165 numbers was reshaped to (5, 55, 3): a transposed (T, 3, 55) became garbage rotations."""
    with pytest.raises(
        ValueError,
        match=re.escape(f"SMPLXMotion: poses: expected (T, 165) or (T, 55, 3) numbers, got {shape}"),
    ):
        SMPLXMotion(np.zeros(shape), np.zeros((5, 3)), fps=30)
    rows = np.arange(5 * 165.0).reshape(5, 165) / 1000
    a, b = SMPLXMotion(rows, np.zeros((5, 3)), 30), SMPLXMotion(rows.reshape(5, 55, 3), np.zeros((5, 3)), 30)
    assert a.poses.shape == (5, 55, 3) and np.array_equal(a.poses, b.poses) and a.poses[0, 1, 2] == rows[0, 5]


def test_read_smplx_refuses_a_decompression_bomb_before_decompressing(tmp_path):
    path = tmp_path / "bomb.npz"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        buf = io.BytesIO()
        np.lib.format.write_array(buf, np.zeros((100_000, 165)))  # 132 MB of zeros, ~130 kB stored
        z.writestr("poses.npy", buf.getvalue())
    with pytest.raises(FormatError, match="field 'poses'.*refused"):
        read_smplx(path)


@pytest.mark.parametrize("key", ["poses", "trans", "betas"])
def test_read_smplx_refuses_a_member_whose_header_claims_more_than_it_holds(tmp_path, key):
    """numpy allocates the shape an .npy header claims before reading data: a 27 kB file claiming 10**13 frames
    raised a bare MemoryError (5.86 PiB); now a FormatError naming the key, before anything is allocated."""
    arrays = _beat2_like()
    path = tmp_path / "take.npz"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED) as z:
        for name, value in arrays.items():
            buf = io.BytesIO()
            if name == key:  # the true data under a header claiming 10**13 rows
                header = {
                    "descr": value.dtype.str,
                    "fortran_order": False,
                    "shape": (10**13, *value.shape[1:]),
                }
                np.lib.format.write_array_header_1_0(buf, header)
                buf.write(value.tobytes())
            else:
                np.lib.format.write_array(buf, value)
            z.writestr(f"{name}.npy", buf.getvalue())
    with pytest.raises(
        FormatError, match=rf"field '{key}'.*needs \d+ bytes, the member holds {arrays[key].nbytes}"
    ):
        read_smplx(path)


def test_read_smplx_names_the_key_of_damaged_member_bytes(tmp_path):
    """Corrupt deflate data (savez_compressed) raised a bare zlib.error, and a header numpy's tokenizer cannot read
    a bare tokenize.TokenError; each is now a FormatError naming the key."""
    import struct

    path = tmp_path / "deflated.npz"
    np.savez_compressed(path, **_beat2_like())
    data = bytearray(path.read_bytes())
    with zipfile.ZipFile(path) as z:
        offset = z.getinfo("poses.npy").header_offset
    name_len, extra_len = struct.unpack("<HH", data[offset + 26 : offset + 30])
    start = offset + 30 + name_len + extra_len  # the member's deflate stream
    data[start + 40 : start + 80] = bytes(range(7, 247, 6))
    path.write_bytes(bytes(data))
    with pytest.raises(FormatError, match="field 'poses'.*decompressing"):
        read_smplx(path)
    path = tmp_path / "header.npz"
    with zipfile.ZipFile(path, "w") as z:
        for key, value in _beat2_like().items():
            if key != "trans":
                buf = io.BytesIO()
                np.lib.format.write_array(buf, value)
                z.writestr(f"{key}.npy", buf.getvalue())
        text = b"{'descr': '<f4', 'fortran_order': False, 'shape': (".ljust(117) + b"\n"  # an unclosed tuple
        z.writestr("trans.npy", b"\x93NUMPY\x01\x00" + len(text).to_bytes(2, "little") + text + bytes(480))
    with pytest.raises(FormatError, match="field 'trans'.*EOF in multi-line statement"):
        read_smplx(path)


@pytest.mark.parametrize("damage", ["method", "encrypted"])
def test_read_smplx_names_a_member_zipfile_cannot_open(tmp_path, damage):
    """An unknown compression method raised a bare NotImplementedError, the encryption flag a bare RuntimeError."""
    path = _save(tmp_path / "take.npz", _beat2_like())
    path.write_bytes(
        bytes(flag_every_member(bytearray(path.read_bytes()), damage))
    )  # every local and central header
    with pytest.raises(FormatError, match="field 'betas'.*not a readable array"):
        read_smplx(path)


def test_read_beat2_split_names_the_bad_line(tmp_path):
    path = tmp_path / "train_test_split.csv"
    path.write_text("id,type\n2_scott_0_1_1,test\n2_scott_0_2_2,holdout\n")
    with pytest.raises(FormatError, match="line 3.*holdout"):
        read_beat2_split(path)
    path.write_text("id,type\n2_scott_0_1_1,test\n2_scott_0_1_1,train\n")
    with pytest.raises(FormatError, match="line 3.*twice"):
        read_beat2_split(path)


# ------------------------------------------------------------------------------------------ kinematics
def test_topology_is_smplx_kintree():
    assert len(SMPLX_JOINTS) == 55 and all(SMPLX_PARENTS[j] < j for j in range(1, 55))
    named = dict(zip(SMPLX_JOINTS, SMPLX_PARENTS, strict=True))
    assert SMPLX_JOINTS[named["left_wrist"]] == "left_elbow" and SMPLX_JOINTS[named["jaw"]] == "head"
    assert (
        SMPLX_JOINTS[named["right_thumb3"]] == "right_thumb2"
        and SMPLX_JOINTS[named["right_index1"]] == "right_wrist"
    )


def test_forward_kinematics_by_hand():
    rest = approximate_rest()
    poses = np.zeros((1, 55, 3))
    e, w = SMPLX_JOINTS.index("left_elbow"), SMPLX_JOINTS.index("left_wrist")
    poses[0, SMPLX_JOINTS.index("left_shoulder")] = [
        0,
        0,
        np.pi / 2,
    ]  # the whole left arm turns 90 deg about Z
    x = smplx_forward_kinematics(poses, np.array([[1.0, 2.0, 3.0]]))
    forearm = rest.joints[w] - rest.joints[e]  # along +X at rest
    np.testing.assert_allclose(x[0, w] - x[0, e], [-forearm[1], forearm[0], forearm[2]], atol=1e-12)
    np.testing.assert_allclose(x[0, 0], rest.joints[0] + [1.0, 2.0, 3.0])


def _fake_model(path: Path, rng: np.random.Generator) -> Path:
    """A random SMPL-X model file with the keys and shapes the smplx package reads (V = 10000 vertices)."""
    v = 10000
    reg = rng.random((55, v)) * (rng.random((55, v)) < 0.002)
    reg[:, 0] += 1e-3
    reg /= reg.sum(1, keepdims=True)
    kintree = np.stack([np.where(SMPLX_PARENTS < 0, 2**32 - 1, SMPLX_PARENTS), np.arange(55)]).astype(
        np.int64
    )
    np.savez(
        path, v_template=rng.normal(size=(v, 3)), shapedirs=rng.normal(scale=1e-3, size=(v, 3, 400)).astype(np.float32),
        posedirs=np.zeros((v, 3, 486), np.float32), J_regressor=reg, kintree_table=kintree,
        weights=np.full((v, 55), 1 / 55), f=rng.integers(0, v, size=(200, 3)),
        hands_componentsl=np.eye(45), hands_componentsr=np.eye(45),
        hands_meanl=rng.normal(scale=0.2, size=45), hands_meanr=rng.normal(scale=0.2, size=45),
        lmk_faces_idx=np.zeros(51, np.int64), lmk_bary_coords=np.full((51, 3), 1 / 3),
        dynamic_lmk_faces_idx=np.zeros((79, 17), np.int64), dynamic_lmk_bary_coords=np.full((79, 17, 3), 1 / 3),
    )  # fmt: skip
    return path


@pytest.mark.slow
def test_forward_kinematics_equals_the_smplx_package_on_a_fake_model(tmp_path):
    smplx = pytest.importorskip("smplx", reason="the optional smplx package (pip install beatlite[smplx])")
    torch = pytest.importorskip("torch")
    rng = np.random.default_rng(3)
    model_path = _fake_model(tmp_path / "SMPLX_NEUTRAL.npz", rng)
    betas, expr = rng.normal(size=(1, 10)), rng.normal(size=(1, 10))
    poses, trans = rng.normal(scale=0.4, size=(4, 55, 3)), rng.normal(size=(4, 3))
    model = smplx.SMPLX(str(model_path), num_betas=10, num_expression_coeffs=10, use_pca=False,
                        flat_hand_mean=False, batch_size=4)  # fmt: skip
    t = lambda x: torch.as_tensor(np.asarray(x), dtype=torch.float32)  # noqa: E731
    out = model(
        betas=t(np.repeat(betas, 4, 0)), expression=t(np.repeat(expr, 4, 0)), transl=t(trans),
        global_orient=t(poses[:, 0]), body_pose=t(poses[:, 1:22].reshape(4, -1)), jaw_pose=t(poses[:, 22]),
        leye_pose=t(poses[:, 23]), reye_pose=t(poses[:, 24]), left_hand_pose=t(poses[:, 25:40].reshape(4, -1)),
        right_hand_pose=t(poses[:, 40:55].reshape(4, -1)), return_verts=False,
    )  # fmt: skip
    rest = rest_from_model(model_path, betas[0], expr[0])
    ours = smplx_forward_kinematics(poses, trans, rest)
    scale = float(np.abs(ours).max())
    # float32 in the package: its error grows with the chain depth (~20 products), ~1e-6 relative each
    np.testing.assert_allclose(out.joints[:, :55].numpy(), ours, atol=1e-5 * scale)


def test_rest_from_model_refuses_bad_files(tmp_path):
    p = tmp_path / "SMPLX_NEUTRAL.npz"
    np.savez(p, v_template=np.zeros((5, 3)))
    with pytest.raises(FormatError, match="no shapedirs"):
        rest_from_model(p)
    obj = np.empty(1, dtype=object)
    np.savez(p, v_template=obj, shapedirs=obj, J_regressor=obj, kintree_table=obj)
    with pytest.raises(FormatError, match="pickles"):
        rest_from_model(p)


def test_angular_speed_is_the_rotation_between_frames():
    rng = np.random.default_rng(0)
    poses = rng.normal(size=(5, 55, 3))
    r = axis_angle_to_matrix(poses)
    np.testing.assert_allclose(angular_speed(poses, 30.0), _angle(r[:-1], r[1:]) * 30.0, atol=1e-9)


# ------------------------------------------------------------------------------------------ retargeting
def _unmapped_beat_joints() -> set[str]:
    from beatlite.skeleton.beat import beat_skeleton

    return set(beat_skeleton().names) - set(BEAT_COUNTERPARTS.values())


def test_beat_to_smplx_points_every_aligned_bone_exactly_and_bounds_the_rest():
    take = load_take(SAMPLES / "2_scott_0_1_1", fps=30)
    poses, trans = beat_to_smplx(take.motion)
    errors = bone_direction_errors(take.motion, poses, trans)
    print({k: round(float(v.max()), 2) for k, v in errors.items() if v.max() > 1e-6})
    exact = {"pelvis->spine1", "spine3->neck", "left_wrist->left_middle1", "right_wrist->right_middle1"}
    for bone, e in errors.items():
        parent = bone.split("->")[0]
        single = parent not in ("pelvis", "spine3", "left_wrist", "right_wrist")
        if single or bone in exact:
            assert e.max() < 1e-6, bone  # the aligned bone of each joint: exact by construction
        else:
            assert e.max() < 10.0, bone  # the other children of pelvis, spine3 and wrists
    # the pelvis lands on BEAT's Hips
    np.testing.assert_allclose(trans * 100, take.motion.positions()[:, 0], atol=1e-9)


def test_bvh_to_smplx_to_bvh_round_trip_bone_directions():
    take = load_take(SAMPLES / "2_scott_0_1_1", fps=30)
    back = smplx_to_beat(*beat_to_smplx(take.motion), fps=30)
    a, b = take.motion.positions(), back.positions()
    sk = take.motion.skeleton
    worst = {}
    for k in range(1, sk.n_joints):
        p = sk.parents[k]
        u, v = a[:, k] - a[:, p], b[:, k] - b[:, p]
        angle = np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.sum(u * v, -1))  # exact near 0
        worst[f"{sk.names[p]}->{sk.names[k]}"] = float(np.degrees(angle).max())
    print("round trip, worst bone errors in degrees:", {k: round(v, 2) for k, v in worst.items() if v > 1e-6})
    unmapped = _unmapped_beat_joints()
    for bone, e in worst.items():
        parent, child = bone.split("->")
        if parent in unmapped or child in unmapped:  # a folded joint's own rotation is lost
            assert e < 10.0, bone
        else:
            assert e < 1e-6, bone
    np.testing.assert_allclose(a[:, 0], b[:, 0], atol=1e-9)


def test_smplx_to_bvh_to_smplx_recovers_every_mapped_rotation():
    rng = np.random.default_rng(5)
    poses = rng.normal(scale=0.3, size=(20, 55, 3))
    trans = rng.normal(scale=0.2, size=(20, 3))
    back, trans2 = beat_to_smplx(smplx_to_beat(poses, trans, fps=30))
    mapped = [j for j, n in enumerate(SMPLX_JOINTS) if n in BEAT_COUNTERPARTS]
    err = _angle(axis_angle_to_matrix(poses[:, mapped]), axis_angle_to_matrix(back[:, mapped]))
    assert err.max() < 1e-7
    np.testing.assert_allclose(trans2, trans, atol=1e-12)
    assert np.abs(back[:, [22, 23, 24]]).max() == 0.0  # jaw and eyes: BEAT has no such joints


# ----------------------------------------------------------------------------------------- BEAT2 folders
@pytest.fixture(scope="module")
def beat2_folder(tmp_path_factory):
    from beatlite.data.beat2 import write_beat2_folder
    from beatlite.data.examples import example_corpus

    src = example_corpus()
    dst = tmp_path_factory.mktemp("beat2") / "beat_english_v2.0.0"
    write_beat2_folder(src.name, dst)
    src.cleanup()
    return dst


def test_index_and_load_a_beat2_folder(beat2_folder):
    from beatlite.data.index import index_folder

    (beat2_folder / "train_test_split.csv").write_text(
        "id,type\n2_scott_0_1_1,test\n2_scott_0_9_9,additional\n"
    )
    index = index_folder(beat2_folder, cache=False)
    assert index.stems == ["2_scott_0_1_1", "2_scott_0_9_9"]
    assert [r.format for r in index] == ["beat2", "beat2"] and [r.split for r in index] == [
        "test",
        "additional",
    ]
    assert all(r.usable for r in index) and not any("face" in p for r in index for p in r.problems)
    take = load_take(index[0].path("motion"))
    beat = load_take(SAMPLES / "2_scott_0_1_1")
    assert (
        take.format == "beat2"
        and take.n_frames == beat.n_frames
        and take.expressions.shape == (beat.n_frames, 100)
    )
    np.testing.assert_array_equal(take.audio, beat.audio)
    assert take.words.words == beat.words.words
    # the body (no fingers) is where BEAT puts it, up to the folded Spine1 and Neck1: a chain of two 11 cm bones
    # bent by theta is 22 (1 - cos(theta / 2)) cm shorter than straight, < 0.05 cm for the sample's bends (< 4 deg)
    names = [n for n in BEAT_COUNTERPARTS.values() if "Hand" not in n or n.endswith("Hand")]
    cols = [beat.motion.skeleton.index(n) for n in names]
    np.testing.assert_allclose(take.positions()[:, cols], beat.positions()[:, cols], atol=0.05)


@pytest.mark.parametrize("phase, first", [("start", 0), ("beat", 1)])
def test_a_beat2_takes_expressions_keep_its_motions_frames(beat2_folder, tmp_path, phase, first):
    """With phase="beat" the motion kept 30 fps frames 1, 3, 5, ... and the expressions 0, 2, 4, ...: one frame
    out of step. Frame i is written into both (pelvis rotation i / 1000 rad about y, expression 0 = i)."""
    folder = tmp_path / "beat2"
    shutil.copytree(beat2_folder, folder)
    path = folder / "smplxflame_30" / "2_scott_0_1_1.npz"
    m = read_smplx(path)
    poses, expressions = np.zeros_like(m.poses), np.zeros((m.n_frames, 100))
    poses[:, 0, 1] = np.arange(m.n_frames) / 1000
    expressions[:, 0] = np.arange(m.n_frames)
    write_smplx(path, SMPLXMotion(poses, m.trans, 30, m.betas, expressions))
    take = load_take(path, fps=15, phase=phase)
    skeleton = take.motion.skeleton  # the root's rotation about y (BEAT2's y axis is BEAT's: up)
    hips_y = int(skeleton.channel_starts[0]) + list(skeleton.channels[0]).index("Yrotation")
    frames = np.radians(take.motion.channels[:, hips_y]) * 1000
    want = first + 2 * np.arange(take.n_frames)  # 30 -> 15 fps: every second frame from `first`
    np.testing.assert_allclose(frames, want, atol=1e-6)
    np.testing.assert_array_equal(take.expressions[:, 0], want)


def test_an_audio_file_load_take_would_not_find_makes_the_take_unusable(beat2_folder, tmp_path):
    """wave16k/ renamed audio/: the index found the .wav anyway and called the take usable, load_take did not find
    it, and the store build failed on a take without audio. The index now lists the files loading reads."""
    from beatlite.data.index import index_folder

    folder = tmp_path / "beat2"
    shutil.copytree(beat2_folder, folder)
    (folder / "wave16k").rename(folder / "audio")
    record = index_folder(folder, cache=False)["2_scott_0_1_1"]
    take = load_take(record.path("motion"))
    assert (
        take.audio is None and ".wav" not in take.paths and "audio" not in record.files and not record.usable
    )
    wav = folder / "audio" / "2_scott_0_1_1.wav"
    assert record.problems[:2] == [
        f"audio file {wav} is not beside the motion file or in wave16k/ beside its folder, where load_take looks: "
        "not used",
        "missing audio (.wav) file",
    ]
    assert record.files["text"] == take.paths[".TextGrid"] == folder / "textgrid" / "2_scott_0_1_1.TextGrid"


def test_a_bvh_and_its_converted_npz_index_and_load_the_same_file(tmp_path):
    """A take with its .bvh.gz and a converted .npz beside it: the index used the .npz (plain files sorted before
    .gz) while load_take(stem) read the .bvh.gz; both now read BEAT's own file, the .npz noted as a duplicate."""
    from beatlite.convert import convert
    from beatlite.data.index import index_folder

    for name in ("2_scott_0_1_1.bvh.gz", "2_scott_0_1_1.wav"):
        shutil.copy(SAMPLES / name, tmp_path)
    convert(tmp_path / "2_scott_0_1_1.bvh.gz", tmp_path / "2_scott_0_1_1.npz")
    record = index_folder(tmp_path, cache=False)["2_scott_0_1_1"]
    take = load_take(tmp_path / "2_scott_0_1_1")
    assert record.files["motion"] == take.paths[".bvh"] == tmp_path / "2_scott_0_1_1.bvh.gz"
    assert record.format == take.format == "beat" and record.usable
    assert (
        f"duplicate motion files: using {tmp_path / '2_scott_0_1_1.bvh.gz'}, ignoring {tmp_path / '2_scott_0_1_1.npz'}"
        in record.problems
    )


def test_the_split_list_of_a_beat2_root_nested_in_the_indexed_folder_sets_its_takes_splits(
    beat2_folder, tmp_path
):
    """Indexing a folder that holds a BEAT2 root: its train_test_split.csv was ignored (BEAT's name rule used)."""
    from beatlite.data.index import index_folder

    nested = tmp_path / "nest" / "beat_english_v2.0.0"
    shutil.copytree(beat2_folder, nested)
    # by BEAT's rule 2_scott_0_1_1 is test and 2_scott_0_9_9 train: the list says otherwise
    (nested / "train_test_split.csv").write_text("id,type\n2_scott_0_1_1,train\n2_scott_0_9_9,additional\n")
    for root in (nested, tmp_path / "nest", tmp_path):
        index = index_folder(root, cache=False)
        assert {r.stem: r.split for r in index} == {"2_scott_0_1_1": "train", "2_scott_0_9_9": "additional"}


@pytest.mark.slow
def test_score_a_folder_of_beat2_predictions(beat2_folder, tmp_path):
    from beatlite.score import read_prediction, score_folder

    (beat2_folder / "train_test_split.csv").write_text("id,type\n2_scott_0_1_1,test\n2_scott_0_9_9,train\n")
    shutil.copy(beat2_folder / "smplxflame_30" / "2_scott_0_1_1.npz", tmp_path)
    assert read_prediction(tmp_path / "2_scott_0_1_1.npz").form.startswith("npz smplx")
    result = score_folder(tmp_path, beat2_folder, metrics=["FGD", "FGD (rot6d)", "MPJPE", "BC (emage)"])
    values = result.evaluation.values()
    assert values["FGD"] < 1e-6 and values["FGD (rot6d)"] < 1e-6 and values["MPJPE"] < 1e-4
    assert "6D autoencoder sha256" in result.to_markdown()
    assert values["BC (emage)"] == pytest.approx(result.truth.values()["BC (emage)"], abs=1e-9)


def test_a_take_moved_to_another_split_by_the_csv_moves_in_the_store(tmp_path, monkeypatch):
    """train_test_split.csv changes a take's split without changing its files: the store built before must follow
    (it kept the old split, so a test take went on training)."""
    from beatlite.data.beat2 import write_beat2_folder
    from beatlite.data.examples import example_corpus
    from beatlite.data.index import index_folder
    from beatlite.data.store import build_store

    monkeypatch.setenv("BEATLITE_BUILD", str(tmp_path / "build"))
    src, root = example_corpus(), tmp_path / "beat2"
    write_beat2_folder(src.name, root)
    src.cleanup()
    csv = root / "train_test_split.csv"
    csv.write_text("id,type\n2_scott_0_1_1,train\n2_scott_0_9_9,test\n")
    first = build_store(index_folder(root), workers=0)
    assert {t.stem: t.meta["split"] for t in first.takes} == {
        "2_scott_0_1_1": "train",
        "2_scott_0_9_9": "test",
    }
    csv.write_text("id,type\n2_scott_0_1_1,test\n2_scott_0_9_9,train\n")
    again = build_store(index_folder(root), workers=0)
    assert {t.stem: t.meta["split"] for t in again.takes} == {
        "2_scott_0_1_1": "test",
        "2_scott_0_9_9": "train",
    }
    assert [again.takes[int(i)].stem for i in np.unique(again.windows("train").take_ids)] == ["2_scott_0_9_9"]


def test_writing_into_an_existing_beat2_folder_extends_its_split_list(tmp_path):
    """The destination "to create or extend": rows of other takes stay, the takes written replace theirs (the
    list was rewritten with this call's takes only)."""
    from beatlite.data.beat2 import write_beat2_folder
    from beatlite.data.examples import example_corpus
    from beatlite.data.index import index_folder
    from beatlite.io.smplx import read_beat2_split

    src, root = example_corpus(), tmp_path / "beat2"
    root.mkdir()
    (root / "train_test_split.csv").write_text("id,type\n7_sophie_0_1_1,val\n2_scott_0_1_1,additional\n")
    written = write_beat2_folder(src.name, root)
    want = {r.stem: r.split for r in index_folder(src.name)}
    src.cleanup()
    assert read_beat2_split(root / "train_test_split.csv") == {"7_sophie_0_1_1": "val", **want}
    assert written == list(want)


# ------------------------------------------------------------------------------------------ conversion
def test_convert_command_round_trip_and_one_line_errors(tmp_path, capsys):
    from beatlite.convert import main
    from beatlite.io import read_bvh

    src = SAMPLES / "2_scott_0_1_1.bvh.gz"
    assert main([str(src), str(tmp_path / "t.npz")]) == 0
    out = capsys.readouterr().out
    assert "left_wrist->left_pinky1" in out and "jaw, left_eye_smplhf, right_eye_smplhf" in out
    smplx = read_smplx(tmp_path / "t.npz")
    assert (
        smplx.fps == 30.0 and smplx.n_frames == 2 * load_take(SAMPLES / "2_scott_0_1_1").n_frames
    )  # 15 fps take
    assert main([str(tmp_path / "t.npz"), str(tmp_path / "back.bvh")]) == 0
    back = read_bvh(tmp_path / "back.bvh")
    np.testing.assert_allclose(back.channels, smplx.to_beat().channels, atol=1e-6)  # 6 decimals in the file
    assert main([str(tmp_path / "t.npz"), str(tmp_path / "own.bvh"), "--skeleton", "smplx"]) == 0
    own = read_bvh(tmp_path / "own.bvh")
    from beatlite.skeleton.smplx import DEPTH_FIRST

    np.testing.assert_allclose(own.positions(), 100 * smplx.positions()[:, DEPTH_FIRST], atol=1e-3)
    capsys.readouterr()
    assert main([str(SAMPLES / "2_scott_0_1_1.wav"), str(tmp_path / "x.npz")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error:") and "2_scott_0_1_1.wav" in err[0]
    # --fps is the rate of a written .npz: given for a .bvh it was ignored silently
    assert main([str(tmp_path / "t.npz"), str(tmp_path / "fps.bvh"), "--fps", "60"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert (
        len(err) == 1
        and "--fps is the rate of a written .npz" in err[0]
        and not (tmp_path / "fps.bvh").exists()
    )


def test_convert_folder_names_each_skipped_take_and_refuses_another_fps(tmp_path, capsys, monkeypatch):
    """A folder conversion skipped unusable takes silently ("1 takes written") and ignored --fps."""
    from beatlite.convert import main

    monkeypatch.setenv("BEATLITE_BUILD", str(tmp_path / "build"))
    src = tmp_path / "src"
    src.mkdir()
    for path in SAMPLES.glob("2_scott_0_1_1.*"):
        shutil.copy(path, src)
    shutil.copy(SAMPLES / "2_scott_0_9_9.wav", src)  # audio without motion: not usable
    assert main([str(src), str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out == [
        "skipped 2_scott_0_9_9 (not usable): missing motion (.bvh or .npz) file; missing face (.json) file; "
        "missing text (.TextGrid) file; missing semantic (.txt) file; missing emotion (.csv) file",
        f"1 takes written to {tmp_path / 'out'}, 1 skipped",
    ]
    assert sorted(p.name for p in (tmp_path / "out" / "smplxflame_30").iterdir()) == ["2_scott_0_1_1.npz"]
    assert main([str(src), str(tmp_path / "out60"), "--fps", "60"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error:") and "30 fps" in err[0] and "fps=60.0" in err[0]
    assert not (tmp_path / "out60").exists()


@pytest.mark.parametrize("fps", ["0", "-5", "nan", "inf"])
def test_convert_refuses_a_frame_rate_that_is_not_finite_and_positive(tmp_path, capsys, fps):
    """--fps 0 was a ZeroDivisionError traceback (nan and inf went on into the resampler)."""
    from beatlite.convert import main

    assert main([str(SAMPLES / "2_scott_0_1_1.bvh.gz"), str(tmp_path / "a.npz"), "--fps", fps]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"error: convert: fps must be finite and > 0, got {float(fps)!r}"]
    assert list(tmp_path.iterdir()) == []


def test_convert_to_a_folder_given_as_the_output_file_is_one_error_line(tmp_path, capsys):
    """An output path that is a folder was an IsADirectoryError traceback."""
    from beatlite.convert import main

    (tmp_path / "out.npz").mkdir()
    assert main([str(SAMPLES / "2_scott_0_1_1.bvh.gz"), str(tmp_path / "out.npz")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error:") and str(tmp_path / "out.npz") in err[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.npz"] and not any(
        (tmp_path / "out.npz").iterdir()
    )
