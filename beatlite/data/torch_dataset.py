"""torch ``Dataset`` / ``DataLoader`` over windows (torch imported here only).

Works with both window containers: :class:`beatlite.data.windows.Windows` (in memory) and
:class:`beatlite.data.store.StoreWindows` (read from a :class:`~beatlite.data.store.WindowStore`
on disk at batch time). Indexing the dataset with a list of indices returns a whole batch
(one read per window and stream), which is how :func:`window_loader` uses it: a
``BatchSampler`` hands each worker a list of indices, so batches are assembled in the
workers, not collated item by item.

>>> loader = window_loader(store.windows("train"), batch_size=32, shuffle=True, num_workers=2)  # doctest: +SKIP
>>> batch = next(iter(loader)); batch["pose"].shape  # doctest: +SKIP
torch.Size([32, 34, 141])

Not used in the notebooks (they train on data_samples/ in memory).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import torch
from torch.utils.data import BatchSampler, DataLoader, Dataset, RandomSampler, SequentialSampler

from beatlite.data.store import StoreWindows
from beatlite.data.windows import Windows


def _to_torch(batch: dict[str, Any], *, copy: bool = True) -> dict[str, Any]:
    """numpy arrays -> tensors (float32 / int64 as they are); ``take`` stays str (a list for a batch).

    ``copy=False`` wraps arrays the caller owns (a fresh batch) without copying them.
    """
    out: dict[str, Any] = {}
    for k, v in batch.items():
        if k == "take":
            out[k] = str(v) if np.ndim(v) == 0 else [str(s) for s in v]
        else:
            out[k] = torch.from_numpy(np.array(v, copy=True) if copy or not v.flags.writeable else v)
    return out


class WindowDataset(Dataset):
    """Items (or batches) of a :class:`Windows` or :class:`StoreWindows` as dicts of tensors.

    Parameters
    ----------
    windows : Windows or StoreWindows
        Windowed or whole-take items (whole-take items have different lengths: use
        ``batch_size=1`` with them and integer indices).
    keys : sequence of str, optional
        Keys to return (default: all of ``windows.keys()``). With a ``StoreWindows`` only
        these streams are read.

    ``dataset[i]`` is one item (tensors without the batch axis); ``dataset[[i, j, ...]]`` is a
    batch dict (tensors with a leading batch axis, ``take`` a list of str).

    Examples
    --------
    >>> from beatlite.data.store import build_store
    >>> from pathlib import Path
    >>> from beatlite.data.examples import example_corpus
    >>> from beatlite.data.index import index_folder
    >>> tmp = example_corpus()  # a test and a train take of data_samples/, copied to a temporary folder
    >>> index = index_folder(tmp.name, cache=False)
    >>> windows = build_store(index, Path(tmp.name) / "store").windows("test")
    >>> dataset = WindowDataset(windows, keys=("pose", "word"))
    >>> len(dataset), tuple(dataset[0]["pose"].shape), tuple(dataset[[0, 1]]["pose"].shape)
    (19, (34, 141), (2, 34, 141))
    >>> tmp.cleanup()
    """

    def __init__(self, windows: Windows | StoreWindows, keys: Sequence[str] | None = None) -> None:
        if not isinstance(windows, Windows | StoreWindows):
            raise TypeError(
                f"WindowDataset: windows must be Windows or StoreWindows, got {type(windows).__name__}"
            )
        self.windows = windows
        self.keys = tuple(windows.keys() if keys is None else keys)
        missing = [k for k in self.keys if k not in windows]
        if missing:
            raise KeyError(f"WindowDataset: keys {missing} not in the windows ({windows.keys()})")

    def __len__(self) -> int:
        return len(self.windows)

    def __getitem__(self, index: int | Sequence[int]) -> dict[str, Any]:
        if isinstance(index, int | np.integer):
            item = self.windows.item(int(index))
            return _to_torch({k: item[k] for k in self.keys})
        idx = np.asarray(index, dtype=np.int64)
        if isinstance(self.windows, StoreWindows):
            batch = self.windows.batch(idx, keys=self.keys)
        else:
            batch = self.windows.batch(idx)
        return _to_torch({k: batch[k] for k in self.keys}, copy=False)  # batch() returns new arrays


def window_loader(
    windows: Windows | StoreWindows,
    *,
    batch_size: int = 32,
    shuffle: bool = True,
    drop_last: bool = False,
    keys: Sequence[str] | None = None,
    num_workers: int = 0,
    pin_memory: bool = False,
    seed: int = 0,
    **loader_kwargs: Any,
) -> DataLoader:
    """A ``DataLoader`` yielding batch dicts of tensors, each batch read in one call.

    Parameters
    ----------
    windows : Windows or StoreWindows
    batch_size : int
    shuffle : bool
        Random order each epoch, drawn from a ``torch.Generator`` seeded with ``seed``
        (same order on every machine for a seed, whatever ``num_workers``).
    drop_last : bool
        Drop the last incomplete batch.
    keys : sequence of str, optional
        Keys to read (default all).
    num_workers : int
        Worker processes that read batches (0: in this process).
    pin_memory : bool
        Page-locked batches for fast copies to a GPU (ignored, with torch's warning, without one).
    seed : int
    **loader_kwargs
        Passed to ``DataLoader`` (e.g. ``prefetch_factor``, ``persistent_workers``,
        ``multiprocessing_context``).

    Returns
    -------
    torch.utils.data.DataLoader

    Examples
    --------
    >>> from beatlite.data.store import build_store
    >>> from pathlib import Path
    >>> from beatlite.data.examples import example_corpus
    >>> from beatlite.data.index import index_folder
    >>> tmp = example_corpus()  # a test and a train take of data_samples/, copied to a temporary folder
    >>> index = index_folder(tmp.name, cache=False)
    >>> windows = build_store(index, Path(tmp.name) / "store").windows("test")
    >>> loader = window_loader(windows, batch_size=8, keys=("pose",))
    >>> [tuple(batch["pose"].shape) for batch in loader]  # 19 windows
    [(8, 34, 141), (8, 34, 141), (3, 34, 141)]
    >>> tmp.cleanup()
    """
    if not isinstance(batch_size, int) or batch_size < 1:
        raise ValueError(f"window_loader: batch_size must be a positive int, got {batch_size!r}")
    dataset = WindowDataset(windows, keys)
    if shuffle:
        order = RandomSampler(dataset, generator=torch.Generator().manual_seed(int(seed)))
    else:
        order = SequentialSampler(dataset)
    sampler = BatchSampler(order, batch_size=batch_size, drop_last=drop_last)
    return DataLoader(
        dataset,
        batch_size=None,
        sampler=sampler,
        num_workers=num_workers,
        pin_memory=pin_memory,
        **loader_kwargs,
    )
