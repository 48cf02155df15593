"""CaMN: module shapes, output assembly, losses, switches, gradients (tiny/paper presets)."""

from __future__ import annotations

import math

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from beatlite.models import build_model  # noqa: E402
from beatlite.models.base import huber, seed_input  # noqa: E402
from beatlite.models.camn import CaMN, EmotionEncoder, FaceEncoder, SpeakerEncoder  # noqa: E402
from beatlite.models.layers import ConvDiscriminator, TextEncoderTCN, WavEncoder, ns_gan_d_loss  # noqa: E402
from beatlite.models.testing import fake_batch  # noqa: E402

V = 50  # vocabulary of the fake batches


def tiny(**kw) -> CaMN:
    torch.manual_seed(0)
    return build_model("camn", preset="tiny", vocab_size=V, **kw)


@pytest.fixture(scope="module")
def batch():
    return fake_batch(3, vocab_size=V)


def test_wav_encoder_maps_36266_samples_to_34_frames():
    # (36266 + 2*1600 - 15)//5 + 1 = 7891; (7891-15)//6+1 = 1313; (1313-15)//6+1 = 217; (217-15)//6+1 = 34
    enc = WavEncoder((32, 32, 32, 64, 64, 128))
    out = enc(torch.zeros(2, 36266))
    assert out.shape == (2, 34, 128)


def test_wav_encoder_length_formula_for_other_lengths():
    enc = WavEncoder((4, 4, 4, 4, 4, 4))
    s = 16000 * 5
    n = (s + 3200 - 15) // 5 + 1
    for _ in range(3):
        n = (n - 15) // 6 + 1
    assert enc(torch.zeros(1, s)).shape == (1, n, 4)


def test_encoder_shapes_paper_sizes():
    b = 2
    assert FaceEncoder((16, 16, 16, 32))(torch.zeros(b, 34, 51)).shape == (b, 34, 32)
    assert EmotionEncoder(8, 8)(torch.zeros(b, 34, dtype=torch.long)).shape == (b, 34, 8)
    assert SpeakerEncoder(30, 8)(torch.tensor([0, 29])).shape == (b, 8)
    text = TextEncoderTCN(100, 300, 256, 4, 128, 0.3)
    assert text(torch.zeros(b, 34, dtype=torch.long)).shape == (b, 34, 128)
    d = ConvDiscriminator(141)
    assert d(torch.zeros(b, 34, 141)).shape == (b, 1)


def test_paper_preset_builds_with_reference_sizes_and_runs(batch):
    torch.manual_seed(0)
    model = build_model("camn", preset="paper", vocab_size=V)
    # decoder input 446 = 142 pre_seq + 8 spk + 8 emo + 128 text + 128 audio + 32 face; hands 446 + 27 = 473
    assert model.decoder_in == 446
    assert model.body_decoder.lstm.input_size == 446
    assert model.hands_decoder.lstm.input_size == 473
    assert model.body_decoder.lstm.num_layers == 4 and model.body_decoder.lstm.hidden_size == 256
    out = model(batch)
    assert out["pose"].shape == (3, 34, 141)
    assert out["body"].shape == (3, 34, 27) and out["hands"].shape == (3, 34, 114)


def test_output_assembly_follows_reference_layout(batch):
    out = tiny()(batch)
    pose, body, hands = out["pose"], out["body"], out["hands"]
    assert torch.equal(pose[..., 0:18], body[..., 0:18])
    assert torch.equal(pose[..., 18:75], hands[..., 0:57])
    assert torch.equal(pose[..., 75:84], body[..., 18:27])
    assert torch.equal(pose[..., 84:141], hands[..., 57:114])


def test_seed_input_holds_four_frames_and_indicator():
    pose = torch.arange(2 * 34 * 3, dtype=torch.float32).reshape(2, 34, 3)
    pre = seed_input(pose, 4)
    assert pre.shape == (2, 34, 4)
    assert torch.equal(pre[:, :4, :3], pose[:, :4])
    assert torch.all(pre[:, :4, 3] == 1) and torch.all(pre[:, 4:] == 0)


