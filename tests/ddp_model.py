"""The model the torchrun scripts (tests/ddp_fit.py, tests/ddp_resume.py) train: the CaMN tiny recipe with
dropout 0, so that nothing random differs between processes."""

import torch

from beatlite.train.recipes import build_recipe_model


def camn_without_dropout(data) -> torch.nn.Module:
    """CaMN tiny (seed 7) for ``data`` (a ``training_data()``), every ``Dropout`` set to p = 0."""
    model = build_recipe_model("camn_tiny", data, seed=7)
    for module in model.modules():
        if isinstance(module, torch.nn.Dropout):
            module.p = 0.0
    return model
