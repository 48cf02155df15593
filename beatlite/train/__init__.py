"""One training harness and whole-take generation for every gesture model (torch, imported lazily).

- :class:`TrainConfig` (``beatlite.train.config``), :func:`fit` (``beatlite.train.training``),
- :func:`save_checkpoint`, :func:`load_checkpoint`, :func:`load_model`, :func:`export_checkpoint`
  (``beatlite.train.checkpoint``),
- :func:`generate`, :func:`generate_sequence`, :func:`generate_sequences` (``beatlite.train.generation``),
- :func:`evaluate_models`, :func:`write_results`, :class:`ModelResults` (``beatlite.train.evaluation``: the
  results table on whole test takes), :func:`load_test_set` (``beatlite.train.testset``: the test takes and
  scoring one model on them),
- ``beatlite.train.recipes`` (how every shipped checkpoint is trained: ``RECIPES``, ``retrain``)
  and ``beatlite.train.seeds`` (the results table as mean ± sd over training seeds), both
  reachable as attributes (``bl.train.recipes.RECIPES``).

``import beatlite.train`` does not import torch; the names above import their module on
first access. Command line: ``python -m beatlite.train {retrain-all,results,seeds}``.

Taught in notebooks/05_camn.ipynb, sections 4-6 (training, generating a whole take, evaluation on the test split).
"""

from __future__ import annotations

import importlib
from typing import Any

_NAMES = {
    "TrainConfig": "beatlite.train.config",
    "fit": "beatlite.train.training",
    "FitResult": "beatlite.train.training",
    "data_fingerprint": "beatlite.train.training",
    "save_checkpoint": "beatlite.train.checkpoint",
    "load_checkpoint": "beatlite.train.checkpoint",
    "load_model": "beatlite.train.checkpoint",
    "export_checkpoint": "beatlite.train.checkpoint",
    "generate": "beatlite.train.generation",
    "generate_sequence": "beatlite.train.generation",
    "generate_sequences": "beatlite.train.generation",
    "GeneratedTake": "beatlite.train.generation",
    "evaluate_models": "beatlite.train.evaluation",
    "load_test_set": "beatlite.train.testset",
    "write_results": "beatlite.train.evaluation",
    "ModelResults": "beatlite.train.evaluation",
}

__all__ = sorted(_NAMES)


_SUBMODULES = ("recipes", "seeds", "evaluation", "testset", "training", "generation", "checkpoint", "config")


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        module = importlib.import_module(f"beatlite.train.{name}")
        globals()[name] = module
        return module
    if name in _NAMES:
        value = getattr(importlib.import_module(_NAMES[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'beatlite.train' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*__all__, *_SUBMODULES])