def test_generate_reads_only_the_seed_frames(batch):
    model = tiny()
    other = dict(batch)
    other["pose"] = batch["pose"].clone()
    other["pose"][:, 4:] += 5.0
    assert torch.equal(model.generate(batch), model.generate(other))
    other["pose"][:, :4] += 1.0
    assert not torch.equal(model.generate(batch), model.generate(other))


def test_huber_matches_hand_values():
    # |d| < beta: 0.5 d^2 / beta = 0.5 * 0.0025 / 0.1 = 0.0125 ; |d| >= beta: |d| - beta/2 = 0.95
    assert float(huber(torch.tensor([0.05]), torch.tensor([0.0]))) == pytest.approx(0.0125)
    assert float(huber(torch.tensor([1.0]), torch.tensor([0.0]))) == pytest.approx(0.95)


@pytest.mark.parametrize("beta", [0.0, -0.1, float("nan"), float("inf")])
def test_huber_refuses_a_beta_that_is_not_a_positive_number(beta):
    # beta = 0 gave nan (0/0), beta = -0.1 gave the loss -0.95 for |d| = 1, beta = inf gave nan
    with pytest.raises(ValueError, match="beta must be a positive number"):
        huber(torch.tensor([1.0]), torch.tensor([0.0]), beta=beta)


def test_reconstruction_loss_zero_on_target_and_semantic_weighting(batch):
    model = tiny()
    assert float(model.reconstruction_loss(batch, batch["pose"].clone())) == 0.0
    b = dict(batch)
    b["semantic"] = torch.ones_like(batch["semantic"])
    # (1+1)*(target+1) - (1+1)*target = 2 -> Huber = 2 - 0.05
    assert float(model.reconstruction_loss(b, batch["pose"] + 1.0)) == pytest.approx(1.95, rel=1e-5)
    plain = tiny(semantic_weighting=False)
    assert float(plain.reconstruction_loss(b, batch["pose"] + 1.0)) == pytest.approx(0.95, rel=1e-5)


def test_adversarial_term_off_before_no_adv_epochs_and_ns_gan_after(batch):
    model = tiny(no_adv_epochs=3, rec_weight=1.0, adv_weight=1.0)
    model.eval()
    torch.set_grad_enabled(False)
    try:
        _check_schedule(model, batch)
    finally:
        torch.set_grad_enabled(True)


def _check_schedule(model, batch):
    out = model(batch)
    early = model.losses(batch, out, epoch=2)
    assert float(early["adv"]) == 0.0 and not model.adversarial_active(2)
    late = model.losses(batch, out, epoch=3)
    logit = model.discriminator(out["pose"])
    expected = float(torch.mean(-torch.log(torch.sigmoid(logit))))
    assert float(late["adv"]) == pytest.approx(expected, rel=1e-5)
    assert float(late["total"]) == pytest.approx(float(late["rec"]) + expected, rel=1e-5)


def test_squared_generator_quirk_option(batch):
    model = tiny(no_adv_epochs=0, squared_adv_loss=True)
    model.eval()
    with torch.no_grad():
        out = model(batch)
        logit = model.discriminator(out["pose"])
        adv = model.losses(batch, out, epoch=0)["adv"]
    assert float(adv) == pytest.approx(float(torch.mean(torch.sigmoid(logit) ** 2)), rel=1e-5)


def test_discriminator_loss_values():
    zero = torch.zeros(4, 1)
    # D = 0.5 everywhere: -(log .5 + log .5) = 2 log 2
    assert float(ns_gan_d_loss(zero, zero)) == pytest.approx(2 * math.log(2), rel=1e-6)
    # a perfect discriminator has (almost) zero loss
    assert float(ns_gan_d_loss(zero + 30, zero - 30)) < 1e-10


def test_discriminator_step_trains(batch):
    model = tiny(no_adv_epochs=0)
    out = model(batch)
    d_loss = model.discriminator_losses(batch, out)["total"]
    d_loss.backward()
    grads = [p.grad for p in model.discriminator.parameters()]
    assert all(g is not None and float(g.abs().sum()) > 0 for g in grads)


