"""beatlite: co-speech gesture synthesis research (BEAT/CaMN, HA2G) on a laptop CPU.

Submodules are imported lazily, so ``import beatlite`` is fast and never
imports torch:

>>> import beatlite
>>> motion = beatlite.io.read_bvh("data_samples/2_scott_0_1_1.bvh.gz")  # doctest: +SKIP

(The doctests skip the ``read_bvh`` line: its path is relative to the repository root.)

==================  ==========================================================
``beatlite.io``       readers and writers for every file of a BEAT take
``beatlite.skeleton`` the BEAT skeleton, rotations, forward kinematics
``beatlite.synth``    the generator of the ``data_samples/`` corpus
``beatlite.data``     dataset index, vocabulary, training windows
``beatlite.stats``    the BEAT paper's dataset analysis (Table 1, Figs. 2-4, Table 6)
``beatlite.metrics``  FGD, SRGR, BeatAlign, beat consistency, diversity
``beatlite.models``   CaMN, HA2G and baselines (torch)
``beatlite.train``    one training harness and generation of whole takes (torch)
``beatlite.viz``      skeleton plots and animations (matplotlib, pyvista)
``beatlite.score``    ``python -m beatlite.score``: any model's outputs scored, variants named
==================  ==========================================================

Taught in notebooks/00_setup_and_tour.ipynb, sections 1 (the environment) and 2 (the data folder); its section 6 maps every notebook.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

_SUBMODULES = (
    "io",
    "skeleton",
    "synth",
    "data",
    "stats",
    "metrics",
    "models",
    "train",
    "viz",
    "score",
    "paths",
    "report",
    "exercise",
    "notebook",
)

__all__ = ["__version__", *_SUBMODULES]


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        module = importlib.import_module(f"beatlite.{name}")
        globals()[name] = module
        return module
    raise AttributeError(f"module 'beatlite' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)


if TYPE_CHECKING:  # pragma: no cover
    from beatlite import (  # noqa: F401
        data,
        exercise,
        io,
        metrics,
        models,
        notebook,
        paths,
        report,
        skeleton,
        stats,
        synth,
        train,
        viz,
    )
