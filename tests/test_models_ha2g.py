"""HA2G model (beatlite.models.ha2g): shapes of every module, switches, gradients, determinism."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from beatlite.data.normalize import Normalizer, Normalizers  # noqa: E402
from beatlite.models import build_model  # noqa: E402
from beatlite.models.ha2g import (  # noqa: E402
    ABLATIONS,
    HA2G,
    PRESETS,
    HA2GDiscriminator,
    build_ha2g,
)
from beatlite.models.ha2g_audio import HierarchicalAudioEncoder, StyleCoordinator, blend_audio  # noqa: E402
from beatlite.models.ha2g_losses import aligned_against_level_ce, style_diverging_loss  # noqa: E402
from beatlite.models.testing import fake_batch, fake_windows  # noqa: E402
from beatlite.train.recipes import HA2G_ABLATIONS  # noqa: E402

PAPER_LEVEL_DIMS = (24, 30, 36, 66, 96, 126)  # docs/reference_code.md#ha2g-levels: 8/10/12/22/32/42 bones x 3


@pytest.fixture(autouse=True)
def _one_thread() -> None:
    torch.set_num_threads(1)


def _unit_windows(n: int, seed: int = 0) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """Fake windows whose "dirvec" are real mean-subtracted unit vectors; returns (windows, mean)."""
    w = fake_windows(n, seed=seed)
    rng = np.random.default_rng(seed)
    u = rng.standard_normal((n, 34, 42, 3)) + np.array([0.0, 2.0, 0.0])  # mostly "up", varied
    u /= np.linalg.norm(u, axis=-1, keepdims=True)
    u = u.reshape(n, 34, 126)
    mean = u.reshape(-1, 126).mean(axis=0)
    w["dirvec"] = (u - mean).astype(np.float32)
    return w, mean


def _model(seed: int = 0, **overrides: object) -> HA2G:
    torch.manual_seed(seed)
    model = build_model("ha2g", preset="tiny", **overrides)
    w, mean = _unit_windows(8)
    model.prepare(w, _norms(mean))
    return model


def _norms(mean: np.ndarray) -> Normalizers:
    """Train-split normalisers whose direction mean is ``mean`` (the pose part is unused by HA2G)."""
    return Normalizers(Normalizer(np.zeros(141), np.ones(141)), Normalizer(mean, np.ones(126)))


# ----------------------------------------------------------------------------- audio learner
@pytest.mark.parametrize(
    ("channels", "blocks", "feat", "freq_stride"),
    [
        ((4, 8, 16, 32), (1, 1, 1, 1), 16, 1),
        ((4, 8, 16, 32), (1, 1, 1, 1), 16, 2),
        ((32, 64, 128, 256), (1, 1, 1, 1), 32, 1),
    ],
)
def test_audio_encoder_maps_mel_to_three_levels_of_34_frames(channels, blocks, feat, freq_stride) -> None:
    enc = HierarchicalAudioEncoder(channels, blocks, reduction=4, out_features=feat, freq_stride=freq_stride)
    out = enc(torch.randn(2, 70, 128) * 20 - 40)
    assert sorted(out) == ["high", "low", "mid"]
    for level in ("low", "mid", "high"):
        assert tuple(out[level].shape) == (2, 34, feat)
    # each stream's Linear reads (frequency rows after its conv) x channels: 128 / (2 s) - 1 rows for low
    assert enc.streams["low"].proj.in_features == (128 // (2 * freq_stride) - 1) * channels[1]
    assert enc.streams["high"].proj.in_features == (128 // (8 * freq_stride) * 4 - 2) * (channels[3] // 16)


def test_audio_encoder_freq_stride_is_validated() -> None:
    with pytest.raises(ValueError, match="freq_stride"):
        HierarchicalAudioEncoder((4, 8, 16, 32), (1, 1, 1, 1), freq_stride=3)


def test_audio_encoder_builds_only_requested_levels_and_validates() -> None:
    enc = HierarchicalAudioEncoder((4, 8, 16, 32), (1, 1, 1, 1), 4, 8, levels=("low",))
    assert enc.layer3 is None and enc.layer4 is None
    assert list(enc(torch.zeros(1, 70, 128))) == ["low"]
    with pytest.raises(ValueError, match=r"mel must be \(B, M >= 8, 128\).*\(2, 70, 80\)"):
        enc(torch.zeros(2, 70, 80))
    with pytest.raises(ValueError, match="pixel-shuffled"):
        HierarchicalAudioEncoder((4, 8, 16, 24), (1, 1, 1, 1))


def test_style_coordinator_weights_are_a_softmax_over_audio_levels() -> None:
    coord = StyleCoordinator(8, 16, 6)
    w = coord(torch.randn(5, 8))
    assert tuple(w.shape) == (5, 3, 6)
    np.testing.assert_allclose(w.sum(dim=1).detach().numpy(), 1.0, atol=1e-6)
    assert float(w.detach().min()) > 0.0


def test_blend_audio_is_the_weighted_sum_of_eq3() -> None:
    g = torch.Generator().manual_seed(0)
    feats = {lv: torch.randn(2, 34, 4, generator=g) for lv in ("low", "mid", "high")}
    w = torch.zeros(2, 3, 2)
    w[:, 0, 0] = 1.0  # body level 0 <- low only
    w[:, 1, 1] = 0.25  # body level 1 <- 0.25 mid + 0.75 high
    w[:, 2, 1] = 0.75
    out = blend_audio(feats, w)
    assert tuple(out.shape) == (2, 2, 34, 4)
    torch.testing.assert_close(out[:, 0], feats["low"])
    torch.testing.assert_close(out[:, 1], 0.25 * feats["mid"] + 0.75 * feats["high"])


# ----------------------------------------------------------------------------- pose inferer
def test_level_outputs_have_the_paper_dimensions() -> None:
    from beatlite.skeleton import ted

    model = _model()
    assert model.level_dims == PAPER_LEVEL_DIMS
    assert model.level_dims == tuple(3 * len(lv) for lv in ted.HA2G_LEVELS)
    out = model(fake_batch(3))
    for k, d in enumerate(PAPER_LEVEL_DIMS):
        assert tuple(out[f"level{k}"].shape) == (3, 34, d)
    assert tuple(out["pose"].shape) == (3, 34, 126)
    assert tuple(out["style_weights"].shape) == (3, 3, 6)
    for level in ("low", "mid", "high"):
        assert tuple(out[f"audio_{level}"].shape) == (3, 34, 16)
    # the 126-d output is the last level's prediction (all 42 bones, in bone order)
    torch.testing.assert_close(out["pose"], out["level5"])


def test_holistic_switch_has_one_level_with_all_bones() -> None:
    model = _model(**ABLATIONS["holistic"])
    out = model(fake_batch(2))
    assert model.level_dims == (126,)
    assert "level1" not in out and tuple(out["level0"].shape) == (2, 34, 126)
    assert tuple(out["style_weights"].shape) == (2, 3, 1)


def test_the_reference_layer_order_is_the_codes() -> None:
    # HA2G's ResNetSE34V2 / SEBasicBlock: stem conv (biased) -> ReLU -> BN; block conv1 -> ReLU -> BN1; each stream
    # conv -> ReLU -> BN -> fc. Built by hand from a beatlite-order encoder's weights, the reference order gives
    # the same features as HierarchicalAudioEncoder(order="reference") with those weights.
    torch.manual_seed(0)
    ref = HierarchicalAudioEncoder((8, 8, 16, 16), (1, 1, 1, 1), 4, 6, order="reference").eval()
    for m in ref.modules():  # non-trivial BatchNorm statistics
        if isinstance(m, torch.nn.BatchNorm2d):
            m.running_mean.uniform_(-0.5, 0.5), m.running_var.uniform_(0.5, 2.0)
    mel = torch.randn(2, 70, 128) * 20 - 40
    x = (mel / 40.0 + 1.0).transpose(1, 2).unsqueeze(1)
    conv, bn = ref.stem[0], ref.stem[2]
    assert conv.bias is not None and isinstance(ref.stem[1], torch.nn.ReLU)
    y = bn(torch.relu(conv(x)))
    for block in [*ref.layer1, *ref.layer2]:
        h = block.bn1(torch.relu(block.conv1(y)))
        h = block.se(block.bn2(block.conv2(h)))
        y = torch.relu(h + block.shortcut(y))
    s = ref.streams["low"]
    z = s.post[1](torch.relu(s.conv(y)))
    b, c, f, t = z.shape
    low = s.proj(z.permute(0, 3, 1, 2).reshape(b, t, c * f))[:, :34]
    torch.testing.assert_close(ref(mel)["low"], low)
    beat = HierarchicalAudioEncoder((8, 8, 16, 16), (1, 1, 1, 1), 4, 6)
    assert beat.stem[0].bias is None and isinstance(beat.stem[1], torch.nn.BatchNorm2d)
    extra = sum(p.numel() for p in ref.parameters()) - sum(p.numel() for p in beat.parameters())
    assert extra == 8 + 2 * (8 + 4 + 1)  # the stem bias, and each stream's BatchNorm (2 per channel)
    with pytest.raises(ValueError, match="order must be one of"):
        HierarchicalAudioEncoder(order="other")


def test_single_audio_and_same_audio_switches() -> None:
    single = _model(**ABLATIONS["single_audio"])
    assert single.coordinator is None
    w = single(fake_batch(2))["style_weights"]
    np.testing.assert_array_equal(w[:, 0].numpy(), 1.0)  # all body levels read the low level
    np.testing.assert_array_equal(w[:, 1:].numpy(), 0.0)
    same = _model(**ABLATIONS["same_audio"])
    w = same(fake_batch(2))["style_weights"]
    torch.testing.assert_close(w, w[:, :, :1].expand_as(w))


def test_coarse_to_fine_level_k_reads_level_k_minus_1() -> None:
    # Changing level 0's output weights changes level 1's prediction (cascade), and the seed
    # frames of the target are the only part of "dirvec" the model reads.
    model = _model().eval()
    batch = fake_batch(2)
    before = model(batch)
    with torch.no_grad():
        model.generators[0].head[-1].bias += 1.0
    after = model(batch)
    assert not torch.allclose(before["level1"], after["level1"])
    future = dict(batch)
    future["dirvec"] = batch["dirvec"].clone()
    future["dirvec"][:, model.n_pre :] += 5.0
    torch.testing.assert_close(model(future)["pose"], after["pose"])


# The levels' vectors as the reference's slices list them (docs/reference_code.md#ha2g-levels), in channel order.
_LEVEL_VECTORS = (
    [0, 1, 2, 37, 38, 39, 40, 41],
    [0, 1, 2, 3, 20, 37, 38, 39, 40, 41],
    [0, 1, 2, 3, 4, 20, 21, 37, 38, 39, 40, 41],
    [*range(6), 8, 11, 14, 17, 20, 21, 22, 25, 28, 31, 34, *range(37, 42)],
    [*range(7), 8, 9, 11, 12, 14, 15, 17, 18, *range(20, 24), 25, 26, 28, 29, 31, 32, 34, 35, *range(37, 42)],
    list(range(42)),
)


def test_cascade_copies_every_shared_bone_into_its_own_channels() -> None:
    # The reference copies the head bones 37-41 one channel off (docs/reference_code.md#ha2g-levels); beatlite
    # must put each bone of level k-1's prediction in that bone's channels of level k's seed, new bones and the
    # indicator 0 from frame n_pre on, and the ground-truth seed frames with indicator 1 before.
    model = _model().eval()
    seen: list[torch.Tensor] = []
    hooks = [g.register_forward_hook(lambda m, args, out: seen.append(args[0])) for g in model.generators]
    batch = fake_batch(2)
    with torch.no_grad():
        out = model(batch)
    for h in hooks:
        h.remove()
    n_pre = model.n_pre
    assert [s.shape[-1] for s in seen] == [3 * len(v) + 1 for v in _LEVEL_VECTORS]
    for k in range(1, 6):
        prev, cur, pre_seq = _LEVEL_VECTORS[k - 1], _LEVEL_VECTORS[k], seen[k]
        pred = out[f"level{k - 1}"]
        for i, bone in enumerate(cur):
            got = pre_seq[:, n_pre:, 3 * i : 3 * i + 3]
            if bone in prev:
                j = prev.index(bone)
                torch.testing.assert_close(got, pred[:, n_pre:, 3 * j : 3 * j + 3])
            else:
                assert torch.count_nonzero(got) == 0, f"level {k + 1}, new bone {bone}"
            torch.testing.assert_close(
                pre_seq[:, :n_pre, 3 * i : 3 * i + 3], batch["dirvec"][:, :n_pre, 3 * bone : 3 * bone + 3]
            )
        assert torch.all(pre_seq[:, n_pre:, -1] == 0) and torch.all(pre_seq[:, :n_pre, -1] == 1)


def test_discriminator_shape_and_losses() -> None:
    d = HA2GDiscriminator(126, 16, 2, 34, 0.1)
    assert tuple(d(torch.randn(3, 34, 126)).shape) == (3, 1)
    with pytest.raises(ValueError, match=r"\(B, 34, 126\)"):
        d(torch.randn(3, 33, 126))
    model = _model()
    batch = fake_batch(4)
    out = model(batch)
    d_losses = model.discriminator_losses(batch, out)
    # log(4) when D outputs 1/2 for everything; an untrained D is near that
    assert 0.5 < float(d_losses["total"].detach()) < 3.0
    torch.testing.assert_close(d_losses["total"].detach(), d_losses["real"] + d_losses["fake"])


# ----------------------------------------------------------------------------- losses and gradients
def test_loss_terms_follow_the_switches_and_warmup() -> None:
    model = _model()
    batch = fake_batch(4)
    out = model(batch)
    early = model.losses(batch, out, epoch=0)
    assert "adv" not in early  # warm-up
    late = model.losses(batch, out, epoch=model.config.no_adv_epochs)
    assert {"huber", "kld", "adv", "style", "contrastive_pos", "contrastive_neg", "physical", "total"} <= set(
        late
    )
    c = model.config
    torch.manual_seed(5)
    again = model.losses(batch, out, epoch=0)
    torch.manual_seed(5)
    ref = model.losses(batch, out, epoch=0)
    expected = (
        c.huber_weight * ref["huber"]
        + c.kld_weight * ref["kld"]
        + c.style_weight * ref["style"]
        + c.contrastive_pos_weight * ref["contrastive_pos"]
        - c.contrastive_neg_weight * ref["contrastive_neg"]
        + c.physical_weight * ref["physical"]
    )
    torch.testing.assert_close(again["total"], expected)
    bare = _model(use_contrastive=False, use_physical=False, adversarial=False, use_style_loss=False)
    terms = bare.losses(batch, bare(batch), epoch=100)
    assert set(terms) == {"huber", "kld", "total"}
    assert bare.discriminator is None and bare.contrastive_text is None


@pytest.mark.parametrize("style", ["reference", "shared"])
def test_style_decode_in_the_forward_batch_equals_a_separate_decode(style: str) -> None:
    """Training forward runs the other-speaker cascade in the same 2B batch: same output as alone."""
    model = _model(style=style)
    model.train()
    batch = fake_batch(3)
    out = model(batch)
    assert tuple(out["pose_other"].shape) == (3, 34, 126) and tuple(out["z_other"].shape) == (3, 8)
    assert tuple(out["z_levels"].shape) == tuple(out["z_levels_other"].shape) == (3, 6, 8)
    audio = {lv[6:]: v for lv, v in out.items() if lv.startswith("audio_")}
    texts = [out[f"text{k}"] for k in range(len(model.text_encoders))]
    if style == "reference":  # the coordinator keeps the true speakers (HA2G's code)
        coord = coord_other = model.coordinator_embedding(batch["speaker"])
    else:  # one z drives everything
        coord, coord_other = out["z"], out["z_other"]
    alone, _ = model._decode(batch["dirvec"], audio, texts, coord_other, out["z_levels_other"])
    torch.testing.assert_close(out["pose_other"], alone[-1], rtol=1e-5, atol=1e-6)
    mine, _ = model._decode(batch["dirvec"], audio, texts, coord, out["z_levels"])
    torch.testing.assert_close(out["level5"], mine[-1], rtol=1e-5, atol=1e-6)
    assert not torch.allclose(out["pose_other"], out["level5"])  # another style, another output
    model.eval()
    assert "pose_other" not in model(batch)  # inference pays nothing for the style loss
    assert "style" in model.losses(batch, model(batch), epoch=0)  # an eval output still gets it


def test_reference_style_has_a_coordinator_embedding_and_one_code_per_level() -> None:
    model = _model()  # the tiny preset: style="reference"
    assert model.config.style == "reference" and model.config.slope == 0.01
    assert not hasattr(model, "speaker_embedding") and len(model.level_styles) == model.n_levels
    model.eval()
    batch = fake_batch(3)
    out = model(batch)
    # eval: every level reads its own mu; the KL's mu / logvar / z are the last level's
    for k, style in enumerate(model.level_styles):
        mu, logvar, z = style(batch["speaker"], sample=False)
        torch.testing.assert_close(out["z_levels"][:, k], mu)
    torch.testing.assert_close(out["mu"], mu)
    torch.testing.assert_close(out["logvar"], logvar)
    assert not torch.allclose(out["z_levels"][:, 0], out["z_levels"][:, -1])  # codes differ per level
    # the coordinator reads its own embedding: changing it changes the weights only through it
    w = model.coordinator(model.coordinator_embedding(batch["speaker"]))
    torch.testing.assert_close(out["style_weights"], w)
    with torch.no_grad():
        model.level_styles[-1].mu.bias += 1.0
    torch.testing.assert_close(model(batch)["style_weights"], w)


def test_reference_style_loss_is_per_sample_and_detaches_the_other_output() -> None:
    # two samples: pose gaps of 0.2 (> beta 0.05: Huber = 0.2 - 0.025 = 0.175) over one element each;
    # per-sample z distances 0.5 and 0.25 -> -(0.175/0.5 + 0.175/0.25) / 2 (1e-5 aside)
    pose = torch.zeros(2, 1, 1, requires_grad=True)
    other = torch.full((2, 1, 1), 0.2, requires_grad=True)
    z, z_other = torch.zeros(2, 2), torch.tensor([[0.5, 0.5], [0.25, 0.25]])
    loss = style_diverging_loss(pose, other, z, z_other, reference=True)
    want = -(0.175 / (0.5 + 1e-5) + 0.175 / (0.25 + 1e-5)) / 2
    assert float(loss.detach()) == pytest.approx(want, rel=1e-6)
    loss.backward()
    assert other.grad is None and pose.grad is not None
    shared = style_diverging_loss(pose, other, z, z_other)  # batch-mean distance 0.375
    assert float(shared.detach()) == pytest.approx(-0.175 / (0.375 + 1e-5), rel=1e-6)


def test_contrastive_without_high_negatives_hand_computed() -> None:
    # rows q = e0, e1; positives = q (logit 1 / max(0, 1) = 1); negatives -e0, -e1 at distances
    # 2 and sqrt 2 from each row (logits 1/2 and 1/sqrt 2): CE = log(e + e^0.5 + e^0.7071) - 1
    q = torch.eye(2)[None]
    loss = aligned_against_level_ce(q, q, -q, min_distance=1.0)
    want = math.log(math.e + math.exp(0.5) + math.exp(1 / math.sqrt(2))) - 1.0
    assert float(loss) == pytest.approx(want, rel=1e-6)
    model = _model(**ABLATIONS["no_high_negatives"])
    batch = fake_batch(2)
    out = model(batch)
    terms = model.losses(batch, out, epoch=0)
    text, high, low = out["text_contrast"], out["audio_high"], out["audio_low"]
    torch.testing.assert_close(terms["contrastive_pos"], aligned_against_level_ce(text, high, low))


def test_hierarchy_ablations_merge_body_or_hand_levels() -> None:
    no_hand = _model(**ABLATIONS["no_hand_hierarchy"])
    assert no_hand.level_dims == (24, 30, 36, 126)  # body levels 1-3, then every finger at once
    no_body = _model(**ABLATIONS["no_body_hierarchy"])
    assert no_body.level_dims == (36, 66, 96, 126)  # spine to wrists at once, then 3 finger rings
    out = no_body(fake_batch(2))
    assert tuple(out["style_weights"].shape) == (2, 3, 4) and "level4" not in out


def test_no_text_reads_no_words_and_has_no_text_encoder() -> None:
    model = _model(**ABLATIONS["no_text"])
    assert "word" not in model.input_keys
    assert len(model.text_encoders) == 0 and model.contrastive_text is None
    batch = {k: v for k, v in fake_batch(2).items() if k != "word"}
    out = model(batch)
    assert tuple(out["pose"].shape) == (2, 34, 126)
    assert "contrastive_pos" not in model.losses(batch, out, epoch=0)
    with pytest.raises(ValueError, match="use_contrastive needs use_text"):
        build_model("ha2g", use_text=False)


@pytest.mark.parametrize(("ablation", "level"), [("mid_only", 1), ("high_only", 2)])
def test_mid_and_high_only_read_one_audio_level(ablation: str, level: int) -> None:
    model = _model(**ABLATIONS[ablation])
    assert model.coordinator is None
    w = model(fake_batch(2))["style_weights"]
    np.testing.assert_array_equal(w[:, level].numpy(), 1.0)
    assert float(w.sum()) == 2 * model.n_levels


@pytest.mark.parametrize("style", ["reference", "shared"])
def test_sampled_protocol_is_seeded_and_draws_from_the_given_speakers(style: str) -> None:
    model = _model(style=style).eval()
    batch = fake_batch(3)
    det = model.generate(batch)
    torch.testing.assert_close(det, model.generate(batch, protocol="deterministic"))
    a = model.generate(batch, protocol="sampled", speakers=[1, 3], generator=torch.Generator().manual_seed(4))
    b = model.generate(batch, protocol="sampled", speakers=[1, 3], generator=torch.Generator().manual_seed(4))
    c = model.generate(batch, protocol="sampled", speakers=[1, 3], generator=torch.Generator().manual_seed(5))
    torch.testing.assert_close(a, b)
    assert not torch.allclose(a, c) and not torch.allclose(a, det)
    # with no variance left and a single speaker, sampling gives the deterministic output of that speaker
    logvars = [s.logvar for s in model.level_styles] if style == "reference" else [model.speaker_logvar]
    with torch.no_grad():
        for lin in logvars:
            lin.weight.zero_()
            lin.bias.fill_(-200.0)
    one = dict(batch, speaker=torch.full((3,), 7))
    torch.testing.assert_close(model.generate(batch, protocol="sampled", speakers=[7]), model.generate(one))
    with pytest.raises(ValueError, match="speakers="):
        model.generate(batch, protocol="sampled")
    with pytest.raises(ValueError, match="protocol must be one of"):
        model.generate(batch, protocol="random")
    with pytest.raises(ValueError, match="speakers must be"):
        model.generate(batch, protocol="sampled", speakers=[99])


def test_checkpoint_configs_without_style_load_the_shared_design() -> None:
    model = _model(style="shared", slope=0.1).eval()
    old = json.loads(json.dumps(model.to_config()))
    del old["style"], old["body_hierarchy"], old["hand_hierarchy"], old["use_text"]
    del old["contrastive_high_negatives"]
    old["d_lr_scale"] = 0.2  # a retired field of older checkpoints
    clone = HA2G.from_config(old)
    assert clone.config.style == "shared" and hasattr(clone, "speaker_embedding")
    clone.load_state_dict(model.state_dict())  # strict: the same parameters
    batch = fake_batch(2)
    torch.testing.assert_close(clone.eval()(batch)["pose"], model(batch)["pose"])


@pytest.mark.parametrize("ablation", [*sorted(ABLATIONS), "shared_style"])
def test_every_switched_on_component_receives_gradient(ablation: str) -> None:
    model = _model(**ABLATIONS.get(ablation, {"style": "shared"}))
    batch = fake_batch(4)
    out = model(batch)
    losses = model.losses(batch, out, epoch=model.config.no_adv_epochs)
    losses["total"].backward()
    g_ids = {id(p) for p in model.generator_parameters()}
    dead = [
        name
        for name, p in model.named_parameters()
        if id(p) in g_ids and (p.grad is None or not torch.any(p.grad != 0))
    ]
    assert dead == []
    # the discriminator learns from its own loss
    model.zero_grad()
    model.discriminator_losses(batch, model(batch))["total"].backward()
    dead_d = [
        n for n, p in model.discriminator.named_parameters() if p.grad is None or not torch.any(p.grad != 0)
    ]
    assert dead_d == []


def test_physical_statistics_come_from_prepare() -> None:
    torch.manual_seed(0)
    model = build_model("ha2g", preset="tiny")
    batch = fake_batch(2)
    with pytest.raises(RuntimeError, match="prepare"):
        model.losses(batch, model(batch), epoch=0)
    w, mean = _unit_windows(6)
    with pytest.raises(ValueError, match="Normalizers"):
        model.prepare(w)  # no guessing the mean: the normalisers travel with the data
    model.prepare(w, _norms(mean))
    np.testing.assert_allclose(model.mean_dirvec.numpy(), mean, atol=1e-7)
    assert bool(model.statistics_ready)
    assert model.angle_mean.shape == model.angle_var.shape == (len(model.angle_pairs),)
    assert float(model.angle_var.min()) >= model.config.angle_var_floor


def test_fit_passes_the_normalizers_of_its_meta_and_word_vectors_load() -> None:
    from beatlite.train import TrainConfig, fit

    w, mean = _unit_windows(4)
    torch.manual_seed(0)
    model = build_model("ha2g", preset="tiny")
    fit(model, w, TrainConfig(epochs=0, progress=False), meta=_norms(mean).to_meta())
    np.testing.assert_allclose(model.mean_dirvec.numpy(), mean, rtol=0, atol=1e-7)
    vectors = np.random.default_rng(0).standard_normal((1000, 16)).astype(np.float32)
    model.set_word_vectors(vectors)
    for enc in [*model.text_encoders, model.contrastive_text]:
        np.testing.assert_array_equal(enc.embedding.weight.detach().numpy(), vectors)
    with pytest.raises(ValueError, match="vocab_size, word_dim"):
        model.set_word_vectors(vectors[:, :8])


# ----------------------------------------------------------------------------- registry, config, errors
def test_registry_presets_ablations_and_config_round_trip() -> None:
    assert set(PRESETS) == {"tiny", "paper"}
    assert {"full", "holistic", "single_audio", "no_contrastive", "no_physical"} <= set(ABLATIONS)
    model = _model(**ABLATIONS["holistic"])
    assert model.representation == "dirvec126" and model.target_key == "dirvec"
    config = json.loads(json.dumps(model.to_config()))
    clone = HA2G.from_config(config)
    clone.load_state_dict(model.state_dict())
    model.eval()
    clone.eval()
    batch = fake_batch(2)
    torch.testing.assert_close(clone(batch)["pose"], model(batch)["pose"])
    assert build_ha2g("tiny", "no_physical").config.use_physical is False
    with pytest.raises(ValueError, match="ablation must be one of"):
        build_ha2g("tiny", "no_such_thing")
    with pytest.raises(ValueError, match="audio_mode"):
        build_model("ha2g", audio_mode="loud")


def test_bad_inputs_raise_clear_errors() -> None:
    model = _model()
    batch = fake_batch(2)
    bad = dict(batch, mel=torch.zeros(2, 70, 64))
    with pytest.raises(ValueError, match=r"batch\['mel'\] must be \(2, M, 128\)"):
        model(bad)
    bad = dict(batch, speaker=torch.tensor([0, 99]))
    with pytest.raises(ValueError, match=r"speaker ids must be in \[0, 30\)"):
        model(bad)
    bad = dict(batch, dirvec=torch.zeros(2, 34, 141))
    with pytest.raises(ValueError, match=r"batch\['dirvec'\] must have shape \(2, 34, 126\)"):
        model(bad)
    with pytest.raises(KeyError, match="word"):
        model({k: v for k, v in batch.items() if k != "word"})


# ----------------------------------------------------------------------------- training
def test_two_short_runs_with_one_seed_give_identical_losses() -> None:
    from beatlite.train import TrainConfig, fit

    w, mean = _unit_windows(12)
    histories = []
    for _ in range(2):
        torch.manual_seed(123)
        model = build_model("ha2g", preset="tiny", no_adv_epochs=1)
        cfg = TrainConfig(epochs=2, batch_size=6, seed=3, progress=False, threads=1)
        histories.append(fit(model, w, cfg, meta=_norms(mean).to_meta()).history)
    assert histories[0] == histories[1]
    assert "adv" in histories[0][1]["train"] and "adv" not in histories[0][0]["train"]
    assert all(np.isfinite(v) for e in histories[0] for v in e["train"].values())


def test_paper_preset_builds_and_runs_one_forward() -> None:
    torch.manual_seed(0)
    model = build_model("ha2g", preset="paper")
    assert model.config.hidden == 300 and model.config.n_layers == 4
    assert model.level_dims == PAPER_LEVEL_DIMS
    assert len(model.text_encoders) == 6 and model.config.audio_channels == (32, 64, 128, 256)
    model.eval()
    with torch.no_grad():
        out = model(fake_batch(2, vocab_size=100))
    assert tuple(out["pose"].shape) == (2, 34, 126)
    assert tuple(out["audio_high"].shape) == (2, 34, 32)


@pytest.mark.parametrize("name", sorted(HA2G_ABLATIONS))
def test_shipped_checkpoint_loads_and_generates(name: str) -> None:
    from beatlite.paths import checkpoints_dir
    from beatlite.train import load_model

    path = checkpoints_dir() / f"{name}.pt"
    if not path.is_file():
        pytest.skip(f"{path} not trained yet (python -m beatlite.train retrain-all --only {name})")
    model, data = load_model(path)
    assert isinstance(model, HA2G) and model.config.preset == "tiny"
    for field, value in HA2G_ABLATIONS[name][1].items():
        assert getattr(model.config, field) == value
    if "style" not in data["model"]:  # saved before the field existed: the shared-z design
        assert model.config.style == "shared" and hasattr(model, "speaker_embedding")
    assert bool(model.statistics_ready)
    np.testing.assert_allclose(model.mean_dirvec.numpy(), data["meta"]["dirvec_mean"], atol=1e-3)  # float16
    assert path.stat().st_size < 2_000_000
    batch = fake_batch(2, vocab_size=model.config.vocab_size)
    pose = model.generate(batch)
    assert tuple(pose.shape) == (2, 34, 126) and bool(torch.isfinite(pose).all())
    assert float(pose[:, 4:].std(dim=1).mean()) > 0.0  # not a frozen pose


@pytest.mark.parametrize("style", ["reference", "shared"])
def test_coordinator_weights_are_eq3_mixes_from_the_coordinators_input(style: str) -> None:
    model = _model(style=style).eval()
    speaker = torch.tensor([0, 3, 3])
    with torch.no_grad():
        w = model.coordinator_weights(speaker)
        # the coordinator's input: its own embedding (reference) or the mean style (shared, z = mu)
        coord = (
            model.coordinator_embedding(speaker) if style == "reference" else model.speaker_style(speaker)[0]
        )
        expected = model.coordinator(coord)
    assert w.shape == (3, 3, 6)
    torch.testing.assert_close(w, expected)
    torch.testing.assert_close(w.sum(dim=1), torch.ones(3, 6))
    torch.testing.assert_close(w[1], w[2])  # one speaker, one mix


def test_coordinator_weights_of_a_single_audio_level_are_one_hot() -> None:
    model = _model(audio_mode="mid").eval()
    with torch.no_grad():
        w = model.coordinator_weights(torch.tensor([0, 1]))
    assert w[:, 1].eq(1).all() and w[:, [0, 2]].eq(0).all()


@pytest.mark.slow  # inductor compiles the forward pass, the losses and their backward: about 70 s uncached
def test_inductor_compiles_the_training_pass_to_the_eager_losses_and_gradients_in_float64() -> None:
    """HA2G's forward pass and losses through inductor as ``fit --compile default`` builds them on the CPU
    (``training._compiled``), in float64 and with inductor drawing dropout from torch's generator
    (``fallback_random``; by default it draws its own masks): the losses and every gradient of the eager
    pass, to float64 rounding. Sums reassociated over at most ~1e5 terms move a value by at most
    1e5 x 2.2e-16 ~ 2e-11 of the largest term, so 1e-9 of the largest gradient is generous and still seven
    orders below a changed mask or weight (float64 convolutions do not run in oneDNN: its float32 bug is
    ``training._compiled``'s test). Inductor stopped in its pattern for indexing with a random permutation
    (``BackendCompilerFailed``) until the style loss picked its other speakers with ``gather``."""
    from torch._dynamo.utils import counters
    from torch._inductor import config as inductor

    from beatlite.train.training import _compiled

    w, mean = _unit_windows(4)
    model = _model(0)
    model.prepare(w, _norms(mean))
    model = model.double().train()
    batch = {
        k: torch.from_numpy(v).double() if v.dtype.kind == "f" else torch.from_numpy(v)
        for k, v in w.items() if k in type(model).batch_keys(model.config)
    }  # fmt: skip

    def step(forward, losses) -> tuple[dict[str, float], dict[str, torch.Tensor]]:
        model.zero_grad(set_to_none=True)
        torch.manual_seed(7)  # the same dropout masks and style codes in both passes
        terms = losses(batch, forward(batch), epoch=1000)
        terms["total"].backward()
        grads = {k: p.grad.clone() for k, p in model.named_parameters() if p.grad is not None}
        return {k: float(v.detach()) for k, v in terms.items()}, grads

    eager_terms, eager_grads = step(model, model.losses)
    cpu = torch.device("cpu")
    counters.clear()
    with inductor.patch(fallback_random=True):
        terms, grads = step(_compiled(model, "default", cpu), _compiled(model.losses, "default", cpu))
    assert counters["stats"]["unique_graphs"] >= 2  # inductor compiled (forward and losses at least)
    assert terms.keys() == eager_terms.keys() and grads.keys() == eager_grads.keys()
    for k, v in eager_terms.items():
        assert terms[k] == pytest.approx(v, rel=1e-9, abs=1e-12), k
    largest = max(float(g.abs().max()) for g in eager_grads.values())
    for k, g in eager_grads.items():
        torch.testing.assert_close(grads[k], g, rtol=0, atol=1e-9 * largest, msg=k)
