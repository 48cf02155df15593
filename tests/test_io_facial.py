"""Tests of the facial blendshape JSON reader/writer."""

from __future__ import annotations

import gzip
import json
from pathlib import Path

import numpy as np
import pytest

from beatlite.io import ARKIT_51, ARKIT_52, FormatError, read_facial, write_facial
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
