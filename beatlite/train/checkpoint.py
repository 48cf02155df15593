"""Atomic, resumable checkpoints of gesture models (torch).

A checkpoint is a ``torch.save`` dict::

    {"format": "beatlite-checkpoint/1",
     "model": model.to_config(),           # {"name": ..., **config fields}
     "state": model.state_dict(),          # float32 (float16 in exported files)
     "epoch": completed epochs, "history": [per-epoch loss dicts],
     "fingerprint": data fingerprint (str), "train_config": TrainConfig.to_dict(),
     "meta": {...}                          # e.g. normalisation statistics for generation
     "steps": optimiser steps done over the whole run,
     # training checkpoints only:
     "optimizer", "d_optimizer", "rng": torch's CPU generator state (process 0's),
     "rng_processes": every process's, in rank order (under torchrun; None with one process)}

Files are written to a temporary file in the same folder and moved into place with
:func:`os.replace`, so a crash never leaves a half-written checkpoint.

Loading never runs code from the file: :func:`load_checkpoint` uses ``torch.load(weights_only=True)``
(tensors and plain Python values only). numpy arrays in the metadata (nested in dicts and lists too) are
saved as tensors of their dtype and given back as numpy arrays; checkpoints written before that (numpy arrays
pickled as such, e.g. the shipped ones) load through an allow-list (:data:`NUMPY_ARRAY_GLOBALS`: an ndarray's reconstructor, its
class, ``numpy.dtype`` and the numeric dtype classes), which rebuilds arrays and nothing else.

Taught in notebooks/05_camn.ipynb, section 4 (training: loading a shipped checkpoint) and notebooks/07_benchmark.ipynb, section 1 (exporting one).
"""

from __future__ import annotations

import zipfile
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import torch

from beatlite import paths
from beatlite.io.atomic import atomic_write
from beatlite.io.errors import FormatError
from beatlite.io.textfile import ZIP_MEMBER_ERRORS, describe_bytes, zip_members
from beatlite.models.base import GestureModel

FORMAT = "beatlite-checkpoint/1"


def _numpy_array_globals() -> list[Any]:
    try:  # numpy >= 2
        from numpy._core.multiarray import _reconstruct
    except ImportError:  # pragma: no cover - numpy 1.x
        from numpy.core.multiarray import _reconstruct
    numeric = (np.float64, np.float32, np.float16, np.int64, np.int32, np.int16, np.int8, np.uint8, np.bool_)
    return [_reconstruct, np.ndarray, np.dtype, *(type(np.dtype(t)) for t in numeric)]


#: What ``weights_only`` loading may rebuild besides tensors: numpy arrays of older checkpoints' metadata.
NUMPY_ARRAY_GLOBALS = _numpy_array_globals()


def _nested(value: Any, leaf: Callable[[Any], Any], memo: dict[int, Any], key: Any = None) -> Any:
    """``value`` with its dicts (mappings), lists and tuples copied and every other object through ``leaf``;
    dict keys through ``key`` (default: kept).

    Each object is converted once (``memo``, by ``id``): what ``value`` shares stays shared, and a container
    holding itself stays a cycle, so the work and the copy are the size of ``value``'s objects, not of its
    paths (10 KB of metadata nesting each level twice, 40 deep, is 2**40 paths).
    """
    if id(value) in memo:
        return memo[id(value)]
    if isinstance(value, Mapping):
        memo[id(value)] = out = {}
        out.update(((k if key is None else key(k)), _nested(v, leaf, memo, key)) for k, v in value.items())
        return out
    if isinstance(value, list):
        memo[id(value)] = out = []
        out.extend(_nested(v, leaf, memo, key) for v in value)
        return out
    if isinstance(value, tuple):
        memo[id(value)] = out = type(value)(_nested(v, leaf, memo, key) for v in value)
        return out
    memo[id(value)] = out = leaf(value)
    return out


