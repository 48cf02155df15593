"""Fake window batches and the model contract suite (:func:`check_model`), for tests.

:func:`fake_windows` / :func:`fake_batch`: random (seeded) windows with the shapes of
:func:`beatlite.data.windows.build_windows`, each key in its type and range, so a model's
forward/backward pass can be unit-tested without the data pipeline.

:func:`check_model` runs every rule of the :class:`~beatlite.models.base.GestureModel` contract on a
model (in the spirit of scikit-learn's ``check_estimator``): shapes and seed-only generation on a batch of
exactly its ``batch_keys`` (a key read beyond them named), the pose in the batch's dtype, the batch left unchanged,
the same generation twice, finite losses whose backward reaches every parameter, determinism under a
seed, the checkpoint round trip, a training pass that never reads the device back to the host, and (given a small window store) two training steps from the store that
equal the in-memory route bit for bit, and two under bfloat16 autocast with CUDA's dtype rules.
``tests/test_models_contract.py`` runs it over the whole registry.

Not taught in a notebook: fake windows and batches and the contract checks for the tests.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch.utils._python_dispatch import TorchDispatchMode
from torch.utils._pytree import tree_leaves

from beatlite.constants import FPS, SR, WINDOW_LENGTH

FAKE_SHAPES: dict[str, tuple[int, ...]] = {
    "pose": (WINDOW_LENGTH, 141),
    "dirvec": (WINDOW_LENGTH, 126),
    "audio": (36266,),
    "mel": (70, 128),
    "face": (WINDOW_LENGTH, 51),
    "word": (WINDOW_LENGTH,),
    "emotion": (WINDOW_LENGTH,),
    "semantic": (WINDOW_LENGTH,),
    "speaker": (),
}
"""Per-window shape of each key (the batch adds a leading B)."""


def fake_windows(
    n: int, *, seed: int = 0, vocab_size: int = 100, n_speakers: int = 4, n_frames: int = WINDOW_LENGTH
) -> dict[str, np.ndarray]:
    """A numpy window dict of ``n`` random windows (the layout of ``build_windows``).

    Parameters
    ----------
    n : int
        Number of windows N.
    seed : int
        Seed of the numpy generator.
    vocab_size, n_speakers : int
        Ranges of ``"word"`` ids (``0..vocab_size-1``) and ``"speaker"`` ids.
    n_frames : int
        Frames T per window (34 by default; audio gets ``floor(T / 15 * 16000)`` samples,
        mel ``round((T / 15 * 16000 - 1024) / 512 + 1)`` frames).

    Returns
    -------
    dict of str -> ndarray
        ``"pose"`` (N, T, 141) float32 ~N(0, 1); ``"dirvec"`` (N, T, 126) float32 small;
        ``"audio"`` (N, S) float32 in [-1, 1]; ``"mel"`` (N, M, 128) float32 in [-80, 0] dB;
        ``"face"`` (N, T, 51) float32 in [0, 1]; ``"word"`` (N, T) int64; ``"emotion"`` (N, T) int64
        in 0..7; ``"semantic"`` (N, T) float32 in [0, 1]; ``"speaker"`` (N,) int64.

    Examples
    --------
    Ten frames (2/3 s) give ``floor(10 / 15 * 16000) = 10666`` audio samples and
    ``round((10666.7 - 1024) / 512 + 1) = 20`` mel frames; one seed gives the same windows.

    >>> import numpy as np
    >>> from beatlite.models.testing import fake_windows
    >>> w = fake_windows(2, n_frames=10)
    >>> w["pose"].shape, w["audio"].shape, w["mel"].shape, w["speaker"].shape
    ((2, 10, 141), (2, 10666), (2, 20, 128), (2,))
    >>> bool(np.array_equal(fake_windows(2, n_frames=10)["pose"], w["pose"]))
    True
    """
    if n < 1 or n_frames < 1:
        raise ValueError(f"n and n_frames must be >= 1, got n={n}, n_frames={n_frames}")
    rng = np.random.default_rng(seed)
    t = n_frames
    n_audio = int(np.floor(t / FPS * SR))
    n_mel = int(round((t / FPS * SR - 1024) / 512 + 1))
    emotion = np.repeat(rng.integers(0, 8, size=(n, 1)), t, axis=1).astype(np.int64)
    return {
        "pose": rng.standard_normal((n, t, 141)).astype(np.float32),
        "dirvec": (0.3 * rng.standard_normal((n, t, 126))).astype(np.float32),
        "audio": rng.uniform(-0.5, 0.5, size=(n, n_audio)).astype(np.float32),
        "mel": rng.uniform(-80.0, 0.0, size=(n, n_mel, 128)).astype(np.float32),
        "face": rng.uniform(0.0, 1.0, size=(n, t, 51)).astype(np.float32),
        "word": rng.integers(0, vocab_size, size=(n, t)).astype(np.int64),
        "emotion": emotion,
        "semantic": rng.uniform(0.0, 1.0, size=(n, t)).astype(np.float32),
        "speaker": rng.integers(0, n_speakers, size=n).astype(np.int64),
    }


def fake_batch(b: int = 2, *, seed: int = 0, **kwargs: int) -> dict[str, torch.Tensor]:
    """:func:`fake_windows` as a dict of torch tensors (float32 / int64), batch size ``b``.

    Examples
    --------
    >>> from beatlite.models.testing import fake_batch
    >>> batch = fake_batch(2)
    >>> tuple(batch["pose"].shape), batch["pose"].dtype, tuple(batch["word"].shape), batch["word"].dtype
    ((2, 34, 141), torch.float32, (2, 34), torch.int64)
    """
    return {k: torch.from_numpy(v) for k, v in fake_windows(b, seed=seed, **kwargs).items()}


# ---------------------------------------------------------------------------- the model contract suite
#: Epoch given to ``losses`` in the checks: late enough that every adversarial term is on.
LATE_EPOCH = 1000


@dataclasses.dataclass
class ModelCase:
    """What every contract check receives: the model class, how to build it, and where to write.

    Attributes
    ----------
    cls : GestureModel subclass
    preset : str
        Preset to build (``"tiny"``: the checks run in seconds on one core).
    overrides : dict
        Config overrides (e.g. ``vocab_size`` of the store's vocabulary).
    folder : Path
        A scratch folder for checkpoints.
    train : StoreWindows, optional
        A small window store's train view (the store checks need it).
    reference : Windows or dict of ndarray, optional
        The same windows in memory (``build_windows`` with the store view's statistics and vocabulary).

    Examples
    --------
    A case builds a fresh seeded model and a fake batch of exactly the keys it reads:

    >>> import tempfile
    >>> from beatlite.models.testing import model_case
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     case = model_case("s2g", folder)
    ...     model = case.build()
    ...     sorted(case.batch(model)), model.training
    (['mel', 'pose'], True)
    """

    cls: type
    preset: str
    overrides: dict[str, Any]
    folder: Path
    train: Any = None
    reference: Any = None

    def build(self, seed: int = 0) -> Any:
        """A freshly initialised model (torch seeded with ``seed``), in training mode."""
        from beatlite.models import presets
        from beatlite.models.base import config_from_preset

        torch.manual_seed(seed)
        table = presets(self.cls)
        return self.cls(config_from_preset(self.cls.config_class, table, self.preset, **self.overrides))

    def batch(self, model: Any, b: int = 2, seed: int = 0) -> dict[str, torch.Tensor]:
        """A fake batch of ``b`` windows holding exactly the model's :meth:`batch_keys` (ids in its ranges)."""
        cfg = model.config
        full = fake_batch(
            b, seed=seed, vocab_size=int(getattr(cfg, "vocab_size", 100)),
            n_speakers=min(4, int(getattr(cfg, "n_speakers", 4))),
        )  # fmt: skip
        return {k: full[k] for k in type(model).batch_keys(cfg)}


def _prepared(case: ModelCase, model: Any) -> Any:
    """``model`` after ``prepare`` on 8 fake windows with their own normalisers (statistics buffers set)."""
    from beatlite.data.normalize import Normalizer, Normalizers

    windows = fake_windows(8, seed=1)
    pose, dirvec = windows["pose"].reshape(-1, 141), windows["dirvec"].reshape(-1, 126)
    norms = Normalizers(Normalizer(pose.mean(0), pose.std(0)), Normalizer(dirvec.mean(0), np.ones(126)))
    model.prepare(windows, norms)
    return model


def _reset(model: Any) -> Any:
    """Restart a model's counted draws (``reset()`` of RandomClip, A2G) so two calls can be compared."""
    if callable(getattr(model, "reset", None)):
        model.reset()
    return model


def _train_losses(model: Any, batch: dict[str, torch.Tensor]) -> dict[str, torch.Tensor]:
    """One training-mode forward pass and the generator losses at :data:`LATE_EPOCH`."""
    model.train()
    return model.losses(batch, model(batch), epoch=LATE_EPOCH)


def _checked_losses(case: ModelCase, model: Any, batch: dict[str, torch.Tensor]) -> dict[str, torch.Tensor]:
    """:func:`_train_losses`, checked: a dict of tensors with a ``"total"``, and the batch unchanged."""
    before = _snapshot(batch)
    model.train()
    out = _forward(case, model, batch)
    losses = _reading(case, "losses", model.losses, batch, out, epoch=LATE_EPOCH)
    _expect(
        isinstance(losses, Mapping) and "total" in losses,
        case,
        f"losses must return a dict with 'total', got {sorted(losses) if isinstance(losses, Mapping) else losses}",
    )
    loose = [k for k, v in losses.items() if not isinstance(v, torch.Tensor)]
    _expect(not loose, case, f"losses {loose} are not tensors (keep them as tensors: no .item() or float())")
    _unchanged(case, batch, before, "forward or losses")
    return losses


def _expect(ok: Any, case: ModelCase, message: str) -> None:
    """Raise ``AssertionError`` naming the model when ``ok`` is false (kept under ``python -O``)."""
    if not bool(ok):
        raise AssertionError(f"{case.cls.__name__} ({case.preset}): {message}")


def _reading(
    case: ModelCase, what: str, fn: Any, batch: Mapping[str, torch.Tensor], *args: Any, **kw: Any
) -> Any:
    """``fn(batch, *args, **kw)``; a ``KeyError`` for a window key the batch lacks becomes an ``AssertionError``
    naming the model, the key and the ``batch_keys`` that do not list it (``fit`` gives only those)."""
    try:
        return fn(batch, *args, **kw)
    except KeyError as error:
        key = error.args[0] if error.args else None
        if key not in FAKE_SHAPES or key in batch:
            raise
        where = "input_keys (or keys_for)" if what == "forward" else "batch_keys (the losses read more)"
        raise AssertionError(
            f"{case.cls.__name__} ({case.preset}): {what} reads batch[{key!r}], which batch_keys(config) = "
            f"{tuple(batch)} does not list: add it to {where}"
        ) from error


def _forward(case: ModelCase, model: Any, batch: Mapping[str, torch.Tensor]) -> dict[str, torch.Tensor]:
    """``model(batch)``, checked to be a dict holding a ``"pose"`` tensor."""
    out = _reading(case, "forward", model, batch)
    _expect(
        isinstance(out, Mapping), case, f"forward must return a dict with 'pose', got {type(out).__name__}"
    )
    _expect("pose" in out, case, f"forward returned no 'pose' (keys: {sorted(out)})")
    _expect(isinstance(out["pose"], torch.Tensor), case, f"out['pose'] is a {type(out['pose']).__name__}")
    return out


def _unchanged(
    case: ModelCase, batch: Mapping[str, torch.Tensor], before: Mapping[str, torch.Tensor], what: str
) -> None:
    """Every key of ``before`` still in ``batch`` with the same values: ``what`` did not change the batch (in place
    or by assigning a key), which the losses and the harness read after it."""
    changed = [k for k, v in before.items() if k not in batch or not torch.equal(batch[k], v)]
    _expect(
        not changed,
        case,
        f"{what} changed the batch's {changed} (in place or by assigning the key): "
        "the losses and the harness read the batch after it; work on a copy",
    )


def _snapshot(batch: Mapping[str, torch.Tensor]) -> dict[str, torch.Tensor]:
    return {k: v.clone() for k, v in batch.items()}


def _finite(values: Mapping[str, Any]) -> list[str]:
    """Names of the non-finite values of a loss dict (tensors or floats)."""
    return [
        k
        for k, v in values.items()
        if not bool(torch.isfinite(torch.as_tensor(v, dtype=torch.float64)).all())
    ]


def check_shapes(case: ModelCase) -> None:
    """``batch_keys`` covers ``keys_for`` and the target; on a batch of exactly those keys ``forward`` (a dict)
    and ``generate`` give a finite (B, T, D) pose in the batch's dtype, leave the batch unchanged, ``generate``
    gives the same pose twice and reads only the ``n_pre`` seed frames (and leaves a model in training mode
    there).

    Examples
    --------
    A model that drops a frame fails, the message naming the model and the rule:

    >>> import tempfile
    >>> from beatlite.models.baselines import MeanPose
    >>> from beatlite.models.testing import check_shapes, model_case
    >>> class Short(MeanPose):
    ...     def forward(self, batch):
    ...         return {"pose": super().forward(batch)["pose"][:, 1:]}
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     check_shapes(model_case(Short, folder))
    Traceback (most recent call last):
    ...
    AssertionError: Short (tiny): forward pose has shape (2, 33, 141), not (B, T, D) = (2, 34, 141)
    """
    model = _prepared(case, case.build())
    keys = set(type(model).batch_keys(model.config))
    missing = (set(type(model).keys_for(model.config)) | {model.target_key}) - keys
    _expect(not missing, case, f"batch_keys lacks {sorted(missing)}")
    batch = case.batch(model)
    before = _snapshot(batch)
    b, t = batch[model.target_key].shape[:2]
    pose = _forward(case, model, batch)["pose"]
    _unchanged(case, batch, before, "forward")
    _expect(
        tuple(pose.shape) == (b, t, model.pose_dim),
        case,
        f"forward pose has shape {tuple(pose.shape)}, not (B, T, D) = {(b, t, model.pose_dim)}",
    )
    want = batch[model.target_key].dtype
    wide = [n for n, v in (*model.named_parameters(), *model.named_buffers()) if v.dtype == torch.float64]
    _expect(
        pose.dtype == want,
        case,
        f"forward pose is {pose.dtype}, the batch's {model.target_key!r} {want}"
        + (f" (float64 parameters or buffers, from numpy?: {wide[:5]})" if wide else ""),
    )
    _expect(torch.isfinite(pose).all(), case, "forward pose is not finite")
    seeded = _reset(model).generate(batch)
    _unchanged(case, batch, before, "generate")
    _expect(tuple(seeded.shape) == (b, t, model.pose_dim), case, f"generate gave shape {tuple(seeded.shape)}")
    _expect(
        torch.equal(_reset(model).generate(batch), seeded),
        case,
        "generate gives another pose for the same batch: draw any randomness of eval mode from a "
        "torch.Generator seeded from the config and restarted by reset() (as A2G and DiffGesture do)",
    )
    later = dict(batch)
    later[model.target_key] = batch[model.target_key].clone()
    later[model.target_key][:, model.n_pre :] += 1.0
    _expect(torch.equal(_reset(model).generate(later), seeded), case, "generate reads frames after the seed")
    _expect(model.training, case, "generate did not restore training mode")


def check_gradients(case: ModelCase) -> None:
    """``losses`` returns a dict of tensors (the batch unchanged) with a finite scalar ``"total"`` whose backward
    gives every generator parameter a finite, non-zero gradient (adversarial terms on), and a discriminator loss
    that does the same for the discriminator."""
    model = _prepared(case, case.build())
    batch = case.batch(model)
    losses = _checked_losses(case, model, batch)
    _expect(losses["total"].ndim == 0, case, "losses['total'] is not a scalar")
    _expect(not _finite(losses), case, f"non-finite losses {_finite(losses)}")
    names = {id(p): n for n, p in model.named_parameters()}
    if model.trainable:
        losses["total"].backward()
        dead = [names[id(p)] for p in model.generator_parameters() if p.grad is None or not p.grad.any()]
        bad = [
            names[id(p)]
            for p in model.generator_parameters()
            if p.grad is not None and not p.grad.isfinite().all()
        ]
        _expect(not dead and not bad, case, f"no gradient: {dead[:5]}; non-finite gradient: {bad[:5]}")
    if model.discriminator is not None:
        model.zero_grad(set_to_none=True)
        d = model.discriminator_losses(batch, model(batch))["total"]
        _expect(d.ndim == 0 and torch.isfinite(d), case, "discriminator loss is not a finite scalar")
        d.backward()
        dead = [names[id(p)] for p in model.discriminator.parameters() if p.grad is None or not p.grad.any()]
        _expect(not dead, case, f"discriminator parameters without gradient: {dead[:5]}")


def check_determinism(case: ModelCase) -> None:
    """One seed, two models: identical weights, and identical training-mode outputs and losses under one seed."""
    runs = []
    for _ in range(2):
        model = _prepared(case, case.build(seed=0))
        batch = case.batch(model)
        torch.manual_seed(1)
        out = model(batch)
        losses = model.losses(batch, out, epoch=LATE_EPOCH)
        runs.append((model.state_dict(), out["pose"].detach(), {k: v.detach() for k, v in losses.items()}))
    (s1, p1, l1), (s2, p2, l2) = runs
    _expect(all(torch.equal(s1[k], s2[k]) for k in s1), case, "two models built with one seed differ")
    _expect(torch.equal(p1, p2), case, "two forward passes with one seed differ")
    _expect(all(torch.equal(l1[k], l2[k]) for k in l1), case, "two loss evaluations with one seed differ")


def check_generate_modes(case: ModelCase) -> None:
    """``generate`` leaves every submodule in the mode it found it in: a submodule frozen in eval while the rest
    trains stays in eval, one training inside an eval model trains again; and it changes no weight or buffer."""
    model = _prepared(case, case.build(seed=0))
    batch = case.batch(model)
    first = next(model.children(), None)
    for top in (True, False):
        model.train(top)
        if first is not None:
            first.train(not top)
        before = {m: m.training for m in model.modules()}
        state = {k: v.clone() for k, v in model.state_dict().items()}
        _reset(model).generate(batch)
        _expect({m: m.training for m in model.modules()} == before, case,
                f"generate changed the modes of submodules (model {'training' if top else 'in eval'})")  # fmt: skip
        _expect(all(torch.equal(state[k], v) for k, v in model.state_dict().items()), case,
                "generate changed a weight or buffer")  # fmt: skip


def check_checkpoint(case: ModelCase) -> None:
    """save_checkpoint -> export_checkpoint (float32) -> ``torch.load(weights_only=True)`` ->
    model_from_checkpoint generates exactly what the model generates."""
    from beatlite.train.checkpoint import FORMAT, export_checkpoint, model_from_checkpoint, save_checkpoint

    model = _prepared(case, case.build()).eval()
    state = {k: v.detach().cpu() for k, v in model.state_dict().items()}
    payload = {"format": FORMAT, "model": model.to_config(), "state": state, "epoch": 0, "history": []}
    src = save_checkpoint(case.folder / f"{model.name}_train.pt", payload)
    dst = export_checkpoint(src, case.folder / f"{model.name}.pt", half=False)
    loaded = model_from_checkpoint(torch.load(dst, map_location="cpu", weights_only=True))
    batch = case.batch(model)
    _expect(loaded.to_config() == model.to_config(), case, "the checkpoint's config differs")
    want, got = _reset(model).generate(batch), _reset(loaded).generate(batch)
    _expect(torch.equal(want, got), case, "the loaded checkpoint generates something else")


class CudaAutocastRules(torch.overrides.TorchFunctionMode):
    """Raise where CUDA's autocast would while running under the CPU's.

    CPU autocast promotes ``index_copy`` to the widest input dtype; CUDA autocast does not, so a float32
    destination and a bfloat16 source fail on the GPU only (``index_copy_(): self and source expected to
    have the same dtype``). Inside this mode they fail on the CPU too, so a CPU test covers the GPU rule.

    Examples
    --------
    >>> import torch
    >>> from beatlite.models.testing import CudaAutocastRules
    >>> with CudaAutocastRules():
    ...     torch.zeros(3).index_copy(0, torch.tensor([1]), torch.ones(1, dtype=torch.bfloat16))
    Traceback (most recent call last):
    ...
    RuntimeError: index_copy: self and source expected to have the same dtype (CUDA autocast), got torch.float32 and torch.bfloat16
    """

    OPS = (torch.Tensor.index_copy, torch.Tensor.index_copy_, torch.index_copy)

    def __torch_function__(self, func: Any, types: Any, args: tuple = (), kwargs: dict | None = None) -> Any:
        kwargs = kwargs or {}
        if func in self.OPS:
            dest, source = args[0], (args[3] if len(args) > 3 else kwargs["source"])
            if dest.dtype != source.dtype:
                raise RuntimeError(
                    f"index_copy: self and source expected to have the same dtype (CUDA autocast), "
                    f"got {dest.dtype} and {source.dtype}"
                )
        return func(*args, **kwargs)


def _store_view(case: ModelCase) -> Any:
    """The case's train windows read through a store view of exactly the model's ``batch_keys``."""
    model, train = case.build(), case.train
    keys = type(model).batch_keys(model.config)
    return train.store.windows(
        train.params["split"], length=train.length, stride=train.params["stride"], keys=keys,
        stats=train.normalizers, vocab=train.vocab,
    )  # fmt: skip


def _fit_two_steps(
    case: ModelCase,
    windows: Any,
    *,
    amp: bool,
    on_device: str = "never",
    compile: str | None = None,  # noqa: A002
    fill: bool = True,
) -> tuple[Any, list[dict[str, Any]]]:
    """A fresh model trained for two steps of 4 windows on ``windows`` (adversarial from the start);
    ``on_device``: ``TrainConfig.data_on_device`` (a store view read by the loader, or held on the device);
    ``compile``: ``TrainConfig.compile``; ``fill``: deterministic mode's filling of new tensors
    (``torch.utils.deterministic.fill_uninitialized_memory``, which ``fit`` turns off on CUDA)."""
    from beatlite.train import TrainConfig, fit

    model = case.build()
    config = TrainConfig(
        epochs=1, batch_size=4, windows_per_epoch=8, seed=1, no_adv_epochs=0, progress=False, amp=amp,
        data_on_device=on_device, compile=compile,
    )  # fmt: skip
    was = torch.utils.deterministic.fill_uninitialized_memory
    torch.utils.deterministic.fill_uninitialized_memory = fill
    try:
        with CudaAutocastRules():
            history = fit(model, windows, config).history
    except FloatingPointError as error:  # fit stops on non-finite losses (check_diverged): the contract fails
        _expect(False, case, f"non-finite losses ({error})")
    finally:
        torch.utils.deterministic.fill_uninitialized_memory = was
    return model, history


def check_store_training(case: ModelCase) -> None:
    """Two steps from a store view of exactly ``batch_keys``, read by the loader and held on the device
    (``data_on_device="always"``), equal two steps from the same windows in memory (same losses, weights and
    buffers, bit for bit), with finite losses. The store route runs without deterministic mode's filling of new
    tensors (as ``fit`` does on CUDA), the in-memory route with it: the model reads no memory it has not written
    (a read of a filled tensor would give NaN, of an unfilled one other bits or a NaN left by an earlier fill)."""
    view = _store_view(case)
    stored, history = _fit_two_steps(case, view, amp=False, fill=False)
    memory, reference = _fit_two_steps(case, case.reference, amp=False, fill=True)
    resident, held = _fit_two_steps(case, view, amp=False, on_device="always")
    _expect(len(history) == (1 if stored.trainable else 0), case, f"history has {len(history)} epochs")
    _expect(all(not _finite(h["train"]) for h in history), case, f"non-finite losses {history}")
    _expect(
        history == reference,
        case,
        f"store route, new tensors unfilled {history} != in-memory route, filled {reference}",
    )
    _expect(held == reference, case, f"resident route {held} != in-memory route {reference}")
    a, b, c = stored.state_dict(), memory.state_dict(), resident.state_dict()
    _expect(
        all(torch.equal(a[k], b[k]) for k in a), case, "store and in-memory training end with other weights"
    )
    _expect(
        all(torch.equal(c[k], b[k]) for k in c),
        case,
        "resident and in-memory training end with other weights",
    )
    pose = _reset(stored).generate(case.batch(stored))
    _expect(torch.isfinite(pose).all(), case, "the model prepared from the store generates non-finite values")


def check_bf16_training(case: ModelCase) -> None:
    """Two steps from the store under bfloat16 autocast (CPU; CUDA's dtype rules enforced): finite losses."""
    _, history = _fit_two_steps(case, _store_view(case), amp=True)
    _expect(all(not _finite(h["train"]) for h in history), case, f"non-finite bf16 losses {history}")


class HostToDevice(TorchDispatchMode):
    """Records the operators that bring host data to another device: a copy of a CPU tensor there, or an
    operator with a CPU tensor of at least one dimension among its inputs and a result there (a 0-dim CPU
    tensor in arithmetic is read as a number, as a Python float is).

    Examples
    --------
    On a CPU-only machine the ``meta`` device stands in for the accelerator: the copy there is recorded,
    arithmetic on the host is not.

    >>> import torch
    >>> from beatlite.models.testing import HostToDevice
    >>> with HostToDevice() as copies:
    ...     on_device = torch.ones(3).to("meta")
    ...     on_host = torch.ones(3) + 1
    >>> copies.found
    ['aten._to_copy.default']
    """

    COPIES = ("_to_copy", "copy_", "_copy_from")

    def __init__(self) -> None:
        super().__init__()
        self.found: list[str] = []

    def __torch_dispatch__(self, func: Any, types: Any, args: tuple = (), kwargs: dict | None = None) -> Any:
        out = func(*args, **(kwargs or {}))
        inputs = [
            t for t in tree_leaves((args, kwargs)) if isinstance(t, torch.Tensor) and t.device.type == "cpu"
        ]
        elsewhere = any(isinstance(t, torch.Tensor) and t.device.type != "cpu" for t in tree_leaves(out))
        copy = func.overloadpacket.__name__ in self.COPIES
        if elsewhere and any(copy or t.dim() > 0 for t in inputs):
            self.found.append(str(func))
        return out


def check_no_host_reads(case: ModelCase) -> None:
    """The training pass (forward, losses, backward, and the discriminator's when adversarial) never reads a
    value of a tensor back to the host, nor copies host data to the device.

    Run on torch's ``meta`` device (shapes without data), where any read (``int(t)``, ``bool(t)``,
    ``t.item()``, ``t.cpu()``, indexing by a boolean mask) raises, and, for a second pass (a table copied to
    the device once, in the first, is set-up), under :class:`HostToDevice`. On a
    GPU each would make the host wait for the device at every step, so no step could be queued ahead of the
    device or captured in a CUDA graph (``TrainConfig.compile="reduce-overhead"``).
    """
    model = _prepared(case, case.build())
    batch = {k: v.to("meta") for k, v in case.batch(model).items()}
    model.to("meta")
    copies = HostToDevice()
    try:
        for mode in (contextlib.nullcontext(), copies):  # the second pass: what every step does (no set-up)
            with mode:
                losses = _train_losses(model, batch)
                if model.trainable:
                    losses["total"].backward()
                if model.discriminator is not None:
                    model.discriminator_losses(batch, model(batch))["total"].backward()
    except (RuntimeError, NotImplementedError) as error:
        raise AssertionError(
            f"{case.cls.__name__} ({case.preset}): the training pass fails on the meta device (it reads the "
            f"device, or mixes devices): {error}"
        ) from error
    if model.trainable:  # (an untrained baseline takes no training step)
        _expect(
            not copies.found, case, f"the training pass copies host data to the device: {copies.found[:5]}"
        )


def check_compiled_training(case: ModelCase) -> None:
    """Two steps from the store with the step through ``torch.compile`` (``TrainConfig.compile="aot_eager"``:
    traced into graphs and run by the same kernels) give the losses of two eager steps (to float32
    reassociation, rel 1e-4)."""
    view = _store_view(case)
    _, eager = _fit_two_steps(case, view, amp=False)
    _, compiled = _fit_two_steps(case, view, amp=False, compile="aot_eager")
    for a, b in zip(eager, compiled, strict=True):
        close = a["train"].keys() == b["train"].keys() and all(
            math.isclose(a["train"][k], b["train"][k], rel_tol=1e-4, abs_tol=1e-9) for k in a["train"]
        )
        _expect(close, case, f"compiled training losses {b['train']} != eager {a['train']}")


#: Contract checks on fake batches: name -> check(case).
CHECKS = {
    "shapes": check_shapes,
    "gradients": check_gradients,
    "determinism": check_determinism,
    "generate_modes": check_generate_modes,
    "checkpoint": check_checkpoint,
    "no_host_reads": check_no_host_reads,
}
#: Contract checks that train from a window store (they need ``ModelCase.train`` and ``.reference``).
STORE_CHECKS = {
    "store_training": check_store_training,
    "bf16_training": check_bf16_training,
    "compiled_training": check_compiled_training,
}


def model_case(model: str | type, folder: str | Path, *, preset: str = "tiny", train: Any = None,
               reference: Any = None, **overrides: Any) -> ModelCase:  # fmt: skip
    """The :class:`ModelCase` of a registry name or model class (``vocab_size`` from ``train``'s vocabulary).

    Parameters
    ----------
    model : str or GestureModel subclass
    folder : str or Path
        Scratch folder for checkpoints.
    preset : str
    train, reference : optional
        A small window store's train view and the same windows in memory (:func:`check_model`).
    **overrides
        Config overrides.

    Examples
    --------
    >>> from beatlite.models.testing import model_case
    >>> case = model_case("camn", "unused", use_audio=False)
    >>> case.cls.__name__, case.preset, case.overrides
    ('CaMN', 'tiny', {'use_audio': False})
    """
    from beatlite.models import model_class

    cls = model_class(model) if isinstance(model, str) else model
    fields = {f.name for f in dataclasses.fields(cls.config_class)}
    if train is not None and "vocab_size" in fields:
        overrides = {"vocab_size": len(train.vocab), **overrides}
    return ModelCase(cls, preset, dict(overrides), Path(folder), train, reference)


def check_model(model: str | type, folder: str | Path, *, train: Any = None, reference: Any = None,
                preset: str = "tiny", **overrides: Any) -> list[str]:  # fmt: skip
    """Run the model contract suite on a registered model (by name) or a model class.

    In the spirit of scikit-learn's ``check_estimator``: every check builds a fresh model and raises
    ``AssertionError`` naming the model and the broken rule.

    Parameters
    ----------
    model : str or GestureModel subclass
    folder : str or Path
        Scratch folder for the checkpoint files.
    train : StoreWindows, optional
        A (small) train split of a window store: also runs :data:`STORE_CHECKS`.
    reference : Windows or dict of ndarray, optional
        The same windows in memory (``build_windows`` with ``train``'s statistics and vocabulary);
        required with ``train``.
    preset : str
        Preset to build (``"tiny"``).
    **overrides
        Config overrides.

    Returns
    -------
    list of str
        The names of the checks run (all passed).

    Examples
    --------
    The mean-pose baseline passes every check that needs no window store (each raises ``AssertionError``
    naming the model and the broken rule; :func:`check_shapes` shows one):

    >>> import tempfile
    >>> from beatlite.models.testing import check_model
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     check_model("mean_pose", folder)
    ['shapes', 'gradients', 'determinism', 'generate_modes', 'checkpoint', 'no_host_reads']
    """
    if (train is None) != (reference is None):
        raise ValueError(
            "check_model: give both train (a store view) and reference (the same windows in memory)"
        )
    case = model_case(model, folder, preset=preset, train=train, reference=reference, **overrides)
    checks = {**CHECKS, **(STORE_CHECKS if train is not None else {})}
    for check in checks.values():
        check(case)
    return list(checks)
