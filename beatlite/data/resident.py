"""Windows gathered on a device from the streams of a window store held in its memory (torch imported here).

A :class:`~beatlite.data.store.StoreWindows` view reads every batch from disk on the host, and the training loop
copies it to the device: on a GPU the model then waits for the host. :class:`ResidentWindows` loads, once, the
streams a model reads (its ``batch_keys``) of every take of the view into one tensor per stream on the device,
already in the form the batches have (z-scored pose and directions, audio as float32 samples, words mapped to
the vocabulary), with per-window offsets. A batch is then one indexed gather per key, on the device: no disk read,
no host copy, no DataLoader. Each take is stored once (windows overlap 3.4 times at stride 10), padded at its end
as :meth:`StoreWindows.batch <beatlite.data.store.StoreWindows.batch>` pads a window that runs past it (audio with
zeros, the mel spectrogram with its last row), so the batches equal the view's bit for bit.

:func:`beatlite.train.fit` uses it for a store view when ``TrainConfig.data_on_device`` says so (on CUDA by
default when the streams take at most half of the free GPU memory, :func:`fits_on_device`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import torch

from beatlite.data.store import KEY_STREAM, StoreWindows
from beatlite.data.windows import MEL_SETTINGS, audio_start

#: Batch keys a :class:`ResidentWindows` can hold (``take`` is a string, ``start`` an index: not model inputs).
RESIDENT_KEYS = tuple(k for k in KEY_STREAM if k not in ("take", "start"))


def resident_bytes(view: StoreWindows, keys: Sequence[str]) -> int:
    """Device memory, bytes, that :class:`ResidentWindows` ``(view, keys)`` takes: every stream of ``keys`` over
    the view's takes (float32 / int64 as in a batch) with its end padding, plus 24 bytes of offsets per window.

    Examples
    --------
    >>> from pathlib import Path
    >>> from beatlite.data.examples import example_corpus
    >>> from beatlite.data.index import index_folder
    >>> from beatlite.data.store import build_store
    >>> tmp = example_corpus()
    >>> view = build_store(index_folder(tmp.name, cache=False), Path(tmp.name) / "store").windows("test")
    >>> frames = view.store.takes[int(view.take_ids[0])].n_frames  # one test take: float32 pose rows, 3 offsets
    >>> resident_bytes(view, ("pose",)) == 4 * 141 * frames + 24 * len(view)
    True
    >>> tmp.cleanup()
    """
    takes = [view.store.takes[int(t)] for t in np.unique(view.take_ids)]
    total = 24 * len(view)
    for key in _keys(keys):
        if key == "speaker":
            total += 8 * len(view)
            continue
        stream = KEY_STREAM[key]
        per_row = int(np.prod(takes[0].meta["shapes"][stream][1:], dtype=np.int64))
        itemsize = 8 if key in ("word", "emotion") else 4
        rows = sum(_n_rows(view, key, t) for t in takes)
        total += itemsize * per_row * rows
    return int(total)


def fits_on_device(view: StoreWindows, keys: Sequence[str], device: Any, *, share: float = 0.5) -> bool:
    """Whether the streams of ``keys`` fit in ``share`` of ``device``'s free memory (CUDA); ``False`` on the CPU,
    where the store's loader keeps training memory-flat (ask for residency explicitly there).

    Examples
    --------
    >>> from pathlib import Path
    >>> from beatlite.data.examples import example_corpus
    >>> from beatlite.data.index import index_folder
    >>> from beatlite.data.store import build_store
    >>> tmp = example_corpus()
    >>> view = build_store(index_folder(tmp.name, cache=False), Path(tmp.name) / "store").windows("test")
    >>> fits_on_device(view, ("pose",), "cpu")  # the CPU route stays the memory-flat loader
    False
    >>> tmp.cleanup()
    """
    device = torch.device(device)
    if device.type != "cuda":
        return False
    free, _ = torch.cuda.mem_get_info(device)
    return resident_bytes(view, keys) <= share * free


def _pad(view: StoreWindows, key: str) -> int:
    """Rows added at the end of each take's ``key`` for windows running past it (audio: zeros; mel: its last
    row repeated)."""
    return {"audio": view.n_audio, "mel": view.n_mel}.get(key, 0)


def _n_rows(view: StoreWindows, key: str, take: Any) -> int:
    """The rows of ``key`` that :class:`ResidentWindows` holds for ``take``, from its metadata (nothing read)."""
    return int(take.meta["shapes"][KEY_STREAM[key]][0]) + _pad(view, key)


def _keys(keys: Sequence[str]) -> list[str]:
    unknown = [k for k in keys if k not in RESIDENT_KEYS]
    if unknown:
        raise KeyError(
            f"ResidentWindows: keys {unknown} cannot be held on a device (known: {list(RESIDENT_KEYS)})"
        )
    return [k for k in RESIDENT_KEYS if k in keys]


class ResidentWindows:
    """The windows of a store view with the streams of ``keys`` held on ``device``; batches gathered there.

    Parameters
    ----------
    view : StoreWindows
        The windows (split, length, stride, statistics, vocabulary) to hold.
    keys : sequence of str
        Batch keys to hold (a model's :meth:`~beatlite.models.base.GestureModel.batch_keys`).
    device : str or torch.device
        Where the streams live and the batches are gathered.

    Attributes
    ----------
    nbytes : int
        Device memory held by the streams and offsets (:func:`resident_bytes`).

    Examples
    --------
    >>> from pathlib import Path
    >>> from beatlite.data.examples import example_corpus
    >>> from beatlite.data.index import index_folder
    >>> from beatlite.data.store import build_store
    >>> tmp = example_corpus()  # a test and a train take of data_samples/, copied to a temporary folder
    >>> view = build_store(index_folder(tmp.name, cache=False), Path(tmp.name) / "store").windows("test")
    >>> resident = ResidentWindows(view, keys=("pose", "audio", "word"), device="cpu")
    >>> batch = resident.batch(torch.tensor([0, 5]))
    >>> tuple(batch["pose"].shape), tuple(batch["audio"].shape), batch["word"].dtype
    ((2, 34, 141), (2, 36266), torch.int64)
    >>> bool(torch.equal(batch["pose"], torch.from_numpy(view.batch([0, 5], keys=("pose",))["pose"])))
    True
    >>> tmp.cleanup()
    """

    def __init__(self, view: StoreWindows, keys: Sequence[str], device: Any = "cpu") -> None:
        if not isinstance(view, StoreWindows):
            raise TypeError(f"ResidentWindows: view must be a StoreWindows, got {type(view).__name__}")
        self.keys = tuple(_keys(keys))
        missing = [k for k in self.keys if k not in view]
        if missing:
            raise KeyError(f"ResidentWindows: keys {missing} not in the view ({view.keys()})")
        self.view, self.device = view, torch.device(device)
        self.length, self.n_audio, self.n_mel = view.length, view.n_audio, view.n_mel
        ids = [int(t) for t in np.unique(view.take_ids)]
        takes = [view.store.takes[t] for t in ids]
        self._streams: dict[str, torch.Tensor] = {}
        for key in self.keys:
            if key != "speaker":
                self._streams[key] = self._stack(key, takes, ids)
        bases = {"frame": [0], "audio": [0], "mel": [0]}
        for t in takes:
            bases["frame"].append(bases["frame"][-1] + t.n_frames)
            bases["audio"].append(bases["audio"][-1] + int(t.meta["shapes"]["audio"][0]) + self.n_audio)
            bases["mel"].append(bases["mel"][-1] + int(t.meta["shapes"]["mel"][0]) + self.n_mel)
        local = np.searchsorted(ids, view.take_ids)  # position of each window's take among the held ones
        fps, sr, hop = view.store.params["fps"], view.store.params["sr"], MEL_SETTINGS["hop_length"]
        a0 = np.array([audio_start(int(s), fps, sr) for s in view.starts], np.int64)
        offsets = np.stack(
            [np.asarray(bases["frame"])[local] + view.starts, np.asarray(bases["audio"])[local] + a0,
             np.asarray(bases["mel"])[local] + a0 // hop]
        )  # fmt: skip
        self._offsets = self._hold(torch.from_numpy(offsets))  # (3, N): frame, audio sample, mel row
        if "speaker" in self.keys:
            speakers = np.array([view.store.takes[int(t)].meta["speaker"] for t in view.take_ids], np.int64)
            self._streams["speaker"] = self._hold(torch.from_numpy(speakers))
        self.nbytes = int(
            sum(s.numel() * s.element_size() for s in self._streams.values()) + 8 * offsets.size
        )

    def _hold(self, tensor: torch.Tensor) -> torch.Tensor:
        return tensor.to(self.device)

    def _stack(self, key: str, takes: list[Any], ids: list[int]) -> torch.Tensor:
        """The takes' :meth:`_rows` of ``key`` one after another, in one tensor on the device, filled a take at
        a time: host memory holds one take's rows and their temporaries at once, not the whole stream (twice, as
        a concatenation of every take's rows did)."""
        sizes = [_n_rows(self.view, key, t) for t in takes]
        out = None
        for take, take_id, start, size in zip(takes, ids, np.cumsum([0, *sizes[:-1]]), sizes):
            rows = self._rows(key, take, take_id)
            rows = torch.from_numpy(
                rows if rows.flags.writeable else rows.copy()
            )  # (a store's read-only map)
            if rows.shape[0] != size:  # (_n_rows and _rows describe the same padding)
                raise RuntimeError(
                    f"ResidentWindows: {key} of take {take_id}: {rows.shape[0]} rows, not {size}"
                )
            if out is None:
                out = torch.empty((sum(sizes), *rows.shape[1:]), dtype=rows.dtype, device=self.device)
            out[int(start) : int(start) + size].copy_(rows)
        if out is None:
            raise ValueError("ResidentWindows: the view has no windows")
        return out

    def _rows(self, key: str, take: Any, take_id: int) -> np.ndarray:
        """One take's stream of ``key`` as its batches hold it, padded at the end for windows running past it."""
        view, stream = self.view, KEY_STREAM[key]
        raw = take.stream(stream).read(0, int(take.meta["shapes"][stream][0]))
        if key == "word":
            return view._word_ids(take_id, raw)
        if key == "audio":
            samples = (raw * np.float64(take.meta["audio_scale"])).astype(np.float32)
            return np.concatenate([samples, np.zeros(_pad(self.view, key), np.float32)])
        rows = view._row_values(key, raw)
        if key == "mel":
            return np.concatenate([rows, np.repeat(rows[-1:], _pad(self.view, key), axis=0)])
        return rows

    def __len__(self) -> int:
        return int(self._offsets.shape[1])

    def batch(self, indices: torch.Tensor | Sequence[int] | np.ndarray) -> dict[str, torch.Tensor]:
        """The batch dict of windows ``indices`` (int64 on the device best; (B,) in ``[0, len)``), on the device."""
        idx = torch.as_tensor(indices, dtype=torch.int64, device=self.device).reshape(-1)
        frame, audio, mel = self._offsets[:, idx]
        out = {}
        for key in self.keys:
            stream = self._streams[key]
            if key == "speaker":
                out[key] = stream[idx]
            elif key == "audio":
                out[key] = stream[audio[:, None] + torch.arange(self.n_audio, device=self.device)]
            elif key == "mel":
                out[key] = stream[mel[:, None] + torch.arange(self.n_mel, device=self.device)]
            else:
                out[key] = stream[frame[:, None] + torch.arange(self.length, device=self.device)]
        return out
