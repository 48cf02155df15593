"""Attention Seq2Seq (Yoon et al. 2019 style): shapes, inputs it reads, loss terms, gradients, determinism."""

from __future__ import annotations

import math

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from beatlite.models import build_model  # noqa: E402
from beatlite.models.testing import fake_batch  # noqa: E402

V = 50


@pytest.fixture(scope="module")
def batch():
    return fake_batch(3, vocab_size=V)


def _model(seed: int = 0, **kw):
    torch.manual_seed(seed)
    return build_model("seq2seq", preset="tiny", vocab_size=V, **kw)


def test_shapes_seed_frame_and_attention_weights(batch):
    model = _model().eval()
    out = model(batch)
    assert out["pose"].shape == (3, 34, 141)
    assert out["attention"].shape == (3, 33, 34)
    # the first output frame is the first seed frame; attention rows are distributions
    assert torch.equal(out["pose"][:, 0], batch["pose"][:, 0])
    assert torch.all(out["attention"] >= 0)
    np.testing.assert_allclose(out["attention"].sum(-1).detach().numpy(), 1.0, atol=1e-6)


def test_reads_only_words_and_the_seed(batch):
    model = _model().eval()
    out = model(batch)["pose"]
    later = dict(batch)
    later["pose"] = batch["pose"].clone()
    later["pose"][:, model.n_pre :] = torch.randn_like(later["pose"][:, model.n_pre :])
    later["audio"] = torch.zeros_like(batch["audio"])
    assert torch.equal(model(later)["pose"], out)
    assert torch.equal(model.generate(later), out)
    seed = dict(batch)
    seed["pose"] = batch["pose"].clone()
    seed["pose"][:, 1] += 1.0
    assert not torch.allclose(model(seed)["pose"][:, 2:], out[:, 2:])
    words = dict(batch)
    words["word"] = (batch["word"] + 1) % V
    assert not torch.allclose(model(words)["pose"][:, 1:], out[:, 1:])


def test_loss_terms_on_hand_cases(batch):
    model = _model()
    b, t, d = batch["pose"].shape
    zero = {"pose": torch.zeros(b, t, d)}
    c = 0.5
    parts = model.losses(zero, {"pose": torch.full((b, t, d), c)}, epoch=0)
    # constant output: MSE c^2, no frame-to-frame change, variance -|c| sqrt(T) * B * D / (B * T * D)
    assert float(parts["mse"]) == pytest.approx(c**2)
    assert float(parts["continuity"]) == 0.0
    assert float(parts["variance"]) == pytest.approx(-c / math.sqrt(t), rel=1e-6)
    cfg = model.config
    expected = cfg.rec_weight * c**2 - cfg.variance_weight * c / math.sqrt(t)
    assert float(parts["total"]) == pytest.approx(expected, rel=1e-6)
    # a ramp out[:, k] = k * delta changes by delta on T - 1 of T frames
    delta = 0.1
    ramp = delta * torch.arange(t, dtype=torch.float32).view(1, t, 1).expand(b, t, d)
    assert float(model.losses(zero, {"pose": ramp}, epoch=0)["continuity"]) == pytest.approx(
        delta * (t - 1) / t, rel=1e-6
    )


def test_word_vectors_and_bad_input(batch):
    model = _model()
    vectors = np.arange(V * model.config.word_dim, dtype=np.float32).reshape(V, -1)
    model.set_word_vectors(vectors)
    np.testing.assert_array_equal(model.embedding.weight.detach().numpy(), vectors)
    with pytest.raises(ValueError, match="vectors must be"):
        model.set_word_vectors(vectors[:-1])
    bad = dict(batch)
    bad["word"] = batch["word"] + V
    with pytest.raises(ValueError, match="word ids"):
        model(bad)
    with pytest.raises(KeyError, match="word"):
        model({"pose": batch["pose"]})


def test_paper_preset_builds_and_runs(batch):
    torch.manual_seed(0)
    model = build_model("seq2seq", preset="paper", vocab_size=V).eval()
    assert model.config.hidden == 200 and model.config.n_layers == 2
    assert model(batch)["pose"].shape == (3, 34, 141)


def test_recipes_give_the_text_models_the_vocabulary():
    from beatlite.train.recipes import RECIPES

    # build_recipe_model sets vocab_size and word vectors exactly for the models that read words
    for name in ("seq2seq_tiny", "a2g_tiny", "joint_embedding_tiny"):
        reads_words = "word" in build_model(RECIPES[name].model, preset="tiny").input_keys
        assert RECIPES[name].uses_text == reads_words, name