SWITCHES = {
    "use_audio": ("audio_encoder", "audio_fusion"),
    "use_text": ("text_encoder",),
    "use_face": ("face_encoder", "face_fusion"),
    "use_emotion": ("emotion_encoder",),
    "use_speaker": ("speaker_encoder",),
}


@pytest.mark.parametrize("switch", [None, *SWITCHES, "cascade"])
def test_every_switched_on_component_gets_gradient(batch, switch):
    kw = {} if switch is None else {switch: False}
    model = tiny(no_adv_epochs=0, **kw)
    out = model(batch)
    model.losses(batch, out, epoch=0)["total"].backward()
    d_ids = {id(p) for p in model.discriminator.parameters()}
    for name, p in model.named_parameters():
        if id(p) in d_ids:
            continue
        assert p.grad is not None and float(p.grad.abs().sum()) > 0, name
    if switch in SWITCHES:
        for module in SWITCHES[switch]:
            assert getattr(model, module) is None
            assert not any(n.startswith(module + ".") for n, _ in model.named_parameters())
    if switch == "cascade":
        assert model.audio_fusion is None and model.face_fusion is None and model.hands_decoder is None
        assert out["pose"].shape == (3, 34, 141)


def test_switches_shrink_decoder_input():
    full = tiny()
    cfg = full.config
    assert (
        full.decoder_in
        == 142
        + cfg.speaker_features
        + cfg.emotion_features
        + cfg.text_features
        + cfg.audio_fused
        + cfg.face_fused
    )
    assert tiny(use_text=False).decoder_in == full.decoder_in - cfg.text_features
    assert tiny(use_face=False).decoder_in == full.decoder_in - cfg.face_fused
    # without the cascade the raw encoder features go to the decoder
    assert tiny(cascade=False).decoder_in == (
        142
        + cfg.speaker_features
        + cfg.emotion_features
        + cfg.text_features
        + cfg.audio_channels[-1]
        + cfg.face_channels[-1]
    )


def test_switched_off_modality_is_not_read(batch):
    model = tiny(use_audio=False)
    other = dict(batch)
    other["audio"] = torch.randn_like(batch["audio"])
    assert torch.equal(model.generate(batch), model.generate(other))
    del other["audio"]
    assert model.generate(other).shape == (3, 34, 141)


def test_leaky_relu_slopes_are_corrected():
    model = tiny()
    fusion_slopes = {
        m.negative_slope for m in model.audio_fusion.modules() if isinstance(m, torch.nn.LeakyReLU)
    }
    assert fusion_slopes == {0.1}


def test_bad_inputs_raise_clear_errors(batch):
    model = tiny()
    bad = dict(batch)
    bad["audio"] = batch["audio"][:, None]
    with pytest.raises(ValueError, match="audio"):
        model(bad)
    missing = {k: v for k, v in batch.items() if k != "face"}
    with pytest.raises(KeyError, match="face"):
        model(missing)
    wrong = dict(batch)
    wrong["word"] = batch["word"] + V
    with pytest.raises(ValueError, match="word ids"):
        model(wrong)


def test_config_round_trip_rebuilds_identical_model(batch):
    model = tiny(use_face=False)
    model.eval()
    clone = CaMN.from_config(model.to_config())
    clone.load_state_dict(model.state_dict())
    clone.eval()
    assert clone.config == model.config
    assert torch.equal(clone(batch)["pose"], model(batch)["pose"])


def test_word_vectors_are_loaded():
    model = tiny()
    vectors = np.random.default_rng(0).standard_normal((V, model.config.word_dim)).astype(np.float32)
    model.set_word_vectors(vectors)
    assert np.array_equal(model.text_encoder.embedding.weight.detach().numpy(), vectors)
    with pytest.raises(ValueError, match="vectors"):
        model.set_word_vectors(vectors[:, :3])


