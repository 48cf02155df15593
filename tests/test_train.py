"""The training harness: determinism, resume, checkpoints, whole-take generation."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from killed_run import step_killed_after  # noqa: E402

from beatlite.models import build_model  # noqa: E402
from beatlite.models.base import GestureModel, ModelConfig  # noqa: E402
from beatlite.models.testing import fake_windows  # noqa: E402
from beatlite.train import TrainConfig, data_fingerprint, export_checkpoint, fit, generate, load_model  # noqa: E402
from beatlite.train.generation import generate_sequence, generate_sequences  # noqa: E402
from beatlite.train.training import ResumeError  # noqa: E402

V = 50


@pytest.fixture(scope="module")
def windows():
    return fake_windows(24, seed=0, vocab_size=V), fake_windows(8, seed=1, vocab_size=V)


def camn():
    torch.manual_seed(0)
    return build_model("camn", preset="tiny", vocab_size=V, no_adv_epochs=1)


def cfg(**kw):
    return TrainConfig(**{"epochs": 2, "batch_size": 8, "lr": 1e-3, "seed": 3, "progress": False, **kw})


def test_two_runs_with_one_seed_give_identical_losses(windows):
    train, val = windows
    a = fit(camn(), train, cfg(), val)
    b = fit(camn(), train, cfg(), val)
    assert a.history == b.history
    assert set(a.history[-1]["train"]) >= {"rec", "adv", "total", "D_d"}  # epoch 1 is adversarial
    assert a.history[-1]["val"]["total"] > 0
    c = fit(camn(), train, cfg(seed=4), val)
    assert c.history != a.history


def test_progress_bar_shows_the_unweighted_losses_of_the_history(windows, capsys, monkeypatch):
    monkeypatch.setenv("BEATLITE_INTERACTIVE", "off")  # a text bar on stderr
    train, val = windows
    last = fit(camn(), train, cfg(progress=True), val).history[-1]
    bar = capsys.readouterr().err.replace("\r", "\n").splitlines()[-1]
    assert f"rec={last['train']['rec']:.4g}, val_rec={last['val']['rec']:.4g}" in bar, bar
    assert f"{last['train']['total']:.4g}" not in bar  # not the 500x weighted total (nor the D_ terms)


def test_resume_reproduces_an_uninterrupted_run(windows, tmp_path):
    train, val = windows
    full = fit(camn(), train, cfg(epochs=3, checkpoint=tmp_path / "full.pt"), val)
    fit(camn(), train, cfg(epochs=2, checkpoint=tmp_path / "part.pt"), val)
    resumed = fit(camn(), train, cfg(epochs=3, checkpoint=tmp_path / "part.pt", resume=True), val)
    assert resumed.history == full.history
    a, _ = load_model(tmp_path / "full.pt")
    b, _ = load_model(tmp_path / "part.pt")
    for (name, p), q in zip(a.state_dict().items(), b.state_dict().values(), strict=True):
        assert torch.equal(p, q), name
    assert not list(tmp_path.glob("*.tmp"))  # atomic writes leave no temp file


def test_a_run_killed_mid_epoch_resumes_from_its_last_step(windows, tmp_path):
    """checkpoint_every=1: a run stopped after 4 optimiser steps (epoch 2, step 1 of 3) resumes there and
    ends with the weights and history of an uninterrupted run."""
    train, val = windows
    full = fit(camn(), train, cfg(epochs=2, checkpoint=tmp_path / "full.pt"), val)
    with step_killed_after(4), pytest.raises(KeyboardInterrupt):
        fit(camn(), train, cfg(epochs=2, checkpoint=tmp_path / "part.pt", checkpoint_every=1), val)
    saved = torch.load(tmp_path / "part.pt", weights_only=True)
    assert saved["epoch"] == 1 and saved["partial"]["step"] == 1  # 3 steps per epoch: killed in epoch 2
    resumed = fit(
        camn(), train, cfg(epochs=2, checkpoint=tmp_path / "part.pt", checkpoint_every=1, resume=True), val
    )
    assert resumed.history == full.history
    a, _ = load_model(tmp_path / "full.pt")
    b, _ = load_model(tmp_path / "part.pt")
    for (name, p), q in zip(a.state_dict().items(), b.state_dict().values(), strict=True):
        assert torch.equal(p, q), name
    assert torch.load(tmp_path / "part.pt", weights_only=True)["partial"] is None


def test_a_mid_epoch_checkpoint_resumes_only_with_the_same_batch_plan(windows, tmp_path):
    """A run killed at step 1 of epoch 2 (24 windows, batch 8, seed 3) refuses to resume with another batch size,
    seed or windows_per_epoch (its step 1 would be a step of another plan), naming the old and new values and
    writing nothing; a checkpoint at an epoch's end resumes with another batch size."""
    train, val = windows
    part = tmp_path / "part.pt"
    with step_killed_after(4), pytest.raises(KeyboardInterrupt):
        fit(camn(), train, cfg(epochs=2, checkpoint=part, checkpoint_every=1), val)
    before = part.read_bytes()
    changes = (({"batch_size": 6}, "batch_size 8 -> 6"), ({"seed": 4}, "seed 3 -> 4"),
               ({"windows_per_epoch": 16}, "windows_per_epoch None -> 16"))  # fmt: skip
    for change, said in changes:
        again = cfg(epochs=2, checkpoint=part, checkpoint_every=1, resume=True, **change)
        with pytest.raises(ResumeError, match="stopped at step 1 of epoch 2") as refused:
            fit(camn(), train, again, val)
        assert f"changed: {said} (" in str(refused.value)
    assert part.read_bytes() == before
    fit(camn(), train, cfg(epochs=1, checkpoint=tmp_path / "end.pt"), val)
    resumed = fit(
        camn(), train, cfg(epochs=2, batch_size=6, checkpoint=tmp_path / "end.pt", resume=True), val
    )
    assert [entry["epoch"] for entry in resumed.history] == [0, 1]


def test_cosine_schedule_factors_closed_form():
    c = TrainConfig(epochs=4, lr_schedule="cosine")
    # (1 + cos(pi e / 4)) / 2 for e = 0..4: 1, (2 + sqrt 2) / 4, 1/2, (2 - sqrt 2) / 4, 0
    expected = [1.0, (2 + 2**0.5) / 4, 0.5, (2 - 2**0.5) / 4, 0.0]
    assert [c.lr_factor(e) for e in range(5)] == pytest.approx(expected)
    assert TrainConfig(epochs=4).lr_factor(3) == 1.0  # constant
    with pytest.raises(ValueError, match="lr_schedule"):
        TrainConfig(lr_schedule="linear")


