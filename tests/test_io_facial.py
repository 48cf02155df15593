"""Tests of the facial blendshape JSON reader/writer."""

from __future__ import annotations

import gzip
import json
from pathlib import Path

import numpy as np
import pytest

from beatlite.io import ARKIT_51, ARKIT_52, FormatError, FormatWarning, load_take, read_facial, write_facial
from beatlite.io.facial import estimate_fps


def test_arkit_names() -> None:
    assert len(ARKIT_52) == 52 and len(set(ARKIT_52)) == 52
    assert len(ARKIT_51) == 51 and "tongueOut" not in ARKIT_51
    assert ARKIT_51[0] == "eyeBlinkLeft" and ARKIT_51[-1] == "noseSneerRight"
    assert ARKIT_51 == tuple(n for n in ARKIT_52 if n != "tongueOut")


def test_round_trip(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    w = np.round(rng.uniform(0, 1, (120, 51)), 6)
    write_facial(tmp_path / "f.json", ARKIT_51, w, fps=60)
    face = read_facial(tmp_path / "f.json")
    assert face.names == ARKIT_51
    assert face.weights.shape == (120, 51) and face.weights.dtype == np.float32
    np.testing.assert_array_equal(face.weights, w.astype(np.float32))
    np.testing.assert_allclose(face.times, np.arange(120) / 60, atol=5e-7)  # times written with 6 decimals
    assert face.fps == 60.0


def test_gz_and_reference_layout(tmp_path: Path) -> None:
    doc = {
        "names": ["a", "b"],
        "frames": [{"time": 0.0, "weights": [0.1, 0.2]}, {"time": 0.5, "weights": [1, 0]}],
    }
    p = tmp_path / "f.json.gz"
    p.write_bytes(gzip.compress(json.dumps(doc).encode()))
    face = read_facial(p)
    np.testing.assert_array_equal(face.weights, np.array([[0.1, 0.2], [1, 0]], dtype=np.float32))
    assert face.fps == 2.0  # 1 / 0.5 s


def test_estimate_fps_with_jitter() -> None:
    t = np.arange(300) / 60 + np.random.default_rng(1).normal(0, 1e-4, 300)
    assert estimate_fps(np.sort(t)) == 60.0
    assert estimate_fps(np.array([0.0])) == 60.0
    assert estimate_fps(np.arange(10) / 29.5) == pytest.approx(29.5)


def _bad(tmp_path: Path, doc: object, text: str | None = None) -> FormatError:
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(doc) if text is None else text)
    with pytest.raises(FormatError) as info:
        read_facial(p)
    assert str(p) in str(info.value)
    return info.value


def test_missing_keys(tmp_path: Path) -> None:
    err = _bad(tmp_path, {"names": ["a"]})
    assert err.field == "frames"
    err = _bad(tmp_path, {"frames": []})
    assert err.field == "names"
    err = _bad(tmp_path, {"names": ["a"], "frames": [{"time": 0, "weights": [1]}, {"weights": [1]}]})
    assert err.field == "frames[1].time"


def test_weight_count_differs_from_names(tmp_path: Path) -> None:
    frames = [{"time": i / 60, "weights": [0.0] * 51} for i in range(5)]
    frames[3]["weights"] = [0.0] * 50
    err = _bad(tmp_path, {"names": list(ARKIT_51), "frames": frames})
    assert err.field == "frames[3].weights" and "50 weights" in str(err) and "51 names" in str(err)


def test_times_not_increasing(tmp_path: Path) -> None:
    frames = [{"time": t, "weights": [0.0]} for t in (0.0, 0.1, 0.1, 0.3)]
    err = _bad(tmp_path, {"names": ["a"], "frames": frames})
    assert err.field == "frames[2].time"


def test_invalid_json_and_values(tmp_path: Path) -> None:
    err = _bad(tmp_path, None, text='{"names": ["a"],\n "frames": [}')
    assert err.line == 2 and err.column is not None
    err = _bad(tmp_path, {"names": ["a"], "frames": [{"time": 0, "weights": ["x"]}]})
    assert err.field == "frames[0].weights"
    _bad(tmp_path, None, text="")


def test_write_validates(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=r"\(T, 2\)"):
        write_facial(tmp_path / "x.json", ["a", "b"], np.zeros((3, 3)))
    assert not (tmp_path / "x.json").exists()


# ----------------------------------------------------------------------------- blendshapes by name


def _weights(n_frames: int, names: tuple[str, ...]) -> np.ndarray:
    """Weight of blendshape ``name`` in frame t: (index of name in ARKIT_52 + 1) / 100 + t / 1000."""
    col = np.array([ARKIT_52.index(n) + 1 for n in names]) / 100
    return np.round(col[None, :] + np.arange(n_frames)[:, None] / 1000, 6)


