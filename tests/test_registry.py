"""Adding a model through the documented route: one module plus two registry calls, nothing else edited."""

from __future__ import annotations

import sys
import textwrap

import pytest

torch = pytest.importorskip("torch")

MODULE = '''
"""A throwaway model: a learned constant offset on top of the seed frames' mean."""

import dataclasses

import torch
from torch import nn

from beatlite.models.base import GestureModel, ModelConfig, huber


@dataclasses.dataclass
class SeedMeanConfig(ModelConfig):
    dim: int = 141


class SeedMean(GestureModel):
    name = "seed_mean"
    representation = "euler141"
    config_class = SeedMeanConfig
    input_keys = ("pose",)
    presets = {"tiny": {}}

    def __init__(self, config):
        super().__init__(config)
        self.offset = nn.Parameter(torch.zeros(config.dim))

    def forward(self, batch):
        seed = batch["pose"][:, : self.n_pre].mean(dim=1, keepdim=True)
        return {"pose": (seed + self.offset).expand_as(batch["pose"])}

    def losses(self, batch, out, *, epoch):
        return {"total": huber(out["pose"], batch["pose"])}
'''


def test_a_new_model_trains_evaluates_and_appears_in_the_table(tmp_path, monkeypatch):
    from beatlite import models
    from beatlite.train import recipes
    from beatlite.train.evaluation import evaluate_models, load_test_set

    (tmp_path / "throwaway_model.py").write_text(textwrap.dedent(MODULE))
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(models, "MODELS", dict(models.MODELS))
    monkeypatch.setattr(recipes, "RECIPES", dict(recipes.RECIPES))

    models.register_model("seed_mean", "throwaway_model:SeedMean")
    recipes.register_recipe(
        "seed_mean_tiny", recipes.Recipe("seed_mean", "Seed mean", epochs=1, select_best=False)
    )
    seconds = recipes.retrain("seed_mean_tiny", out_dir=tmp_path / "ckpt", progress=False)
    assert seconds > 0 and (tmp_path / "ckpt" / "seed_mean_tiny.pt").is_file()

    res = evaluate_models(
        [str(tmp_path / "ckpt" / "seed_mean_tiny.pt")], test=load_test_set(), ground_truth=False
    )
    row = res.get("Seed mean")
    assert row.source.endswith("seed_mean_tiny.pt") and row.representation == "euler141"
    assert all(v == v for k, v in row.metrics.items() if k != "BC")  # finite scores (BC may have no beats)
    assert "| Seed mean |" in res.to_markdown()
    assert "throwaway_model" in sys.modules


def test_registration_refuses_conflicts(monkeypatch):
    from beatlite import models
    from beatlite.train import recipes

    monkeypatch.setattr(models, "MODELS", dict(models.MODELS))
    monkeypatch.setattr(recipes, "RECIPES", dict(recipes.RECIPES))
    with pytest.raises(ValueError, match="already registered"):
        models.register_model("camn", "somewhere:Else")
    with pytest.raises(ValueError, match="ClassName"):
        models.register_model("broken", "no_colon_here")
    with pytest.raises(ValueError, match="not registered"):
        recipes.register_recipe("ghost_tiny", recipes.Recipe("ghost", "Ghost"))
    with pytest.raises(ValueError, match="already a recipe"):
        recipes.register_recipe("camn_tiny", recipes.Recipe("s2g", "Other"))
