"""Joint Embedding (Yoon et al. 2020's adaptation of Language2Pose): shapes, inputs, loss, sampling, parameter count."""

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
    for key in ("z_context", "context_mu", "context_logvar", "z_pose"):
        assert out[key].shape == (3, model.config.embed_dim), key


def test_speech_path_reads_words_audio_and_seed_pose_path_reads_the_motion(batch):
    model = _model(eval_z="mean").eval()
    out = model(batch)
    later = dict(batch)
    later["pose"] = batch["pose"].clone()
    later["pose"][:, model.n_pre :] += 1.0
    moved = model(later)
    assert torch.equal(moved["pose"], out["pose"])
    assert not torch.allclose(moved["pose_recon"], out["pose_recon"])
    assert torch.equal(model.generate(later), out["pose"])
    for key, change in (("word", lambda w: (w + 1) % V), ("audio", lambda a: 0.5 * a)):
        other = dict(batch)
        other[key] = change(batch[key])
        assert not torch.allclose(model(other)["pose"], out["pose"]), key
    seed = dict(batch)
    seed["pose"] = batch["pose"].clone()
    seed["pose"][:, 0] += 1.0
    assert not torch.allclose(model(seed)["pose"], out["pose"])


def test_one_decoder_for_both_embeddings(batch):
    model = _model().eval()
    out = model(batch)
    assert torch.equal(model.decode(out["z_pose"], batch["pose"]), out["pose_recon"])
    assert torch.equal(model.decode(out["z_context"], batch["pose"]), out["pose"])


def test_the_speech_embedding_is_sampled_and_seeded(batch):
    a, b = _model(seed=3).eval(), _model(seed=3).eval()
    out = a(batch)
    # z = mu + exp(logvar / 2) * eps with eps from Generator(seed + 0)
    eps = torch.randn(out["context_mu"].shape, generator=torch.Generator().manual_seed(3))
    want = out["context_mu"] + torch.exp(0.5 * out["context_logvar"]) * eps
    torch.testing.assert_close(out["z_context"], want)
    assert torch.equal(b(batch)["pose"], out["pose"])
    assert not torch.equal(a(batch)["pose"], out["pose"])  # the next call draws again
    a.reset()
    assert torch.equal(a(batch)["pose"], out["pose"])
    mean = _model(eval_z="mean").eval()(batch)
    assert torch.equal(mean["z_context"], mean["context_mu"])


def test_loss_on_a_hand_case(batch):
    model = _model(rec_weight=2.0)
    target = batch["pose"]
    parts = model.losses(batch, {"pose": target, "pose_recon": target + 0.5}, epoch=0)
    assert float(parts["speech_rec"]) == 0.0
    assert float(parts["pose_rec"]) == pytest.approx(0.5, rel=1e-6)
    assert float(parts["total"]) == pytest.approx(2.0 * 0.5, rel=1e-6)


def test_speech_reconstruction_trains_the_speech_path_not_the_pose_encoder(batch):
    model = _model()
    model.losses(batch, model(batch), epoch=0)["speech_rec"].backward()
    assert all(p.grad is None for p in model.pose_conv.parameters())
    parts = (
        model.text_encoder,
        model.audio_encoder,
        model.context_gru,
        model.decoder,
        model.head,
        model.seed_net,
    )
    for module in parts:
        assert all(float(p.grad.abs().sum()) > 0 for p in module.parameters() if p.requires_grad)


def test_bad_input_raises(batch):
    a = _model(3)
    with pytest.raises(ValueError, match="word"):
        a({"pose": batch["pose"], "word": batch["word"][:, :10], "audio": batch["audio"]})
    with pytest.raises(ValueError, match="pose"):
        a({"pose": batch["pose"][:, :20], "word": batch["word"][:, :20], "audio": batch["audio"]})
    with pytest.raises(ValueError, match="eval_z"):
        _model(eval_z="median")


def _gru(n_in: int, hidden: int, layers: int, directions: int = 1) -> int:
    """nn.GRU parameters: per layer and direction 3 gates x (input weights + hidden weights + 2 biases)."""
    first = 3 * (n_in * hidden + hidden * hidden + 2 * hidden)
    rest = 3 * (directions * hidden * hidden + hidden * hidden + 2 * hidden)
    return directions * (first + (layers - 1) * rest)


def reference_count(vocab: int) -> int:
    """``EmbeddingNet(mode="random")`` of ai4r/Gesture-Generation-from-Trimodal-Context with pose_dim 141,
    34 frames, 300-d words and parse_args' text TCN (hidden_size 200, n_layers 2), from its layer shapes."""
    tcn = (
        vocab * 300
        + (200 * 300 * 2 + 200 + 200) + (200 * 200 * 2 + 200 + 200) + (300 * 200 + 200)  # level 0 (weight norm: g, bias)
        + 2 * (200 * 200 * 2 + 200 + 200)  # level 1
        + (200 * 32 + 32)  # TextEncoderTCN.decoder
    )  # fmt: skip
    wav = (
        (1 * 16 * 15 + 16 + 2 * 16)
        + (16 * 32 * 15 + 32 + 2 * 32)
        + (32 * 64 * 15 + 64 + 2 * 64)
        + (64 * 32 * 15 + 32)
    )
    context = tcn + wav + _gru(64, 256, 2) + (256 * 128 + 128 + 2 * 128 + 128 * 32 + 32) + 2 * (32 * 32 + 32)
    pose_encoder = (
        (141 * 32 * 3 + 32 + 2 * 32) + (32 * 64 * 3 + 64 + 2 * 64) + (64 * 64 * 4 + 64 + 2 * 64) + (64 * 32 * 3 + 32)
        + (384 * 256 + 256 + 2 * 256) + (256 * 128 + 128 + 2 * 128) + (128 * 32 + 32)
        + 2 * (32 * 32 + 32)  # fc_mu, fc_logvar
    )  # fmt: skip
    decoder = (
        (141 * 4 * 32 + 32 + 2 * 32 + 32 * 32 + 32)
        + _gru(64, 300, 4, 2)
        + (300 * 150 + 150 + 150 * 141 + 141)
    )
    return context + pose_encoder + decoder


def test_gru_count_formula_on_torch():
    assert _gru(7, 5, 3, 2) == sum(p.numel() for p in torch.nn.GRU(7, 5, 3, bidirectional=True).parameters())


def test_paper_preset_has_the_reference_parameter_count(batch):
    torch.manual_seed(0)
    model = build_model("joint_embedding", preset="paper", vocab_size=V)
    cfg = model.config
    assert (cfg.text_hidden, cfg.text_layers, cfg.context_hidden, cfg.hidden, cfg.dec_layers) == (
        200,
        2,
        256,
        300,
        4,
    )
    assert sum(p.numel() for p in model.parameters()) == reference_count(V)
    # the pose encoder's log-variance head is the reference's but never trained (z = mu in its training)
    assert model.n_parameters() == reference_count(V) - (32 * 32 + 32)
    assert sum(
        p.numel() for p in build_model("joint_embedding", preset="paper").parameters()
    ) == reference_count(5793)
    assert model.eval()(batch)["pose"].shape == (3, 34, 141)