def test_input_widths_match_the_built_layers_and_the_paper():
    from beatlite.models import build_model
    from beatlite.models.camn import PARTS, input_widths, part_parameters

    for preset in ("tiny", "paper"):
        model = build_model("camn", preset=preset, vocab_size=20)
        w = input_widths(model.config)
        assert w["audio fusion in"] == model.audio_fusion[0].in_features
        assert w["face fusion in"] == model.face_fusion[0].in_features
        assert w["body decoder in"] == model.body_decoder.lstm.input_size
        assert w["hands decoder in"] == model.hands_decoder.lstm.input_size
        counts = part_parameters(model)
        assert list(counts) == [*PARTS, "total"] and sum(counts[p] for p in PARTS) == counts["total"]
    # BEAT's reference code: context 8 + 8 + 128 = 144; audio fusion 128 + 144 = 272; face 32 + 128 + 144 = 304
    assert input_widths(model.config) == {
        "audio fusion in": 272,
        "face fusion in": 304,
        "body decoder in": 446,
        "hands decoder in": 473,
    }


def test_id_ranges_are_checked_except_in_a_training_step_on_another_device():
    """``check_ids``: out-of-range ids are a ValueError naming the ids and their range, on the CPU and whenever
    gradients are off (generation, evaluation); a training step on another device (here ``meta``, which
    has no values to read) is not read back to the host."""
    from beatlite.models.layers import check_ids

    check_ids(torch.tensor([0, 4]), 5, "speaker ids")  # in range
    with pytest.raises(ValueError, match=r"speaker ids must be in \[0, 5\), got range \[-1, 4\]"):
        check_ids(torch.tensor([4, -1]), 5, "speaker ids")
    with pytest.raises(ValueError, match=r"got range \[0, 5\]"):
        check_ids(torch.tensor([[0, 5]]), 5, "word ids")
    on_device = torch.tensor([0, 9]).to("meta")
    check_ids(on_device, 5, "speaker ids")  # gradients on: skipped, nothing read
    with torch.no_grad(), pytest.raises(RuntimeError, match="meta"):
        check_ids(on_device, 5, "speaker ids")  # gradients off: read (meta has nothing to give)


# ---------------------------------------------------------------------------- first audio block as a matrix product
@pytest.mark.parametrize(
    ("length", "kernel", "stride", "padding"),
    [(36266, 15, 5, 1600), (100, 15, 5, 7), (40, 15, 5, 1600), (15, 15, 1, 0), (97, 4, 3, 2)],
)
def test_frame_conv1d_is_conv1d(length, kernel, stride, padding):
    from beatlite.models.layers import frame_conv1d

    g = torch.Generator().manual_seed(length)
    x = torch.randn(2, 1, length, generator=g, dtype=torch.float64)
    w = torch.randn(3, 1, kernel, generator=g, dtype=torch.float64)
    want = torch.nn.functional.conv1d(x, w, stride=stride, padding=padding)
    got = frame_conv1d(x, w, stride, padding)
    assert got.shape == want.shape
    # float64: the two sum the same `kernel` products in another order (bound: kernel * eps * sum |x w|)
    bound = kernel * 2.0**-52 * torch.nn.functional.conv1d(x.abs(), w.abs(), stride=stride, padding=padding)
    assert ((got - want).abs() <= bound).all()


def test_frame_conv1d_refuses_more_than_one_channel():
    from beatlite.models.layers import frame_conv1d

    with pytest.raises(ValueError, match="frame_conv1d"):
        frame_conv1d(torch.zeros(1, 2, 30), torch.zeros(3, 2, 15))
    for stride, padding in ((0, 0), (5, -1)):  # (F.pad would crop with a negative padding)
        with pytest.raises(ValueError, match="stride must be >= 1 and padding >= 0"):
            frame_conv1d(torch.zeros(1, 1, 30), torch.zeros(3, 1, 15), stride, padding)


def _block_step(block, x):
    block.zero_grad()
    y = block(x)
    (y * torch.linspace(-1, 1, y.numel(), dtype=y.dtype).reshape(y.shape)).sum().backward()
    return y.detach(), {n: p.grad.clone() for n, p in block.named_parameters()}