class _RecordLr(torch.optim.Adam):
    """Adam that records the learning rate of each step (to see the schedule fit applies)."""

    seen: list[float] = []

    def step(self, closure=None):  # type: ignore[override]
        _RecordLr.seen.append(self.param_groups[0]["lr"])
        return super().step(closure)


def test_fit_applies_the_cosine_schedule_to_both_optimisers(windows, monkeypatch):
    train, _ = windows
    _RecordLr.seen = []
    monkeypatch.setattr(torch.optim, "Adam", _RecordLr)
    model = build_model("camn", preset="tiny", vocab_size=V, no_adv_epochs=0)
    fit(model, train, cfg(epochs=2, lr=1e-3, lr_schedule="cosine"))
    steps = len(train["pose"]) // 8  # 3 batches per epoch; each has a D step then a G step
    d_lr, g_lr = _RecordLr.seen[0::2], _RecordLr.seen[1::2]
    assert g_lr == pytest.approx([1e-3] * steps + [5e-4] * steps)  # epoch 1 of 2: (1 + cos(pi/2)) / 2
    assert d_lr == pytest.approx([2e-4] * steps + [1e-4] * steps)  # d_lr_weight 0.2


def test_resume_is_exact_with_the_cosine_schedule(windows, tmp_path):
    train, val = windows
    full = fit(camn(), train, cfg(epochs=3, lr_schedule="cosine", checkpoint=tmp_path / "full.pt"), val)
    fit(camn(), train, cfg(epochs=1, lr_schedule="cosine", checkpoint=tmp_path / "part.pt"), val)
    again = cfg(epochs=3, lr_schedule="cosine", checkpoint=tmp_path / "part.pt", resume=True)
    assert fit(camn(), train, again, val).history == full.history


def test_resume_refuses_other_data(windows, tmp_path):
    train, val = windows
    fit(camn(), train, cfg(epochs=1, checkpoint=tmp_path / "a.pt"))
    other = dict(train)
    other["pose"] = train["pose"] + 1
    with pytest.raises(ValueError, match="cannot resume"):
        fit(camn(), other, cfg(epochs=2, checkpoint=tmp_path / "a.pt", resume=True))


def test_data_fingerprint_sees_values_and_shapes(windows):
    train, _ = windows
    copy = {k: v.copy() for k, v in train.items()}
    assert data_fingerprint(copy) == data_fingerprint(train)
    copy["pose"][0, 0, 0] += 1.0  # window 0 is always in the sample
    assert data_fingerprint(copy) != data_fingerprint(train)
    fewer = {k: v[:-1] for k, v in train.items()}
    assert data_fingerprint(fewer) != data_fingerprint(train)


def test_fit_checks_keys_and_config(windows):
    train, _ = windows
    with pytest.raises(KeyError, match="face"):
        fit(camn(), {k: v for k, v in train.items() if k != "face"}, cfg())
    with pytest.raises(ValueError, match="batch_size"):
        TrainConfig(batch_size=1)
    assert TrainConfig(batch_size=256).learning_rate == pytest.approx(5e-4)


def test_fit_refuses_a_batch_too_small_for_its_micro_batches(windows, monkeypatch):
    """A batch of 3 split into 2 micro-batches (``micro_batches=2``, or ``torchrun`` with 2 processes) leaves one
    window in a micro-batch, which BatchNorm cannot take: every step was skipped, the weights never changed and
    ``fit`` returned as if it had trained (history ``"train": {}``). It refuses before a step; 4 trains."""
    from beatlite.train import training

    train, _ = windows
    model = camn()
    before = {k: v.clone() for k, v in model.named_parameters()}
    with pytest.raises(ValueError, match=r"batch_size 3 split into 2 micro-batches .* must be >= 4"):
        fit(model, train, cfg(batch_size=3, micro_batches=2, epochs=1))
    assert all(torch.equal(before[k], v) for k, v in model.named_parameters())
    assert fit(camn(), train, cfg(batch_size=4, micro_batches=2, epochs=1)).history[0]["train"]["rec"] > 0
    monkeypatch.setattr(training, "distributed_rank", lambda: (0, 4))  # as under torchrun --nproc_per_node=4
    with pytest.raises(ValueError, match=r"batch_size 6 split into 4 micro-batches \(4 processes"):
        fit(camn(), train, cfg(batch_size=6))


def test_fit_refuses_too_few_windows_to_take_one_step(windows):
    """One training window, or 3 split into 2 micro-batches (2 + 1), fill no micro-batch of 2 windows (BatchNorm):
    every step was skipped and ``fit`` returned as if it had trained (history ``"train": {}``, a checkpoint of the
    epoch). It refuses before a step, also when ``windows_per_epoch`` is what leaves too few; 2 windows train."""
    train, _ = windows

    def first(n):
        return {k: v[:n] for k, v in train.items()}

    model = camn()
    before = {k: v.clone() for k, v in model.named_parameters()}
    with pytest.raises(
        ValueError, match=r"fit: 1 training window per epoch fills no step: .* give at least 2"
    ):
        fit(model, first(1), cfg(epochs=1))
    assert all(torch.equal(before[k], v) for k, v in model.named_parameters())
    with pytest.raises(ValueError, match=r"fit: 3 training windows per epoch .* give at least 4"):
        fit(camn(), first(3), cfg(epochs=1, batch_size=4, micro_batches=2))
    with pytest.raises(ValueError, match=r"fit: 3 training windows per epoch \(windows_per_epoch=3 of 24\)"):
        fit(camn(), train, cfg(epochs=1, batch_size=4, micro_batches=2, windows_per_epoch=3))
    assert fit(camn(), first(2), cfg(epochs=1)).history[0]["train"]["rec"] > 0


def test_fit_checks_the_validation_windows_before_training(windows, tmp_path):
    """Validation windows lacking a key the model reads, or with arrays of different lengths, were found only
    by the first validation, after a whole epoch of training (minutes to hours on real BEAT), whose checkpoint
    was then never written. ``fit`` now refuses them before a step, naming ``val_windows``."""
    train, val = windows
    model = camn()
    before = {k: v.clone() for k, v in model.named_parameters()}
    lacking = {k: v for k, v in val.items() if k != "audio"}
    with pytest.raises(KeyError, match=r"fit: val_windows: windows lack \['audio'\] needed by CaMN"):
        fit(model, train, cfg(epochs=1, checkpoint=tmp_path / "a.pt"), lacking)
    assert all(torch.equal(before[k], v) for k, v in model.named_parameters())
    uneven = {**val, "pose": val["pose"][:5]}
    with pytest.raises(ValueError, match=r"fit: val_windows: window arrays have different lengths"):
        fit(model, train, cfg(epochs=1), uneven)
    assert all(torch.equal(before[k], v) for k, v in model.named_parameters())


