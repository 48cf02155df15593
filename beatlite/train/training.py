"""The training loop :func:`fit`, shared by every :class:`~beatlite.models.base.GestureModel`."""

from __future__ import annotations

import dataclasses
import hashlib
import math
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import torch

from beatlite.models.base import GestureModel
from beatlite.train.checkpoint import FORMAT, load_checkpoint, save_checkpoint
from beatlite.train.config import TrainConfig

TENSOR_KEYS = ("pose", "dirvec", "audio", "mel", "face", "word", "emotion", "semantic", "speaker")
"""Window keys converted to tensors for the models (others, e.g. ``"take"``, are ignored)."""


@dataclasses.dataclass
class FitResult:
    """What :func:`fit` returns.

    Attributes
    ----------
    history : list of dict
        One entry per completed epoch: ``{"epoch": e, "train": {loss: mean}, "val": {loss: mean}}``
        (``"val"`` is ``{}`` without validation windows).
    checkpoint : Path or None
        The checkpoint written after the last epoch.
    fingerprint : str
        :func:`data_fingerprint` of the training windows.
    best_epoch : int or None
        With ``val_score``: the epoch whose weights scored lowest (the model is left with the
        *last* epoch's weights; the checkpoint holds both, :func:`export_checkpoint` exports the best).
    best_score : float or None
        That epoch's score.
    """

    history: list[dict[str, Any]]
    checkpoint: Path | None
    fingerprint: str
    best_epoch: int | None = None
    best_score: float | None = None


