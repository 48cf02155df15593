"""Generation of whole takes of any length with any :class:`~beatlite.models.base.GestureModel`.

The take is cut into 34-frame units with stride 30 (docs/reference_code.md#ha2g-inference): unit ``k``
covers frames ``[30 k, 30 k + 34)``; its seed (first ``n_pre = 4`` frames) is the
ground-truth seed for ``k = 0`` and the previous unit's last 4 output frames
afterwards; the 4 overlapping frames are linearly cross-faded
(weights ``linspace(0, 1, 4)`` for the new unit). Audio and mel slices follow the
unit's *time* axis (the reference sliced the spectrogram along its mel axis, a bug).
The last unit is padded (edge frames, silent audio) and the result cropped to T frames.

Taught in notebooks/05_camn.ipynb, section 5 (generating a whole take).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence

import numpy as np
import torch

from beatlite.constants import FPS, GENERATION_STRIDE, SR, WINDOW_LENGTH
from beatlite.data.normalize import Normalizers
from beatlite.data.windows import MEL_SETTINGS, mel_frames
from beatlite.io.motion import Motion
from beatlite.models.base import GestureModel
from beatlite.skeleton.beat import beat_skeleton, expand_subset
from beatlite.skeleton.ted import directions_to_ted_positions
from beatlite.train.training import model_device

UNIT = WINDOW_LENGTH
STRIDE = GENERATION_STRIDE


@dataclasses.dataclass(eq=False)
class GeneratedTake:
    """The result of :func:`generate` for one take.

    Attributes
    ----------
    pose : (T, D) float32
        Output in the model's normalised representation (D = 141 or 126).
    representation : str
        ``"euler141"`` or ``"dirvec126"``.
    motion : Motion or None
        Euler models: a 228-channel BEAT :class:`Motion` at 15 fps (the 141 predicted
        channels denormalised to degrees, every other channel 0 = rest pose, root at the
        origin). ``None`` for direction models (no IK).
    positions : (T, 43, 3) float64 or None, centimetres
        Direction models: TED-43 joint positions from the denormalised unit directions
        and the BEAT rest-pose bone lengths (root at the origin; the common space of the
        results tables, :func:`beatlite.skeleton.ted.rest_bone_lengths`). Euler models: ``None``
        (use ``motion.positions()``).
    fps : float
        15.
    """

    pose: np.ndarray
    representation: str
    motion: Motion | None
    positions: np.ndarray | None
    fps: float = float(FPS)


def _unit_slice(a: np.ndarray, start: int, length: int) -> np.ndarray:
    """Frames ``[start, start + length)`` of ``a`` (axis 0), edge-padded past the end."""
    part = a[start : start + length]
    if part.shape[0] < length:
        if part.shape[0] == 0:
            raise ValueError(f"unit start {start} is past the end ({a.shape[0]} frames)")
        pad = np.repeat(part[-1:], length - part.shape[0], axis=0)
        part = np.concatenate([part, pad], axis=0)
    return part


def _zero_padded(a: np.ndarray, start: int, length: int) -> np.ndarray:
    part = a[start : start + length]
    if part.shape[0] < length:
        part = np.concatenate([part, np.zeros((length - part.shape[0], *a.shape[1:]), dtype=a.dtype)], axis=0)
    return part


def unit_streams(streams: Mapping[str, np.ndarray], start: int, keys: Sequence[str]) -> dict[str, np.ndarray]:
    """The unit starting at frame ``start`` of whole-take ``streams``, as numpy arrays of their own dtypes.

    Frame streams are sliced ``[start, start + 34)`` (edge-padded), audio samples
    ``[floor(start * 16000 / 15), + floor(34 / 15 * 16000))`` (zero-padded), mel frames
    ``[floor(a0 / 512), + 70)`` with ``a0`` the unit's first audio sample (edge-padded, as
    :mod:`beatlite.data.windows` slices the whole-take log-mel), ``speaker`` is copied.

    Examples
    --------
    The last unit of a 100-frame take starts at frame 90: 10 real frames, then frame 99 repeated; its
    36266 audio samples hold the take's last ``floor(10 / 15 * 16000) = 10666``, then silence.

    >>> take = {"pose": np.arange(100.0)[:, None] * np.ones(141), "audio": np.ones(106666, np.float32)}
    >>> unit = unit_streams(take, 90, ("pose", "audio"))
    >>> unit["pose"].shape, unit["pose"][[0, 9, 10, 33], 0]
    ((34, 141), array([90., 99., 99., 99.]))
    >>> unit["audio"].shape, int(unit["audio"].sum())
    ((36266,), 10666)
    """
    n_samples = int(np.floor(UNIT / FPS * SR))
    out: dict[str, np.ndarray] = {}
    for key in keys:
        a = np.asarray(streams[key])
        if key == "speaker":
            out[key] = a
        elif key == "audio":
            out[key] = _zero_padded(a, int(start * SR // FPS), n_samples)
        elif key == "mel":
            out[key] = _unit_slice(
                a, int(start * SR // FPS) // MEL_SETTINGS["hop_length"], mel_frames(n_samples)
            )
        else:
            out[key] = _unit_slice(a, start, UNIT)
    return out


def unit_batch(
    streams: Mapping[str, np.ndarray], start: int, keys: tuple[str, ...]
) -> dict[str, torch.Tensor]:
    """The one-window batch (B = 1) of the unit starting at frame ``start`` (:func:`unit_streams` as tensors:
    integers as int64, the rest float32, ``speaker`` of shape (1,)).

    Examples
    --------
    >>> take = {"pose": np.zeros((100, 141)), "word": np.ones(100, np.int32), "speaker": np.int64(2)}
    >>> for key, value in unit_batch(take, 0, ("pose", "word", "speaker")).items():
    ...     print(key, tuple(value.shape), value.dtype)
    pose (1, 34, 141) torch.float32
    word (1, 34) torch.int64
    speaker (1,) torch.int64
    """
    batch: dict[str, torch.Tensor] = {}
    for key, part in unit_streams(streams, start, keys).items():
        if key == "speaker":
            batch[key] = torch.from_numpy(np.asarray(part, dtype=np.int64).reshape(1))
            continue
        dtype = np.int64 if part.dtype.kind in "iu" else np.float32
        batch[key] = torch.from_numpy(np.ascontiguousarray(part.astype(dtype))[None])
    return batch


def generate_sequence(
    model: GestureModel, streams: Mapping[str, np.ndarray], *, stride: int = STRIDE
) -> np.ndarray:
    """Generate a whole sequence in the model's normalised representation.

    Parameters
    ----------
    model : GestureModel
        Any trained model (put in eval mode for the call).
    streams : mapping
        Whole-take inputs: ``model.target_key`` (T, D) float (only frames 0..3 are read,
        the seed), per-frame ``"face"`` (T, 51), ``"word"``/``"emotion"`` (T,) int,
        ``"semantic"`` (T,), ``"audio"`` (S,) 16 kHz, ``"mel"`` (M, 128) log-mel of the
        whole take (hop 512), ``"speaker"`` int — those the model reads.
    stride : int
        Frames between unit starts (30; must be in [1, 34 - n_pre]).

    Returns
    -------
    (T, D) float32

    Examples
    --------
    A mean-pose model outputs its stored pose on every frame, so the 4 units of a 100-frame take (starts 0,
    30, 60, 90) and their cross-fades give that pose on all 100 frames:

    >>> model = GestureModel.from_config({"name": "mean_pose"})
    >>> _ = model.mean.copy_(torch.linspace(-1.0, 1.0, 141))
    >>> out = generate_sequence(model, {"pose": np.zeros((100, 141), np.float32)})
    >>> out.shape, out.dtype, bool(np.allclose(out, np.linspace(-1.0, 1.0, 141)))
    ((100, 141), dtype('float32'), True)
    """
    return generate_sequences(model, [streams], stride=stride)[0]


def generate_sequences(
    model: GestureModel, takes: Sequence[Mapping[str, np.ndarray]], *, stride: int = STRIDE
) -> list[np.ndarray]:
    """:func:`generate_sequence` for several takes at once, their units batched in lock-step.

    Unit ``i`` of every take that has one goes through the model in one batch (B = number of
    takes still running), so a test set is generated several times faster than take by take. For a model that
    does not sample, each take's result equals :func:`generate_sequence` on it alone (up to float rounding); a
    model that samples (random clip, A2G, the joint embedding, DiffGesture) draws the noise of a whole batch from
    one generator, so a take's draws depend on the other takes of the set and their order (the same set, order
    and seed give the same numbers).

    Parameters
    ----------
    model : GestureModel
    takes : sequence of mappings
        Whole-take streams as for :func:`generate_sequence`.
    stride : int
        Frames between unit starts.

    Returns
    -------
    list of (T_i, D) float32

    Examples
    --------
    Two takes of 50 and 100 frames: each keeps its length, and a model that does not sample gives each what it
    gives the take alone.

    >>> model = GestureModel.from_config({"name": "mean_pose"})
    >>> _ = model.mean.copy_(torch.linspace(-1.0, 1.0, 141))
    >>> takes = [{"pose": np.zeros((50, 141))}, {"pose": np.zeros((100, 141))}]
    >>> outs = generate_sequences(model, takes)
    >>> [out.shape for out in outs], bool(np.allclose(outs[1], generate_sequence(model, takes[1])))
    ([(50, 141), (100, 141)], True)
    """
    keys = tuple(k for k in dict.fromkeys(model.input_keys) if k != model.target_key)
    if not 1 <= stride <= UNIT - model.n_pre:
        raise ValueError(f"stride must be in [1, {UNIT - model.n_pre}], got {stride}")
    plans = [_UnitPlan.of(model, streams, keys, stride, n) for n, streams in enumerate(takes)]
    device = model_device(model)
    for i in range(max((len(p.starts) for p in plans), default=0)):
        active = [p for p in plans if i < len(p.starts)]
        batches = [p.unit_batch(i, keys, model) for p in active]
        batch = {k: torch.cat([b[k] for b in batches]).to(device) for k in batches[0]}
        units = model.generate(batch).float().cpu().numpy()
        for unit, plan in zip(units, active, strict=True):
            plan.place(i, unit, stride)
    return [p.out[: p.n_frames] for p in plans]


@dataclasses.dataclass(eq=False)
class _UnitPlan:
    """One take's generation units: their starts, the running seed and the output being assembled."""

    streams: Mapping[str, np.ndarray]
    starts: list[int]
    seed: np.ndarray
    out: np.ndarray
    n_frames: int

    @classmethod
    def of(
        cls,
        model: GestureModel,
        streams: Mapping[str, np.ndarray],
        keys: tuple[str, ...],
        stride: int,
        n: int,
    ) -> _UnitPlan:
        target_key, dim, n_pre = model.target_key, model.pose_dim, model.n_pre
        missing = [k for k in (*keys, target_key) if k not in streams]
        if missing:
            raise KeyError(f"generate_sequence: streams lack {missing} needed by {type(model).__name__}")
        target = np.asarray(streams[target_key], dtype=np.float32)
        if target.ndim != 2 or target.shape[1] != dim:
            raise ValueError(f"take {n}: streams[{target_key!r}] must be (T, {dim}), got {target.shape}")
        t = target.shape[0]
        if t < n_pre:
            raise ValueError(f"take {n} has {t} frames, fewer than the {n_pre} seed frames")
        starts = [0]
        while starts[-1] + UNIT < t:
            starts.append(starts[-1] + stride)
        return cls(streams, starts, target[:n_pre], np.zeros((starts[-1] + UNIT, dim), np.float32), t)

    def unit_batch(self, i: int, keys: tuple[str, ...], model: GestureModel) -> dict[str, torch.Tensor]:
        """Unit ``i``'s one-window batch, its target holding only the seed frames."""
        batch = unit_batch(self.streams, self.starts[i], keys)
        seed = np.zeros((1, UNIT, model.pose_dim), np.float32)
        seed[0, : model.n_pre] = self.seed
        batch[model.target_key] = torch.from_numpy(seed)
        return batch

    def place(self, i: int, unit: np.ndarray, stride: int) -> None:
        """Write unit ``i`` into the output, cross-fading the seed frames, and take the next seed."""
        n_pre, start = len(self.seed), self.starts[i]
        if i == 0:
            self.out[:UNIT] = unit
        else:
            fade = np.linspace(0.0, 1.0, n_pre, dtype=np.float32)[:, None]
            self.out[start : start + n_pre] = (1 - fade) * self.out[start : start + n_pre] + fade * unit[
                :n_pre
            ]
            self.out[start + n_pre : start + UNIT] = unit[n_pre:]
        self.seed = unit[stride : stride + n_pre]


