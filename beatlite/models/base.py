"""The interface every beatlite gesture model implements: :class:`GestureModel`.

A model maps a *window batch* (a dict of tensors, see ``docs/architecture.md``)
to a pose sequence in its normalised representation:

=============  ==================  ==========================================================
key            shape, dtype        meaning
=============  ==================  ==========================================================
``"pose"``     (B, T, 141) float   z-scored Euler degrees of ``spine_neck_141`` (euler141 models)
``"dirvec"``   (B, T, 126) float   TED-43 unit bone directions minus the train mean (dirvec126)
``"audio"``    (B, S) float        16 kHz mono waveform, S = floor(T / 15 * 16000) (36266 for T = 34)
``"mel"``      (B, M, 128) float   log-mel spectrogram (HA2G settings; M = 70 for T = 34)
``"face"``     (B, T, 51) float    ARKit blendshape weights
``"word"``     (B, T) int64        vocabulary ids per frame (0 = PAD)
``"emotion"``  (B, T) int64        emotion id 0..7 per frame
``"semantic"`` (B, T) float        semantic relevance score in [0, 1] per frame
``"speaker"``  (B,) int64          0-based speaker index
=============  ==================  ==========================================================

Contract (shared by CaMN, HA2G and the baselines; the harness in
:mod:`beatlite.train` relies on nothing else):

- class attributes ``name`` (registry name), ``representation`` (``"euler141"`` or
  ``"dirvec126"``), ``config_class`` (a dataclass with a ``preset`` field);
- ``forward(batch) -> dict`` with at least ``"pose"``: (B, T, D) in the normalised
  representation (for dirvec126 models too: the key is always ``"pose"``), in the batch's float dtype
  (float32; a float64 buffer made from numpy would promote it); ``forward`` and ``losses`` leave the batch
  unchanged (no in-place change, no key assigned: the losses and the harness read it after);
- ``losses(batch, out, *, epoch) -> dict[str, Tensor]`` (tensors, not floats) with a scalar ``"total"``
  whose backward reaches every generator parameter in every step (``torchrun`` training reduces gradients with
  DistributedDataParallel, which needs that; losses may call modules that ``forward`` does not);
- the discriminator's parameters live in the ``discriminator`` child alone, the others in child modules;
- ``discriminator``: an ``nn.Module`` or ``None``; when present,
  ``discriminator_losses(batch, out) -> dict`` with ``"total"`` and the harness runs a
  discriminator step whenever :meth:`GestureModel.adversarial_active` says so;
- ``generate(batch) -> (B, T, D)``: inference seeded only by the first ``n_pre`` frames
  of ``batch[target_key]`` (the later frames are zeroed before the forward pass), the same pose for the same
  batch (randomness of eval mode drawn from a generator seeded from the config, restarted by ``reset()``);
- ``to_config() -> dict`` / ``GestureModel.from_config(dict)`` for checkpoints;
- optional ``prepare(train_windows, normalizers=None)``: called once by ``fit`` before training with the
  training window set (a numpy window dict or a :class:`~beatlite.data.store.StoreWindows`; read it
  with :func:`window_count`, :func:`window_rows` and :func:`window_chunks`, which serve both) and the
  train split's ``Normalizers`` (used by the untrained baselines to store a mean pose / clip bank, and
  by HA2G for its angle statistics);
- optional classmethod ``keys_for(config)`` when config switches change ``input_keys``;
- classmethod ``batch_keys(config)``: every batch key read in training and evaluation (``keys_for``,
  the target and what the losses read; override it when the losses read more, as CaMN's
  ``semantic``). ``fit`` gives the model exactly these keys and a window store reads only these.

Adding a model: write the class in its own module, then ``beatlite.models.register_model(name,
"module:Class")`` and ``beatlite.train.recipes.register_recipe(checkpoint, Recipe(name, label, ...))``;
nothing else changes (``docs/architecture.md``, "Adding a model and a metric").

Torch is imported at module import time here; :mod:`beatlite.models` itself stays lazy.

Taught in notebooks/05_camn.ipynb, sections 2 (the seed input) and 3 (the semantic-weighted Huber loss).
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
from collections.abc import Iterator, Mapping, Sequence
from typing import Any, ClassVar

import numpy as np
import torch
from torch import nn

from beatlite.constants import N_PRE, WINDOW_LENGTH

Batch = dict[str, torch.Tensor]

REPRESENTATIONS: dict[str, tuple[str, int]] = {"euler141": ("pose", 141), "dirvec126": ("dirvec", 126)}
"""Representation name -> (window key of its target, channels D)."""


@dataclasses.dataclass
class ModelConfig:
    """Base of every model configuration dataclass.

    Attributes
    ----------
    preset : str
        Name of the preset the configuration started from (``"tiny"``, ``"paper"``, ...).
    """

    preset: str = "tiny"


@dataclasses.dataclass
class TextConfig(ModelConfig):
    """Fields of a model reading word ids through a :class:`~beatlite.models.layers.TextEncoderTCN`.

    Attributes
    ----------
    vocab_size, word_dim : int
        Embedding table (id 0 = PAD; the recipes set ``vocab_size`` to the corpus vocabulary and load
        pretrained vectors with :meth:`GestureModel.set_word_vectors`).
    text_hidden, text_layers : int
        Width and depth (levels) of the TCN.
    text_features : int
        Text features per frame.
    """

    vocab_size: int = 5793
    word_dim: int = 300
    text_hidden: int = 300
    text_layers: int = 4
    text_features: int = 32


@dataclasses.dataclass
class AdversarialConfig(ModelConfig):
    """Fields of a model trained with a :class:`~beatlite.models.layers.ConvDiscriminator`-style critic.

    Attributes
    ----------
    adversarial : bool
        Build the discriminator and train adversarially.
    adv_weight : float
        Weight of the generator's adversarial term.
    no_adv_epochs : int
        0-based epoch from which the adversarial term is on (:meth:`GestureModel.adversarial_active`).
    d_hidden, d_layers : int
        Width and recurrent layers of the discriminator.
    n_frames : int
        Frames T per window (the discriminator's time head is sized for it).
    """

    adversarial: bool = True
    adv_weight: float = 0.5
    no_adv_epochs: int = 10
    d_hidden: int = 64
    d_layers: int = 4
    n_frames: int = WINDOW_LENGTH


def config_from_preset(
    config_class: type, presets: Mapping[str, Mapping[str, Any]], preset: str, **overrides: Any
) -> Any:
    """Build ``config_class(**presets[preset], **overrides, preset=preset)`` with checked names.

    Parameters
    ----------
    config_class : dataclass type with a ``preset`` field
        A :class:`ModelConfig` subclass.
    presets : mapping
        Preset name -> ``{field: value}`` (what :func:`beatlite.models.presets` returns).
    preset : str
        The preset to start from (recorded in the config's ``preset`` field).
    **overrides
        Fields set on top of the preset.

    Raises
    ------
    ValueError
        Unknown preset name.
    TypeError
        An override that is not a field of ``config_class``.

    Examples
    --------
    An override wins over the preset, which wins over the dataclass default:

    >>> @dataclasses.dataclass
    ... class Config(ModelConfig):
    ...     hidden: int = 256
    ...     dropout: float = 0.1
    >>> table = {"paper": {}, "tiny": {"hidden": 32}}
    >>> config_from_preset(Config, table, "tiny", dropout=0.0)
    Config(preset='tiny', hidden=32, dropout=0.0)
    >>> config_from_preset(Config, table, "tiny", hiden=8)
    Traceback (most recent call last):
    ...
    TypeError: Config: unknown option(s) ['hiden']; known: ['dropout', 'hidden', 'preset']
    """
    if preset not in presets:
        raise ValueError(f"{config_class.__name__}: preset must be one of {sorted(presets)}, got {preset!r}")
    fields = {f.name for f in dataclasses.fields(config_class)}
    unknown = sorted(set(overrides) - fields)
    if unknown:
        raise TypeError(f"{config_class.__name__}: unknown option(s) {unknown}; known: {sorted(fields)}")
    values = {**dict(presets[preset]), **overrides, "preset": preset}
    return config_class(**values)


def seed_input(pose: torch.Tensor, n_pre: int = N_PRE) -> torch.Tensor:
    """The seed-pose input ``pre_seq`` of CaMN / HA2G / Trimodal.

    Parameters
    ----------
    pose : (B, T, D) float tensor
        Target pose sequence (normalised); only its first ``n_pre`` frames are read.
    n_pre : int
        Number of seed frames.

    Returns
    -------
    (B, T, D + 1) float tensor
        Frames ``< n_pre`` hold ``pose`` and an indicator bit 1 in the last channel;
        later frames are all zero.

    Examples
    --------
    Four frames of a 2-channel pose with two seed frames: the first two rows keep the pose and gain the bit 1,
    the last two are zero:

    >>> pose = torch.arange(1.0, 9.0).reshape(1, 4, 2)
    >>> seed_input(pose, n_pre=2)[0]
    tensor([[1., 2., 1.],
            [3., 4., 1.],
            [0., 0., 0.],
            [0., 0., 0.]])
    """
    if pose.ndim != 3:
        raise ValueError(f"pose must be (B, T, D), got shape {tuple(pose.shape)}")
    b, t, d = pose.shape
    if not 0 <= n_pre <= t:
        raise ValueError(f"n_pre must be in [0, {t}], got {n_pre}")
    pre = pose.new_zeros(b, t, d + 1)
    pre[:, :n_pre, :d] = pose[:, :n_pre]
    pre[:, :n_pre, d] = 1.0
    return pre


def huber(pred: torch.Tensor, target: torch.Tensor, beta: float = 0.1) -> torch.Tensor:
    """Mean Huber loss as the reference defines it: ``smooth_l1(pred/beta, target/beta) * beta``.

    Equals ``0.5 * d**2 / beta`` for ``|d| < beta`` and ``|d| - 0.5 * beta`` otherwise
    (``d = pred - target``), averaged over all elements.

    Parameters
    ----------
    pred, target : float tensors of one shape
        Any shape (the models pass (B, T, D) normalised poses); the loss has their units.
    beta : float > 0
        Where the loss turns from quadratic to linear, in the units of ``d``.

    Returns
    -------
    () float tensor
        The mean loss, differentiable in ``pred``.

    Raises
    ------
    ValueError
        ``beta`` is not a finite positive number (it divides: 0 gave ``nan``, a negative one a negative loss).

    Examples
    --------
    Two errors at the default ``beta = 0.1``: ``d = 0.05`` is in the quadratic part,
    ``0.5 * 0.05**2 / 0.1 = 0.0125``, and ``d = 1`` in the linear one, ``1 - 0.05 = 0.95``; the mean is 0.48125:

    >>> round(float(huber(torch.tensor([0.05, 1.0]), torch.zeros(2))), 5)
    0.48125
    """
    if not math.isfinite(beta) or beta <= 0:
        raise ValueError(f"huber: beta must be a positive number, got {beta!r}")
    return nn.functional.smooth_l1_loss(pred / beta, target / beta) * beta


#: Batch keys that hold ids (integer tensors); the others hold numbers (floating tensors).
ID_KEYS = frozenset({"word", "speaker", "emotion"})


def check_batch(batch: Mapping[str, Any], keys: tuple[str, ...], who: str) -> None:
    """Raise ``KeyError``/``TypeError`` naming ``who`` when ``batch`` lacks a key, is not a tensor, or holds ids
    that are not integers (:data:`ID_KEYS`) or numbers that are not floating point.

    Examples
    --------
    >>> check_batch({"word": torch.zeros(2, 34)}, ("word",), "CaMN.forward")
    Traceback (most recent call last):
    ...
    TypeError: CaMN.forward: batch['word'] holds ids: an integer tensor, got torch.float32
    """
    for key in keys:
        if key not in batch:
            raise KeyError(f"{who}: batch has no {key!r} (keys: {sorted(batch)})")
        value = batch[key]
        if not isinstance(value, torch.Tensor):
            raise TypeError(f"{who}: batch[{key!r}] must be a torch.Tensor, got {type(value).__name__}")
        if key in ID_KEYS and (value.is_floating_point() or value.is_complex() or value.dtype == torch.bool):
            raise TypeError(f"{who}: batch[{key!r}] holds ids: an integer tensor, got {value.dtype}")
        if key not in ID_KEYS and not value.is_floating_point():
            raise TypeError(f"{who}: batch[{key!r}] holds numbers: a floating tensor, got {value.dtype}")


@contextlib.contextmanager
def evaluating(model: nn.Module) -> Iterator[None]:
    """``model`` in eval mode inside; after, every submodule back in its own mode (one frozen in eval while the
    rest trains stays in eval, one training in an eval model trains again).

    Examples
    --------
    >>> net = nn.Sequential(nn.Linear(2, 2), nn.BatchNorm1d(2))
    >>> _ = net[1].eval()  # frozen while the rest trains
    >>> with evaluating(net):
    ...     net.training, net[0].training
    (False, False)
    >>> net.training, net[0].training, net[1].training
    (True, True, False)
    """
    modes = [(m, m.training) for m in model.modules()]
    if any(training for _, training in modes):
        model.eval()
    try:
        yield
    finally:
        for m, training in modes:
            m.training = training


def _reads_by_batch(windows: Any) -> bool:
    """Whether ``windows`` is a store view read with ``batch(indices, keys=)`` (a ``StoreWindows``)."""
    return hasattr(windows, "store") and callable(getattr(windows, "batch", None))


def _check_key(windows: Any, key: str) -> None:
    """``KeyError`` naming ``key`` and the keys there when the window set lacks it."""
    if key not in windows:
        raise KeyError(f"the windows have no {key!r} (keys: {sorted(windows.keys())})")


def window_count(windows: Any, key: str) -> int:
    """Number of windows N of a window set (a numpy window dict, ``Windows`` or ``StoreWindows``).

    Examples
    --------
    A window dict holds N windows along the first axis of every key (here 5 windows of T = 34 frames):

    >>> window_count({"pose": np.zeros((5, 34, 141)), "speaker": np.zeros(5, dtype=np.int64)}, "pose")
    5
    """
    _check_key(windows, key)
    return len(windows) if _reads_by_batch(windows) else int(np.shape(windows[key])[0])


def window_rows(windows: Any, key: str, indices: Sequence[int] | np.ndarray) -> np.ndarray:
    """``windows[key][indices]`` of a window set, reading only those rows from a window store.

    Returns
    -------
    (len(indices), ...) ndarray
        In the order of ``indices`` (repeats allowed).

    Examples
    --------
    >>> windows = {"speaker": np.array([10, 11, 12, 13])}
    >>> window_rows(windows, "speaker", [3, 0, 3])
    array([13, 10, 13])
    """
    _check_key(windows, key)
    idx = np.asarray(indices, dtype=np.int64).reshape(-1)
    if _reads_by_batch(windows):
        return windows.batch(idx, keys=[key])[key]
    return np.asarray(windows[key])[idx]


def window_chunks(windows: Any, key: str, *, max_bytes: int = 2**28) -> Iterator[np.ndarray]:
    """``windows[key]`` for every window in order, in chunks of at most ``max_bytes`` (one chunk in RAM).

    A numpy window dict (or ``Windows``) gives its whole array as one chunk; a window store is read
    chunk by chunk, so statistics over a corpus larger than memory stream (one chunk when it fits in
    ``max_bytes``: then a statistic equals the in-memory one bit for bit).

    Yields
    ------
    (n, ...) ndarray
        Consecutive windows; the ``n`` of all chunks sum to :func:`window_count`.

    Examples
    --------
    A mean over chunks, weighted by their lengths, is the mean of the whole set (here 3 windows in memory,
    one chunk):

    >>> windows = {"pose": np.arange(6.0).reshape(3, 2)}
    >>> chunks = list(window_chunks(windows, "pose"))
    >>> [c.shape for c in chunks], float(sum(c.sum() for c in chunks) / windows["pose"].size)
    ([(3, 2)], 2.5)
    """
    _check_key(windows, key)
    if not _reads_by_batch(windows):
        yield np.asarray(windows[key])
        return
    n = window_count(windows, key)
    first = window_rows(windows, key, [0])
    per = max(1, int(max_bytes // max(1, first.nbytes)))
    for start in range(0, n, per):
        yield window_rows(windows, key, np.arange(start, min(n, start + per)))


class GestureModel(nn.Module):
    """Base class of every gesture model (see the module docstring for the contract).

    Subclasses set ``name``, ``representation``, ``config_class``, ``input_keys``
    (optionally ``presets``: preset -> config overrides; else their module's ``PRESETS``) and
    implement :meth:`forward` and :meth:`losses`.

    Parameters
    ----------
    config : ModelConfig subclass instance
        The model's configuration (stored in checkpoints via :meth:`to_config`).

    Examples
    --------
    The smallest subclass: a model that echoes its target. :meth:`generate` gives it only the ``n_pre`` seed
    frames (4), so every later frame of what it returns is zero, whatever the batch held:

    >>> class Echo(GestureModel):
    ...     name = "echo"
    ...     input_keys = ("pose",)
    ...     def forward(self, batch):
    ...         return {"pose": batch["pose"] * 1.0}
    >>> model = Echo(ModelConfig())
    >>> out = model.generate({"pose": torch.ones(2, 34, 141)})
    >>> tuple(out.shape), float(out[:, : model.n_pre].mean()), float(out[:, model.n_pre :].abs().max())
    ((2, 34, 141), 1.0, 0.0)
    >>> model.to_config(), model.batch_keys(model.config), model.trainable
    ({'name': 'echo', 'preset': 'tiny'}, ('pose',), False)
    """

    name: ClassVar[str] = "base"
    representation: ClassVar[str] = "euler141"
    config_class: ClassVar[type] = ModelConfig
    input_keys: ClassVar[tuple[str, ...]] = ()
    presets: ClassVar[Mapping[str, Mapping[str, Any]] | None] = None
    inductor_failure: ClassVar[str | None] = None
    """Why ``torch.compile``'s inductor cannot compile this model's training pass (``None``: it can);
    :func:`beatlite.train.fit` then refuses ``TrainConfig.compile`` modes that use it, naming this."""
    n_pre: int = N_PRE

    def __init_subclass__(cls, **kwargs: Any) -> None:
        """Refuse an unknown ``representation`` where the class is defined (it failed later as a bare
        ``KeyError`` deep in the harness)."""
        super().__init_subclass__(**kwargs)
        if cls.representation not in REPRESENTATIONS:
            raise TypeError(
                f"{cls.__name__}: representation must be one of {sorted(REPRESENTATIONS)}, got {cls.representation!r}"
            )

    def __init__(self, config: ModelConfig) -> None:
        super().__init__()
        if not isinstance(config, self.config_class):
            raise TypeError(
                f"{type(self).__name__}: config must be {self.config_class.__name__}, "
                f"got {type(config).__name__}"
            )
        self.config = config
        self.discriminator: nn.Module | None = None

    @classmethod
    def keys_for(cls, config: ModelConfig) -> tuple[str, ...]:
        """Batch keys a model built from ``config`` reads (default: the class's ``input_keys``).

        Override it when switches in the config change the inputs (CaMN's ablations); the recipes
        ask it whether a model reads words (to give it the vocabulary and word vectors).
        """
        keys = cls.input_keys
        if isinstance(keys, property):
            raise TypeError(f"{cls.__name__}: input_keys depends on the config: define keys_for(config) too")
        return tuple(keys)

    @classmethod
    def batch_keys(cls, config: ModelConfig) -> tuple[str, ...]:
        """Every batch key a model built from ``config`` reads in training and evaluation.

        :meth:`keys_for` plus the target key (default). Override it when the losses read a key the
        forward pass does not (CaMN's ``semantic``). ``fit`` gives the model exactly these keys, and a
        window store (``store.windows(split, keys=cls.batch_keys(config))``) reads only these.
        """
        target = REPRESENTATIONS[cls.representation][0]
        return tuple(dict.fromkeys((*cls.keys_for(config), target)))

    # ---------------------------------------------------------------- representation
    @property
    def target_key(self) -> str:
        """Window key of the training target: ``"pose"`` (euler141) or ``"dirvec"`` (dirvec126)."""
        return REPRESENTATIONS[self.representation][0]

    @property
    def pose_dim(self) -> int:
        """Channels D of the output (141 or 126)."""
        return REPRESENTATIONS[self.representation][1]

    # ---------------------------------------------------------------- interface
    def forward(self, batch: Batch) -> dict[str, torch.Tensor]:  # pragma: no cover - abstract
        """Map a window batch to ``{"pose": (B, T, D), ...}`` (normalised representation)."""
        raise NotImplementedError

    def losses(self, batch: Batch, out: dict[str, torch.Tensor], *, epoch: int) -> dict[str, torch.Tensor]:
        """Generator losses; ``"total"`` is what the harness back-propagates."""
        raise NotImplementedError  # pragma: no cover - abstract

    def discriminator_losses(self, batch: Batch, out: dict[str, torch.Tensor]) -> dict[str, torch.Tensor]:
        """Discriminator losses (``"total"``); only called when :attr:`discriminator` is set."""
        raise NotImplementedError(f"{type(self).__name__} has no discriminator")

    def adversarial_active(self, epoch: int) -> bool:
        """Whether epoch ``epoch`` (0-based) trains adversarially.

        True when a discriminator exists and ``epoch >= config.no_adv_epochs``
        (``no_adv_epochs`` defaults to 0 when the config has no such field).
        """
        return self.discriminator is not None and epoch >= int(getattr(self.config, "no_adv_epochs", 0))

    def generator_parameters(self) -> list[nn.Parameter]:
        """Trainable parameters that are not part of :attr:`discriminator`."""
        d_ids = set() if self.discriminator is None else {id(p) for p in self.discriminator.parameters()}
        return [p for p in self.parameters() if p.requires_grad and id(p) not in d_ids]

    def prepare(self, train_windows: Any, normalizers: Any = None) -> None:
        """Hook called once by ``fit`` with the training window set and the train split's
        :class:`~beatlite.data.normalize.Normalizers` (None when unknown) (default: nothing).

        ``train_windows`` is a numpy window dict or a ``StoreWindows``: read it with
        :func:`window_count`, :func:`window_rows` and :func:`window_chunks`.
        """

    def word_embeddings(self) -> list[nn.Embedding]:
        """The word-embedding tables that pretrained vectors initialise (default: none; text models list theirs)."""
        return []

    def set_word_vectors(self, vectors: np.ndarray | torch.Tensor) -> None:
        """Copy pretrained word vectors ``(vocab_size, word_dim)`` into every table of
        :meth:`word_embeddings` (they stay trainable); a no-op for a model without text.

        Raises
        ------
        ValueError
            ``vectors`` does not have a table's shape.
        """
        for table in self.word_embeddings():
            values = torch.as_tensor(np.asarray(vectors), dtype=table.weight.dtype)
            if tuple(values.shape) != tuple(table.weight.shape):
                raise ValueError(
                    f"vectors must be {tuple(table.weight.shape)} (vocab_size, word_dim), got {tuple(values.shape)}"
                )
            with torch.no_grad():
                table.weight.copy_(values)

    @property
    def trainable(self) -> bool:
        """False for baselines without trainable generator parameters (``fit`` then only calls prepare)."""
        return len(self.generator_parameters()) > 0

    @torch.no_grad()
    def generate(self, batch: Batch) -> torch.Tensor:
        """Inference on a window batch seeded by its first ``n_pre`` target frames.

        Parameters
        ----------
        batch : dict of tensors
            A window batch; ``batch[target_key]`` (B, T, D) only provides the seed:
            frames ``>= n_pre`` are zeroed before the forward pass, so they cannot leak.

        Returns
        -------
        (B, T, D) float tensor
            The generated pose in the normalised representation.
        """
        check_batch(batch, (self.target_key,), f"{type(self).__name__}.generate")
        with evaluating(self):
            seeded = dict(batch)
            target = batch[self.target_key].clone()
            target[:, self.n_pre :] = 0.0
            seeded[self.target_key] = target
            return self.forward(seeded)["pose"]

    # ---------------------------------------------------------------- (de)serialisation
    def to_config(self) -> dict[str, Any]:
        """``{"name": <registry name>, **dataclasses.asdict(config)}`` (JSON-serialisable)."""
        return {"name": self.name, **dataclasses.asdict(self.config)}

    @classmethod
    def from_config(cls, config: Mapping[str, Any]) -> GestureModel:
        """Rebuild an (untrained) model from :meth:`to_config`'s dict.

        Called on :class:`GestureModel` itself it dispatches on ``config["name"]``
        through :func:`beatlite.models.model_class`.
        """
        values = dict(config)
        name = values.pop("name", cls.name)
        if cls is GestureModel:
            from beatlite.models import model_class

            return model_class(name).from_config({"name": name, **values})
        fields = {f.name for f in dataclasses.fields(cls.config_class)}
        unknown = sorted(set(values) - fields)
        if unknown:
            raise TypeError(f"{cls.__name__}.from_config: unknown field(s) {unknown}")
        return cls(cls.config_class(**values))

    def n_parameters(self) -> int:
        """Number of trainable parameters (discriminator included)."""
        return sum(p.numel() for p in self.parameters() if p.requires_grad)