def _tensors_for_numpy(value: Any, other: Any = None) -> Any:
    """``value`` with every numpy array (in dicts, lists, tuples) as a tensor and numpy scalars as Python ones;
    anything else that is not a tensor or a plain value, and dict keys that are not int or str, go through
    ``other`` (default: kept as they are). Shared parts stay shared (:func:`_nested`)."""

    def leaf(v: Any) -> Any:
        if isinstance(v, np.ndarray):
            return torch.from_numpy(np.array(v))
        if isinstance(v, np.generic):
            return v.item()
        plain = torch.is_tensor(v) or v is None or isinstance(v, bool | int | float | str)
        return v if other is None or plain else other(v)

    key = None if other is None else (lambda k: k if isinstance(k, int | str) else other(k))
    return _nested(value, leaf, {}, key)


def save_checkpoint(path: str | Path, payload: Mapping[str, Any]) -> Path:
    """``torch.save(payload)`` atomically (:func:`beatlite.io.atomic.atomic_write`: a temp file
    ``.{name}.{pid}.*.tmp`` in the same folder, fsync, ``os.replace``; temp files of killed writers
    are removed by the next save). Numpy arrays of ``payload["meta"]`` are stored as tensors.

    Parameters
    ----------
    path : str or Path
        The file to write (its folders are created).
    payload : mapping
        The checkpoint dict (module docstring): ``"format"``, ``"model"``, ``"state"``, ...

    Returns
    -------
    Path
        The written path.

    Examples
    --------
    A mean-pose model's checkpoint, written into a new folder and read back: the metadata's float32 array
    comes back as it was, and no temporary file is left beside it.

    >>> import tempfile
    >>> model = GestureModel.from_config({"name": "mean_pose"})
    >>> payload = {"format": FORMAT, "model": model.to_config(), "state": model.state_dict(),
    ...            "meta": {"pose_std": np.full(3, 2.5, dtype=np.float32)}}
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = save_checkpoint(Path(tmp) / "run" / "mean.pt", payload)
    ...     back = load_checkpoint(path)
    ...     print([p.name for p in path.parent.iterdir()], back["model"], back["meta"]["pose_std"])
    ['mean.pt'] {'name': 'mean_pose', 'preset': 'tiny'} [2.5 2.5 2.5]
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_write(path, "wb") as fh:
        torch.save({**payload, "meta": _tensors_for_numpy(payload.get("meta", {}))}, fh)
    return path


def read_plain(path: Path) -> Any:
    """``torch.load(path, weights_only=True)`` on the CPU: tensors, plain values and :data:`NUMPY_ARRAY_GLOBALS` only.

    A ZIP file (what ``torch.save`` writes, members stored uncompressed) is first checked from its directory
    (:func:`beatlite.io.textfile.zip_members`), so a decompression bomb is refused before anything is inflated.
    Shared by :func:`load_checkpoint` and :func:`beatlite.metrics.extractor.load_extractor`.

    Raises
    ------
    PermissionError
        The file cannot be read.
    beatlite.io.FormatError
        Truncated or damaged (a ZIP member failing its CRC-32 included), a decompression bomb, or a pickle of
        anything but tensors and plain values (refused, never executed).

    Examples
    --------
    Any ``torch.save`` of tensors and plain values reads; a pickled object (here a path) is refused unread.

    >>> import pathlib, tempfile
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     torch.save({"w": torch.ones(2), "step": 3}, Path(tmp) / "plain.pt")
    ...     print(read_plain(Path(tmp) / "plain.pt"))
    ...     torch.save({"data": pathlib.PurePosixPath("/data")}, Path(tmp) / "object.pt")
    ...     try:
    ...         read_plain(Path(tmp) / "object.pt")
    ...     except FormatError as err:
    ...         print("refused:", "not a plain torch checkpoint" in str(err))
    {'w': tensor([1., 1.]), 'step': 3}
    refused: True
    """
    if zipfile.is_zipfile(path):
        zip_members(path)
        _check_crcs(path)
    try:
        with torch.serialization.safe_globals(NUMPY_ARRAY_GLOBALS):
            data = torch.load(path, map_location="cpu", weights_only=True)
    except PermissionError:
        raise  # unreadable, not damaged
    except Exception as exc:  # noqa: BLE001 - any unpickling failure is a format problem
        if isinstance(exc, EOFError | OSError) or "zip archive" in str(exc):  # cut short, or bytes damaged
            reason = (str(exc).splitlines() or [""])[0].split(". ")[0] or type(exc).__name__
            raise FormatError(
                path,
                f"truncated or corrupted file ({reason}): write it again, e.g. train again or copy it anew",
            ) from None
        globals_ = [ln.strip() for ln in str(exc).splitlines() if "GLOBAL" in ln]
        if globals_:  # a pickled object the safe loader blocks: what convert_legacy(trust=True) is for
            raise FormatError(
                path,
                f"not a plain torch checkpoint (tensors and plain values only): {globals_[0]}; if you trust where "
                "the file comes from, beatlite.train.checkpoint.convert_legacy(path, new_path, trust=True) rewrites it",
            ) from None
        with open(path, "rb") as fh:
            head = fh.read(64)
        first = (str(exc).strip().splitlines() or [""])[0]
        raise FormatError(
            path,
            f"not a torch checkpoint ({type(exc).__name__}{': ' + first if first else ''}); it starts with "
            f"{describe_bytes(head)}",
        ) from None
    return data


def _check_crcs(path: Path) -> None:
    """Every member's CRC-32, which ``torch.load`` does not check: a flipped byte in a tensor's data loads as a
    silently different weight."""
    try:
        with zipfile.ZipFile(path) as z:
            bad = z.testzip()
        reason = None if bad is None else f"member {bad} fails its CRC-32 check"
    except (*ZIP_MEMBER_ERRORS, ValueError) as exc:  # a damaged member name, an unknown method, encryption
        reason = " ".join(str(exc).split())
    if reason is not None:
        raise FormatError(
            path, f"truncated or corrupted file ({reason}): write it again, e.g. train again or copy it anew"
        )


def load_checkpoint(path: str | Path) -> dict[str, Any]:
    """Read a checkpoint dict on the CPU, running no code from the file (``weights_only=True``).

    The metadata's arrays, nested in dicts, lists and tuples too, come back as numpy arrays of their dtype
    (saved as tensors, or as numpy arrays by older checkpoints: :data:`NUMPY_ARRAY_GLOBALS`; a floating dtype
    numpy lacks, e.g. bfloat16, as float64).

    Raises
    ------
    FileNotFoundError
        No file at ``path``.
    beatlite.io.FormatError
        The file is truncated or corrupted, is not a beatlite checkpoint, or holds anything but tensors and
        plain values (a pickled object that would run code when loaded is refused, never executed).

    Examples
    --------
    The shipped mean-pose checkpoint: the model's config, its one buffer (the 141 pose channels) and the
    train split's normalisation statistics, 141 Euler channels and 126 direction-vector ones.

    >>> data = load_checkpoint(paths.checkpoints_dir() / "mean_pose.pt")
    >>> data["format"], data["model"]["name"], tuple(data["state"]["mean"].shape)
    ('beatlite-checkpoint/1', 'mean_pose', (141,))
    >>> data["meta"]["pose_mean"].shape, data["meta"]["dirvec_mean"].shape
    ((141,), (126,))
    """

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"checkpoint not found: {path}")
    data = read_plain(path)
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise FormatError(path, f"not a beatlite checkpoint (missing format {FORMAT!r})", field="format")
    for key in ("model", "state"):
        if key not in data:
            raise FormatError(path, f"checkpoint has no {key!r}", field=key)
    if isinstance(
        data.get("meta"), dict
    ):  # every tensor, nested too, as a numpy array: the inverse of the save
        memo: dict[int, Any] = {}
        data["meta"] = {
            k: _nested(v, lambda t, k=k: _meta_array(path, k, t) if torch.is_tensor(t) else t, memo)
            for k, v in data["meta"].items()
        }
    return data


def _meta_array(path: Path, key: Any, value: torch.Tensor) -> np.ndarray:
    """A metadata tensor as a numpy array of its dtype (floating dtypes numpy lacks, bfloat16, float8, as float64):
    detached and dense first; a tensor numpy cannot hold (quantized, ...) is a FormatError naming it."""
    try:
        dense = value.detach().to_dense()
        if dense.is_floating_point() and dense.dtype not in (torch.float16, torch.float32, torch.float64):
            dense = dense.double()
        return dense.resolve_conj().numpy()
    except (TypeError, RuntimeError) as exc:
        reason = (str(exc).splitlines() or [type(exc).__name__])[0]
        raise FormatError(path, f"a tensor numpy cannot hold ({reason})", field=f"meta.{key}") from None


def check_state(state: Any, path: str | Path | None, field: str = "state") -> None:
    """Refuse weights that are not a mapping of names to dense tensors, floating ones finite.

    Raises
    ------
    beatlite.io.FormatError
        Naming ``path`` and ``field`` (and the first bad key): not a mapping, a value that is not a dense
        real tensor, or a floating tensor holding NaN or infinity.

    Examples
    --------
    >>> check_state({"w": torch.zeros(2), "steps": torch.tensor(3)}, "run.pt")  # fine: returns None
    >>> check_state({"w": torch.tensor([1.0, float("nan")])}, "run.pt")
    Traceback (most recent call last):
    ...
    beatlite.io.errors.FormatError: run.pt, field 'state': 'w': non-finite or complex weights
    """
    if not isinstance(state, Mapping):
        raise FormatError(
            path, f"expected a mapping of names to tensors, got {type(state).__name__}", field=field
        )
    for key, value in state.items():
        if not isinstance(key, str) or not torch.is_tensor(value) or value.layout != torch.strided:
            what = f"a {value.layout} tensor" if torch.is_tensor(value) else type(value).__name__
            raise FormatError(path, f"{key!r}: expected a dense tensor, got {what}", field=field)
        if value.is_complex() or (value.is_floating_point() and not bool(torch.isfinite(value).all())):
            raise FormatError(path, f"{key!r}: non-finite or complex weights", field=field)


def state_mismatch(model: torch.nn.Module, state: Mapping[str, Any]) -> str | None:
    """The first difference between ``model``'s state dict and ``state`` (names and shapes), or None.

    Examples
    --------
    A ``Linear(2, 3)`` holds ``weight`` (3, 2) and ``bias`` (3,):

    >>> layer = torch.nn.Linear(2, 3)
    >>> print(state_mismatch(layer, {"weight": torch.zeros(3, 2), "bias": torch.zeros(3)}))
    None
    >>> state_mismatch(layer, {"weight": torch.zeros(2, 3), "bias": torch.zeros(3)})
    "'weight' of shape (2, 3), the model's is (3, 2)"
    >>> state_mismatch(layer, {"weight": torch.zeros(3, 2)})
    "no weights 'bias' (the model's shape (3,))"
    """
    own = model.state_dict()
    for key, value in own.items():
        if key not in state:
            return f"no weights {key!r} (the model's shape {tuple(value.shape)})"
        shape = tuple(state[key].shape) if torch.is_tensor(state[key]) else type(state[key]).__name__
        if shape != tuple(value.shape):
            return f"{key!r} of shape {shape}, the model's is {tuple(value.shape)}"
    extra = [k for k in state if k not in own]
    return f"unexpected weights {extra[0]!r} (not in the model)" if extra else None


def model_from_checkpoint(data: Mapping[str, Any], path: str | Path | None = None) -> GestureModel:
    """Rebuild the model of a checkpoint dict and load its (float32) weights, in eval mode.

    The model is first built on torch's ``meta`` device (no memory, no initialisation) and its parameter and
    buffer names and shapes compared with ``data["state"]``, so a small file whose config asks for a huge
    model is refused before anything is allocated.

    Raises
    ------
    beatlite.io.FormatError
        ``field="state"``: not a mapping of names to dense tensors with finite floating values
        (:func:`check_state`), or weights of other names or shapes than the model its config builds (the first
        such key and both shapes named); ``path`` names the file (None: in memory).

    Examples
    --------
    A checkpoint dict built in memory: the rebuilt model holds the same weights, in eval mode.

    >>> model = GestureModel.from_config({"name": "mean_pose"})
    >>> _ = model.mean.fill_(0.5)
    >>> copy = model_from_checkpoint({"model": model.to_config(), "state": model.state_dict()})
    >>> type(copy).__name__, copy.training, bool(torch.equal(copy.mean, model.mean))
    ('MeanPose', False, True)
    """
    check_state(data["state"], path)
    try:
        with torch.device("meta"):
            skeleton = GestureModel.from_config(data["model"])
    except (
        KeyError,
        TypeError,
        ValueError,
        RuntimeError,
        AttributeError,
    ) as exc:  # unknown name, field or value
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise FormatError(path, f"the config does not build a model: {first}", field="model") from None
    why = state_mismatch(skeleton, data["state"])
    if why is not None:
        raise FormatError(path, f"the weights do not fit the model its config builds: {why}", field="state")
    model = GestureModel.from_config(data["model"])
    state = {
        k: v.float() if torch.is_tensor(v) and v.is_floating_point() else v for k, v in data["state"].items()
    }
    model.load_state_dict(state)
    return model.eval()


def load_model(path_or_name: str | Path) -> tuple[GestureModel, dict[str, Any]]:
    """Load a model from a checkpoint file or a shipped checkpoint name.

    Parameters
    ----------
    path_or_name : str or Path
        A ``.pt`` path, or a name such as ``"camn_tiny"`` looked up as
        ``beatlite.paths.checkpoints_dir() / "<name>.pt"``.

    Returns
    -------
    (GestureModel in eval mode, checkpoint dict)

    Raises
    ------
    beatlite.io.FormatError
        Not a plain beatlite checkpoint (:func:`load_checkpoint`); weights that are not finite tensors, or of
        other shapes or names than the model its config builds (field ``state``); an unknown config field.

    Examples
    --------
    The shipped mean-pose baseline by name: its pose is the train windows' mean in z-scored units, so every
    channel is near 0.

    >>> model, data = load_model("mean_pose")
    >>> type(model).__name__, model.training, data["epoch"]
    ('MeanPose', False, 0)
    >>> bool(model.mean.abs().max() < 0.1)
    True
    """

    path = Path(path_or_name)
    if path.suffix != ".pt" and not path.is_file():
        path = paths.checkpoints_dir() / f"{path_or_name}.pt"
    data = load_checkpoint(path)
    try:
        return model_from_checkpoint(data, path), data
    except FormatError:
        raise
    except (RuntimeError, KeyError, TypeError, ValueError) as exc:  # what the checks before did not foresee
        lines = [ln.strip() for ln in str(exc).strip().splitlines() if ln.strip()]
        if lines and lines[0].startswith(
            "Error(s) in loading"
        ):  # torch's header; the next line names the key
            lines = lines[1:]
        reason = (lines or [type(exc).__name__])[0]
        raise FormatError(
            path, f"the weights or config do not fit the model: {reason}", field="state"
        ) from None


def export_checkpoint(src: str | Path, dst: str | Path, *, half: bool = True, best: bool = True) -> Path:
    """Write a small inference-only copy of a training checkpoint.

    Drops the optimiser and RNG states; stores floating-point weights as float16 when
    ``half`` (:func:`model_from_checkpoint` converts them back to float32). With ``best`` and a
    ``"best"`` entry (training with ``val_score``, see :func:`beatlite.train.fit`), the exported
    weights are those of the best-scoring epoch, recorded as ``"selected"``:
    ``{"epoch": e, "score": s, "of_epochs": n}`` (and ``"step"``, the global optimiser step, when it was
    validated every ``TrainConfig.val_every`` steps); otherwise the last epoch's.

    The copy is meant to be shared: the paths it records, ``train_config["checkpoint"]`` and ``meta["data"]``,
    are written as :func:`beatlite.paths.shareable` names them (relative to the repository, else the file's or
    folder's name), also when ``src`` was written by an older beatlite with absolute ones; the data fingerprint
    identifies the data.

    Examples
    --------
    Exporting a checkpoint whose weight is 0.1 and which carries an optimiser state: the copy drops the
    optimiser and loads back within float16's rounding of 0.1 (half its spacing there, ``2**-4 * 2**-11``).

    >>> import tempfile
    >>> model = GestureModel.from_config({"name": "mean_pose"})
    >>> _ = model.mean.fill_(0.1)
    >>> payload = {"format": FORMAT, "model": model.to_config(), "state": model.state_dict(),
    ...            "optimizer": {"state": {}}, "epoch": 3}
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     small = export_checkpoint(save_checkpoint(Path(tmp) / "train.pt", payload), Path(tmp) / "small.pt")
    ...     copy, data = load_model(small)
    >>> "optimizer" in data, data["state"]["mean"].dtype, copy.mean.dtype
    (False, torch.float16, torch.float32)
    >>> bool((copy.mean - 0.1).abs().max() <= 2**-4 * 2**-11)
    True
    """
    data = load_checkpoint(src)
    keep = {
        k: v for k, v in data.items() if k not in ("optimizer", "d_optimizer", "rng", "rng_processes", "best")
    }
    keep.update(shareable_paths(keep))
    chosen = data.get("best")
    if best and chosen is not None:
        keep["state"] = chosen["state"]
        keep["selected"] = {
            "epoch": int(chosen["epoch"]),
            "score": float(chosen["score"]),
            "of_epochs": int(data.get("epoch", 0)),
        }
        if chosen.get("step") is not None:
            keep["selected"]["step"] = int(chosen["step"])
    if half:
        keep["state"] = {
            k: v.half() if torch.is_tensor(v) and v.is_floating_point() else v
            for k, v in keep["state"].items()
        }
    return save_checkpoint(dst, keep)


def shareable_paths(data: Mapping[str, Any]) -> dict[str, Any]:
    """The ``"train_config"`` and ``"meta"`` entries of checkpoint dict ``data`` with the paths they record,
    ``train_config["checkpoint"]`` and ``meta["data"]``, as :func:`beatlite.paths.shareable` writes them (no
    absolute path of the machine that trained it); the entries ``data`` lacks are left out.

    >>> shareable_paths({"train_config": {"checkpoint": "/home/alice/run/train/camn_tiny.pt", "seed": 1},
    ...                  "meta": {"data": "/home/alice/beat_english_v0.2.1"}})
    {'train_config': {'checkpoint': 'camn_tiny.pt', 'seed': 1}, 'meta': {'data': 'beat_english_v0.2.1'}}
    """
    out: dict[str, Any] = {}
    for key, field in (("train_config", "checkpoint"), ("meta", "data")):
        entry = data.get(key)
        if isinstance(entry, Mapping):
            value = entry.get(field)
            out[key] = {**entry, field: paths.shareable(value)} if isinstance(value, str) else dict(entry)
    return out


def convert_legacy(src: str | Path, dst: str | Path, *, trust: bool = False) -> Path:
    """Rewrite a checkpoint that only the full (code-running) unpickler can read as a plain one.

    For a file of a source you trust, made by an older beatlite or another tool that pickled objects
    (numpy arrays of other dtypes, ``pathlib`` paths, ...): it is loaded with ``weights_only=False``,
    which runs whatever code the file holds, so ``trust=True`` must be passed explicitly. The copy keeps
    tensors and plain values only (numpy arrays become tensors, other objects their ``str``) and then
    loads with :func:`load_checkpoint`.

    Raises
    ------
    PermissionError
        ``trust`` is not True.

    Examples
    --------
    A checkpoint that pickled a ``pathlib`` path: :func:`load_checkpoint` refuses it; the converted copy records
    the path as a string and loads.

    >>> import pathlib, tempfile
    >>> model = GestureModel.from_config({"name": "mean_pose"})
    >>> old = {"format": FORMAT, "model": model.to_config(), "state": model.state_dict(),
    ...        "meta": {"data": pathlib.PurePosixPath("/data/beat")}}
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     torch.save(old, Path(tmp) / "old.pt")
    ...     new = convert_legacy(Path(tmp) / "old.pt", Path(tmp) / "new.pt", trust=True)
    ...     print(load_checkpoint(new)["meta"])
    {'data': '/data/beat'}
    """
    if trust is not True:
        raise PermissionError(
            f"convert_legacy({src}): loading it runs any code it holds; pass trust=True only for a file you trust"
        )
    data = torch.load(Path(src), map_location="cpu", weights_only=False)  # the explicit opt-in above
    save_checkpoint(
        dst, _tensors_for_numpy(data, other=str)
    )  # tensors and plain values; other objects as str
    load_checkpoint(dst)  # the copy reads without running code
    return Path(dst)