@pytest.fixture()
def frame_calls(monkeypatch):
    """Counts the calls of layers.frame_conv1d and of the first block's convolution modules."""
    from beatlite.models import layers

    calls = {"frame_conv1d": 0, "conv": 0}
    real = layers.frame_conv1d

    def counted(*args, **kwargs):
        calls["frame_conv1d"] += 1
        return real(*args, **kwargs)

    monkeypatch.setattr(layers, "frame_conv1d", counted)
    return calls


def _count_convs(block, calls):
    for conv in (block.conv1, block.shortcut[0]):
        conv.register_forward_hook(lambda *_: calls.__setitem__("conv", calls["conv"] + 1))


def test_first_audio_block_as_matmul_gives_the_same_values_and_gradients(frame_calls):
    from beatlite.models.layers import use_frame_matmul

    torch.manual_seed(0)
    enc = WavEncoder((4, 8, 8, 16, 16, 32)).double()
    block, keys = enc.blocks[0], list(enc.state_dict())
    _count_convs(block, frame_calls)
    x = torch.randn(3, 1, 2000, dtype=torch.float64)
    y0, g0 = _block_step(block, x)
    assert frame_calls == {"frame_conv1d": 0, "conv": 2}
    stats0 = [b.clone() for b in block.buffers()]
    assert use_frame_matmul(enc) == 1 and block.frames_as_matmul  # only the one-channel block
    assert not any(b.frames_as_matmul for b in enc.blocks[1:])
    assert list(enc.state_dict()) == keys  # the same parameters: checkpoints load either way
    for b, s in zip(block.buffers(), stats0):  # reset BN's running statistics to before the first step
        b.copy_(s)
    y1, g1 = _block_step(block, x)
    assert frame_calls == {"frame_conv1d": 1, "conv": 2}  # one matrix product, no convolution module
    # float64, sums of 15 products in another order (each within 15 eps = 3e-15 of the other)
    assert torch.allclose(y1, y0, rtol=0, atol=1e-12)
    for name in g0:
        assert torch.allclose(g1[name], g0[name], rtol=1e-10, atol=1e-12), name
    assert use_frame_matmul(enc, on=False) == 1 and not block.frames_as_matmul


def _camn_step(batch, matmul: bool, amp: bool = False, dtype=torch.float32):
    from beatlite.models.layers import use_frame_matmul

    model = tiny().to(dtype)
    assert use_frame_matmul(model, matmul) == 1
    model.train()
    batch = {k: v.to(dtype) if v.is_floating_point() else v for k, v in batch.items()}
    torch.manual_seed(1)  # (dropout)
    with torch.autocast("cpu", dtype=torch.bfloat16, enabled=amp):
        loss = model.losses(batch, model(batch), epoch=0)["total"]
    loss.backward()
    first = model.audio_encoder.blocks[0]
    grads = torch.cat([first.conv1.weight.grad.flatten(), first.shortcut[0].weight.grad.flatten()])
    every = torch.cat([p.grad.flatten() for p in model.parameters() if p.grad is not None])
    return loss.item(), grads.double(), every.double()


def test_camn_trains_the_same_with_the_first_audio_block_as_matmul(batch, frame_calls):
    # float64: the same sums in another order; through the whole network the loss and every gradient stay
    # within 1e-12 relative (thousands of eps; measured here: 0 and 6e-16)
    (l0, _, g0), (l1, _, g1) = (_camn_step(batch, on, dtype=torch.float64) for on in (False, True))
    assert frame_calls["frame_conv1d"] == 1
    assert abs(l1 - l0) <= 1e-12 * abs(l0)
    assert (g1 - g0).norm() <= 1e-12 * g0.norm()


def test_in_bf16_the_matmul_route_is_as_close_to_fp32_as_the_convolutions(batch, frame_calls):
    # bf16 autocast itself moves these weight gradients far from fp32's (a sum of 23,673 products of 8-bit
    # operands that cancel): the matrix product, which rounds at other places, must not be further off than
    # the convolutions (their errors measured here are of one size; 1.5 lets that ratio vary with the data)
    (l32, g32, _), (lc, gc, _), (lm, gm, _) = (
        _camn_step(batch, *a) for a in ((False, False), (False, True), (True, True))
    )
    assert frame_calls["frame_conv1d"] == 1
    conv_error, matmul_error = (gc - g32).norm(), (gm - g32).norm()
    assert 0 < conv_error and matmul_error <= 1.5 * conv_error
    assert abs(lm - l32) <= 2 * abs(lc - l32) + 1e-6 * abs(l32)