def test_52_names_with_tongue_out_are_mapped_to_51(tmp_path: Path) -> None:
    write_facial(tmp_path / "f.json", ARKIT_52, _weights(5, ARKIT_52))
    assert read_facial(tmp_path / "f.json").weights.shape == (5, 52)  # as in the file by default
    with pytest.warns(FormatWarning, match=r"dropping 1 blendshapes .*tongueOut") as record:
        face = read_facial(tmp_path / "f.json", names=ARKIT_51)
    assert len(record) == 1  # one warning: ARKit's order without tongueOut is BEAT's order
    assert face.names == ARKIT_51 and face.weights.shape == (5, 51)
    np.testing.assert_allclose(face.weights, _weights(5, ARKIT_51), rtol=1e-6)


def test_other_order_is_reordered_by_name_with_a_warning(tmp_path: Path) -> None:
    shuffled = tuple(np.random.default_rng(1).permutation(ARKIT_51))
    write_facial(tmp_path / "f.json", shuffled, _weights(4, shuffled))
    with pytest.warns(FormatWarning, match="reordered by name"):
        face = read_facial(tmp_path / "f.json", names=ARKIT_51)
    np.testing.assert_allclose(face.weights, _weights(4, ARKIT_51), rtol=1e-6)  # each name's values follow it
    assert face.weights[0, ARKIT_51.index("jawOpen")] == pytest.approx((ARKIT_52.index("jawOpen") + 1) / 100)


def test_missing_blendshape_is_named(tmp_path: Path) -> None:
    names = tuple(n for n in ARKIT_51 if n != "jawOpen")
    write_facial(tmp_path / "f.json", names, _weights(3, names))
    with pytest.raises(FormatError, match="blendshape 'jawOpen' is missing") as err:
        read_facial(tmp_path / "f.json", names=ARKIT_51)
    assert err.value.field == "names"
    twice = _bad(tmp_path, {"names": ["a", "a"], "frames": []})
    assert "appear twice" in str(twice)


def test_load_take_face_is_51_wide_by_name(tmp_path: Path) -> None:
    from test_io_take import make_take

    stem = make_take(tmp_path)
    n = 120  # 2 s at 60 fps, as make_take writes
    write_facial(tmp_path / f"{stem.name}.json", ARKIT_52, _weights(n, ARKIT_52))
    with pytest.warns(FormatWarning, match="tongueOut"):
        take = load_take(stem)
    assert take.face is not None and take.face.shape == (30, 51) and take.face_names == ARKIT_51
    np.testing.assert_allclose(take.face, _weights(n, ARKIT_51)[::4], rtol=1e-6)  # 60 -> 15 fps
    raw = load_take(stem, blendshapes=None)  # the file's own columns
    assert raw.face is not None and raw.face.shape == (30, 52)


def test_an_empty_track_is_an_error_and_a_hole_in_the_time_stamps_warns_with_its_size(tmp_path: Path) -> None:
    """A 10 s hole was read silently as a uniform 60 fps track; an empty track was accepted."""
    import warnings

    write_facial(tmp_path / "empty.json", ARKIT_51, np.zeros((0, 51)), fps=60)
    with pytest.raises(FormatError, match="no frames"):
        read_facial(tmp_path / "empty.json")
    times = np.concatenate([np.arange(120) / 60, 12.0 + np.arange(120) / 60])  # 2 s, a 10 s hole, 2 s
    write_facial(tmp_path / "hole.json", ARKIT_51, np.full((240, 51), 0.5), fps=60, times=times)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        face = read_facial(tmp_path / "hole.json")
    messages = [str(w.message) for w in caught if issubclass(w.category, FormatWarning)]
    assert face.fps == 60 and len(messages) == 1, messages
    gap = times[120] - times[119]  # 10.0167 s between frames 119 and 120: 10 s of frames missing
    assert f"{gap:.3f} s after frame 119" in messages[0] and f"{gap - 1 / 60:.3f} s early" in messages[0]
    write_facial(tmp_path / "even.json", ARKIT_51, np.full((240, 51), 0.5), fps=60)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a regular track: no warning
        read_facial(tmp_path / "even.json")


@pytest.mark.parametrize("key", ["names", "frames", "weights", "time"])
def test_a_key_given_twice_in_one_object_is_a_format_error(tmp_path: Path, key: str) -> None:
    """json keeps the last of two equal keys: a file with a second, reversed "names" list was read with every
    column reordered by the wrong names (and a second "time" or "weights" replaced a frame's values)."""
    path = tmp_path / "face.json"
    write_facial(path, ARKIT_51, np.arange(3 * 51).reshape(3, 51) / 1000, fps=60)
    text = path.read_text()
    twice = {
        "names": ('{"names":', '{"names":' + json.dumps(list(ARKIT_51[::-1])) + ',"names":'),
        "frames": ('"frames":', '"frames":[],"frames":'),
        "weights": ('{"time":0.0,', '{"time":0.0,"weights":[],'),
        "time": ('{"time":0.0,', '{"time":0.0,"time":0.5,'),
    }[key]
    assert text.count(twice[0]) == 1
    path.write_text(text.replace(*twice))
    with pytest.raises(FormatError, match=f"key '{key}' appears twice") as info:
        read_facial(path, names=ARKIT_51)
    assert info.value.field == key
