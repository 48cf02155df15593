"""A torch ``Dataset`` over :class:`beatlite.data.windows.Windows` (torch imported here only).

Usage (skipped by the doctests: ``windows`` stands for a :class:`~beatlite.data.windows.Windows` of a corpus):

>>> from torch.utils.data import DataLoader  # doctest: +SKIP
>>> loader = DataLoader(WindowDataset(windows), batch_size=64, shuffle=True)  # doctest: +SKIP
>>> batch = next(iter(loader)); batch["pose"].shape  # doctest: +SKIP
torch.Size([64, 34, 141])

Not used in the notebooks: :func:`beatlite.train.fit` (notebooks/05_camn.ipynb, section 4) batches windows itself.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import torch
from torch.utils.data import Dataset

from beatlite.data.windows import Windows


class WindowDataset(Dataset):
    """Items of a :class:`Windows` as dicts of tensors (float32 / int64; ``take`` stays a str).

    Parameters
    ----------
    windows : Windows
        Windowed or whole-take items. Whole-take items have different lengths, so
        use ``batch_size=1`` with them.
    keys : sequence of str, optional
        Keys to return (default: all of ``windows.keys()``).
    """

    def __init__(self, windows: Windows, keys: list[str] | tuple[str, ...] | None = None) -> None:
        if not isinstance(windows, Windows):
            raise TypeError(f"WindowDataset: windows must be a Windows, got {type(windows).__name__}")
        self.windows = windows
        self.keys = tuple(windows.keys() if keys is None else keys)
        missing = [k for k in self.keys if k not in windows]
        if missing:
            raise KeyError(f"WindowDataset: keys {missing} not in the windows ({windows.keys()})")

    def __len__(self) -> int:
        return len(self.windows)

    def __getitem__(self, i: int) -> dict[str, Any]:
        item = self.windows.item(int(i))
        out: dict[str, Any] = {}
        for k in self.keys:
            v = item[k]
            if k == "take":
                out[k] = str(v)
            else:
                out[k] = torch.from_numpy(np.array(v, copy=True))
        return out