def test_export_is_small_and_equivalent(windows, tmp_path):
    train, _ = windows
    model = camn()
    fit(model, train, cfg(epochs=1, checkpoint=tmp_path / "t.pt"))
    export_checkpoint(tmp_path / "t.pt", tmp_path / "s.pt")
    assert (tmp_path / "s.pt").stat().st_size < 0.4 * (tmp_path / "t.pt").stat().st_size
    small, data = load_model(tmp_path / "s.pt")
    assert "optimizer" not in data
    batch = {k: torch.from_numpy(v[:2]) for k, v in train.items()}
    model.eval()
    np.testing.assert_allclose(small.generate(batch).numpy(), model.generate(batch).numpy(), atol=0.05)


def test_untrained_baselines_fit_saves_and_loads(windows, tmp_path):
    train, _ = windows
    model = build_model("mean_pose")
    fit(model, train, cfg(checkpoint=tmp_path / "m.pt"))
    loaded, _ = load_model(tmp_path / "m.pt")
    np.testing.assert_allclose(loaded.mean.numpy(), train["pose"].mean(axis=(0, 1)), atol=1e-5)


def _with_nan(train: dict, window: int = 0) -> dict:
    """The windows with one NaN in ``window``'s pose (the target every model's loss reads)."""
    pose = train["pose"].copy()
    pose[window, 5, 7] = np.nan
    return {**train, "pose": pose}


def test_a_diverged_run_stops_before_writing_a_checkpoint_load_would_refuse(windows, tmp_path):
    """NaN losses (here NaN in the data; a too high learning rate or bf16 overflow alike): fit raises
    FloatingPointError at the epoch's end instead of saving weights that load_checkpoint refuses."""
    train, val = windows
    path = tmp_path / "nan.pt"
    with pytest.raises(
        FloatingPointError, match="camn diverged: the mean training losses of epoch 0 are not finite"
    ):
        fit(camn(), _with_nan(train), cfg(checkpoint=path), val)
    assert not path.exists()
    assert fit(
        camn(), train, cfg(checkpoint=path), val
    ).history  # the same run on finite data trains and saves
    load_model(path)


def test_a_mid_epoch_checkpoint_of_diverged_weights_is_not_written(windows, tmp_path):
    """With checkpoint_every=1, the save after the step that read the NaN window raises; the checkpoint of the
    step before it (finite weights) stays and loads."""
    train, _ = windows
    config = cfg(checkpoint=tmp_path / "mid.pt", checkpoint_every=1)
    order = np.random.default_rng([config.seed, 0]).permutation(len(train["pose"]))  # fit's plan of epoch 0
    second_step = order[config.batch_size : 2 * config.batch_size]
    with pytest.raises(FloatingPointError, match="camn diverged: its weights after 2 steps are not finite"):
        fit(camn(), _with_nan(train, int(second_step[0])), config)
    _, saved = load_model(config.checkpoint)
    assert saved["partial"]["step"] == 1 and saved["epoch"] == 0


def test_zero_epochs_write_the_checkpoint_of_the_initial_weights(windows, tmp_path):
    """TrainConfig allows epochs=0: fit returned FitResult.checkpoint without writing it (export_checkpoint then
    failed, 'checkpoint not found', or exported an older run's file at that path). It writes the untrained
    weights, as for an untrained baseline; resuming a finished run with epochs=0 leaves its checkpoint alone."""
    train, _ = windows
    model = camn()
    start = {k: v.clone() for k, v in model.state_dict().items()}
    result = fit(model, train, cfg(epochs=0, checkpoint=tmp_path / "z.pt"))
    assert result.history == [] and result.checkpoint == tmp_path / "z.pt"
    export_checkpoint(tmp_path / "z.pt", tmp_path / "z_small.pt")
    loaded, data = load_model(tmp_path / "z.pt")
    assert data["epoch"] == 0
    assert all(torch.equal(v, start[k]) for k, v in loaded.state_dict().items())
    fit(camn(), train, cfg(epochs=1, checkpoint=tmp_path / "one.pt"))
    fit(camn(), train, cfg(epochs=0, checkpoint=tmp_path / "one.pt", resume=True))
    assert load_model(tmp_path / "one.pt")[1]["epoch"] == 1


# --------------------------------------------------------------------------- whole-take generation
@dataclasses.dataclass
class _StubConfig(ModelConfig):
    pass


class _Counter(GestureModel):
    """Returns the constant k on call k (k = 0, 1, ...): exposes the cross-fade."""

    name = "stub"
    config_class = _StubConfig
    input_keys = ("pose",)

    def __init__(self) -> None:
        super().__init__(_StubConfig())
        self.calls = 0

    def forward(self, batch):
        self.calls += 1
        return {"pose": torch.full_like(batch["pose"], float(self.calls - 1))}


class _SeedPlusOne(_Counter):
    """Every output frame = seed frame 0 + 1: exposes how seeds propagate between units."""

    def forward(self, batch):
        return {"pose": (batch["pose"][:, :1] + 1).expand_as(batch["pose"]).clone()}


def _streams(t: int) -> dict[str, np.ndarray]:
    return {"pose": np.zeros((t, 141), np.float32)}


