"""The training configuration :class:`TrainConfig` (no torch import).

Taught in notebooks/05_camn.ipynb, section 4 (training).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

from beatlite.paths import shareable

LR_SCHEDULES = ("constant", "cosine")
"""Values of :attr:`TrainConfig.lr_schedule`."""
DATA_ON_DEVICE = ("auto", "always", "never")
"""Values of :attr:`TrainConfig.data_on_device`."""
COMPILE_MODES = ("default", "reduce-overhead", "max-autotune", "max-autotune-no-cudagraphs")
"""Values of :attr:`TrainConfig.compile` that are ``torch.compile`` modes (of its default backend, inductor)."""
COMPILE_BACKENDS = ("cudagraphs", "aot_eager")
"""Values of :attr:`TrainConfig.compile` that are other ``torch.compile`` backends."""
AUDIO_MATMUL = ("auto", "on", "off")
"""Values of :attr:`TrainConfig.audio_matmul`."""


@dataclasses.dataclass
class TrainConfig:
    """Settings of :func:`beatlite.train.fit` (defaults follow CaMN's reference, docs/reference_code.md#camn-training).

    Attributes
    ----------
    epochs : int
        Number of epochs (total, also when resuming).
    batch_size : int
        Windows per step. A last batch of a single window is dropped (BatchNorm needs 2); fewer than 2
        training windows per epoch (per micro-batch) are a ``ValueError`` of :func:`beatlite.train.fit`
        (:func:`beatlite.train.training.check_window_count`).
    lr : float or None
        Generator learning rate; ``None`` = ``5e-4 * batch_size / 256`` (the reference's
        ``lr_base * batch / 128`` with ``lr_base = 2.5e-4``).
    lr_schedule : {"constant", "cosine"}
        ``"constant"`` (the reference's); ``"cosine"``: epoch e trains at
        ``lr * (1 + cos(pi * e / epochs)) / 2`` (both optimisers), from ``lr`` down towards 0.
        A function of the epoch alone, so resuming is exact.
    betas : (float, float)
        Adam betas (0.5, 0.999).
    d_lr_weight : float
        Discriminator learning rate = ``d_lr_weight * lr`` (0.2).
    seed : int
        Seeds torch (weights, dropout) and the per-epoch shuffles.
    windows_per_epoch : int or None
        If set, each epoch trains on this many windows drawn without replacement from the
        epoch's shuffle (a different subset every epoch); ``None`` = all windows.
    threads : int or None
        Torch CPU threads; ``None`` = :func:`beatlite.paths.n_threads` (``$BEATLITE_THREADS``).
    no_adv_epochs : int or None
        If set, overrides the model's ``config.no_adv_epochs`` (first adversarial epoch, 0-based).
    grad_clip : float
        Gradient-norm clip of each optimiser step (reference 200).
    checkpoint : str or Path or None
        Where to save (atomically, after every epoch); ``None`` = do not save. Under ``torchrun`` every
        process is given the same (process 0 writes; all of them take part in gathering the random
        generators' states at each save).
    resume : bool
        Continue from ``checkpoint`` if it exists (same data fingerprint and model config required; from a
        mid-epoch checkpoint also the same :data:`beatlite.train.training.PLAN_FIELDS`, else
        :class:`beatlite.train.training.ResumeError`).
    progress : bool
        Show a tqdm bar.
    device : {"cpu", "cuda", "auto"} or str
        Where the model trains (``"auto"``: CUDA when available, else the CPU). Checkpoints are
        always written and read on the CPU, so they load on any device.
    amp : bool
        Mixed precision: bfloat16 autocast of the forward pass and losses on the training device (CUDA,
        or the CPU, where torch autocasts to bfloat16 too; weights, optimiser and gradients stay
        float32). Off by default: float32 training on the CPU is bitwise deterministic.
    deterministic : bool
        What :func:`beatlite.train.fit` passes to ``torch.use_deterministic_algorithms`` (torch's setting is
        process-wide: it stays set after ``fit``). ``True`` (default): only deterministic kernels, what repeatable
        CUDA runs need (on an H200 two CUDA trainings of camn_tiny and of ha2g_tiny with one seed gave the same
        weights to the bit, and with ``False`` they did not, at 4b776c0, before ``audio_matmul``'s ``"auto"`` was on
        for CUDA: ``bench/records/repeat_fit_h200.json``; new tensors are not filled on CUDA,
        :func:`~beatlite.train.training.set_deterministic`). ``False`` lets CUDA use its faster nondeterministic
        kernels: on an H200, before deterministic mode stopped filling every new tensor on CUDA, it took CaMN's paper preset (bf16, batch 256) from 112 to 70 ms per step and HA2G's from 323 to 260
        (``bench/bench_train.py --deterministic on off``; README, "Using real BEAT"); the same seed may then give
        slightly different numbers from run to run on a GPU. No effect on CPU results (its kernels are
        deterministic either way).
    checkpoint_every : int or None
        Also write the full checkpoint every this many optimiser steps inside an epoch (an epoch of real
        BEAT is long on a CPU); ``resume=True`` then continues from that step, with the same numbers as
        an uninterrupted run (under ``torchrun`` too: the checkpoint keeps the loss sums of all processes).
    val_every : int or None
        Validate (the validation losses and ``val_score`` of :func:`beatlite.train.fit`, and the best weights)
        after every this many optimiser steps, counted over the whole run (steps of the earlier epochs plus
        the step in this one, the same when resuming), instead of after every epoch; the run ends with one
        more validation when its last step was not one. ``None`` = after every epoch.
    workers : int
        DataLoader worker processes that read the batches of a window store
        (:class:`beatlite.data.store.StoreWindows`); in-memory windows are indexed in the loop.
    data_on_device : {"auto", "always", "never"}
        For a window store view (train and validation windows): hold the streams the model reads on the
        training device and gather every batch there (:class:`beatlite.data.resident.ResidentWindows`: no
        disk read, host copy or DataLoader per step; the same batches to the bit). ``"auto"``: on CUDA when
        they take at most half of its free memory (:func:`beatlite.data.resident.fits_on_device`), never on
        the CPU, where the store's loader keeps the memory flat. In-memory windows are indexed in the loop.
    compile : str or None
        Run the forward pass and the losses through ``torch.compile``: one of :data:`COMPILE_MODES`
        (``"reduce-overhead"``: inductor's kernels replayed as CUDA graphs, one launch for the many small
        kernels of a step) or :data:`COMPILE_BACKENDS` (``"cudagraphs"``: CUDA graphs of the eager kernels;
        ``"aot_eager"``: traced, not compiled, for checking on a CPU). ``None`` (default): eager. The
        first steps compile (tens of seconds, again for a new batch shape); the recurrent layers run
        eagerly between compiled parts. The training pass of every registered model reads nothing back
        from the device (a model contract), which capturing a step in a CUDA graph needs. On an H200,
        ``"reduce-overhead"`` took CaMN's paper preset (bf16) from 112 to 57 ms per step at batch 256 and,
        with ``deterministic=False``, from 235 to 146 ms at 1024 (README, "Using real BEAT"). Every
        trainable model's pass compiled with inductor on the CPU (README; HA2G's since its style loss gathers
        its permutation, tested; on an H200 ``"reduce-overhead"`` took HA2G's paper-preset step, bf16 at batch
        512, from 375 to 273 ms). A compiled pass draws dropout
        masks with inductor's own generator: seeded, repeatable, but not the eager run's masks.
    audio_matmul : {"auto", "on", "off"}
        How the model's one-channel raw-audio blocks (CaMN's first waveform block) compute their two
        first convolutions while ``fit`` trains: ``"on"``, as one matrix product of the waveform's frames
        (:func:`beatlite.models.layers.use_frame_matmul`: the same parameters, the same values to float
        rounding); ``"off"``, as convolution kernels; ``"auto"`` (default): ``"on"`` on CUDA, ``"off"``
        elsewhere (:meth:`frame_matmul`). The model keeps the switch after ``fit``; checkpoints do not record
        it. On an H200 it took CaMN's compiled paper-preset step (bf16, batch 1024, ``deterministic=False``)
        from 141 to 69 ms (README, "Using real BEAT"). On the CPU the kernels stay, so CPU runs train the
        recorded numbers.
    micro_batches : int
        Split every batch into this many micro-batches whose gradients are averaged before the step
        (gradient accumulation: the same step in less memory). Under ``torchrun`` with K processes a
        batch is split into ``max(micro_batches, K)`` parts spread over the processes, so K processes
        and one process with ``micro_batches=K`` take the same steps (BatchNorm statistics are per
        micro-batch in both). ``batch_size`` must be at least twice the parts (BatchNorm needs 2 windows per
        micro-batch): :func:`beatlite.train.fit` raises ``ValueError`` otherwise
        (:func:`beatlite.train.training.check_batch_split`).

    Examples
    --------
    Without ``lr``, the learning rate follows the batch size, ``5e-4 * 128 / 256``; the cosine schedule halves
    it at the middle epoch, ``(1 + cos(pi / 2)) / 2``, and reaches 0 at the end:

    >>> config = TrainConfig(epochs=4, batch_size=128, lr_schedule="cosine")
    >>> config.learning_rate, [round(config.lr_factor(e), 4) for e in range(5)]
    (0.00025, [1.0, 0.8536, 0.5, 0.1464, 0.0])

    What a checkpoint records names no folder of this machine:

    >>> TrainConfig(checkpoint="/home/alice/run/camn_tiny.pt").to_dict()["checkpoint"]
    'camn_tiny.pt'
    >>> TrainConfig(batch_size=1)
    Traceback (most recent call last):
    ...
    ValueError: TrainConfig: batch_size must be >= 2 (BatchNorm), got 1
    """

    epochs: int = 30
    batch_size: int = 64
    lr: float | None = None
    lr_schedule: str = "constant"
    betas: tuple[float, float] = (0.5, 0.999)
    d_lr_weight: float = 0.2
    seed: int = 2021
    windows_per_epoch: int | None = None
    threads: int | None = None
    no_adv_epochs: int | None = None
    grad_clip: float = 200.0
    checkpoint: str | Path | None = None
    resume: bool = False
    progress: bool = True
    device: str = "cpu"
    amp: bool = False
    micro_batches: int = 1
    workers: int = 0
    checkpoint_every: int | None = None
    val_every: int | None = None
    data_on_device: str = "auto"
    compile: str | None = None
    deterministic: bool = True
    audio_matmul: str = "auto"

    def __post_init__(self) -> None:
        if self.epochs < 0:
            raise ValueError(f"TrainConfig: epochs must be >= 0, got {self.epochs}")
        if self.batch_size < 2:
            raise ValueError(f"TrainConfig: batch_size must be >= 2 (BatchNorm), got {self.batch_size}")
        if self.lr is not None and not self.lr > 0:
            raise ValueError(f"TrainConfig: lr must be positive, got {self.lr}")
        if self.lr_schedule not in LR_SCHEDULES:
            raise ValueError(
                f"TrainConfig: lr_schedule must be one of {LR_SCHEDULES}, got {self.lr_schedule!r}"
            )
        if self.windows_per_epoch is not None and self.windows_per_epoch < 2:
            raise ValueError(f"TrainConfig: windows_per_epoch must be >= 2, got {self.windows_per_epoch}")
        if self.checkpoint_every is not None and self.checkpoint_every < 1:
            raise ValueError(
                f"TrainConfig: checkpoint_every must be >= 1 or None, got {self.checkpoint_every}"
            )
        if self.val_every is not None and self.val_every < 1:
            raise ValueError(f"TrainConfig: val_every must be >= 1 or None, got {self.val_every}")
        if self.data_on_device not in DATA_ON_DEVICE:
            raise ValueError(
                f"TrainConfig: data_on_device must be one of {DATA_ON_DEVICE}, got {self.data_on_device!r}"
            )
        if self.compile is not None and self.compile not in COMPILE_MODES + COMPILE_BACKENDS:
            raise ValueError(
                f"TrainConfig: compile must be None or one of {COMPILE_MODES + COMPILE_BACKENDS}, "
                f"got {self.compile!r}"
            )
        if self.audio_matmul not in AUDIO_MATMUL:
            raise ValueError(
                f"TrainConfig: audio_matmul must be one of {AUDIO_MATMUL}, got {self.audio_matmul!r}"
            )
        if self.workers < 0:
            raise ValueError(f"TrainConfig: workers must be >= 0, got {self.workers}")
        if self.micro_batches < 1:
            raise ValueError(f"TrainConfig: micro_batches must be >= 1, got {self.micro_batches}")
        if self.threads is not None and self.threads < 1:
            raise ValueError(f"TrainConfig: threads must be >= 1, got {self.threads}")
        self.betas = (float(self.betas[0]), float(self.betas[1]))

    def torch_device(self) -> Any:
        """The resolved ``torch.device`` (imports torch); ``ValueError`` for a name torch does not know or CUDA on a
        machine without it."""
        import torch

        name = ("cuda" if torch.cuda.is_available() else "cpu") if self.device == "auto" else self.device
        try:
            device = torch.device(name)
        except RuntimeError as exc:  # e.g. "gpu", "cuda:x"
            raise ValueError(f"TrainConfig: device {self.device!r} is not a torch device ({exc})") from None
        if device.type == "cuda" and not torch.cuda.is_available():
            raise ValueError(
                f"TrainConfig: device {self.device!r} asked for CUDA, which this machine does not have"
            )
        return device

    def frame_matmul(self, device: Any) -> bool:
        """Whether ``fit`` on ``device`` (a ``torch.device``) computes raw-audio blocks as a matrix product
        (:attr:`audio_matmul`).

        >>> import torch
        >>> config = TrainConfig()
        >>> config.frame_matmul(torch.device("cuda")), config.frame_matmul(torch.device("cpu"))
        (True, False)
        >>> TrainConfig(audio_matmul="on").frame_matmul(torch.device("cpu"))
        True
        """
        if self.audio_matmul == "auto":
            return device.type == "cuda"
        return self.audio_matmul == "on"

    @property
    def learning_rate(self) -> float:
        """The generator learning rate actually used (``lr`` or ``5e-4 * batch_size / 256``)."""
        return float(self.lr) if self.lr is not None else 5e-4 * self.batch_size / 256

    def lr_factor(self, epoch: int) -> float:
        """Multiplier of both learning rates during 0-based ``epoch`` (see ``lr_schedule``)."""
        if self.lr_schedule == "constant" or self.epochs <= 0:
            return 1.0
        return 0.5 * (1.0 + math.cos(math.pi * min(epoch, self.epochs) / self.epochs))

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly dict, what a checkpoint records as ``"train_config"``: ``checkpoint`` as
        :func:`beatlite.paths.shareable` writes it (relative to the repository, else the file's name: no
        absolute path of this machine)."""
        d = dataclasses.asdict(self)
        d["checkpoint"] = None if self.checkpoint is None else shareable(self.checkpoint)
        return d
