"""Tests of the FGD feature extractor (torch): shapes, loss, determinism, checkpoint round trip."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from beatlite.metrics import fgd  # noqa: E402
from beatlite.metrics.extractor import (  # noqa: E402
    ExtractorConfig,
    MotionAutoencoder,
    autoencoder_loss,
    load_extractor,
    save_extractor,
    train_autoencoder,
)
from beatlite.paths import checkpoints_dir  # noqa: E402


def smooth_windows(n=96, d=6, seed=0):
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 1, 34)[None, :, None]
    return (np.sin(2 * np.pi * (rng.uniform(0.5, 2, (n, 1, d)) * t + rng.uniform(0, 1, (n, 1, d))))).astype(
        np.float32
    )


def test_autoencoder_shapes_and_latent_size():
    for latent in (8, 48):
        model = MotionAutoencoder(ExtractorConfig(input_dim=6, latent_dim=latent, channels=8)).eval()
        x = torch.zeros(3, 34, 6)
        assert model.encode(x).shape == (3, latent)
        assert model(x).shape == (3, 34, 6)
        assert model.encoder(x.transpose(1, 2)).shape == (3, 8, 12)  # 34 -> 12 frames, as BEAT's encoder


def test_autoencoder_loss_hand_computed():
    target = torch.zeros(1, 34, 2)
    # constant offset 1: L1 = 1, velocity error 0 -> 1
    assert float(autoencoder_loss(target + 1, target)) == pytest.approx(1.0)
    # ramp recon[t] = t: L1 = mean(0..33) = 16.5; every frame difference 1 -> MSE 1, x 0.1 -> 16.6
    ramp = torch.arange(34.0).view(1, 34, 1).repeat(1, 1, 2)
    assert float(autoencoder_loss(ramp, target)) == pytest.approx(16.6)


def test_training_is_deterministic_and_reduces_the_loss():
    w = smooth_windows()
    cfg = ExtractorConfig(input_dim=6, latent_dim=8, channels=8, epochs=6, batch_size=16, seed=3)
    m1, info1 = train_autoencoder(w, cfg, log=False)
    m2, _ = train_autoencoder(w, cfg, log=False)
    for a, b in zip(m1.state_dict().values(), m2.state_dict().values()):
        assert torch.equal(a, b)
    hist = [h["train"] for h in info1["history"]]
    assert hist[-1] < hist[0]
    np.testing.assert_allclose(info1["mean"], w.reshape(-1, 6).mean(0), atol=1e-6)


def test_checkpoint_round_trip(tmp_path):
    w = smooth_windows(d=126)  # a dirvec extractor's windows: 126 channels
    cfg = ExtractorConfig(input_dim=126, latent_dim=8, channels=8, epochs=1, batch_size=32)
    model, info = train_autoencoder(w, cfg, log=False)
    path = save_extractor(tmp_path / "x.pt", model, info, space="dirvec", meta={"data_fingerprint": "abc"})
    ex = load_extractor(path=path)
    with torch.no_grad():
        direct = model.eval().encode(torch.from_numpy((w - info["mean"]) / info["std"])).numpy()
    np.testing.assert_allclose(ex(w), direct, rtol=1e-5, atol=1e-6)
    assert ex.meta["data_fingerprint"] == "abc" and ex.latent_dim == 8
    assert fgd(w, w, extractor=ex) == pytest.approx(0.0, abs=1e-6)
    with pytest.raises(ValueError, match=r"windows must be \(N, 34, 126\)"):
        ex(np.zeros((2, 30, 126)))
    assert not list(tmp_path.glob(".*tmp"))  # atomic write left no temporary file


def test_load_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="python -m beatlite.metrics.extractor train"):
        load_extractor(path=tmp_path / "missing.pt")
    torch.save({"format": "other"}, tmp_path / "bad.pt")
    with pytest.raises(ValueError, match="not a beatlite FGD extractor"):
        load_extractor(path=tmp_path / "bad.pt")
    with pytest.raises(ValueError, match="space"):
        load_extractor("euler")


def test_command_line_help():
    out = subprocess.run(
        [sys.executable, "-m", "beatlite.metrics.extractor", "train", "--help"],
        capture_output=True,
        text=True,
    )
    assert out.returncode == 0 and "--space" in out.stdout


@pytest.mark.parametrize("space, dim", [("dirvec", 126), ("pose", 141), ("rot6d", 282)])
def test_shipped_checkpoint(space, dim):
    from beatlite.metrics.extractor import SPACES

    path = checkpoints_dir() / SPACES[space][1]
    if not path.is_file():
        pytest.skip(
            f"{path.name} not trained yet (python -m beatlite.metrics.extractor train --space {space})"
        )
    assert path.stat().st_size <= 2_000_000
    ex = load_extractor(space)
    assert ex.space == space and len(ex.meta["data_fingerprint"]) == 16
    feats = ex(np.zeros((3, 34, dim), np.float32))
    assert feats.shape == (3, ex.latent_dim) and np.all(np.isfinite(feats))


def test_reference_page_states_the_velocity_weights():
    """docs/reference_code.md#fgd-autoencoder names each extractor's velocity weight; they are ``VELOCITY_WEIGHT``."""
    from pathlib import Path

    from beatlite.metrics.extractor import VELOCITY_WEIGHT

    page = " ".join((Path(__file__).resolve().parents[1] / "docs" / "reference_code.md").read_text().split())
    assert VELOCITY_WEIGHT == {"pose": 0.1, "dirvec": 10.0, "rot6d": 10.0}
    assert (
        "the Euler-pose one with BEAT's 0.1, the direction-vector and rot6d ones with a velocity weight of 10"
        in page
    )