@pytest.mark.parametrize("t", [4, 33, 34, 35, 64, 65, 100])
def test_generate_sequence_length_and_unit_count(t):
    model = _Counter()
    out = generate_sequence(model, _streams(t))
    assert out.shape == (t, 141)
    # units start at 0, 30, 60, ... until one reaches frame t: 1 + ceil(max(t - 34, 0) / 30) units
    assert model.calls == 1 + -(-max(t - 34, 0) // 30)


def test_cross_fade_is_linear_over_the_overlap():
    out = generate_sequence(_Counter(), _streams(64))[:, 0]
    np.testing.assert_array_equal(out[:30], 0.0)
    # frames 30..33: (1 - w) * unit0 + w * unit1 with w = 0, 1/3, 2/3, 1 and unit0 = 0, unit1 = 1
    np.testing.assert_allclose(out[30:34], [0.0, 1 / 3, 2 / 3, 1.0], atol=1e-6)
    np.testing.assert_array_equal(out[34:], 1.0)


def test_units_are_seeded_by_the_previous_output():
    streams = _streams(94)
    streams["pose"][:4] = 5.0
    out = generate_sequence(_SeedPlusOne(), streams)[:, 0]
    # unit 0 = 5 + 1; unit 1 is seeded with unit 0's frames 30..33 -> 7; unit 2 -> 8
    np.testing.assert_allclose(out[:30], 6.0)
    np.testing.assert_allclose(out[34:60], 7.0)
    np.testing.assert_allclose(out[64:], 8.0)


def test_generate_returns_denormalised_full_motion():
    from beatlite.data.normalize import Normalizer, Normalizers
    from beatlite.skeleton.beat import beat_skeleton, subset_columns

    t = 50
    rng = np.random.default_rng(0)
    windows = fake_windows(6)
    model = build_model("mean_pose")
    model.prepare(windows)
    mean, std = rng.normal(size=141), rng.uniform(1, 20, size=141)
    norms = Normalizers(Normalizer(mean, std), Normalizer(np.zeros(126), np.ones(126)))
    result = generate(model, _streams(t), normalizers=norms)
    assert result.motion.channels.shape == (t, 228) and result.motion.fps == 15
    expected = windows["pose"].astype(np.float64).mean(axis=(0, 1)) * std + mean
    cols = subset_columns(beat_skeleton(), "spine_neck_141")
    np.testing.assert_allclose(
        result.motion.channels[:, cols], np.broadcast_to(expected, (t, 141)), atol=1e-3
    )
    others = np.setdiff1d(np.arange(228), cols)
    np.testing.assert_array_equal(result.motion.channels[:, others], 0.0)


def test_generate_camn_on_a_take_of_odd_length():
    t = 77
    model = camn().eval()
    take = {k: v[0] for k, v in fake_windows(1, n_frames=t, vocab_size=V).items()}
    take["speaker"] = 1
    out = generate_sequence(model, take)
    assert out.shape == (t, 141) and np.all(np.isfinite(out))
    # the first unit is exactly the model's output on the first window
    first = {
        k: torch.from_numpy(
            np.asarray(v)[None, :34] if k not in ("audio", "speaker") else np.asarray(v)[None]
        )
        for k, v in take.items()
        if k != "mel"
    }
    first["audio"] = first["audio"][:, :36266]
    first["speaker"] = torch.tensor([1])
    np.testing.assert_allclose(out[:30], model.generate(first)[0, :30].numpy(), atol=1e-6)


# --------------------------------------------------------------------------- windows per epoch
@dataclasses.dataclass
class _ScaleConfig(ModelConfig):
    pass


class _Scale(GestureModel):
    """One trainable scalar; records how many windows each training forward pass sees."""

    name = "scale"
    config_class = _ScaleConfig
    input_keys = ("pose",)

    def __init__(self) -> None:
        super().__init__(_ScaleConfig())
        self.w = torch.nn.Parameter(torch.zeros(()))
        self.seen: list[int] = []

    def forward(self, batch):
        if self.training:
            self.seen.append(int(batch["pose"].shape[0]))
        return {"pose": batch["pose"] * self.w}

    def losses(self, batch, out, *, epoch):
        return {"total": ((out["pose"] - batch["pose"]) ** 2).mean()}


def test_windows_per_epoch_limits_each_epoch(windows):
    train, _ = windows  # 24 windows
    model = _Scale()
    fit(model, train, cfg(epochs=3, batch_size=4, windows_per_epoch=10))
    # 10 windows per epoch in batches of 4: 4 + 4 + 2, three epochs
    assert model.seen == [4, 4, 2] * 3
    full = _Scale()
    fit(full, train, cfg(epochs=1, batch_size=4))
    assert full.seen == [4] * 6
    with pytest.raises(ValueError, match="windows_per_epoch"):
        TrainConfig(windows_per_epoch=1)


def test_windows_per_epoch_draws_a_new_subset_each_epoch(windows):
    train, _ = windows
    marked = dict(train)
    marked["pose"] = np.broadcast_to(
        np.arange(24, dtype=np.float32)[:, None, None], train["pose"].shape
    ).copy()  # window i is filled with the value i

    class _Ids(_Scale):
        def forward(self, batch):
            if self.training:
                self.ids.append(sorted(int(v) for v in batch["pose"][:, 0, 0]))
            return {"pose": batch["pose"] * self.w}

    model = _Ids()
    model.ids = []
    fit(model, marked, cfg(epochs=2, batch_size=8, windows_per_epoch=8))
    first, second = model.ids
    assert len(set(first)) == 8 and len(set(second)) == 8  # no window twice within an epoch
    assert first != second


def test_fit_accepts_a_windows_like_object(windows):
    train, _ = windows

    class _WindowsLike:
        whole_takes = False

        def keys(self):
            return list(train)

        def __getitem__(self, key):
            return train[key]

    a = fit(camn(), train, cfg(epochs=1))
    b = fit(camn(), _WindowsLike(), cfg(epochs=1))
    assert a.history == b.history


def test_batched_generation_equals_take_by_take():
    model = camn().eval()
    takes = []
    for t, seed in ((77, 0), (40, 1), (130, 2)):
        take = {k: v[0] for k, v in fake_windows(1, n_frames=t, vocab_size=V, seed=seed).items()}
        take["speaker"] = seed
        takes.append(take)
    batched = generate_sequences(model, takes)
    for take, out in zip(takes, batched, strict=True):
        assert out.shape == (take["pose"].shape[0], 141)
        np.testing.assert_allclose(out, generate_sequence(model, take), atol=1e-5)
    counter = _Counter()
    generate_sequences(counter, [_streams(34), _streams(94)])
    assert counter.calls == 3  # units 0, 1, 2 of the longer take; unit 0 of both in one call


def _scripted_scores(*values):
    """A val_score that returns ``values`` in turn (epoch 0, 1, ...), recording the model's mode."""
    calls = []

    def score(model):
        calls.append(model.training)
        return values[len(calls) - 1]

    return score, calls


def test_val_score_keeps_the_best_epoch_and_export_uses_it(windows, tmp_path):
    train, val = windows
    score, calls = _scripted_scores(3.0, 1.0, float("nan"), 2.0)
    res = fit(camn(), train, cfg(epochs=4, checkpoint=tmp_path / "run.pt"), val, val_score=score)
    assert calls == [False] * 4  # scored in eval mode
    assert (res.best_epoch, res.best_score) == (1, 1.0)  # NaN never wins
    assert [h["val_score"] for h in res.history][:2] == [3.0, 1.0]
    # the best state is the model after epoch 1: the same as a 2-epoch run (training is deterministic)
    fit(camn(), train, cfg(epochs=2, checkpoint=tmp_path / "two.pt"), val)
    export_checkpoint(tmp_path / "run.pt", tmp_path / "best.pt", half=False)
    export_checkpoint(tmp_path / "run.pt", tmp_path / "last.pt", half=False, best=False)
    best, data = load_model(tmp_path / "best.pt")
    two, _ = load_model(tmp_path / "two.pt")
    last, last_data = load_model(tmp_path / "last.pt")
    assert data["selected"] == {"epoch": 1, "score": 1.0, "of_epochs": 4} and "selected" not in last_data
    for (name, p), q in zip(best.state_dict().items(), two.state_dict().values(), strict=True):
        assert torch.equal(p, q), name
    assert any(not torch.equal(p, q) for p, q in zip(best.state_dict().values(), last.state_dict().values()))


def test_resume_keeps_the_best_epoch_so_far(windows, tmp_path):
    train, val = windows
    fit(
        camn(),
        train,
        cfg(epochs=2, checkpoint=tmp_path / "r.pt"),
        val,
        val_score=_scripted_scores(2.0, 1.0)[0],
    )
    res = fit(
        camn(),
        train,
        cfg(epochs=3, checkpoint=tmp_path / "r.pt", resume=True),
        val,
        val_score=_scripted_scores(5.0)[0],
    )
    assert (res.best_epoch, res.best_score) == (1, 1.0)
    assert [h["val_score"] for h in res.history] == [2.0, 1.0, 5.0]


STEPS_PER_EPOCH = 24 // 8  # the fixture's 24 train windows in batches of 8 (cfg)


def _steps_of(history):
    """The global steps of every epoch's validations."""
    return [[v["step"] for v in h["validations"]] for h in history]


def _trained_four_steps(train, path):
    """CaMN after a run's first 4 optimiser steps, trained another way: one full epoch (3 steps), then
    resumed for epoch 1 on its first batch only (``windows_per_epoch=8``: batch 0 of the same shuffle)."""
    fit(camn(), train, cfg(epochs=1, checkpoint=path))
    fit(camn(), train, cfg(epochs=2, checkpoint=path, resume=True, windows_per_epoch=8))
    return load_model(path)[0]


def _assert_same_weights(a, b):
    for (name, p), q in zip(a.state_dict().items(), b.state_dict().values(), strict=True):
        assert torch.equal(p, q), name


def test_val_every_validates_at_every_nth_step_of_the_run_and_at_its_end(windows, tmp_path):
    from beatlite.train.training import evaluate_losses

    train, val = windows
    res = fit(camn(), train, cfg(epochs=3, val_every=4), val)
    # 3 epochs of 3 steps: steps 4 and 8 (in epochs (4 - 1) // 3 = 1 and (8 - 1) // 3 = 2), then the last, 9
    assert 3 * STEPS_PER_EPOCH == 9 and _steps_of(res.history) == [[], [4], [8, 9]]
    assert res.history[0]["val"] == {} and "val_score" not in res.history[0]
    assert [h["val"] for h in res.history[1:]] == [h["validations"][-1]["val"] for h in res.history[1:]]
    # step 4's losses are those of the model trained 4 steps another way (step 4 is in epoch 1)
    four = _trained_four_steps(train, tmp_path / "four.pt")
    assert res.history[1]["validations"][0]["val"] == evaluate_losses(four, val, epoch=1, batch_size=8)
    # step 9 ends a plain 3-epoch run, whose per-epoch validation of its last epoch saw the same model
    plain = fit(camn(), train, cfg(epochs=3), val)
    assert res.history[2]["validations"][1]["val"] == plain.history[2]["val"]
    assert [h["train"] for h in res.history] == [
        h["train"] for h in plain.history
    ]  # validating changed nothing
    assert "validations" not in plain.history[0] and plain.best_step is None


def test_val_every_keeps_the_weights_of_the_lowest_scoring_step(windows, tmp_path):
    train, val = windows
    score, calls = _scripted_scores(3.0, 1.0, 2.0)
    config = cfg(epochs=2, val_every=2, checkpoint=tmp_path / "run.pt")
    res = fit(camn(), train, config, val, val_score=score)
    assert calls == [False] * 3  # steps 2, 4 and 6 (the last: no extra one), scored in eval mode
    assert _steps_of(res.history) == [[2], [4, 6]]
    assert [[v["val_score"] for v in h["validations"]] for h in res.history] == [[3.0], [1.0, 2.0]]
    assert [h["val_score"] for h in res.history] == [3.0, 2.0]  # an epoch's last validation
    assert (res.best_epoch, res.best_step, res.best_score) == (1, 4, 1.0)
    export_checkpoint(tmp_path / "run.pt", tmp_path / "best.pt", half=False)
    best, data = load_model(tmp_path / "best.pt")
    assert data["selected"] == {"epoch": 1, "score": 1.0, "of_epochs": 2, "step": 4}
    _assert_same_weights(best, _trained_four_steps(train, tmp_path / "four.pt"))


def test_a_run_validating_every_n_steps_killed_mid_epoch_resumes_with_the_same_record(windows, tmp_path):
    """val_every=2 with checkpoint_every=1: a run stopped after 5 steps (epoch 1, after its validation at step
    4) resumes at step 5 without validating step 4 again, and ends with the history, best and weights of an
    uninterrupted run."""
    train, val = windows
    every = {"val_every": 2, "checkpoint_every": 1}
    score = _scripted_scores(3.0, 1.0, 2.0)[0]
    full = fit(camn(), train, cfg(checkpoint=tmp_path / "full.pt", **every), val, val_score=score)
    with step_killed_after(5), pytest.raises(KeyboardInterrupt):
        fit(
            camn(),
            train,
            cfg(checkpoint=tmp_path / "part.pt", **every),
            val,
            val_score=_scripted_scores(3.0, 1.0)[0],
        )
    saved = torch.load(tmp_path / "part.pt", weights_only=True)
    assert (saved["epoch"], saved["partial"]["step"], saved["steps"]) == (1, 2, 5)
    assert [v["step"] for v in saved["partial"]["validations"]] == [4] and saved["best"]["step"] == 4
    score, scored = _scripted_scores(2.0)
    resumed = fit(
        camn(), train, cfg(checkpoint=tmp_path / "part.pt", resume=True, **every), val, val_score=score
    )
    assert len(scored) == 1  # step 6 only
    assert resumed.history == full.history and _steps_of(resumed.history) == [[2], [4, 6]]
    assert (resumed.best_epoch, resumed.best_step, resumed.best_score) == (1, 4, 1.0)
    a = torch.load(tmp_path / "full.pt", weights_only=True)
    b = torch.load(tmp_path / "part.pt", weights_only=True)
    for key in ("state", "optimizer", "best"):
        assert _equal(a[key], b[key]), key


def _equal(a, b):
    """Nested dicts, lists and tensors equal to the bit."""
    if torch.is_tensor(a):
        return torch.is_tensor(b) and a.dtype == b.dtype and torch.equal(a, b)
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(_equal(a[k], b[k]) for k in a)
    if isinstance(a, list | tuple):
        return type(a) is type(b) and len(a) == len(b) and all(_equal(x, y) for x, y in zip(a, b))
    return a == b


def test_resuming_a_checkpoint_without_the_step_count_counts_the_epochs_steps(windows, tmp_path):
    """A checkpoint written before the global step was stored: the run goes on counting from
    epochs done x steps per epoch (epoch 1's steps are 4, 5, 6: validations at 4 and 6)."""
    train, val = windows
    fit(camn(), train, cfg(epochs=1, checkpoint=tmp_path / "old.pt"), val)
    old = torch.load(tmp_path / "old.pt", weights_only=True)
    del old["steps"]
    torch.save(old, tmp_path / "old.pt")
    res = fit(camn(), train, cfg(epochs=2, val_every=2, checkpoint=tmp_path / "old.pt", resume=True), val)
    assert "validations" not in res.history[0] and [v["step"] for v in res.history[1]["validations"]] == [
        4,
        6,
    ]
    assert torch.load(tmp_path / "old.pt", weights_only=True)["steps"] == 2 * STEPS_PER_EPOCH


def test_val_every_must_be_positive():
    with pytest.raises(ValueError, match="val_every must be >= 1 or None, got 0"):
        TrainConfig(val_every=0)
    assert TrainConfig(val_every=1).val_every == 1 and TrainConfig().val_every is None


class _Marker:
    """A pickled object whose loading would run code: it writes a file when unpickled with the full loader."""

    def __init__(self, path: str) -> None:
        self.path = path

    def __reduce__(self):
        import pathlib

        return (pathlib.Path.touch, (pathlib.Path(self.path),))  # unpickling calls Path(path).touch()


def test_a_checkpoint_that_would_run_code_is_refused_and_runs_nothing(windows, tmp_path):
    from beatlite.io import FormatError
    from beatlite.train.checkpoint import load_checkpoint

    marker = tmp_path / "ran.txt"
    payload = {
        "format": "beatlite-checkpoint/1",
        "model": {"name": "camn"},
        "state": {},
        "x": _Marker(str(marker)),
    }
    torch.save(payload, tmp_path / "evil.pt")
    assert not marker.exists()
    with pytest.raises(FormatError, match="plain torch checkpoint"):
        load_checkpoint(tmp_path / "evil.pt")
    assert not marker.exists(), "loading ran code from the checkpoint"
    torch.load(tmp_path / "evil.pt", weights_only=False)  # the unsafe loader does run it: the test can fail
    assert marker.exists()


def test_checkpoint_metadata_is_saved_as_tensors_and_read_back_as_numpy(windows, tmp_path):
    from beatlite.train.checkpoint import load_checkpoint, save_checkpoint

    meta = {"pose_mean": np.arange(3, dtype=np.float64) / 3, "n": np.int64(4), "vocab": ["a", "b"]}
    save_checkpoint(
        tmp_path / "c.pt", {"format": "beatlite-checkpoint/1", "model": {}, "state": {}, "meta": meta}
    )
    raw = torch.load(tmp_path / "c.pt", weights_only=True)  # no allow-list needed: tensors and plain values
    assert torch.is_tensor(raw["meta"]["pose_mean"]) and raw["meta"]["n"] == 4
    back = load_checkpoint(tmp_path / "c.pt")["meta"]
    assert back["pose_mean"].dtype == np.float64 and np.array_equal(back["pose_mean"], meta["pose_mean"])
    assert back["vocab"] == ["a", "b"]


def test_a_checkpoint_whose_weights_do_not_fit_is_a_format_error(windows, tmp_path):
    from beatlite.io import FormatError
    from beatlite.train.checkpoint import load_checkpoint, save_checkpoint

    train, _ = windows
    fit(camn(), train, cfg(epochs=1, checkpoint=tmp_path / "t.pt"))
    data = load_checkpoint(tmp_path / "t.pt")
    name = next(k for k, v in data["state"].items() if v.ndim == 2)
    bad_shape = {**data, "state": {**data["state"], name: data["state"][name][:, :1]}}
    unknown = {**data, "state": {**data["state"], "no_such.weight": torch.zeros(1)}}
    bad_field = {**data, "model": {**data["model"], "no_such_field": 1}}
    expected = [
        ("do not fit the model", "state"),
        ("do not fit the model", "state"),
        ("no_such_field", "model"),
    ]
    for i, (payload, (text, field)) in enumerate(zip((bad_shape, unknown, bad_field), expected, strict=True)):
        save_checkpoint(tmp_path / f"bad{i}.pt", payload)
        with pytest.raises(FormatError, match=text) as refused:
            load_model(tmp_path / f"bad{i}.pt")
        assert refused.value.field == field


def test_a_save_killed_midway_leaves_no_temp_file_after_the_next_save(windows, tmp_path):
    """A kill during save_checkpoint left a temp file no cleanup recognised (its name had no pid)."""
    import subprocess
    import sys

    from beatlite.train.checkpoint import load_checkpoint, save_checkpoint

    code = (
        "import os, torch, beatlite.train.checkpoint as c\n"
        "torch.save = lambda obj, f: (f.write(b'partial'), f.flush(), os._exit(9))  # killed mid-write\n"
        f"c.save_checkpoint({str(tmp_path / 'c.pt')!r}, {{'format': 'x', 'model': {{}}, 'state': {{}}}})\n"
    )
    assert subprocess.run([sys.executable, "-c", code], capture_output=True).returncode == 9
    assert [p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp")], (
        "the kill should leave a temp file"
    )
    save_checkpoint(tmp_path / "c.pt", {"format": "beatlite-checkpoint/1", "model": {}, "state": {}})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.pt"]
    assert load_checkpoint(tmp_path / "c.pt")["state"] == {}


def test_a_truncated_checkpoint_is_said_to_be_truncated_not_legacy(windows, tmp_path):
    """A checkpoint cut short (a copy or a write that stopped) or empty: a FormatError naming the file that says
    so, not the advice to convert a legacy pickle (which fails on it too)."""
    from beatlite.io import FormatError
    from beatlite.train.checkpoint import load_checkpoint

    train, _ = windows
    fit(camn(), train, cfg(epochs=1, checkpoint=tmp_path / "full.pt"))
    whole = (tmp_path / "full.pt").read_bytes()
    for size in (len(whole) // 2, len(whole) - 10, 100, 0):
        (tmp_path / "cut.pt").write_bytes(whole[:size])
        with pytest.raises(FormatError, match="truncated or corrupted file") as refused:
            load_checkpoint(tmp_path / "cut.pt")
        assert str(tmp_path / "cut.pt") in str(refused.value) and "convert_legacy" not in str(refused.value)


def test_convert_legacy_needs_trust_and_writes_a_plain_copy(windows, tmp_path):
    import pathlib

    from beatlite.io import FormatError
    from beatlite.train.checkpoint import convert_legacy, load_checkpoint

    train, _ = windows
    fit(camn(), train, cfg(epochs=1, checkpoint=tmp_path / "t.pt"))
    data = load_checkpoint(tmp_path / "t.pt")
    legacy = {
        **data,
        "meta": {**data["meta"], "source": pathlib.PurePosixPath("/data/beat")},
    }  # a pickled object
    torch.save(legacy, tmp_path / "legacy.pt")
    with pytest.raises(FormatError, match="convert_legacy"):
        load_checkpoint(tmp_path / "legacy.pt")
    with pytest.raises(PermissionError, match="trust=True"):
        convert_legacy(tmp_path / "legacy.pt", tmp_path / "plain.pt")
    convert_legacy(tmp_path / "legacy.pt", tmp_path / "plain.pt", trust=True)
    plain = load_checkpoint(tmp_path / "plain.pt")
    assert plain["meta"]["source"] == "/data/beat"
    assert all(torch.equal(v, data["state"][k]) for k, v in plain["state"].items())
    model, _ = load_model(tmp_path / "plain.pt")
    assert all(torch.equal(v, data["state"][k]) for k, v in model.state_dict().items())


def test_a_compiled_step_gives_the_losses_and_poses_of_the_eager_one(windows):
    """``TrainConfig.compile``: the step through ``torch.compile`` (the ``aot_eager`` backend: traced into
    graphs, run by the same kernels, as on a CPU without a compiler) trains as the eager step does: the same
    losses and, in eval mode, the same poses. (Not the same raw weights: a convolution's bias before a
    BatchNorm has a gradient of rounding noise only, which Adam scales up to full steps in either run.)"""
    train, val = windows
    eager, compiled = camn(), camn()
    a = fit(eager, train, cfg(), val)
    b = fit(compiled, train, cfg(compile="aot_eager"), val)
    assert b.history[-1]["train"].keys() == a.history[-1]["train"].keys()
    for x, y in zip(a.history, b.history, strict=True):  # fp32 reassociation in traced graphs at most
        assert y["train"] == pytest.approx(x["train"], rel=1e-5)
        assert y["val"] == pytest.approx(x["val"], rel=1e-5)
    batch = {k: torch.from_numpy(v) for k, v in val.items()}
    with torch.no_grad():
        poses = [m.eval()(batch)["pose"] for m in (eager, compiled)]
    # z-scored poses (sd 1): 1e-3 = a thousandth of a standard deviation (seen: 1.5e-4 after 6 steps)
    torch.testing.assert_close(poses[1], poses[0], rtol=0, atol=1e-3)
    with pytest.raises(ValueError, match="compile must be None or one of"):
        TrainConfig(compile="fast")


def test_compiling_on_the_cpu_keeps_each_mode_s_options_without_inductor_s_layout_optimisation(monkeypatch):
    """``training._compiled``: on the CPU an inductor mode becomes its own options plus
    ``layout_optimization=False`` (channels-last 2-D convolutions crash torch 2.13's oneDNN backward); on CUDA
    the mode is passed as it is; backends and ``None`` are unchanged."""
    from torch._inductor import list_mode_options

    from beatlite.train.config import COMPILE_BACKENDS, COMPILE_MODES
    from beatlite.train.training import _compiled

    calls = []
    monkeypatch.setattr(torch, "compile", lambda fn, **kw: calls.append(kw) or fn)
    fn = lambda x: x  # noqa: E731
    assert _compiled(fn, None, torch.device("cpu")) is fn and not calls
    for mode in COMPILE_MODES:
        _compiled(fn, mode, torch.device("cpu"))
        _compiled(fn, mode, torch.device("cuda"))
        assert calls[-2:] == [
            {"options": {**list_mode_options(mode), "layout_optimization": False}},
            {"mode": mode},
        ]
    for backend in COMPILE_BACKENDS:
        _compiled(fn, backend, torch.device("cpu"))
        assert calls[-1] == {"backend": backend}
    assert list_mode_options("reduce-overhead")["triton.cudagraphs"]  # (a mode's options are kept)


def test_a_compiled_pass_draws_its_own_dropout_masks_repeatably_from_the_seed():
    """``TrainConfig.compile``'s docstring: under inductor a pass draws dropout masks with inductor's own
    generator, seeded from torch's, so one seed repeats them to the bit, but they are not the eager masks."""
    from beatlite.train.training import _compiled

    x = torch.ones(4096)
    drop = _compiled(
        lambda t: torch.nn.functional.dropout(t, 0.5, training=True), "default", torch.device("cpu")
    )
    masks = []
    for fn in (drop, drop, lambda t: torch.nn.functional.dropout(t, 0.5, training=True)):
        torch.manual_seed(11)
        masks.append(fn(x) != 0)
    assert torch.equal(masks[0], masks[1])
    assert not torch.equal(masks[0], masks[2])  # 4096 coin flips agreeing by chance: 2^-4096
    assert 0.4 < masks[0].float().mean() < 0.6  # kept with probability 1/2 (sd 0.008 over 4096)


def test_a_model_that_states_an_inductor_failure_is_refused_by_name_before_a_step(windows, monkeypatch):
    """``GestureModel.inductor_failure`` (a model whose training pass breaks inductor says why): ``fit``
    refuses every inductor mode at once, naming it and leaving the weights as they were; ``aot_eager``
    (traced, no inductor) still trains. No shipped model states one (all compile on the CPU here)."""
    from beatlite.models.camn import CaMN
    from beatlite.train.config import COMPILE_MODES

    train, val = windows
    monkeypatch.setattr(CaMN, "inductor_failure", "a stated reason")
    for mode in COMPILE_MODES:
        model = camn()
        before = {k: v.detach().clone() for k, v in model.named_parameters()}
        with pytest.raises(
            ValueError, match=f"camn cannot be compiled with inductor .*'{mode}'.*a stated reason"
        ):
            fit(model, train, cfg(compile=mode), val)
        assert all(torch.equal(v, before[k]) for k, v in model.named_parameters())  # not one step taken
    history = fit(camn(), train, cfg(epochs=1, compile="aot_eager"), val).history
    assert np.isfinite(history[0]["train"]["total"])


def test_nondeterministic_training_sets_torch_so_and_changes_nothing_on_the_cpu(windows):
    """``TrainConfig(deterministic=False)`` turns torch's deterministic algorithms off for the run (the
    default turns them on); the CPU's kernels are deterministic either way, so the history is the same to the
    bit (on CUDA it is not: the point of the option)."""
    train, val = windows
    a = fit(camn(), train, cfg(deterministic=False), val)
    assert not torch.are_deterministic_algorithms_enabled()
    b = fit(camn(), train, cfg(), val)
    assert torch.are_deterministic_algorithms_enabled()
    assert [h["train"] for h in a.history] == [h["train"] for h in b.history]
    assert [h["val"] for h in a.history] == [h["val"] for h in b.history]


def test_adam_keeps_the_loop_on_the_cpu_and_the_fused_kernel_takes_the_same_steps():
    """Fused Adam (CUDA's one kernel for all parameters) and torch's default loop: the same updates (to
    float32 rounding), checked on the CPU, where torch has the fused kernel too; the CPU keeps the loop."""
    from beatlite.train.training import _adam

    torch.manual_seed(0)
    params = [torch.nn.Parameter(torch.randn(5, 3)), torch.nn.Parameter(torch.randn(7))]
    assert _adam(params, 1e-3, (0.5, 0.999)).defaults["fused"] is None  # on the CPU: the default loop
    assert _adam([], 1e-3, (0.5, 0.999)) is None
    copies = [[torch.nn.Parameter(p.detach().clone()) for p in params] for _ in range(2)]
    loop = torch.optim.Adam(copies[0], lr=1e-2, betas=(0.5, 0.999))
    fused = torch.optim.Adam(copies[1], lr=1e-2, betas=(0.5, 0.999), fused=True)
    for step in range(5):
        for group, opt in zip(copies, (loop, fused), strict=True):
            opt.zero_grad()
            sum(((p - step) ** 2).sum() for p in group).backward()
            opt.step()
    for p, q in zip(*copies, strict=True):
        torch.testing.assert_close(q, p, rtol=1e-5, atol=1e-6)


def test_validating_every_n_steps_leaves_the_training_draws_alone(windows):
    """With ``val_every``, a validation that draws random numbers does not shift the numbers training draws
    (DiffGesture draws its steps and noise): the same train losses as a run that never validates."""
    train, _ = windows

    def diffgesture():
        torch.manual_seed(0)
        return build_model("diffgesture", preset="tiny")

    def noisy_score(model):
        return float(torch.rand(100).mean())  # draws from torch's global generator, as a sampled FGD does

    plain = fit(diffgesture(), train, cfg(epochs=2))
    scored = fit(diffgesture(), train, cfg(epochs=2, val_every=2), val_score=noisy_score)
    assert [h["train"] for h in scored.history] == [h["train"] for h in plain.history]
    assert [v["step"] for h in scored.history for v in h["validations"]] == [2, 4, 6]


def test_set_deterministic_stops_filling_new_tensors_on_cuda_only():
    """Deterministic mode fills every new tensor (NaN); on CUDA each fill is a kernel launch, so ``fit`` turns the
    filling off there and on again (torch's default) for the CPU, also after a CUDA run; the mode is set on both."""
    import torch

    from beatlite.train.training import set_deterministic

    fill, mode = (
        torch.utils.deterministic.fill_uninitialized_memory,
        torch.are_deterministic_algorithms_enabled(),
    )
    try:
        torch.utils.deterministic.fill_uninitialized_memory = True
        set_deterministic(True, "cpu")
        assert (
            torch.are_deterministic_algorithms_enabled()
            and torch.utils.deterministic.fill_uninitialized_memory
        )
        assert torch.isnan(torch.empty(3)).all()  # filled
        set_deterministic(False, torch.device("cpu"))
        assert not torch.are_deterministic_algorithms_enabled()
        set_deterministic(True, "cuda")  # (a device name: no GPU needed)
        assert torch.are_deterministic_algorithms_enabled()
        assert not torch.utils.deterministic.fill_uninitialized_memory
        set_deterministic(True, "cpu")  # a CPU run after a CUDA one in the same process: filled again
        assert torch.utils.deterministic.fill_uninitialized_memory and torch.isnan(torch.empty(3)).all()
    finally:
        torch.utils.deterministic.fill_uninitialized_memory = fill
        torch.use_deterministic_algorithms(mode)


def test_fit_computes_the_raw_audio_block_as_its_config_says_with_the_kernels_losses(windows):
    """``TrainConfig.audio_matmul``: ``"on"`` trains CaMN with its waveform block as one matrix product of the
    waveform's frames, the convolutions' values to float32 rounding, so the same losses to rounding that the
    steps carry on (after these 6 steps: 7.7e-7 relative at most, seen; bound 1e-4); ``"auto"`` on the CPU switches it back off (the recorded numbers
    are the kernels'); an unknown value is refused."""
    from beatlite.models.layers import BasicBlock1d

    def switched(model):
        return [
            m.frames_as_matmul
            for m in model.modules()
            if isinstance(m, BasicBlock1d) and m.conv1.in_channels == 1
        ]

    train, val = windows
    kernels, matmul = camn(), camn()
    a = fit(kernels, train, cfg(audio_matmul="off"), val)
    b = fit(matmul, train, cfg(audio_matmul="on"), val)
    assert switched(kernels) == [False] and switched(matmul) == [True]
    for x, y in zip(a.history, b.history, strict=True):
        assert y["train"] == pytest.approx(x["train"], rel=1e-4)
        assert y["val"] == pytest.approx(x["val"], rel=1e-4)
    fit(matmul, train, cfg(epochs=1), val)  # "auto" on the CPU
    assert switched(matmul) == [False]
    default = fit(camn(), train, cfg(), val)
    assert default.history == a.history  # auto on the CPU is the kernels' run, to the bit
    with pytest.raises(ValueError, match="audio_matmul must be one of"):
        TrainConfig(audio_matmul="yes")