def as_arrays(windows: Any) -> Mapping[str, np.ndarray]:
    """The numpy dict of a window set.

    A Mapping itself, an object's ``.arrays`` Mapping, or a mapping-like object with
    ``keys()`` and ``[key]`` (a :class:`beatlite.data.windows.Windows` in windowed mode).
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

    Uses the object's ``fingerprint`` attribute (e.g. the window cache's) when it has one;
    otherwise hashes, per key in sorted order, the name, shape, dtype and every
    ``max(1, N // 16)``-th window's bytes.

    Returns
    -------
    str
        16 hexadecimal characters.
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


def _batch(
    arrays: Mapping[str, np.ndarray], keys: tuple[str, ...], idx: np.ndarray
) -> dict[str, torch.Tensor]:
    out = {}
    for k in keys:
        a = np.asarray(arrays[k])[idx]
        out[k] = torch.from_numpy(
            np.ascontiguousarray(a.astype(np.int64 if a.dtype.kind in "iu" else np.float32))
        )
    return out


def _needed_keys(model: GestureModel, arrays: Mapping[str, np.ndarray], who: str) -> tuple[str, ...]:
    needed = set(model.input_keys) | {model.target_key}
    missing = sorted(needed - set(arrays))
    if missing:
        raise KeyError(
            f"{who}: windows lack {missing} needed by {type(model).__name__} (have {sorted(arrays)})"
        )
    return tuple(k for k in TENSOR_KEYS if k in arrays)


def configure_torch(seed: int, threads: int | None) -> None:
    """Seed torch, force deterministic algorithms and set the CPU thread count."""
    from beatlite.paths import n_threads

    torch.manual_seed(seed)
    torch.use_deterministic_algorithms(True)
    torch.set_num_threads(threads if threads is not None else n_threads())


def _mean_losses(sums: dict[str, float], n: int) -> dict[str, float]:
    return {k: v / max(n, 1) for k, v in sums.items()}


def _accumulate(
    sums: dict[str, float], losses: Mapping[str, torch.Tensor], weight: int, prefix: str = ""
) -> None:
    for k, v in losses.items():
        sums[prefix + k] = sums.get(prefix + k, 0.0) + float(v.detach()) * weight


@torch.no_grad()
def evaluate_losses(
    model: GestureModel, windows: Any, *, epoch: int, batch_size: int = 64
) -> dict[str, float]:
    """Mean of ``model.losses`` over ``windows`` in eval mode (weighted by batch size)."""
    arrays = as_arrays(windows)
    keys = _needed_keys(model, arrays, "evaluate_losses")
    n = _n_windows(arrays, keys, "evaluate_losses")
    was_training = model.training
    model.eval()
    sums: dict[str, float] = {}
    try:
        for start in range(0, n, batch_size):
            idx = np.arange(start, min(n, start + batch_size))
            batch = _batch(arrays, keys, idx)
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
    train_windows : dict of str -> ndarray (or an object with ``.arrays``)
        Window arrays as :func:`beatlite.data.windows.build_windows` makes them
        (N windows each); only the keys in :data:`TENSOR_KEYS` are used.
    config : TrainConfig
        Epochs, batch size, learning rates, seed, threads, checkpoint path, resume.
    val_windows : same type as ``train_windows``, optional
        Validation windows: their mean losses are recorded after every epoch.
    meta : mapping, optional
        Stored verbatim in the checkpoint (e.g. normalisation statistics needed by
        :func:`beatlite.train.generate`).
    val_score : callable, optional
        ``val_score(model) -> float``, lower is better, called in eval mode after every epoch
        (e.g. :func:`beatlite.train.evaluation.fgd_scorer`: FGD on the validation takes, the
        reference's choice of its best checkpoint). Recorded as ``history[e]["val_score"]``; the
        lowest-scoring epoch's weights are kept in the checkpoint as ``"best"``.

    Returns
    -------
    FitResult

    Notes
    -----
    Per step: the forward pass, then (when ``model.adversarial_active(epoch)``) a
    discriminator step on ``model.discriminator_losses`` with its own Adam at
    ``d_lr_weight * lr``, then the generator step on ``model.losses(...)["total"]``.
    Both clip the gradient norm at ``grad_clip``. Shuffling uses
    ``numpy.random.default_rng([seed, epoch])`` (an epoch keeps the first
    ``windows_per_epoch`` windows of its shuffle when that is set) and the torch RNG state is checkpointed,
    so ``resume=True`` reproduces the losses of an uninterrupted run exactly.
    """
    if not isinstance(model, GestureModel):
        raise TypeError(f"fit: model must be a GestureModel, got {type(model).__name__}")
    if not isinstance(config, TrainConfig):
        raise TypeError(f"fit: config must be a TrainConfig, got {type(config).__name__}")
    from beatlite.notebook import progress

    arrays = as_arrays(train_windows)
    keys = _needed_keys(model, arrays, "fit")
    n = _n_windows(arrays, keys, "fit")
    fingerprint = data_fingerprint(train_windows)
    configure_torch(config.seed, config.threads)
    if config.no_adv_epochs is not None and hasattr(model.config, "no_adv_epochs"):
        model.config.no_adv_epochs = int(config.no_adv_epochs)
    model.prepare(arrays)

    lr = config.learning_rate
    g_params = model.generator_parameters()
    g_opt = torch.optim.Adam(g_params, lr=lr, betas=config.betas) if g_params else None
    d_opt = None
    if model.discriminator is not None:
        d_opt = torch.optim.Adam(
            model.discriminator.parameters(), lr=lr * config.d_lr_weight, betas=config.betas
        )

    history: list[dict[str, Any]] = []
    start_epoch = 0
    best: dict[str, Any] | None = None  # {"epoch", "score", "state"} of the lowest val_score
    ckpt_path = None if config.checkpoint is None else Path(config.checkpoint)
    if config.resume and ckpt_path is not None and ckpt_path.is_file():
        data = load_checkpoint(ckpt_path)
        if data.get("fingerprint") != fingerprint:
            raise ValueError(
                f"fit: cannot resume from {ckpt_path}: it was trained on data {data.get('fingerprint')!r}, "
                f"these windows are {fingerprint!r}"
            )
        if data["model"] != model.to_config():
            raise ValueError(f"fit: cannot resume from {ckpt_path}: model config differs ({data['model']})")
        model.load_state_dict(data["state"])
        if g_opt is not None and data.get("optimizer") is not None:
            g_opt.load_state_dict(data["optimizer"])
        if d_opt is not None and data.get("d_optimizer") is not None:
            d_opt.load_state_dict(data["d_optimizer"])
        if data.get("rng") is not None:
            torch.set_rng_state(data["rng"])
        history = list(data.get("history", []))
        start_epoch = int(data["epoch"])
        best = data.get("best")

    def save(epoch_done: int) -> None:
        if ckpt_path is None:
            return
        save_checkpoint(
            ckpt_path,
            {
                "format": FORMAT,
                "model": model.to_config(),
                "state": model.state_dict(),
                "optimizer": None if g_opt is None else g_opt.state_dict(),
                "d_optimizer": None if d_opt is None else d_opt.state_dict(),
                "epoch": epoch_done,
                "history": history,
                "fingerprint": fingerprint,
                "train_config": config.to_dict(),
                "rng": torch.get_rng_state(),
                "meta": dict(meta or {}),
                "best": best,
            },
        )

    def result() -> FitResult:
        if best is None:
            return FitResult(history, ckpt_path, fingerprint)
        return FitResult(history, ckpt_path, fingerprint, int(best["epoch"]), float(best["score"]))

    if g_opt is None:  # untrained baseline: nothing to optimise
        save(config.epochs)
        return result()

    bar = progress(
        range(start_epoch, config.epochs), disable=not config.progress, desc=model.name, unit="epoch"
    )
    for epoch in bar:
        model.train()
        factor = config.lr_factor(epoch)
        for opt, base in ((g_opt, lr), (d_opt, lr * config.d_lr_weight)):
            for group in [] if opt is None else opt.param_groups:
                group["lr"] = base * factor
        order = np.random.default_rng([config.seed, epoch]).permutation(n)
        if config.windows_per_epoch is not None:
            order = order[: config.windows_per_epoch]
        sums: dict[str, float] = {}
        seen = 0
        for start in range(0, len(order), config.batch_size):
            idx = np.sort(order[start : start + config.batch_size])
            if len(idx) < 2:
                continue
            batch = _batch(arrays, keys, idx)
            out = model(batch)
            if d_opt is not None and model.adversarial_active(epoch):
                d_losses = model.discriminator_losses(batch, out)
                d_opt.zero_grad(set_to_none=True)
                d_losses["total"].backward()
                torch.nn.utils.clip_grad_norm_(model.discriminator.parameters(), config.grad_clip)
                d_opt.step()
                _accumulate(sums, {k: v for k, v in d_losses.items() if k != "total"}, len(idx), "D_")
            losses = model.losses(batch, out, epoch=epoch)
            g_opt.zero_grad(set_to_none=True)
            losses["total"].backward()
            torch.nn.utils.clip_grad_norm_(g_params, config.grad_clip)
            g_opt.step()
            _accumulate(sums, losses, len(idx))
            seen += len(idx)
        entry: dict[str, Any] = {"epoch": epoch, "train": _mean_losses(sums, seen), "val": {}}
        if val_windows is not None:
            entry["val"] = evaluate_losses(model, val_windows, epoch=epoch, batch_size=config.batch_size)
        if val_score is not None:
            model.eval()
            with torch.no_grad():
                score = float(val_score(model))
            entry["val_score"] = score
            if math.isfinite(score) and (best is None or score < best["score"]):
                state = {k: v.detach().clone() for k, v in model.state_dict().items()}
                best = {"epoch": epoch, "score": score, "state": state}
        history.append(entry)
        # the bar shows the model's first unweighted term (as the history and summaries do), not the weighted total
        main = next((k for k in entry["train"] if k != "total" and not k.startswith("D_")), "total")
        shown = {main: entry["train"].get(main, float("nan"))} | (
            {f"val_{main}": entry["val"][main]} if main in entry["val"] else {}
        )
        bar.set_postfix({k: f"{v:.4g}" for k, v in shown.items()})
        save(epoch + 1)
    return result()
