"""Argument validation shared by the metric functions (private).

Every public metric validates its inputs here so that a wrong shape gives a
``ValueError`` naming the argument and the shape received, never a bare numpy
traceback or a silently wrong number.
"""

from __future__ import annotations

import numpy as np


def as_array(
    x: object, name: str, *, ndim: int | tuple[int, ...], last: int | None = None, dtype: type = np.float64
) -> np.ndarray:
    """``x`` as a finite ``dtype`` (float64) array with ``ndim`` dimensions (and last axis ``last`` if given).

    Raises
    ------
    TypeError
        ``x`` is not array-like numbers.
    ValueError
        Wrong number of dimensions, wrong last axis, or non-finite values.
    """
    try:
        arr = np.asarray(x, dtype=dtype)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be an array of numbers, got {type(x).__name__}") from exc
    dims = (ndim,) if isinstance(ndim, int) else ndim
    if arr.ndim not in dims:
        want = " or ".join(f"{d}-D" for d in dims)
        raise ValueError(f"{name} must be {want}, got shape {arr.shape}")
    if last is not None and arr.shape[-1] != last:
        raise ValueError(f"{name} must have last axis {last}, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} contains NaN or infinite values (shape {arr.shape})")
    return arr


def positive(value: float, name: str) -> float:
    """``value`` as a float, ``ValueError`` unless finite and > 0."""
    v = float(value)
    if not np.isfinite(v) or v <= 0:
        raise ValueError(f"{name} must be a positive number, got {value!r}")
    return v


def as_list(x: object, name: str) -> tuple[list[object], bool]:
    """``(items, was_list)``: a list/tuple of takes stays a list; anything else becomes ``[x]``.

    A single take must therefore be passed as an array, several takes as a list of arrays.
    """
    if isinstance(x, (list, tuple)):
        if not x:
            raise ValueError(f"{name} is an empty list of takes")
        return list(x), True
    return [x], False
