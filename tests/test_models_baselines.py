"""Baselines (mean pose, random clip, S2G-style, Trimodal-style) and the model registry."""

from __future__ import annotations

import numpy as np
import pytest
from childproc import run_ok

torch = pytest.importorskip("torch")

from beatlite.models import MODELS, build_model  # noqa: E402
from beatlite.models.testing import fake_batch, fake_windows  # noqa: E402

V = 50


@pytest.fixture(scope="module")
def batch():
    return fake_batch(3, vocab_size=V)


def test_mean_pose_is_the_training_mean(batch):
    windows = fake_windows(10, seed=1)
    model = build_model("mean_pose")
    model.prepare(windows)
    expected = windows["pose"].astype(np.float64).mean(axis=(0, 1))
    out = model.generate(batch).numpy()
    assert out.shape == (3, 34, 141)
    np.testing.assert_allclose(out, np.broadcast_to(expected, out.shape), atol=1e-5)
    assert not model.trainable


def test_random_clip_returns_real_training_windows_deterministically(batch):
    windows = fake_windows(20, seed=2)
    a, b = build_model("random_clip", n_clips=8), build_model("random_clip", n_clips=8)
    a.prepare(windows)
    b.prepare(windows)
    out = a.generate(batch).numpy()
    assert np.array_equal(out, b.generate(batch).numpy())
    for clip in out:
        assert any(np.array_equal(clip, w) for w in windows["pose"])
    assert not np.array_equal(out, a.generate(batch).numpy())  # the next call draws again


def test_s2g_shapes_and_audio_only(batch):
    torch.manual_seed(0)
    model = build_model("s2g", preset="tiny").eval()
    out = model(batch)["pose"]
    assert out.shape == (3, 34, 141)
    other = dict(batch)
    other["pose"] = torch.randn_like(batch["pose"])
    other["word"] = torch.zeros_like(batch["word"])
    assert torch.equal(model(other)["pose"], out)
    other["mel"] = batch["mel"] - 10
    assert not torch.equal(model(other)["pose"], out)


def test_trimodal_shapes_kld_and_eval_determinism(batch):
    torch.manual_seed(0)
    model = build_model("trimodal", preset="tiny", vocab_size=V)
    model.eval()
    out = model(batch)
    assert out["pose"].shape == (3, 34, 141) and out["z_mu"].shape == (3, 16)
    assert torch.equal(model(batch)["pose"], out["pose"])  # eval: z = mu
    zero = {"pose": out["pose"], "z_mu": torch.zeros(3, 16), "z_logvar": torch.zeros(3, 16)}
    # KLD of N(0, 1) against N(0, 1) is 0
    assert float(model.losses(batch, zero, epoch=0)["kld"]) == 0.0
    one = {**zero, "z_mu": torch.ones(3, 16)}
    # -0.5 * mean(1 + 0 - 1 - 1) = 0.5
    assert float(model.losses(batch, one, epoch=0)["kld"]) == pytest.approx(0.5)


@pytest.mark.parametrize("name", ["s2g", "trimodal"])
def test_learned_baselines_reconstruction_is_zero_on_the_target(batch, name):
    torch.manual_seed(0)
    kw = {"vocab_size": V} if name == "trimodal" else {}
    model = build_model(name, preset="tiny", no_adv_epochs=0, **kw)
    out = model(batch)
    assert float(model.losses(batch, {**out, "pose": batch["pose"]}, epoch=-1)["rec"]) == 0.0


@pytest.mark.parametrize("name", ["s2g", "trimodal"])
def test_paper_presets_build_and_run(batch, name):
    torch.manual_seed(0)
    kw = {"vocab_size": V} if name == "trimodal" else {}
    model = build_model(name, preset="paper", **kw)
    assert model(batch)["pose"].shape == (3, 34, 141)


def test_registry_names_presets_and_options_are_checked():
    assert {"camn", "ha2g", "s2g", "trimodal", "mean_pose", "random_clip"} <= set(MODELS)
    with pytest.raises(ValueError, match="model name"):
        build_model("nope")
    with pytest.raises(TypeError, match="unknown option"):
        build_model("s2g", preset="tiny", widht=3)
    with pytest.raises(ValueError, match="preset"):
        build_model("s2g", preset="huge")


def test_import_models_does_not_import_torch():
    import sys

    code = "import sys, beatlite.models, beatlite.train; assert 'torch' not in sys.modules"
    run_ok([sys.executable, "-c", code])
