"""Skeleton plots and animations: matplotlib always, pyvista renders behind a subprocess probe.

Submodules are imported lazily (``import beatlite.viz`` imports neither
matplotlib's pyplot, pyvista nor torch):

==========================  ==================================================================
``beatlite.viz.style``       one figure style (:func:`figure_style`) and :func:`save_figure`
==========================  ==================================================================
"""

from __future__ import annotations

import importlib
from typing import Any

_SUBMODULES = ("style",)
_EXPORTS: dict[str, str] = {
    "STYLE": "style",
    "figure_style": "style",
    "save_figure": "style",
    "GROUP_COLOURS": "style",
    "SYSTEM_COLOURS": "style",
}

__all__ = [*_SUBMODULES, *_EXPORTS]


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        return importlib.import_module(f"beatlite.viz.{name}")
    if name in _EXPORTS:
        return getattr(importlib.import_module(f"beatlite.viz.{_EXPORTS[name]}"), name)
    raise AttributeError(f"module 'beatlite.viz' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
