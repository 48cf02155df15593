"""Joint Embedding (Language2Pose style): shapes, the two decodings, loss, gradients, determinism."""

from __future__ import annotations

import pytest

torch = pytest.importorskip("torch")

from beatlite.models import build_model  # noqa: E402
from beatlite.models.testing import fake_batch  # noqa: E402

V = 50


@pytest.fixture(scope="module")
def batch():
    return fake_batch(3, vocab_size=V)


def _model(torch_seed: int = 0, **kw):
    torch.manual_seed(torch_seed)
    return build_model("joint_embedding", preset="tiny", vocab_size=V, **kw)


def test_shapes(batch):
    model = _model()
    out = model(batch)
    assert out["pose"].shape == out["pose_recon"].shape == (3, 34, 141)
    assert out["z_text"].shape == out["z_pose"].shape == (3, model.config.embed_dim)


def test_text_path_reads_words_and_seed_only_pose_path_reads_the_motion(batch):
    model = _model().eval()
    out = model(batch)
    later = dict(batch)
    later["pose"] = batch["pose"].clone()
    later["pose"][:, model.n_pre :] += 1.0
    moved = model(later)
    assert torch.equal(moved["pose"], out["pose"])
    assert not torch.allclose(moved["pose_recon"], out["pose_recon"])
    assert torch.equal(model.generate(later), out["pose"])
    words = dict(batch)
    words["word"] = (batch["word"] + 1) % V
    assert not torch.allclose(model(words)["pose"], out["pose"])
    seed = dict(batch)
    seed["pose"] = batch["pose"].clone()
    seed["pose"][:, 0] += 1.0
    assert not torch.allclose(model(seed)["pose"], out["pose"])


def test_one_decoder_for_both_embeddings(batch):
    model = _model().eval()
    out = model(batch)
    # the two outputs are the same decoder applied to the two embeddings
    assert torch.equal(model.decode(out["z_pose"], batch["pose"]), out["pose_recon"])
    assert torch.equal(model.decode(out["z_text"], batch["pose"]), out["pose"])


def test_loss_on_a_hand_case(batch):
    model = _model(rec_weight=2.0)
    target = batch["pose"]
    parts = model.losses(batch, {"pose": target, "pose_recon": target + 0.5}, epoch=0)
    assert float(parts["text_rec"]) == 0.0
    assert float(parts["pose_rec"]) == pytest.approx(0.5, rel=1e-6)
    assert float(parts["total"]) == pytest.approx(2.0 * 0.5, rel=1e-6)


def test_text_reconstruction_trains_the_text_path_not_the_pose_encoder(batch):
    model = _model()
    model.losses(batch, model(batch), epoch=0)["text_rec"].backward()
    assert all(p.grad is None for p in model.pose_gru.parameters())
    for module in (model.text_encoder, model.text_gru, model.decoder, model.head, model.seed_net):
        assert all(float(p.grad.abs().sum()) > 0 for p in module.parameters())


def test_words_of_another_length_raise(batch):
    a = _model(3)
    with pytest.raises(ValueError, match="word"):
        a({"pose": batch["pose"], "word": batch["word"][:, :10]})


def test_paper_preset_builds_and_runs(batch):
    torch.manual_seed(0)
    model = build_model("joint_embedding", preset="paper", vocab_size=V).eval()
    assert model.config.hidden == 300 and model.config.dec_layers == 4
    assert model(batch)["pose"].shape == (3, 34, 141)