def generate(
    model: GestureModel, take: Mapping[str, np.ndarray], *, normalizers: Normalizers | None = None
) -> GeneratedTake:
    """Generate a whole take of any length and return it as motion / positions.

    Parameters
    ----------
    model : GestureModel
        A trained model.
    take : mapping
        Whole-take streams as for :func:`generate_sequence` (the per-take arrays that
        the window builder cuts windows from).
    normalizers : Normalizers, optional
        The train statistics the model was trained with (``Windows.normalizers``, or
        ``Normalizers.from_meta(checkpoint["meta"])``). Without them only :attr:`GeneratedTake.pose`
        is filled.

    Returns
    -------
    GeneratedTake

    Examples
    --------
    The shipped mean-pose baseline on a 3-second take: with the train statistics of its checkpoint the pose
    becomes a 228-channel BEAT motion at 15 fps whose every frame is the mean pose in degrees
    (``z * std + mean``).

    >>> from beatlite.train.checkpoint import load_model
    >>> model, checkpoint = load_model("mean_pose")
    >>> normalizers = Normalizers.from_meta(checkpoint["meta"])
    >>> take = generate(model, {"pose": np.zeros((45, 141), np.float32)}, normalizers=normalizers)
    >>> take.representation, take.pose.shape, take.motion.channels.shape, take.motion.fps, take.positions
    ('euler141', (45, 141), (45, 228), 15.0, None)
    >>> degrees = normalizers.inverse_transform(model.mean.numpy(), "euler141")
    >>> expected = expand_subset(degrees[None], "spine_neck_141", beat_skeleton())
    >>> bool(np.allclose(take.motion.channels, expected, atol=1e-4))  # degrees, float32 cross-fades
    True
    """
    pose = generate_sequence(model, take)
    motion = positions = None
    if normalizers is not None:
        values = normalizers.inverse_transform(pose, model.representation)
        if model.representation == "euler141":
            skeleton = beat_skeleton()
            motion = Motion(skeleton, expand_subset(values, "spine_neck_141", skeleton), FPS)
        else:
            positions = directions_to_ted_positions(values)
    return GeneratedTake(pose=pose, representation=model.representation, motion=motion, positions=positions)
