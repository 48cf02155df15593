"""Gesture models (CaMN, HA2G, DiffGesture and baselines), built by name; torch is imported lazily.

Usage (a tiny network builds in a fraction of a second; :func:`build_model` shows more):

>>> from beatlite.models import build_model
>>> model = build_model("camn", preset="tiny", use_audio=False)
>>> model.config.use_audio, model.pose_dim
(False, 141)

``import beatlite.models`` does not import torch: :func:`build_model` and
:func:`model_class` import the model module on first use. Every model follows the
:class:`beatlite.models.base.GestureModel` contract.

===================  =======================================================  ==============
name                 class                                                    representation
===================  =======================================================  ==============
``camn``             :class:`beatlite.models.camn.CaMN`                       euler141
``ha2g``             ``beatlite.models.ha2g.HA2G``                            dirvec126
``s2g``              :class:`beatlite.models.baselines.S2G`                   euler141
``trimodal``         :class:`beatlite.models.baselines.Trimodal`              euler141
``mean_pose``        :class:`beatlite.models.baselines.MeanPose`              euler141
``random_clip``      :class:`beatlite.models.baselines.RandomClip`            euler141
``seq2seq``          :class:`beatlite.models.seq2seq.Seq2Seq`                 euler141
``a2g``              :class:`beatlite.models.a2g.A2G`                         euler141
``joint_embedding``  :class:`beatlite.models.joint_embedding.JointEmbedding`  euler141
``diffgesture``      :class:`beatlite.models.diffgesture.DiffGesture`         dirvec126
===================  =======================================================  ==============

The table lists the built-in registry :data:`MODELS` (``tests/test_models_contract.py`` checks it);
``docs/architecture.md`` ("Adding a model and a metric") is the guide.

Taught in notebooks/05_camn.ipynb, section 2 (the architecture, piece by piece) and notebooks/06_ha2g.ipynb, section 7 (training).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from beatlite.notebook import defined_again

if TYPE_CHECKING:  # pragma: no cover
    from beatlite.models.base import GestureModel

MODELS: dict[str, tuple[str, str] | type[GestureModel]] = {
    "camn": ("beatlite.models.camn", "CaMN"),
    "ha2g": ("beatlite.models.ha2g", "HA2G"),
    "s2g": ("beatlite.models.baselines", "S2G"),
    "trimodal": ("beatlite.models.baselines", "Trimodal"),
    "mean_pose": ("beatlite.models.baselines", "MeanPose"),
    "random_clip": ("beatlite.models.baselines", "RandomClip"),
    "seq2seq": ("beatlite.models.seq2seq", "Seq2Seq"),
    "a2g": ("beatlite.models.a2g", "A2G"),
    "joint_embedding": ("beatlite.models.joint_embedding", "JointEmbedding"),
    "diffgesture": ("beatlite.models.diffgesture", "DiffGesture"),
}
"""Registry: model name -> (module, class name), imported on first use, or a registered class."""

__all__ = ["MODELS", "build_model", "model_class", "presets", "register_model"]


def register_model(name: str, model: str | type[GestureModel]) -> None:
    """Add a model to :data:`MODELS`: the one step that makes it buildable, trainable and loadable.

    Parameters
    ----------
    name : str
        The registry name (stored in its checkpoints' config; ``GestureModel.name`` must equal it:
        :func:`model_class` refuses a class whose ``name`` differs).
    model : str or GestureModel subclass
        ``"package.module:ClassName"`` (imported on first use, so torch stays lazy) or the class.

    Raises
    ------
    ValueError
        ``name`` is already registered to another model.

    Examples
    --------
    >>> register_model("camn", "beatlite.models.camn:CaMN")  # the same entry again: a no-op

    A class defined again under the same module and name (a notebook cell run twice) replaces its entry.
    """
    entry = tuple(model.split(":")) if isinstance(model, str) else model
    if isinstance(entry, tuple) and len(entry) != 2:
        raise ValueError(f"register_model: give 'package.module:ClassName', got {model!r}")
    if name in MODELS and MODELS[name] != entry and not defined_again(MODELS[name], entry):
        raise ValueError(f"register_model: {name!r} is already registered as {MODELS[name]!r}")
    MODELS[name] = entry


def model_class(name: str) -> type[GestureModel]:
    """The model class registered as ``name`` (imports its module, hence torch).

    Raises
    ------
    ValueError
        Unknown name, or a class whose ``name`` is not ``name``.

    Examples
    --------
    The class of a name, and what its attributes say about the pose it predicts (the table above):

    >>> cls = model_class("ha2g")
    >>> cls.__name__, cls.representation, cls.name
    ('HA2G', 'dirvec126', 'ha2g')
    """
    if name not in MODELS:
        raise ValueError(f"model name must be one of {sorted(MODELS)}, got {name!r}")
    entry = MODELS[name]
    if isinstance(entry, tuple):
        module_name, class_name = entry
        entry = getattr(importlib.import_module(module_name), class_name)
    if getattr(entry, "name", None) != name:  # its checkpoints store entry.name and load by it
        raise ValueError(
            f"model {name!r} is registered as {entry.__module__}:{entry.__qualname__}, whose name is "
            f"{getattr(entry, 'name', None)!r}: set its class attribute name = {name!r}"
        )
    return entry


def presets(name: str | type[GestureModel]) -> dict[str, dict[str, Any]]:
    """Preset table of model ``name`` (a registry name or a model class; preset -> config field overrides).

    The class attribute ``presets`` when set, else the ``PRESETS`` dict of the model's module (or of the module of
    the nearest base class that has one: a subclass of CaMN in a module of its own gets CaMN's).

    Returns
    -------
    dict of str -> dict
        A fresh copy (changing it changes no model): preset name -> ``{config field: value}``.

    Raises
    ------
    TypeError
        No presets found (naming the class).

    Examples
    --------
    Every built-in model has a ``"tiny"`` preset (CPU minutes) and a ``"paper"`` one; a preset only lists the
    fields it changes from the config's defaults (CaMN's defaults are the paper's sizes; the mean-pose baseline
    has nothing to size):

    >>> sorted(presets("camn"))
    ['paper', 'tiny']
    >>> presets("camn")["paper"], presets("mean_pose")
    ({}, {'tiny': {}, 'paper': {}})
    """
    cls = model_class(name) if isinstance(name, str) else name
    table = cls.presets
    for klass in cls.__mro__ if table is None else ():  # the module of the class, else of a base it extends
        table = getattr(importlib.import_module(klass.__module__), "PRESETS", None)
        if table is not None or klass.__name__ == "GestureModel":
            break
    if table is None:
        raise TypeError(
            f"{cls.__name__}: no presets: set its class attribute presets (or a PRESETS dict in its module "
            f"{cls.__module__}), at least {{'tiny': {{...}}}}"
        )
    return {k: dict(v) for k, v in table.items()}


def build_model(name: str, *, preset: str = "tiny", **overrides: Any) -> GestureModel:
    """Build model ``name`` from its preset plus config overrides (e.g. ``use_audio=False``).

    Parameters
    ----------
    name : str
        A key of :data:`MODELS`.
    preset : str
        A key of :func:`presets` (the class's ``presets`` or its module's ``PRESETS``) (``"tiny"``, ``"paper"``, ...).
    **overrides
        Fields of the model's config dataclass.

    Returns
    -------
    GestureModel
        A freshly initialised model (seed torch first for reproducible weights).

    Raises
    ------
    ValueError
        Unknown model or preset name.
    TypeError
        An override that is not a config field (the message lists the fields).

    Examples
    --------
    The config is the preset's values with the overrides on top, and :meth:`~GestureModel.to_config` /
    :meth:`~GestureModel.from_config` (what a checkpoint stores) rebuild the same architecture:

    >>> import torch
    >>> from beatlite.models.base import GestureModel
    >>> _ = torch.manual_seed(0)
    >>> model = build_model("camn", preset="tiny", use_audio=False)
    >>> model.config.hidden == presets("camn")["tiny"]["hidden"], model.config.use_audio
    (True, False)
    >>> again = GestureModel.from_config(model.to_config())
    >>> type(again).__name__, again.config == model.config, again.n_parameters() == model.n_parameters()
    ('CaMN', True, True)
    """
    from beatlite.models.base import config_from_preset

    cls = model_class(name)
    config = config_from_preset(cls.config_class, presets(name), preset, **overrides)
    return cls(config)
