"""The training loop :func:`fit`, shared by every :class:`~beatlite.models.base.GestureModel`.

Taught in notebooks/05_camn.ipynb, section 4 (training).
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import torch

from beatlite import paths
from beatlite.data.normalize import Normalizers
from beatlite.data.resident import ResidentWindows, fits_on_device
from beatlite.models.base import GestureModel
from beatlite.models.layers import use_frame_matmul
from beatlite.notebook import progress
from beatlite.train.checkpoint import FORMAT, load_checkpoint, save_checkpoint
from beatlite.train.config import COMPILE_BACKENDS, COMPILE_MODES, TrainConfig
from beatlite.train.distributed import (
    distributed_rank,
    local_device,
    rng_states,
    sum_over_processes,
    sync_on_last,
    wait_for_all,
    wrap_for_ddp,
)

PLAN_FIELDS = ("batch_size", "seed", "windows_per_epoch")
"""The :class:`TrainConfig` fields that decide an epoch's batch plan (which windows each step trains on): a
mid-epoch checkpoint resumes only with the same values (micro-batches and processes split a step, not the plan)."""

TENSOR_KEYS = ("pose", "dirvec", "audio", "mel", "face", "word", "emotion", "semantic", "speaker")
"""Window keys converted to tensors for the models (others, e.g. ``"take"``, are ignored)."""


class ResumeError(ValueError):
    """A checkpoint cannot be resumed by this run: other data, another model config, or (inside an epoch)
    other :data:`PLAN_FIELDS`. The message names the checkpoint and what differs.

    Examples
    --------
    >>> isinstance(ResumeError("fit: cannot resume from run.pt: batch_size 32 -> 64"), ValueError)
    True
    """


@dataclasses.dataclass
class FitResult:
    """What :func:`fit` returns.

    Attributes
    ----------
    history : list of dict
        One entry per completed epoch: ``{"epoch": e, "train": {loss: mean}, "val": {loss: mean}}``
        (``"val"`` is ``{}`` without validation windows), plus ``"val_score"`` with a ``val_score``. With
        ``TrainConfig.val_every`` also ``"validations"``: the epoch's validations in order,
        ``[{"step": global step, "val": {...}, "val_score": score}, ...]`` (possibly none); ``"val"`` and
        ``"val_score"`` are then the last of them (``{}`` and absent when the epoch had none).
    checkpoint : Path or None
        The checkpoint written after the last epoch (with ``epochs=0``, of the initial weights).
    fingerprint : str
        :func:`data_fingerprint` of the training windows.
    best_epoch : int or None
        With ``val_score``: the epoch whose weights scored lowest (the model is left with the
        *last* epoch's weights; the checkpoint holds both, :func:`export_checkpoint` exports the best).
    best_score : float or None
        That epoch's score.
    best_step : int or None
        With ``TrainConfig.val_every``: the global optimiser step (1-based, counted over the whole run) of
        the best-scoring validation, which happened in ``best_epoch``; ``None`` for per-epoch validation.
    """

    history: list[dict[str, Any]]
    checkpoint: Path | None
    fingerprint: str
    best_epoch: int | None = None
    best_score: float | None = None
    best_step: int | None = None


def as_arrays(windows: Any) -> Mapping[str, np.ndarray]:
    """The numpy dict of a window set.

    A Mapping itself, an object's ``.arrays`` Mapping, or a mapping-like object with
    ``keys()`` and ``[key]`` (a :class:`beatlite.data.windows.Windows` in windowed mode).

    Examples
    --------
    >>> windows = {"pose": np.zeros((2, 34, 141), np.float32)}
    >>> as_arrays(windows) is windows
    True
    >>> class Holder:
    ...     arrays = windows
    >>> as_arrays(Holder()) is windows
    True
    """
    if isinstance(windows, Mapping):
        return windows
    arrays = getattr(windows, "arrays", None)
    if isinstance(arrays, Mapping):
        return arrays
    if callable(getattr(windows, "keys", None)) and hasattr(windows, "__getitem__"):
        if getattr(windows, "whole_takes", False):
            raise TypeError(
                "windows: whole-take items have different lengths; build windows with whole_takes=False"
            )
        return {k: windows[k] for k in windows.keys()}
    raise TypeError(
        f"windows must be a dict of arrays (or have an .arrays dict), got {type(windows).__name__}"
    )


def data_fingerprint(windows: Any) -> str:
    """A short hash identifying a window set (shapes, dtypes and a sample of values).

    Uses the object's ``fingerprint`` attribute (``Windows`` and store views have one) when it has one;
    otherwise hashes, per key in sorted order, the name, shape, dtype and every
    ``max(1, N // 16)``-th window's bytes.

    Returns
    -------
    str
        16 hexadecimal characters.

    Examples
    --------
    With 8 windows every window is hashed (``8 // 16`` rounds up to a step of 1): a copy has the same
    fingerprint, one changed value in the last window gives another.

    >>> from beatlite.models.testing import fake_windows
    >>> windows = fake_windows(8)
    >>> copy = {k: v.copy() for k, v in windows.items()}
    >>> data_fingerprint(copy) == data_fingerprint(windows), len(data_fingerprint(windows))
    (True, 16)
    >>> copy["pose"][7, 0, 0] += 1.0
    >>> data_fingerprint(copy) == data_fingerprint(windows)
    False
    """
    fp = getattr(windows, "fingerprint", None)
    if isinstance(fp, str) and fp:
        return fp
    arrays = as_arrays(windows)
    h = hashlib.sha256()
    for key in sorted(arrays):
        a = np.asarray(arrays[key])
        h.update(f"{key}|{a.shape}|{a.dtype}|".encode())
        if a.dtype.kind in "biuf" and a.ndim >= 1 and a.shape[0]:
            h.update(np.ascontiguousarray(a[:: max(1, a.shape[0] // 16)]).tobytes())
    return h.hexdigest()[:16]


def _n_windows(arrays: Mapping[str, np.ndarray], keys: tuple[str, ...], who: str) -> int:
    sizes = {k: int(np.shape(arrays[k])[0]) for k in keys}
    if len(set(sizes.values())) != 1:
        raise ValueError(f"{who}: window arrays have different lengths N: {sizes}")
    n = next(iter(sizes.values()))
    if n == 0:
        raise ValueError(f"{who}: no windows")
    return n


def _is_store_view(windows: Any) -> bool:
    """Whether ``windows`` is a window store view (a ``StoreWindows``: read with ``batch(indices, keys=)``)."""
    return hasattr(windows, "store") and callable(getattr(windows, "batch", None))


def _batch(
    arrays: Mapping[str, np.ndarray], keys: tuple[str, ...], idx: np.ndarray | slice, device: Any = None
) -> dict[str, torch.Tensor]:
    out = {}
    for k in keys:
        a = np.asarray(arrays[k])[idx]
        t = torch.from_numpy(np.ascontiguousarray(a.astype(np.int64 if a.dtype.kind in "iu" else np.float32)))
        out[k] = t if device is None else t.to(device, non_blocking=True)
    return out


def model_device(model: torch.nn.Module) -> torch.device:
    """The device of a model's parameters (or buffers); the CPU for a model without either.

    Examples
    --------
    >>> model_device(torch.nn.Linear(2, 3)), model_device(torch.nn.ReLU())
    (device(type='cpu'), device(type='cpu'))
    """
    for tensor in (*model.parameters(), *model.buffers()):
        return tensor.device
    return torch.device("cpu")


def model_keys(model: GestureModel) -> tuple[str, ...]:
    """The batch keys ``model`` reads in training and evaluation (its ``batch_keys``), in contract order
    (:data:`TENSOR_KEYS`).

    Examples
    --------
    The S2G-style baseline reads the seed pose and the mel spectrogram, Seq2Seq the seed pose and the words:

    >>> model_keys(GestureModel.from_config({"name": "s2g", "preset": "tiny"}))
    ('pose', 'mel')
    >>> model_keys(GestureModel.from_config({"name": "seq2seq", "preset": "tiny"}))
    ('pose', 'word')
    """
    needed = set(type(model).batch_keys(model.config))
    return tuple(k for k in TENSOR_KEYS if k in needed)


def _needed_keys(model: GestureModel, windows: Any, who: str) -> tuple[str, ...]:
    """:func:`model_keys`, after checking ``windows`` has them all (``KeyError`` naming the missing ones)."""
    keys = model_keys(model)
    have = set(windows.keys())
    missing = sorted(set(keys) - have)
    if missing:
        raise KeyError(
            f"{who}: windows lack {missing} needed by {type(model).__name__} (have {sorted(have)})"
        )
    return keys


def configure_torch(seed: int, threads: int | None, deterministic: bool = True, device: Any = "cpu") -> None:
    """Seed torch, set deterministic mode for ``device`` (:func:`set_deterministic`) and the CPU thread count.

    Parameters
    ----------
    seed : int
        ``torch.manual_seed(seed)``.
    threads : int or None
        ``torch.set_num_threads``; ``None`` = :func:`beatlite.paths.n_threads` (``$BEATLITE_THREADS``).
    deterministic : bool
    device : torch.device or str
        Where the model trains (see :func:`set_deterministic`).

    Examples
    --------
    The draws after it are those after ``torch.manual_seed(seed)``:

    >>> configure_torch(7, None)
    >>> first = torch.rand(3)
    >>> _ = torch.manual_seed(7)
    >>> bool(torch.equal(first, torch.rand(3))), torch.get_num_threads() == paths.n_threads()
    (True, True)
    """
    torch.manual_seed(seed)
    set_deterministic(deterministic, device)
    torch.set_num_threads(threads if threads is not None else paths.n_threads())


def set_deterministic(deterministic: bool, device: Any = "cpu") -> None:
    """``torch.use_deterministic_algorithms(deterministic)``, and on CUDA no filling of new tensors.

    Deterministic mode also fills every new tensor (NaN, the integer maximum) so that a read of memory never
    written shows (``torch.utils.deterministic.fill_uninitialized_memory``); torch documents turning that off
    for a program that reads no such memory: "and still be deterministic". On CUDA each fill is a kernel launch
    (2,408 per HA2G paper-preset step at batch 64 on an H200: README, "Using real BEAT"), so there the filling
    is turned off (process-wide, as the mode is). On other devices it is torch's default (on), also after a CUDA
    run in the same process: a fill is a memset on the CPU, and it keeps guarding the tests. Every registered
    model trains to the same bits either way (:func:`beatlite.models.testing.check_store_training`).

    Parameters
    ----------
    deterministic : bool
    device : torch.device or str
        Where the model trains: ``"cuda"`` (any index) turns the filling off, any other device on.

    Examples
    --------
    >>> set_deterministic(True, "cpu")
    >>> torch.are_deterministic_algorithms_enabled(), torch.utils.deterministic.fill_uninitialized_memory
    (True, True)
    """
    import os

    # deterministic cuBLAS needs a fixed workspace; it must be set before CUDA's first matrix product
    os.environ.setdefault("CUBLAS_WORKSPACE_CONFIG", ":4096:8")
    torch.use_deterministic_algorithms(deterministic)
    torch.utils.deterministic.fill_uninitialized_memory = torch.device(device).type != "cuda"


def _mean_losses(sums: Mapping[str, Any], n: int) -> dict[str, float]:
    return {k: v / max(n, 1) for k, v in _floats(sums).items()}


def _floats(sums: Mapping[str, Any]) -> dict[str, float]:
    """Loss sums as Python floats (one device-to-host copy per key, where the sums are read)."""
    return {k: float(v) for k, v in sums.items()}


def _accumulate(
    sums: dict[str, Any], losses: Mapping[str, torch.Tensor], weight: int, prefix: str = ""
) -> None:
    """Add ``weight * loss`` to ``sums`` as float64 tensors on the losses' device: no host copy per step
    (a float per loss would wait for the device every step); the same float64 sums as Python floats."""
    for k, v in losses.items():
        sums[prefix + k] = sums.get(prefix + k, 0.0) + v.detach().double() * weight


def _window_reader(
    model: GestureModel, windows: Any, who: str
) -> tuple[int, Callable[[np.ndarray], dict[str, torch.Tensor]]]:
    """``(n, read)``: the number of ``windows`` and ``read(idx)``, the batch of windows ``idx`` on the model's
    device. ``KeyError`` / ``ValueError`` naming ``who`` when they lack a key ``model`` reads or (in memory) hold
    arrays of different lengths."""
    device = model_device(model)
    if isinstance(windows, ResidentWindows):
        _needed_keys(model, dict.fromkeys(windows.keys), who)
        return len(windows), lambda idx: windows.batch(torch.from_numpy(idx).to(windows.device))
    if _is_store_view(windows):
        keys = _needed_keys(model, windows, who)
        return len(windows), lambda idx: _batch(windows.batch(idx, keys=keys), keys, slice(None), device)
    arrays = as_arrays(windows)
    keys = _needed_keys(model, arrays, who)
    return _n_windows(arrays, keys, who), lambda idx: _batch(arrays, keys, idx, device)


@torch.no_grad()
def evaluate_losses(
    model: GestureModel, windows: Any, *, epoch: int, batch_size: int = 64
) -> dict[str, float]:
    """Mean of ``model.losses`` over ``windows`` in eval mode (weighted by batch size).

    ``windows``: in-memory windows, a window store view read batch by batch (only the model's keys), or
    :class:`~beatlite.data.resident.ResidentWindows` on the model's device.

    Returns
    -------
    dict of str -> float
        Each of ``model.losses``' keys (``"total"`` among them): its mean over the N windows.

    Examples
    --------
    A mean weighted by batch size does not depend on how the 5 windows are batched (eval mode: no dropout,
    BatchNorm's running statistics):

    >>> from beatlite.models.testing import fake_windows
    >>> _ = torch.manual_seed(0)
    >>> model = GestureModel.from_config({"name": "s2g", "preset": "tiny"})
    >>> windows = fake_windows(5)
    >>> by_2, at_once = (evaluate_losses(model, windows, epoch=0, batch_size=b) for b in (2, 64))
    >>> sorted(by_2), bool(np.isclose(by_2["total"], at_once["total"], rtol=1e-5))
    (['adv', 'rec', 'total'], True)
    """
    n, read = _window_reader(model, windows, "evaluate_losses")
    was_training = model.training
    model.eval()
    sums: dict[str, Any] = {}
    try:
        for start in range(0, n, batch_size):
            idx = np.arange(start, min(n, start + batch_size))
            batch = read(idx)
            _accumulate(sums, model.losses(batch, model(batch), epoch=epoch), len(idx))
    finally:
        model.train(was_training)
    return _mean_losses(sums, n)


def fit(
    model: GestureModel,
    train_windows: Any,
    config: TrainConfig,
    val_windows: Any = None,
    *,
    meta: Mapping[str, Any] | None = None,
    val_score: Callable[[GestureModel], float] | None = None,
) -> FitResult:
    """Train ``model`` on window batches (in place) and checkpoint it after every epoch.

    Parameters
    ----------
    model : GestureModel
        Any model of :mod:`beatlite.models`. Untrained baselines (no generator
        parameters) only get :meth:`~GestureModel.prepare` and a checkpoint.
    train_windows : dict of str -> ndarray, ``Windows`` or ``StoreWindows``
        Window arrays as :func:`beatlite.data.windows.build_windows` makes them (N windows each), or a
        window store view (:meth:`beatlite.data.store.WindowStore.windows`) read at batch time; only the
        model's :meth:`~beatlite.models.base.GestureModel.batch_keys` are read (a ``KeyError`` names
        the missing ones). :meth:`~beatlite.models.base.GestureModel.prepare` gets the same window set.
    config : TrainConfig
        Epochs, batch size, learning rates, seed, threads, checkpoint path, resume, validation interval.
    val_windows : same type as ``train_windows``, optional
        Validation windows: their mean losses are recorded after every epoch (or every
        ``config.val_every`` optimiser steps, see Notes).
    meta : mapping, optional
        Stored verbatim in the checkpoint (e.g. the train split's
        :meth:`~beatlite.data.normalize.Normalizers.to_meta` needed by :func:`beatlite.train.generate`).
    val_score : callable, optional
        ``val_score(model) -> float``, lower is better, called in eval mode after every epoch
        (e.g. :func:`beatlite.train.testset.fgd_scorer`: FGD on the validation takes, the
        reference's choice of its best checkpoint). Recorded as ``history[e]["val_score"]``; the
        lowest-scoring epoch's weights are kept in the checkpoint as ``"best"`` (or every
        ``config.val_every`` steps: the lowest-scoring step's, see Notes).

    Returns
    -------
    FitResult

    Raises
    ------
    KeyError
        ``train_windows`` or ``val_windows`` lack a key the model reads (before any step).
    ValueError
        Before any step: arrays of different lengths, a batch or an epoch's windows too small to fill a step
        (:func:`check_batch_split`, :func:`check_window_count`), a model inductor cannot compile
        (:func:`check_compilable`). (Non-finite windows are not refused: the losses and weights become NaN and
        the checkpoint then does not load.)
    ResumeError
        ``config.resume`` from a checkpoint of other data, another model config or (mid-epoch) another plan.

    Notes
    -----
    Per step: the forward pass, then (when ``model.adversarial_active(epoch)``) a
    discriminator step on ``model.discriminator_losses`` with its own Adam at
    ``d_lr_weight * lr``, then the generator step on ``model.losses(...)["total"]``.
    Both clip the gradient norm at ``grad_clip``. Shuffling uses
    ``numpy.random.default_rng([seed, epoch])`` (an epoch keeps the first
    ``windows_per_epoch`` windows of its shuffle when that is set) and the torch RNG state is checkpointed,
    so ``resume=True`` reproduces the losses of an uninterrupted run exactly.

    With ``config.val_every = N`` the validation (losses, ``val_score``, best weights) runs after the
    optimiser steps N, 2N, ... of the whole run (steps of the earlier epochs plus the step in this one;
    checkpoints store the count, so resuming, also from a mid-epoch checkpoint, validates at the same steps
    with the same numbers), not at epoch ends, except that the run ends with one more validation when its
    last step was not one (a finished run extended by resuming with more ``epochs`` keeps it). Under
    ``torchrun`` process 0 validates while the others go on to the next step (they wait for it in its
    gradient reduction).

    Examples
    --------
    Two epochs of the tiny S2G-style model on 8 random windows, then the same run interrupted after one epoch
    and resumed from its checkpoint: the resumed run's losses equal the uninterrupted run's to the bit.

    >>> import tempfile
    >>> from beatlite.models.testing import fake_windows
    >>> def tiny_s2g():
    ...     _ = torch.manual_seed(0)  # the same initial weights each time
    ...     return GestureModel.from_config({"name": "s2g", "preset": "tiny"})
    >>> train, val = fake_windows(8, seed=0), fake_windows(4, seed=1)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     config = TrainConfig(epochs=2, batch_size=4, progress=False, checkpoint=Path(tmp) / "a.pt")
    ...     result = fit(tiny_s2g(), train, config, val)
    ...     saved = load_checkpoint(result.checkpoint)
    ...     half = TrainConfig(epochs=1, batch_size=4, progress=False, checkpoint=Path(tmp) / "b.pt")
    ...     _ = fit(tiny_s2g(), train, half, val)
    ...     again = dataclasses.replace(half, epochs=2, resume=True)
    ...     resumed = fit(tiny_s2g(), train, again, val)
    >>> [entry["epoch"] for entry in result.history], sorted(result.history[-1]["val"])
    ([0, 1], ['adv', 'rec', 'total'])
    >>> saved["epoch"], saved["fingerprint"] == result.fingerprint == data_fingerprint(train)
    (2, True)
    >>> resumed.history == result.history
    True
    """
    if not isinstance(model, GestureModel):
        raise TypeError(f"fit: model must be a GestureModel, got {type(model).__name__}")
    if not isinstance(config, TrainConfig):
        raise TypeError(f"fit: config must be a TrainConfig, got {type(config).__name__}")

    check_compilable(type(model), config.compile)  # before any work
    data = _Data.of(model, train_windows)
    if val_windows is not None:  # before any step, not at the first validation after an epoch
        _window_reader(model, val_windows, "fit: val_windows")  # what evaluate_losses finds after an epoch
    configure_torch(config.seed, config.threads, config.deterministic, config.torch_device())
    if config.no_adv_epochs is not None and hasattr(model.config, "no_adv_epochs"):
        model.config.no_adv_epochs = int(config.no_adv_epochs)
    model.prepare(data.arrays if data.store is None else data.store, _normalizers_of(train_windows, meta))
    run = _Run(model, config, data.fingerprint, dict(meta or {}))
    if run.g_opt is not None:  # (an untrained baseline takes no step)
        check_window_count(data.n, config, run.world)
    resumed = False
    if config.resume:
        wait_for_all(run.world)  # every process reads the checkpoint process 0 wrote last, not an older one
        if run.path is not None and run.path.is_file():
            run.resume(data)
            resumed = True
    run.wrap()
    if run.g_opt is None:  # untrained baseline: nothing to optimise
        run.save(config.epochs)
        return run.result()
    data.hold(config.data_on_device, run.device)
    if data.resident is not None and val_windows is not None and _is_store_view(val_windows):
        val_windows = ResidentWindows(val_windows, data.keys, run.device)
    run.val_windows, run.val_score = val_windows, val_score
    show = config.progress and run.rank == 0  # under torchrun, process 0 logs, scores and saves
    bar = progress(range(run.start_epoch, config.epochs), disable=not show, desc=model.name, unit="epoch")
    with bar:  # (closed before an error is printed after it)
        for epoch in bar:
            entry: dict[str, Any] = {"epoch": epoch, "train": run.train_epoch(data, epoch)}
            check_diverged(model.name, f"the mean training losses of epoch {epoch}", entry["train"].items())
            entry.update(run.epoch_validation(epoch))
            run.history.append(entry)
            bar.set_postfix(_shown_losses(entry))
            run.save(epoch + 1)
    if config.epochs == 0 and not resumed:  # no epoch: the initial weights' checkpoint (as a baseline's)
        run.save(0)
    return run.result()


def _backward(totals: list[torch.Tensor], ddp: Any) -> None:
    """Backpropagate the micro-batch losses of one optimiser step.

    One backward per micro-batch, so that the gradients add up micro-batch by micro-batch (the sums
    of one process taking them in turn equal, to the bit, DDP's reduction of one micro-batch per
    process); under DDP with several micro-batches in this process, one backward over their sum (DDP
    reduces once per backward, after the forward outside ``no_sync``).
    """
    if ddp is not None and len(totals) > 1:
        torch.stack(totals).sum().backward()
        return
    for total in totals:
        total.backward()


def _normalizers_of(windows: Any, meta: Mapping[str, Any] | None) -> Normalizers | None:
    """The train split's normalisers: the windows' own (a ``Windows``), else the ones in ``meta``."""
    norms = getattr(windows, "normalizers", None)
    if isinstance(norms, Normalizers):
        return norms
    return Normalizers.in_meta(meta)


def check_diverged(name: str, what: str, values: Any, world: int = 1) -> None:
    """Raise ``FloatingPointError`` when a value of ``values`` (``(name, float or tensor)`` pairs) is not finite:
    training diverged (too high a learning rate, bf16 overflow, or NaN in the data), and :func:`fit` stops before
    writing a checkpoint that :func:`~beatlite.train.checkpoint.load_checkpoint` would refuse (the last one stays).
    With ``world`` > 1 it is a collective (every process calls it) and every process raises when one would, so
    that none waits for the others in the next one (their values may differ: BatchNorm's running statistics).

    Examples
    --------
    >>> check_diverged("camn", "the mean training losses of epoch 3", {"rec": 0.4, "total": 0.5}.items())
    >>> check_diverged("camn", "the mean training losses of epoch 3", {"rec": float("nan")}.items())
    Traceback (most recent call last):
    ...
    FloatingPointError: fit: camn diverged: the mean training losses of epoch 3 are not finite (rec); no checkpoint of it was written (the last one stays). Lower the learning rate (fit --lr), train in fp32 (--precision fp32), or look for NaN or inf in the training windows
    """
    items = list(values)
    tensors = [v for _, v in items if isinstance(v, torch.Tensor)]  # (one device read for all of them)
    finite = iter(torch.stack([torch.isfinite(t).all() for t in tensors]).tolist() if tensors else [])
    bad = [k for k, v in items if not (next(finite) if isinstance(v, torch.Tensor) else math.isfinite(v))]
    if world > 1 and sum_over_processes({"bad": float(bool(bad))}, world)["bad"] and not bad:
        bad = ["on another process"]
    if bad:
        raise FloatingPointError(
            f"fit: {name} diverged: {what} are not finite ({', '.join(bad[:5])}); no checkpoint of it was written "
            "(the last one stays). Lower the learning rate (fit --lr), train in fp32 (--precision fp32), or look "
            "for NaN or inf in the training windows"
        )


def _shown_losses(entry: dict[str, Any]) -> dict[str, str]:
    """The progress bar's losses: the model's first unweighted term (train, and val when there is one),
    as the history and the notebooks' summaries print it, not the weighted total."""
    main = next((k for k in entry["train"] if k != "total" and not k.startswith("D_")), "total")
    shown = {main: entry["train"].get(main, float("nan"))}
    if main in entry["val"]:
        shown[f"val_{main}"] = entry["val"][main]
    return {k: f"{v:.4g}" for k, v in shown.items()}


@dataclasses.dataclass(eq=False)
class _Data:
    """The training windows as the loop reads them: in-memory arrays, or a window store read at batch time."""

    arrays: Mapping[str, np.ndarray] | None
    keys: tuple[str, ...]
    n: int
    fingerprint: str
    store: Any = None
    resident: ResidentWindows | None = None

    def hold(self, mode: str, device: Any) -> None:
        """Hold a store view's streams on ``device`` as ``TrainConfig.data_on_device`` says (``mode``)."""
        if self.store is None or mode == "never":
            return
        if mode == "always" or fits_on_device(self.store, self.keys, device):
            self.resident = ResidentWindows(self.store, self.keys, device)

    @classmethod
    def of(cls, model: GestureModel, windows: Any) -> _Data:
        if _is_store_view(windows):  # read at batch time: only the model's keys
            keys = _needed_keys(model, windows, "fit")
            return cls(None, keys, len(windows), data_fingerprint(windows), windows)
        arrays = as_arrays(windows)
        keys = _needed_keys(model, arrays, "fit")
        return cls(arrays, keys, _n_windows(arrays, keys, "fit"), data_fingerprint(windows))

    def batches(self, steps: list[list[np.ndarray]], device: Any, workers: int) -> Any:
        """For every step, its micro-batches as (tensor dict, windows) on ``device``.

        Resident streams (:meth:`hold`) are gathered on the device; otherwise a window store is read by a ``torch.utils.data.DataLoader`` (``workers`` processes, pinned
        memory on CUDA) in exactly this order; in-memory arrays are indexed here. The loader draws its
        workers' base seed from its own generator, not torch's global one, which the models' dropout and
        sampling use: both routes then take the same steps.
        """
        if self.store is None:
            for step in steps:
                yield [(_batch(self.arrays, self.keys, m, device), len(m)) for m in step]
            return
        if self.resident is not None:  # the epoch's indices copied once, every batch gathered on the device
            flat = [m for step in steps for m in step]
            order = torch.from_numpy(np.concatenate(flat) if flat else np.zeros(0, np.int64)).to(device)
            at = 0
            for step in steps:
                micro = []
                for m in step:
                    micro.append((self.resident.batch(order[at : at + len(m)]), len(m)))
                    at += len(m)
                yield micro
            return
        from torch.utils.data import DataLoader

        from beatlite.data.torch_dataset import WindowDataset

        flat = [m for step in steps for m in step]
        pin = getattr(device, "type", "cpu") == "cuda"
        loader = DataLoader(WindowDataset(self.store, self.keys), batch_size=None, sampler=flat,
                            num_workers=workers, pin_memory=pin, generator=torch.Generator())  # fmt: skip
        batches = iter(loader)
        for step in steps:
            yield [
                ({k: v.to(device, non_blocking=True) for k, v in next(batches).items()}, len(m)) for m in step
            ]


def _adam(params: list[torch.nn.Parameter], lr: float, betas: tuple[float, float]) -> torch.optim.Adam | None:
    """Adam over ``params`` (``None`` without any): fused (one kernel for all parameters) when they are on
    CUDA; torch's default elsewhere, so float32 training on the CPU stays bitwise what it was."""
    if not params:
        return None
    fused = all(p.is_cuda for p in params) or None
    return torch.optim.Adam(params, lr=lr, betas=betas, fused=fused)


def check_compilable(model_class: type[GestureModel], mode: str | None) -> None:
    """Raise ``ValueError`` when :attr:`TrainConfig.compile` ``mode`` uses inductor and the model class says
    inductor cannot compile it (:attr:`beatlite.models.base.GestureModel.inductor_failure`).

    Examples
    --------
    A model class whose inductor compilation is known to fail may train eagerly or traced, not with inductor:

    >>> class Fragile(GestureModel):
    ...     name = "fragile"
    ...     inductor_failure = "a kernel inductor miscompiles"
    >>> check_compilable(Fragile, None), check_compilable(Fragile, "aot_eager")
    (None, None)
    >>> check_compilable(Fragile, "default")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: fit: fragile cannot be compiled with inductor (TrainConfig.compile='default', ...): a kernel inductor miscompiles; ...
    """
    if mode in COMPILE_MODES and model_class.inductor_failure is not None:
        raise ValueError(
            f"fit: {model_class.name} cannot be compiled with inductor (TrainConfig.compile={mode!r}, "
            f"fit --compile {mode}): {model_class.inductor_failure}; train it eagerly (compile=None, no "
            f"--compile) or traced without inductor ('aot_eager')"
        )


def check_batch_split(config: TrainConfig, world: int) -> None:
    """Raise ``ValueError`` when ``config.batch_size`` split into ``max(micro_batches, world)`` micro-batches (``world``:
    the processes under ``torchrun``) leaves fewer than 2 windows in one: BatchNorm needs 2, so every step would be
    skipped and nothing trained. The batch size is the global one, split over the processes.

    Examples
    --------
    >>> check_batch_split(TrainConfig(batch_size=8), world=4)  # 4 processes, 2 windows each
    >>> check_batch_split(TrainConfig(batch_size=4), world=4)
    Traceback (most recent call last):
    ...
    ValueError: fit: batch_size 4 split into 4 micro-batches (4 processes, micro_batches=1) leaves fewer than 2 windows in one (BatchNorm needs 2: no step would train); batch_size must be >= 8 (it is the global batch, split over the processes)
    """
    parts = max(config.micro_batches, world)
    if config.batch_size < 2 * parts:
        raise ValueError(
            f"fit: batch_size {config.batch_size} split into {parts} micro-batches ({world} process"
            f"{'es' if world > 1 else ''}, micro_batches={config.micro_batches}) leaves fewer than 2 windows in "
            f"one (BatchNorm needs 2: no step would train); batch_size must be >= {2 * parts} (it is the global "
            "batch, split over the processes)"
        )


def check_window_count(n: int, config: TrainConfig, world: int) -> None:
    """Raise ``ValueError`` when an epoch's ``n`` training windows (at most ``config.windows_per_epoch``) cannot fill
    one step: each of its ``max(micro_batches, world)`` micro-batches needs 2 windows (BatchNorm), so every step
    would be skipped and nothing trained (:func:`check_batch_split` is the same for the batch size).

    Examples
    --------
    >>> check_window_count(2, TrainConfig(batch_size=8), world=1)
    >>> check_window_count(3, TrainConfig(batch_size=8, micro_batches=2), world=1)
    Traceback (most recent call last):
    ...
    ValueError: fit: 3 training windows per epoch fill no step: each of its 2 micro-batches needs 2 windows (BatchNorm), so nothing would train; give at least 4
    """
    parts = max(config.micro_batches, world)
    used = n if config.windows_per_epoch is None else min(n, config.windows_per_epoch)
    if used < 2 * parts:
        cut = f" (windows_per_epoch={config.windows_per_epoch} of {n})" if used < n else ""
        raise ValueError(
            f"fit: {used} training window{'s' if used != 1 else ''} per epoch{cut} fill{'s' if used == 1 else ''} no step: each of its "
            f"{parts} micro-batch{'es' if parts > 1 else ''} needs 2 windows (BatchNorm), so nothing would "
            f"train; give at least {2 * parts}"
        )


def _compiled(fn: Callable[..., Any], mode: str | None, device: torch.device) -> Callable[..., Any]:
    """``fn`` through ``torch.compile`` as :attr:`TrainConfig.compile` says (``fn`` itself for ``None``).

    On the CPU, inductor's modes run without its layout optimisation (the mode's other options kept): it
    stores 2-D convolutions' activations channels-last, and oneDNN's float32 gradient of a strided 1x1
    convolution on channels-last tensors corrupts memory in torch 2.13 (seen with 4 input channels, stride 2:
    a crash in HA2G's audio encoder; eager channels-last tensors crash the same way).
    """
    if mode is None:
        return fn
    if mode in COMPILE_BACKENDS:
        return torch.compile(fn, backend=mode)
    if device.type == "cpu":
        from torch._inductor import list_mode_options

        return torch.compile(fn, options={**list_mode_options(mode), "layout_optimization": False})
    return torch.compile(fn, mode=mode)


class _Run:
    """One training run's optimisers, history, best epoch and checkpoint (the state :func:`fit` resumes)."""

    def __init__(
        self, model: GestureModel, config: TrainConfig, fingerprint: str, meta: dict[str, Any]
    ) -> None:
        self.model, self.config, self.fingerprint, self.meta = model, config, fingerprint, meta
        self.rank, self.world = distributed_rank()
        if model.generator_parameters():  # before a step (an untrained baseline takes none)
            check_batch_split(config, self.world)
        # micro-batches per optimiser step, spread over the processes
        self.parts = max(config.micro_batches, self.world)
        self.device = local_device(config.torch_device())
        model.to(self.device)
        use_frame_matmul(model, config.frame_matmul(self.device))
        self.amp = bool(config.amp)
        self.lr = config.learning_rate
        self.g_params = model.generator_parameters()
        self.g_opt = _adam(self.g_params, self.lr, config.betas)
        self.d_opt = None
        if model.discriminator is not None:
            d_lr = self.lr * config.d_lr_weight
            self.d_opt = _adam(list(model.discriminator.parameters()), d_lr, config.betas)
        # under torchrun: DistributedDataParallel over the generator and the discriminator (see wrap)
        self.g_ddp: Any = None
        self.d_ddp: Any = None
        self.history: list[dict[str, Any]] = []
        self.start_epoch = 0
        self.partial: dict[str, Any] | None = None  # a mid-epoch checkpoint's epoch, step, sums, validations
        # {"epoch", "score", "state"} of the lowest val_score ("step" too with val_every)
        self.best: dict[str, Any] | None = None
        self.steps = 0  # optimiser steps done over the whole run (the global step of val_every)
        self.validations: list[dict[str, Any]] = []  # with val_every: this epoch's validations so far
        self.val_windows: Any = None
        self.val_score: Callable[[GestureModel], float] | None = None
        self.path = None if config.checkpoint is None else Path(config.checkpoint)
        check_compilable(type(model), config.compile)
        self._bind()

    def wrap(self) -> None:
        """Under ``torchrun``, build the DDP wrappers (after :meth:`resume`: they give every process process
        0's weights)."""
        if self.world > 1 and self.g_opt is not None:
            self.g_ddp, self.d_ddp = wrap_for_ddp(self.model, self.device)
        self._bind()

    def _bind(self) -> None:
        """The step's forward pass and losses: the model's (or its DDP wrappers'), compiled when
        ``config.compile`` says so."""
        mode, model, device = self.config.compile, self.model, self.device
        self.forward = _compiled(self.g_ddp or model, mode, device)
        self.losses = _compiled(model.losses, mode, device)
        self.d_losses = _compiled(self.d_ddp or model.discriminator_losses, mode, device)

    def resume(self, train: _Data) -> None:
        """Load the full checkpoint at :attr:`path` (same data and model config, or :class:`ResumeError`).

        A mid-epoch checkpoint also needs the same :data:`PLAN_FIELDS` (its step counts steps of that
        epoch's batch plan; another batch size or seed would train some windows twice and others never).
        A checkpoint written before the global step was stored counts ``train``'s steps per epoch instead.
        """
        data = load_checkpoint(self.path)
        if data.get("fingerprint") != self.fingerprint:
            raise ResumeError(
                f"fit: cannot resume from {self.path}: it was trained on data {data.get('fingerprint')!r}, "
                f"these windows are {self.fingerprint!r}"
            )
        if data["model"] != self.model.to_config():
            raise ResumeError(f"fit: cannot resume from {self.path}: model config differs ({data['model']})")
        stored = data.get("train_config") or {}
        changed = [
            f"{k} {stored[k]!r} -> {getattr(self.config, k)!r}"
            for k in PLAN_FIELDS
            if k in stored and stored[k] != getattr(self.config, k)
        ]
        if data.get("partial") is not None and changed:
            step = data["partial"]["step"]
            raise ResumeError(
                f"fit: cannot resume from {self.path}: it stopped at step {step} of epoch {data['epoch'] + 1}, "
                f"whose batches depend on {', '.join(PLAN_FIELDS)}; changed: {', '.join(changed)} "
                "(resume with the old values, or start a new run)"
            )
        self.model.load_state_dict(data["state"])  # load_state_dict copies onto the model's device
        for opt, key in ((self.g_opt, "optimizer"), (self.d_opt, "d_optimizer")):
            if opt is not None and data.get(key) is not None:
                opt.load_state_dict(data[key])
        states = data.get("rng_processes")
        if states is not None and len(states) == self.world:  # each process its own generator
            torch.set_rng_state(states[self.rank])
        elif data.get("rng") is not None:  # (written by one process, or by another number of them)
            torch.set_rng_state(data["rng"])
        self.history = list(data.get("history", []))
        self.start_epoch = int(data["epoch"])
        self.partial = data.get("partial")
        self.best = data.get("best")
        if "steps" in data:
            self.steps = int(data["steps"])
        else:  # written before the global step was stored: the epochs' steps, plus the partial epoch's
            in_epoch = 0 if self.partial is None else int(self.partial["step"])
            self.steps = self.start_epoch * len(self.plan(train, 0)[0]) + in_epoch

    def train_epoch(self, data: _Data, epoch: int) -> dict[str, float]:
        """One epoch of optimiser steps; returns the mean losses over its windows (over all processes).

        With ``val_every``, validates after every ``val_every``-th step of the run (:meth:`validate_step`),
        before a mid-epoch checkpoint of the same step.
        """
        model, config = self.model, self.config
        model.train()
        factor = config.lr_factor(epoch)
        for opt, base in ((self.g_opt, self.lr), (self.d_opt, self.lr * config.d_lr_weight)):
            for group in [] if opt is None else opt.param_groups:
                group["lr"] = base * factor
        steps, seen = self.plan(data, epoch)
        first, sums = self.position(epoch)
        every, val_every = config.checkpoint_every, config.val_every
        for k, batches in enumerate(data.batches(steps[first:], self.device, config.workers), start=first):
            self.step(batches, epoch, sums)
            self.steps += 1
            if val_every and self.steps % val_every == 0:
                self.validate_step(epoch)
            if every and (k + 1) % every == 0 and k + 1 < len(steps):
                # (a collective: every process calls it)
                total = sum_over_processes(_floats(sums), self.world)
                self.partial = {"epoch": epoch, "step": k + 1, "sums": total, "validations": self.validations}
                self.save(epoch)  # ``epoch`` epochs done, plus ``step`` steps of the next
                self.partial = None
        return _mean_losses(sum_over_processes(_floats(sums), self.world), seen)

    def plan(self, data: _Data, epoch: int) -> tuple[list[list[np.ndarray]], int]:
        """``epoch``'s optimiser steps (this process's micro-batches of each) and the windows they train on."""
        config = self.config
        order = np.random.default_rng([config.seed, epoch]).permutation(data.n)
        if config.windows_per_epoch is not None:
            order = order[: config.windows_per_epoch]
        steps, seen = [], 0
        for start in range(0, len(order), config.batch_size):
            idx = np.sort(order[start : start + config.batch_size])
            micro = [idx[m :: self.parts] for m in range(self.parts)]
            if min(len(m) for m in micro) < 2:  # BatchNorm needs 2 windows per micro-batch
                continue
            steps.append(micro[self.rank :: self.world])
            seen += len(idx)
        return steps, seen

    def position(self, epoch: int) -> tuple[int, dict[str, Any]]:
        """Where ``epoch`` starts: its first step and loss sums, 0 and none unless a mid-epoch checkpoint
        of it was resumed (then its step, and on process 0 the sums of all processes and the validations)."""
        first, sums, self.validations = 0, {}, []
        if self.partial is not None and self.partial["epoch"] == epoch:  # resuming inside this epoch
            first = int(self.partial["step"])
            if self.rank == 0:
                sums, self.validations = dict(self.partial["sums"]), list(self.partial.get("validations", []))
        self.partial = None
        return first, sums

    def step(
        self,
        batches: list[tuple[dict[str, torch.Tensor], int]],
        epoch: int,
        sums: dict[str, Any],
    ) -> None:
        """The discriminator step (when adversarial) then the generator step on one global batch.

        ``batches`` are this process's micro-batches (tensors, windows) of a global batch split into
        :attr:`parts`, each loss scaled by ``world / parts``: under ``torchrun`` DDP averages the gradients
        over the ``world`` processes, so every step sees the mean of the micro-batch gradients, whatever
        the process count (see :func:`_backward`).
        """
        model, config = self.model, self.config
        last = len(batches) - 1
        if self.config.compile is not None:  # a new iteration for CUDA graphs (outputs of the last one freed)
            torch.compiler.cudagraph_mark_step_begin()
        outs = []
        for i, (batch, _) in enumerate(batches):
            with sync_on_last(self.g_ddp, i == last), self._autocast():
                outs.append(self.forward(batch))
        if self.d_opt is not None and model.adversarial_active(epoch):
            self.d_opt.zero_grad(set_to_none=True)
            d_totals = []
            for i, ((batch, weight), out) in enumerate(zip(batches, outs, strict=True)):
                with sync_on_last(self.d_ddp, i == last), self._autocast():
                    d_losses = self.d_losses(batch, out)
                d_totals.append(d_losses["total"] * self.world / self.parts)
                _accumulate(sums, {k: v for k, v in d_losses.items() if k != "total"}, weight, "D_")
            _backward(d_totals, self.d_ddp)
            torch.nn.utils.clip_grad_norm_(model.discriminator.parameters(), config.grad_clip)
            self.d_opt.step()
        self.g_opt.zero_grad(set_to_none=True)
        totals = []
        for (batch, weight), out in zip(batches, outs, strict=True):
            with self._autocast():
                losses = self.losses(batch, out, epoch=epoch)
            totals.append(losses["total"] * self.world / self.parts)
            _accumulate(sums, losses, weight)
        _backward(totals, self.g_ddp)
        torch.nn.utils.clip_grad_norm_(self.g_params, config.grad_clip)
        self.g_opt.step()

    def _autocast(self) -> Any:
        """bfloat16 autocast on the training device (CUDA or CPU) when ``config.amp`` (a no-op otherwise)."""
        return torch.autocast(self.device.type, dtype=torch.bfloat16, enabled=self.amp)

    def validate(self, epoch: int, step: int | None = None) -> dict[str, Any]:
        """The model's validation now: ``{"val": mean losses on the validation windows ({} without them)}``,
        plus ``"val_score"`` with a ``val_score`` (:meth:`score`); on process 0 only (``{"val": {}}`` on the others).
        """
        record: dict[str, Any] = {"val": {}}
        if self.rank != 0:
            return record
        if self.val_windows is not None:
            batch = self.config.batch_size
            record["val"] = evaluate_losses(self.model, self.val_windows, epoch=epoch, batch_size=batch)
        if self.val_score is not None:
            where = {"epoch": epoch} if step is None else {"epoch": epoch, "step": step}
            record["val_score"] = self.score(where, self.val_score)
        return record

    def validate_step(self, epoch: int) -> None:
        """With ``val_every``: validate after step :attr:`steps` (in ``epoch``) and record it in
        :attr:`validations` as ``{"step", "val", "val_score"}``; the model goes on training. Process 0,
        when there is something to validate (the other processes go on to the next step)."""
        if self.rank == 0 and (self.val_windows is not None or self.val_score is not None):
            # the validation's random draws (HA2G's evaluation losses, a sampled val_score) come from a fork
            # of torch's generators: training draws the same numbers with or without it, in every process,
            # so a resumed run (which restores each process's generator) takes the same steps
            cuda = [self.device.index or 0] if self.device.type == "cuda" else []
            with torch.random.fork_rng(devices=cuda):
                self.validations.append({"step": self.steps, **self.validate(epoch, self.steps)})
            self.model.train()

    def epoch_validation(self, epoch: int) -> dict[str, Any]:
        """The validation part of ``epoch``'s history entry.

        Per epoch (``val_every`` None): :meth:`validate` now. With ``val_every``: ``"validations"``, the
        epoch's (and one more at the end of the run when its last step was not one), and the last of them's
        ``"val"`` (``{}`` without any) and ``"val_score"``.
        """
        every = self.config.val_every
        if every is None:
            return self.validate(epoch)
        if epoch == self.config.epochs - 1 and self.steps % every:
            self.validate_step(epoch)
        last = self.validations[-1] if self.validations else {"val": {}}
        return {**{k: v for k, v in last.items() if k != "step"}, "validations": list(self.validations)}

    def score(self, where: dict[str, int], val_score: Callable[[GestureModel], float]) -> float:
        """Score the model in eval mode; keep a copy of the weights as :attr:`best` (with ``where``: the
        epoch, and the step with ``val_every``) when it is the best so far."""
        self.model.eval()
        with torch.no_grad():
            score = float(val_score(self.model))
        if math.isfinite(score) and (self.best is None or score < self.best["score"]):
            state = {k: v.detach().cpu().clone() for k, v in self.model.state_dict().items()}
            self.best = {**where, "score": score, "state": state}
        return score

    def save(self, epoch_done: int) -> None:
        """Write the full (resumable) checkpoint, when a path is configured (process 0 writes; every process
        calls it, for the generators' states)."""
        if self.path is None:
            return
        weights = ((k, v) for k, v in self.model.state_dict().items() if v.is_floating_point())
        check_diverged(self.model.name, f"its weights after {self.steps} steps", weights, self.world)
        states = rng_states(self.world)
        if self.rank != 0:
            return
        save_checkpoint(
            self.path,
            {
                "format": FORMAT,
                "model": self.model.to_config(),
                "state": {k: v.detach().cpu() for k, v in self.model.state_dict().items()},
                "optimizer": None if self.g_opt is None else self.g_opt.state_dict(),
                "d_optimizer": None if self.d_opt is None else self.d_opt.state_dict(),
                "epoch": epoch_done,
                "history": self.history,
                "fingerprint": self.fingerprint,
                "train_config": self.config.to_dict(),
                "rng": states[0],  # the CPU generator; CUDA kernels are not bitwise reproducible
                "rng_processes": states if self.world > 1 else None,  # under torchrun, each process's
                "meta": self.meta,
                "best": self.best,
                "partial": self.partial,
                "steps": self.steps,
            },
        )

    def result(self) -> FitResult:
        if self.best is None:
            return FitResult(self.history, self.path, self.fingerprint)
        step = self.best.get("step")
        return FitResult(
            self.history,
            self.path,
            self.fingerprint,
            int(self.best["epoch"]),
            float(self.best["score"]),
            None if step is None else int(step),
        )