def test_run_lstm_under_cpu_bf16_autocast_is_the_lstm_on_any_cpu(monkeypatch):
    """On an x86 CPU without AVX-512 (AMD Zen 3: torch's capability "AVX2") CPU bf16 autocast sends an LSTM to
    oneDNN, which raised "could not create a primitive descriptor for the LSTM forward propagation primitive":
    every bf16 training step of CaMN failed there. ``run_lstm`` runs it in float32 with autocast off where that
    kernel is missing (forced here, so every machine tries that route), and as it is where it exists."""
    from beatlite.models import layers

    torch.manual_seed(0)
    lstm = torch.nn.LSTM(5, 6, batch_first=True, bidirectional=True)
    x = torch.randn(3, 7, 5)
    fp32 = lstm(x)[0]
    monkeypatch.setattr(layers, "_cpu_autocast_lstm_works", lambda: False)
    with torch.autocast("cpu", dtype=torch.bfloat16):
        fallback = layers.run_lstm(lstm, x)
    assert fallback.dtype == torch.float32 and torch.equal(fallback, fp32)  # the same float32 computation
    monkeypatch.undo()
    state = torch.random.get_rng_state()
    works = layers._cpu_autocast_lstm_works()
    assert torch.equal(
        torch.random.get_rng_state(), state
    )  # the probe draws no random number of the caller's
    with torch.autocast("cpu", dtype=torch.bfloat16):
        here = layers.run_lstm(lstm, x)
    # with the kernel, the LSTM in bfloat16: each of the 7 steps reads inputs and weights rounded to 8 significant
    # bits (relative 2**-8) and its cell state carries the earlier steps' errors, outputs in (-1, 1): within
    # 7 * 2 * 2**-8 < 2**-4; without it, the fallback's float32 exactly
    assert torch.allclose(here.float(), fp32, atol=2**-4 if works else 0, rtol=0)
    assert torch.equal(layers.run_lstm(lstm, x), fp32)  # no autocast: lstm(x)[0] itself


ABLATIONS = ({"use_audio": False}, {"use_face": False}, {"use_text": False}, {"cascade": False}, {})


@pytest.mark.parametrize("switches", ABLATIONS)
def test_input_widths_follow_the_switches(switches):
    """``input_widths`` of an ablated configuration equals the widths of the layers built from it (0 for a
    part that is not built): it counted every modality whatever the switches (use_audio=False: 238, built 206)."""
    from beatlite.models import build_model
    from beatlite.models.camn import input_widths

    model = build_model("camn", preset="tiny", vocab_size=20, **switches)
    built = {
        "audio fusion in": model.audio_fusion,
        "face fusion in": model.face_fusion,
        "body decoder in": model.body_decoder,
        "hands decoder in": model.hands_decoder,
    }
    want = {
        k: 0 if part is None else (part.lstm.input_size if k.endswith("decoder in") else part[0].in_features)
        for k, part in built.items()
    }
    assert input_widths(model.config) == want


@pytest.mark.parametrize("switches", [*ABLATIONS, {"adversarial": False}])
def test_part_parameters_of_an_ablation_count_absent_parts_as_zero(switches):
    """``part_parameters`` of a model without a part (an ablation, no discriminator) gives that part 0 and
    the parts still add up to the total (it raised AttributeError on the absent part)."""
    from beatlite.models import build_model
    from beatlite.models.camn import PARTS, part_parameters

    model = build_model("camn", preset="tiny", vocab_size=20, **switches)
    counts = part_parameters(model)
    for part in PARTS:
        module = getattr(model, part)
        assert counts[part] == (0 if module is None else sum(p.numel() for p in module.parameters()))
    assert sum(counts[p] for p in PARTS) == counts["total"] == sum(p.numel() for p in model.parameters())
