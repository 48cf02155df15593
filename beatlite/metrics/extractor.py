"""The FGD feature extractor: a small BEAT-style convolutional motion autoencoder (torch).

FGD compares *features* of motion windows, so it needs a network that maps a 34-frame
window to a vector. BEAT trains a convolutional autoencoder (docs/reference_code.md#fgd-autoencoder) and uses its
encoder output; beatlite does the same at a laptop scale:

- encoder: Conv1d(D -> c, k3) -> BN -> LeakyReLU(0.2) -> Conv1d(c -> 2c, k3) -> BN -> LReLU
  -> Conv1d(2c -> 2c, k4, stride 2) -> BN -> LReLU -> Conv1d(2c -> c, k3); time 34 -> 32 -> 30
  -> 14 -> **12**; flatten (12 c) -> Linear(12c, 4L) -> BN -> LReLU -> Linear(4L, L) = latent.
  (BEAT: c = L = 300 with slope-1 "LeakyReLU(True)" in the MLP; beatlite uses c = 32 and
  L = 32 by default, with a real LeakyReLU: a 300-d Gaussian is badly estimated from the few
  thousand windows of ``data_samples/``, the covariance alone having 45150 parameters.)
- decoder: the mirror (Linear, then ConvTranspose1d 12 -> 14 -> 30 -> 32 -> 34).
- loss: ``L1(x^, x) + w * MSE(diff_t x^, diff_t x)`` (reconstruction + velocity, docs/reference_code.md#fgd-autoencoder) with
  BEAT's ``w = 0.1`` for the "pose" extractor and ``w = 10`` for "dirvec": direction vectors move
  little per frame, and with 0.1 the dirvec encoder ignored timing (on ``data_samples/`` test vs
  val windows, FGD ratios frame-shuffled/held-out 0.9 and noisy/held-out 0.3 with w = 0.1;
  2.4 and 11.9 with w = 10).
- input normalisation: per-channel mean/std of the training windows, stored in the checkpoint.

Train with ``python -m beatlite.metrics.extractor train [--space dirvec|pose|rot6d]`` (one thread,
deterministic with ``--seed``); the shipped checkpoints are ``checkpoints/fgd_dirvec.pt``
(TED-43 direction vectors, 126-d, the common evaluation space) and
``checkpoints/fgd_euler141.pt`` (z-scored Euler angles, 141-d, BEAT's space).
:func:`load_extractor` returns a callable ``windows (N, 34, D) -> features (N, L)``.

Taught in notebooks/04_metrics.ipynb, section 1.3 (FGD on motion: the features decide what it sees).
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

from beatlite.constants import WINDOW_LENGTH

FORMAT = "beatlite-fgd-extractor/1"
#: Window key of ``beatlite.data.windows`` for each extractor space, and the shipped file name.
SPACES = {
    "dirvec": ("dirvec", "fgd_dirvec.pt"),
    "pose": ("pose", "fgd_euler141.pt"),
    "rot6d": ("pose_raw", "fgd_rot6d.pt"),
}
#: Channels D of each space's windows: 42 TED-43 bone directions x 3, 47 Euler triplets (``spine_neck_141``), their 47
#: 6D rotations. :func:`load_extractor` and :func:`save_extractor` refuse an extractor of another input size.
SPACE_DIMS = {"dirvec": 126, "pose": 141, "rot6d": 282}
#: Spaces whose windows are computed from their key's values: "rot6d" = the 6D rotation of each of the 47 joints of
#: the raw Euler degrees (:func:`beatlite.skeleton.rotations.euler_to_6d`, 282-d; EMAGE's FGD space is rot6d).
SPACE_INPUTS = {"rot6d": "euler_to_6d"}
#: Weight of the velocity MSE per space. BEAT's 0.1 (docs/reference_code.md#fgd-autoencoder) for "pose"; for "dirvec" 0.1 leaves
#: the encoder blind to timing (FGD of frame-shuffled test windows 0.9x that of held-out real
#: windows on data_samples), 10 makes it see it (2.4x) — measured, see the module docstring.
VELOCITY_WEIGHT = {"dirvec": 10.0, "pose": 0.1, "rot6d": 10.0}  # rot6d: unit-vector columns, as dirvec


@dataclass(frozen=True)
class ExtractorConfig:
    """Architecture and training settings of the motion autoencoder.

    Attributes
    ----------
    input_dim : int
        Channels D of a window (126 dirvec, 141 pose).
    latent_dim : int
        Feature size L (default 32).
    channels : int
        Base conv width c (default 32).
    epochs, batch_size, lr, seed : training settings.
    velocity_weight, velocity_loss : float, "mse" or "l1"
        Weight and kind of the frame-difference term: BEAT's AE uses ``0.1 * MSE`` (docs/reference_code.md#fgd-autoencoder),
        HA2G's MotionAE ``1 * L1`` (docs/reference_code.md#ha2g-feature-extractor).

    Examples
    --------
    >>> config = ExtractorConfig(input_dim=126)
    >>> config.latent_dim, config.channels, config.velocity_loss
    (32, 32, 'mse')
    """

    input_dim: int
    latent_dim: int = 32
    channels: int = 32
    epochs: int = 100
    batch_size: int = 64
    lr: float = 1e-3
    velocity_weight: float = 0.1
    velocity_loss: str = "mse"
    seed: int = 0


class MotionAutoencoder(nn.Module):
    """Convolutional autoencoder of (B, 34, D) windows; ``encode`` gives (B, L) features.

    Examples
    --------
    >>> model = MotionAutoencoder(ExtractorConfig(input_dim=6, latent_dim=4, channels=8)).eval()
    >>> x = torch.zeros(2, 34, 6)
    >>> tuple(model.encode(x).shape), tuple(model(x).shape)
    ((2, 4), (2, 34, 6))
    """

    def __init__(self, config: ExtractorConfig) -> None:
        super().__init__()
        d, c, z = config.input_dim, config.channels, config.latent_dim
        act = nn.LeakyReLU(0.2)
        self.config = config
        self.encoder = nn.Sequential(
            nn.Conv1d(d, c, 3), nn.BatchNorm1d(c), act,
            nn.Conv1d(c, 2 * c, 3), nn.BatchNorm1d(2 * c), act,
            nn.Conv1d(2 * c, 2 * c, 4, stride=2), nn.BatchNorm1d(2 * c), act,
            nn.Conv1d(2 * c, c, 3),
        )  # fmt: skip
        self.to_latent = nn.Sequential(
            nn.Linear(12 * c, 4 * z), nn.BatchNorm1d(4 * z), act, nn.Linear(4 * z, z)
        )
        self.from_latent = nn.Sequential(nn.Linear(z, 12 * c), act)
        self.decoder = nn.Sequential(
            nn.ConvTranspose1d(c, 2 * c, 3), nn.BatchNorm1d(2 * c), act,
            nn.ConvTranspose1d(2 * c, 2 * c, 4, stride=2), nn.BatchNorm1d(2 * c), act,
            nn.ConvTranspose1d(2 * c, c, 3), nn.BatchNorm1d(c), act,
            nn.ConvTranspose1d(c, d, 3),
        )  # fmt: skip

    def encode(self, x: torch.Tensor) -> torch.Tensor:
        """(B, 34, D) normalised windows -> (B, L) features."""
        h = self.encoder(x.transpose(1, 2))
        return self.to_latent(h.flatten(1))

    def decode(self, z: torch.Tensor) -> torch.Tensor:
        """(B, L) -> (B, 34, D) normalised windows."""
        h = self.from_latent(z).view(z.shape[0], self.config.channels, 12)
        return self.decoder(h).transpose(1, 2)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        """Reconstruction of (B, 34, D) windows."""
        return self.decode(self.encode(x))


def autoencoder_loss(
    recon: torch.Tensor, target: torch.Tensor, velocity_weight: float = 0.1, velocity_loss: str = "mse"
) -> torch.Tensor:
    """``mean|x^ - x| + w * mean((diff_t x^ - diff_t x)^2)`` (or ``mean|...|`` for ``"l1"``) on (B, T, D).

    Examples
    --------
    >>> target = torch.zeros(1, 3, 1)
    >>> recon = torch.tensor([[[1.0], [1.0], [3.0]]])  # |error| mean 5/3; frame differences (0, 2) vs (0, 0)
    >>> round(float(autoencoder_loss(recon, target, velocity_weight=0.1)), 6)  # 5/3 + 0.1 * (0 + 4) / 2
    1.866667
    """
    vel = torch.diff(recon, dim=1) - torch.diff(target, dim=1)
    if velocity_loss == "mse":
        term = vel.pow(2).mean()
    elif velocity_loss == "l1":
        term = vel.abs().mean()
    else:
        raise ValueError(f"velocity_loss must be 'mse' or 'l1', got {velocity_loss!r}")
    return (recon - target).abs().mean() + velocity_weight * term


class FeatureExtractor:
    """A trained encoder as a callable ``windows (N, 34, D) -> features (N, L)`` (numpy).

    Attributes
    ----------
    model : MotionAutoencoder (eval mode, CPU)
    mean, std : (D,) float32
        Input normalisation applied before encoding.
    space : str
        ``"dirvec"``, ``"pose"`` or ``"rot6d"`` (what the windows must be: :data:`SPACES`, :func:`space_input`).
    meta : dict
        Everything else stored in the checkpoint (fingerprint, training history...).

    Examples
    --------
    >>> extractor = load_extractor("dirvec")  # the shipped checkpoint
    >>> extractor.space, extractor.latent_dim
    ('dirvec', 32)
    >>> extractor(np.zeros((3, 34, 126), dtype=np.float32)).shape
    (3, 32)
    """

    def __init__(
        self, model: MotionAutoencoder, mean: np.ndarray, std: np.ndarray, space: str, meta: dict
    ) -> None:
        self.model = model.eval()
        self.mean = np.asarray(mean, dtype=np.float32)
        self.std = np.asarray(std, dtype=np.float32)
        self.space = space
        self.meta = meta

    @property
    def latent_dim(self) -> int:
        """Feature size L."""
        return self.model.config.latent_dim

    def _check(self, windows: np.ndarray) -> np.ndarray:
        w = np.asarray(windows, dtype=np.float32)
        d = self.model.config.input_dim
        if w.ndim != 3 or w.shape[1] != WINDOW_LENGTH or w.shape[2] != d:
            raise ValueError(
                f"windows must be (N, {WINDOW_LENGTH}, {d}) ({self.space} space), got shape {w.shape}"
            )
        if not np.all(np.isfinite(w)):
            raise ValueError("windows contain NaN or infinite values")
        return (w - self.mean) / self.std

    def __call__(self, windows: np.ndarray, batch_size: int = 512) -> np.ndarray:
        """Features of (N, 34, D) windows: (N, L) float64."""
        x = self._check(windows)
        out = []
        with torch.no_grad():
            for i in range(0, len(x), batch_size):
                out.append(self.model.encode(torch.from_numpy(x[i : i + batch_size])).numpy())
        return np.concatenate(out).astype(np.float64) if out else np.zeros((0, self.latent_dim))


# ----------------------------------------------------------------------------- training
def space_input(values: np.ndarray, space: str | None) -> np.ndarray:
    """The extractor input of ``space`` from its window key's values (unchanged but for :data:`SPACE_INPUTS`).

    Examples
    --------
    >>> space_input(np.zeros((2, 34, 141)), "rot6d").shape  # 47 Euler triplets -> 47 6D rotations
    (2, 34, 282)
    """
    if space not in SPACE_INPUTS:
        return values
    from beatlite.skeleton import rotations

    return getattr(rotations, SPACE_INPUTS[space])(values)


class WindowSource:
    """The (N, 34, D) float32 training windows of an extractor, from an array or a window view.

    A view (:class:`~beatlite.data.store.StoreWindows` or :class:`~beatlite.data.windows.Windows`)
    is read ``key`` by ``key`` in batches (``view.batch(idx, keys=(key,))``), so training from the
    window store holds one batch in memory, whatever the corpus size. An array is indexed directly.

    Examples
    --------
    >>> source = WindowSource(np.arange(2 * 34 * 3, dtype=np.float32).reshape(2, 34, 3))
    >>> len(source), source.get(np.array([1])).shape
    (2, (1, 34, 3))
    """

    def __init__(self, windows: Any, key: str | None = None, space: str | None = None) -> None:
        self.view = None if key is None else windows
        self.array = np.asarray(windows, dtype=np.float32) if key is None else None
        self.key = key
        self.space = space
        n, shape = (
            (len(windows), self.get(np.arange(min(1, len(windows))))[0].shape) if len(windows) else (0, ())
        )
        self.n, self.shape = n, shape

    def __len__(self) -> int:
        return self.n

    def get(self, idx: np.ndarray) -> np.ndarray:
        """Windows ``idx``: (len(idx), 34, D) float32 (of a view: its ``key``, then :func:`space_input`)."""
        if self.view is None:
            return self.array[idx]
        values = self.view.batch(np.asarray(idx), keys=(self.key,))[self.key]
        return np.asarray(space_input(values, self.space), np.float32)

    def moments(self, chunk: int = 4096) -> tuple[np.ndarray, np.ndarray]:
        """Per-channel mean and std (floored at 1e-3), (D,) float32: of the array as numpy computes
        them; of a view accumulated in float64 over chunks of ``chunk`` windows."""
        if self.view is None:
            flat = self.array.reshape(-1, self.array.shape[2])
            return flat.mean(axis=0), np.maximum(flat.std(axis=0), 1e-3).astype(np.float32)
        total = total_sq = 0.0
        for start in range(0, self.n, chunk):
            flat = (
                self.get(np.arange(start, min(self.n, start + chunk)))
                .astype(np.float64)
                .reshape(-1, self.shape[1])
            )
            total, total_sq = total + flat.sum(axis=0), total_sq + (flat**2).sum(axis=0)
        count = self.n * self.shape[0]
        mean = total / count
        std = np.sqrt(np.maximum(total_sq / count - mean**2, 0.0))
        return mean.astype(np.float32), np.maximum(std, 1e-3).astype(np.float32)


def train_autoencoder(
    windows: Any,
    config: ExtractorConfig,
    *,
    val_windows: Any = None,
    key: str | None = None,
    space: str | None = None,
    log: bool = True,
) -> tuple[MotionAutoencoder, dict[str, Any]]:
    """Train the autoencoder on (N, 34, D) windows, deterministically (one thread by default).

    Parameters
    ----------
    windows : (N, 34, D) float array, or a window view with ``key``
        Training windows in the extractor's space; a view (the window store's
        ``store.windows("train")``) is read one batch at a time (:class:`WindowSource`).
    config : ExtractorConfig
    val_windows : (M, 34, D) float array or a view with ``key``, optional
        Held-out windows whose loss is reported.
    key : str, optional
        The batch key of a view (``"dirvec"``, ``"pose"`` or ``"pose_raw"``); None for arrays.
    space : str, optional
        The extractor space: a view's windows pass through :func:`space_input` (``"rot6d"``: Euler -> 6D).
    log : bool
        Print one line per 10 epochs.

    Returns
    -------
    model : MotionAutoencoder (eval mode)
    info : dict
        ``mean``/``std`` (D,) input normalisation, ``history`` of per-epoch losses, ``seconds``.

    Examples
    --------
    >>> windows = np.random.default_rng(0).normal(size=(16, 34, 6)).astype(np.float32)
    >>> config = ExtractorConfig(input_dim=6, latent_dim=4, channels=8, epochs=2, batch_size=8)
    >>> model, info = train_autoencoder(windows, config, log=False)
    >>> info["mean"].shape, len(info["history"])
    ((6,), 2)
    """
    from beatlite.paths import n_threads

    w = WindowSource(windows, key, space)
    if len(w) and w.shape != (WINDOW_LENGTH, config.input_dim):
        raise ValueError(f"windows must be (N, {WINDOW_LENGTH}, {config.input_dim}), got (N, *{w.shape})")
    if len(w) < 2:
        raise ValueError(f"need at least 2 training windows, got {len(w)}")
    val = None if val_windows is None else WindowSource(val_windows, key, space)
    torch.set_num_threads(n_threads())
    torch.manual_seed(config.seed)
    was_deterministic = torch.are_deterministic_algorithms_enabled()
    torch.use_deterministic_algorithms(True)
    try:
        return _train(w, config, val, log)
    finally:
        torch.use_deterministic_algorithms(was_deterministic)


def _train(
    w: WindowSource, config: ExtractorConfig, val: WindowSource | None, log: bool
) -> tuple[MotionAutoencoder, dict[str, Any]]:
    mean, std = w.moments()
    model = MotionAutoencoder(config)
    opt = torch.optim.Adam(model.parameters(), lr=config.lr, betas=(0.5, 0.999))
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, T_max=config.epochs)
    gen = torch.Generator().manual_seed(config.seed)
    history = []
    t0 = time.perf_counter()
    for epoch in range(config.epochs):
        row = {"epoch": epoch + 1, "train": _train_epoch(model, opt, w, (mean, std), config, gen)}
        sched.step()
        if val is not None and len(val) >= 1:
            row["val"] = _val_loss(model, val, (mean, std), config)
        history.append(row)
        if log and ((epoch + 1) % 10 == 0 or epoch == 0):
            extra = f", val {row['val']:.4f}" if "val" in row else ""
            print(f"epoch {epoch + 1:3d}: train {row['train']:.4f}{extra}", flush=True)
    model.eval()
    return model, {"mean": mean, "std": std, "history": history, "seconds": time.perf_counter() - t0}


def _normalised(w: WindowSource, idx: np.ndarray, moments: tuple[np.ndarray, np.ndarray]) -> torch.Tensor:
    return torch.from_numpy((w.get(idx) - moments[0]) / moments[1])


def _val_loss(
    model: MotionAutoencoder,
    val: WindowSource,
    moments: tuple[np.ndarray, np.ndarray],
    config: ExtractorConfig,
) -> float:
    """Mean validation loss, over chunks of 4096 windows weighted by their size (one chunk: as one batch)."""
    model.eval()
    total, chunk = 0.0, 4096
    with torch.no_grad():
        for start in range(0, len(val), chunk):
            xv = _normalised(val, np.arange(start, min(len(val), start + chunk)), moments)
            loss = autoencoder_loss(model(xv), xv, config.velocity_weight, config.velocity_loss)
            total += float(loss) * len(xv)
    return total / len(val)


def _train_epoch(
    model: MotionAutoencoder,
    opt: torch.optim.Optimizer,
    w: WindowSource,
    moments: tuple[np.ndarray, np.ndarray],
    config: ExtractorConfig,
    gen: torch.Generator,
) -> float:
    """One pass over the windows in shuffled mini-batches (read and normalised per batch); the mean loss."""
    model.train()
    perm = torch.randperm(len(w), generator=gen).numpy()
    total, n = 0.0, 0
    for i in range(0, len(w), config.batch_size):
        idx = perm[i : i + config.batch_size]
        if len(idx) < 2:  # BatchNorm needs 2 samples
            continue
        x = _normalised(w, idx, moments)
        loss = autoencoder_loss(model(x), x, config.velocity_weight, config.velocity_loss)
        opt.zero_grad()
        loss.backward()
        opt.step()
        total += float(loss.detach()) * len(idx)
        n += len(idx)
    return total / n


def save_extractor(
    path: str | Path, model: MotionAutoencoder, info: dict[str, Any], *, space: str, meta: dict
) -> Path:
    """Write the checkpoint atomically: config, weights, input normalisation, fingerprint, history.

    ``space`` is one of :data:`SPACES` and the model's ``input_dim`` its :data:`SPACE_DIMS` (else a ValueError),
    so that :func:`load_extractor` reads the file back. Only tensors and plain Python values are stored, so it loads with ``weights_only=True``.

    Examples
    --------
    >>> import tempfile
    >>> model = MotionAutoencoder(ExtractorConfig(input_dim=126, latent_dim=4, channels=8)).eval()
    >>> info = {"mean": np.zeros(126), "std": np.ones(126), "history": []}  # as train_autoencoder returns it
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = save_extractor(f"{tmp}/ae.pt", model, info, space="dirvec", meta={})
    ...     extractor = load_extractor("dirvec", path)
    >>> windows = np.random.default_rng(0).normal(size=(5, 34, 126)).astype(np.float32)
    >>> features = extractor(windows)  # (N, L); the same as the saved model's
    >>> features.shape, np.allclose(features, model.encode(torch.from_numpy(windows)).detach().numpy(), atol=1e-6)
    ((5, 4), True)
    """
    from beatlite.io.atomic import atomic_write

    if SPACE_DIMS.get(space) != model.config.input_dim:
        raise ValueError(
            f"save_extractor: space must be one of {sorted(SPACES)} with input_dim its SPACE_DIMS, "
            f"got {space!r} and {model.config.input_dim}"
        )
    payload = {
        "format": FORMAT,
        "space": space,
        "config": asdict(model.config),
        "state_dict": {k: v.detach().clone() for k, v in model.state_dict().items()},
        "input_mean": torch.from_numpy(np.asarray(info["mean"], np.float32)),
        "input_std": torch.from_numpy(np.asarray(info["std"], np.float32)),
        "history": info["history"],
        "meta": meta,
    }
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_write(path, "wb") as f:
        torch.save(payload, f)
    return path


def load_extractor(space: str = "dirvec", path: str | Path | None = None) -> FeatureExtractor:
    """The shipped (or a given) FGD extractor as a callable ``(N, 34, D) -> (N, L)``.

    Parameters
    ----------
    space : "dirvec" or "pose"
        Which shipped checkpoint: ``checkpoints/fgd_dirvec.pt`` (126-d TED direction windows)
        or ``checkpoints/fgd_euler141.pt`` (141-d z-scored Euler windows).
    path : str or Path, optional
        Load this checkpoint instead.

    Returns
    -------
    FeatureExtractor

    Raises
    ------
    FileNotFoundError
        The checkpoint does not exist (train it with ``python -m beatlite.metrics.extractor train``).
    ValueError
        ``space`` is not one of :data:`SPACES`.
    beatlite.io.FormatError
        (a ValueError) The file is not a beatlite FGD extractor checkpoint, naming the field: a pickle of
        anything but tensors and plain values (never executed), a decompression bomb, a config of other or
        missing fields or whose ``input_dim`` is not its space's (:data:`SPACE_DIMS`), weights of other
        names or shapes than that config's model or not finite, an ``input_mean``/``input_std`` that is not
        a finite (D,) tensor with std > 0.

    Examples
    --------
    >>> extractor = load_extractor("pose")  # checkpoints/fgd_euler141.pt
    >>> extractor(np.zeros((2, 34, 141), dtype=np.float32)).shape
    (2, 32)
    """
    from beatlite.paths import checkpoints_dir

    if space not in SPACES:
        raise ValueError(f"space must be one of {sorted(SPACES)}, got {space!r}")
    p = checkpoints_dir() / SPACES[space][1] if path is None else Path(path)
    if not p.is_file():
        raise FileNotFoundError(
            f"FGD extractor checkpoint {p} not found; train it with "
            f"`python -m beatlite.metrics.extractor train --space {space}`"
        )
    from beatlite.train.checkpoint import read_plain

    data = read_plain(p)  # no code run, a decompression bomb refused before it inflates
    return _extractor_from(data, p)


def _extractor_from(data: Any, p: Path) -> FeatureExtractor:
    """The :class:`FeatureExtractor` of a loaded checkpoint dict, every field checked (FormatError naming it)."""
    from beatlite.io.errors import FormatError
    from beatlite.train.checkpoint import check_state, state_mismatch

    if not isinstance(data, dict) or data.get("format") != FORMAT:
        found = data.get("format") if isinstance(data, dict) else type(data).__name__
        raise FormatError(p, f"not a beatlite FGD extractor checkpoint (format {found!r})", field="format")
    space = data.get("space")
    if not isinstance(space, str) or space not in SPACES:
        raise FormatError(p, f"space must be one of {sorted(SPACES)}, got {space!r}", field="space")
    try:
        config = ExtractorConfig(**data["config"])
        with torch.device(
            "meta"
        ):  # built without memory first: a huge config is refused before it is allocated
            skeleton = MotionAutoencoder(config)
    except Exception as exc:  # noqa: BLE001 - missing/unknown fields (KeyError, TypeError), bad values
        raise FormatError(
            p, f"not an extractor config ({type(exc).__name__}: {exc})", field="config"
        ) from None
    if config.input_dim != SPACE_DIMS[space]:
        raise FormatError(
            p,
            f"input_dim {config.input_dim}, but {space!r} windows have {SPACE_DIMS[space]} channels",
            field="config",
        )
    check_state(data.get("state_dict"), p, field="state_dict")
    why = state_mismatch(skeleton, data["state_dict"])
    if why is not None:
        raise FormatError(p, f"the weights do not fit the model its config builds: {why}", field="state_dict")
    moments = {}
    for key in ("input_mean", "input_std"):
        value = data.get(key)
        if not torch.is_tensor(value) or tuple(value.shape) != (config.input_dim,) or value.is_complex():
            got = tuple(value.shape) if torch.is_tensor(value) else type(value).__name__
            raise FormatError(p, f"expected a ({config.input_dim},) tensor, got {got}", field=key)
        moments[key] = value.detach().to_dense().float().numpy()
        if not np.isfinite(moments[key]).all() or (key == "input_std" and not (moments[key] > 0).all()):
            raise FormatError(
                p, "non-finite values" + (" or a std <= 0" if key == "input_std" else ""), field=key
            )
    for key, kind in (("meta", dict), ("history", list)):
        if not isinstance(data.get(key, kind()), kind):
            raise FormatError(p, f"expected a {kind.__name__}, got {type(data[key]).__name__}", field=key)
    model = MotionAutoencoder(config)
    model.load_state_dict(data["state_dict"])
    meta = {**data.get("meta", {}), "history": data.get("history", []), "path": str(p)}
    return FeatureExtractor(model, moments["input_mean"], moments["input_std"], space, meta)


# ----------------------------------------------------------------------------- command line
def _train_command(args: argparse.Namespace) -> int:
    from beatlite.data.index import index_folder
    from beatlite.data.store import build_store
    from beatlite.paths import checkpoints_dir, data_dir

    key, fname = SPACES[args.space]
    root = Path(args.data) if args.data else data_dir()
    store = build_store(index_folder(root), args.store, progress=True)
    train = store.windows("train", keys=(key,))  # read one batch at a time: memory flat in the corpus size
    try:
        val = store.windows("val", keys=(key,), stats=train.normalizers)
    except ValueError:
        val = None
    config = ExtractorConfig(
        input_dim=WindowSource(train, key, args.space).shape[1], latent_dim=args.latent, channels=args.channels,
        epochs=args.epochs, batch_size=args.batch_size, lr=args.lr, seed=args.seed,
        velocity_weight=VELOCITY_WEIGHT[args.space] if args.velocity_weight is None else args.velocity_weight,
        velocity_loss=args.velocity_loss,
    )  # fmt: skip
    print(f"training the {args.space} FGD autoencoder on {len(train)} windows from {root}", flush=True)
    model, info = train_autoencoder(train, config, val_windows=val, key=key, space=args.space)
    meta = {
        "data_fingerprint": train.fingerprint,  # files + parameters: the same on every machine
        "n_windows": int(len(train)),
        "n_val_windows": 0 if val is None else int(len(val)),
        "takes": sorted(store.takes[int(i)].stem for i in np.unique(train.take_ids)),
        "window_key": key,
        "seconds": round(float(info["seconds"]), 1),
        "torch": str(torch.__version__),
    }
    out = Path(args.out) if args.out else checkpoints_dir() / fname
    save_extractor(out, model, info, space=args.space, meta=meta)
    print(f"wrote {out} ({out.stat().st_size / 1e6:.2f} MB) in {info['seconds']:.0f} s; "
          f"fingerprint {meta['data_fingerprint']}", flush=True)  # fmt: skip
    return 0


def _info_command(args: argparse.Namespace) -> int:
    ex = load_extractor(args.space, args.path)
    print(f"{ex.meta['path']}: space {ex.space}, config {asdict(ex.model.config)}")
    keys = ("data_fingerprint", "n_windows", "n_val_windows", "seconds")
    print({k: ex.meta.get(k) for k in keys})
    if ex.meta["history"]:
        print("last epoch:", ex.meta["history"][-1])
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m beatlite.metrics.extractor {train,info} ...``

    Examples
    --------
    >>> import contextlib, io
    >>> out = io.StringIO()
    >>> with contextlib.redirect_stdout(out):
    ...     code = main(["info", "--space", "dirvec"])
    >>> code, "space dirvec" in out.getvalue()
    (0, True)
    """
    parser = argparse.ArgumentParser(
        prog="python -m beatlite.metrics.extractor", description=__doc__.split("\n")[0]
    )
    sub = parser.add_subparsers(dest="command", required=True)
    t = sub.add_parser("train", help="train an FGD autoencoder on the corpus' train-split windows")
    t.add_argument("--space", choices=sorted(SPACES), default="dirvec")
    t.add_argument("--data", help="BEAT-format folder (default $BEATLITE_DATA or data_samples/)")
    t.add_argument("--out", help="checkpoint path (default checkpoints/fgd_<space>.pt)")
    t.add_argument("--latent", type=int, default=32)
    t.add_argument("--channels", type=int, default=32)
    t.add_argument("--epochs", type=int, default=100)
    t.add_argument("--batch-size", type=int, default=64)
    t.add_argument("--lr", type=float, default=1e-3)
    t.add_argument("--velocity-weight", type=float, default=None, help="default: 10 for dirvec, 0.1 for pose")
    t.add_argument("--velocity-loss", choices=("mse", "l1"), default="mse")
    t.add_argument("--seed", type=int, default=0)
    t.add_argument("--store", help="window store folder (default: under build/cache/store, built or updated)")
    t.set_defaults(func=_train_command)
    i = sub.add_parser("info", help="describe a checkpoint")
    i.add_argument("--space", choices=sorted(SPACES), default="dirvec")
    i.add_argument("--path")
    i.set_defaults(func=_info_command)
    args = parser.parse_args(argv)
    return int(args.func(args))


if __name__ == "__main__":
    sys.exit(main())
