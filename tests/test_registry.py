"""Adding a model and a metric through the route of docs/architecture.md ("Adding a model and a metric"): one
module plus two registry calls for the model, one function plus one registry call for the metric, nothing else
edited, and the seed record (not re-recorded) reports both as not recorded instead of failing."""

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


METRIC_MODULE = '''
"""A throwaway descriptive metric: the mean joint speed."""

import numpy as np


def mean_speed(positions, fps):
    """Mean joint speed (cm/s) over frames, joints and takes of positions (T, J, 3) cm."""
    return float(np.mean([np.linalg.norm(np.diff(p, axis=0), axis=-1).mean() * fps for p in positions]))
'''


@pytest.fixture
def metrics_restored():
    from beatlite.metrics import scoring

    saved = dict(scoring.METRICS)
    yield scoring
    scoring.METRICS.clear()
    scoring.METRICS.update(saved)


def test_a_new_model_and_metric_train_evaluate_and_appear_in_the_table(
    tmp_path, monkeypatch, metrics_restored
):
    from beatlite import models
    from beatlite.paths import checkpoints_dir
    from beatlite.train import recipes
    from beatlite.train.evaluation import COLUMNS, evaluate_models
    from beatlite.train.seeds import NotRecorded, check_against_record, recorded_seed_results
    from beatlite.train.testset import load_test_set

    (tmp_path / "throwaway_model.py").write_text(textwrap.dedent(MODULE))
    (tmp_path / "throwaway_metric.py").write_text(textwrap.dedent(METRIC_MODULE))
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(models, "MODELS", dict(models.MODELS))
    monkeypatch.setattr(recipes, "RECIPES", dict(recipes.RECIPES))

    models.register_model("seed_mean", "throwaway_model:SeedMean")
    recipes.register_recipe(
        "seed_mean_tiny", recipes.Recipe("seed_mean", "Seed mean", epochs=1, select_best=False)
    )
    from throwaway_metric import mean_speed

    scoring = metrics_restored
    scoring.register_metric(
        "Speed", scoring.Metric("Speed", "beatlite", None, None, mean_speed, "mean joint speed, cm/s")
    )
    assert scoring.METRICS["Speed"].needs == ("positions",)
    seconds = recipes.retrain("seed_mean_tiny", out_dir=tmp_path / "ckpt", progress=False)
    assert seconds > 0 and (tmp_path / "ckpt" / "seed_mean_tiny.pt").is_file()

    res = evaluate_models(
        [str(tmp_path / "ckpt" / "seed_mean_tiny.pt")], test=load_test_set(), columns=(*COLUMNS, "Speed")
    )
    row = res.get("Seed mean")
    assert row.source.endswith("seed_mean_tiny.pt") and row.representation == "euler141"
    assert all(v == v for k, v in row.metrics.items() if k != "BC")  # finite scores (BC may have no beats)
    assert 0 <= row.metrics["Speed"] < res.get("Ground truth").metrics["Speed"]
    table = res.to_markdown()
    assert "| Seed mean |" in table and "| Speed | gen. s |" in table  # descriptive: no arrow
    assert "- **Speed**: mean joint speed, cm/s" in table
    assert "throwaway_model" in sys.modules

    if not (checkpoints_dir() / "results_seeds.json").is_file():
        pytest.skip("no recorded seed table to check against (make seeds)")
    gaps = check_against_record(res, recorded_seed_results(), metrics=("Speed",))
    assert gaps == [
        NotRecorded("Ground truth", "Speed", None),
        NotRecorded("Ground truth (141 Euler channels)", "Speed", None),
        NotRecorded("Seed mean", None, "seed_mean_tiny"),
    ]
    assert str(gaps[-1]) == "Seed mean: not recorded: run `make seeds ONLY=seed_mean_tiny`"
    assert str(gaps[0]) == "Ground truth Speed: not recorded: run `make seeds`"


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


def test_a_recipe_mistake_is_refused_when_it_is_registered(monkeypatch):
    """A typo'd override or training setting, or another recipe's label, is refused by register_recipe naming the
    recipe (the first two failed only when retrain ran, after the data work; a shared label merged two rows'
    seeds into one list of the seed table); every shipped recipe passes the same checks."""
    from beatlite import models
    from beatlite.train import recipes

    monkeypatch.setattr(models, "MODELS", dict(models.MODELS))
    monkeypatch.setattr(recipes, "RECIPES", dict(recipes.RECIPES))
    for name, recipe in list(recipes.RECIPES.items()):
        recipes.register_recipe(name, recipe)  # the same entry again: checked, and a no-op
    with pytest.raises(ValueError, match=r"'s2g_wide': S2GConfig: unknown option\(s\) \['hiden'\]"):
        recipes.register_recipe("s2g_wide", recipes.Recipe("s2g", "S2G wide", overrides={"hiden": 8}))
    with pytest.raises(
        ValueError, match=r"'s2g_cos': TrainConfig: lr_schedule must be one of .* got 'cosin'"
    ):
        recipes.register_recipe("s2g_cos", recipes.Recipe("s2g", "S2G cos", lr_schedule="cosin"))
    with pytest.raises(ValueError, match=r"'s2g_copy': label 'CaMN' is already the row of camn_tiny"):
        recipes.register_recipe("s2g_copy", recipes.Recipe("s2g", "CaMN"))
    with pytest.raises(ValueError, match=r"label 'Ground truth' is already the row of the ground truth"):
        recipes.register_recipe("s2g_gt", recipes.Recipe("s2g", "Ground truth"))
    with pytest.raises(
        ValueError, match=r"'s2g_gpu': TrainConfig: batch_size must be >= 2 \(BatchNorm\), got 1"
    ):
        recipes.register_recipe("s2g_gpu", recipes.Recipe("s2g", "S2G gpu", gpu_batch_size=1))
    with pytest.raises(ValueError, match=r"'s2g_gpu': TrainConfig: lr must be positive, got 0.0"):
        recipes.register_recipe("s2g_gpu", recipes.Recipe("s2g", "S2G gpu", gpu_batch_size=64, gpu_lr=0.0))
    assert not {"s2g_wide", "s2g_cos", "s2g_copy", "s2g_gt", "s2g_gpu"} & set(recipes.RECIPES)


def test_a_recipe_of_zero_epochs_is_refused_for_a_model_that_trains(monkeypatch):
    """epochs=0 marks an untrained baseline's recipe (retrain and fit then skip the epochs >= 1 check): a model
    with trainable parameters registered so trained nothing, then failed exporting a checkpoint it never wrote.
    Refused when registered, naming the recipe and the setting; a baseline's 0 epochs are kept."""
    from beatlite import models
    from beatlite.train import recipes

    monkeypatch.setattr(models, "MODELS", dict(models.MODELS))
    monkeypatch.setattr(recipes, "RECIPES", dict(recipes.RECIPES))
    with pytest.raises(ValueError, match=r"'s2g_zero': epochs=0 for 's2g', a model with trainable"):
        recipes.register_recipe("s2g_zero", recipes.Recipe("s2g", "S2G zero", epochs=0))
    assert "s2g_zero" not in recipes.RECIPES
    recipes.register_recipe("mean_pose_again", recipes.Recipe("mean_pose", "Mean pose again", epochs=0))
    assert recipes.recipe_train_config("mean_pose_again").epochs == 0


def test_metric_registration_binds_inputs_by_name_and_refuses_conflicts(metrics_restored):
    import numpy as np

    scoring = metrics_restored

    def gap(positions, truth_positions, fps, scale=1.0):
        return (
            scale * fps * float(np.mean([np.abs(a - b).mean() for a, b in zip(positions, truth_positions)]))
        )

    metric = scoring.Metric("Gap", "test", False, None, gap, "mean gap")
    assert metric.needs == ("positions",)
    gen, truth = scoring.Takes([np.ones((3, 2, 3))]), scoring.Takes([np.zeros((3, 2, 3))])
    assert scoring.bind_inputs(gap)(gen, scoring.GroundTruth(truth, fps=10), 0) == 10.0
    scoring.register_metric("Gap", metric)
    assert scoring.evaluate(gen, scoring.GroundTruth(truth, fps=10), metrics=["Gap"]).get("Gap").value == 10.0
    with pytest.raises(ValueError, match="already a metric"):
        scoring.register_metric("FGD", metric)
    with pytest.raises(ValueError, match="does not list"):
        scoring.register_metric("Gap2", scoring.Metric("Gap", "test", False, ("euler",), gap, "mean gap"))
    with pytest.raises(ValueError, match=r"does not name its inputs \(g, t not in INPUTS: positions, "):
        scoring.Metric("Gap", "test", False, None, lambda g, t, seed: 0.0, "no names")
    with pytest.raises(
        ValueError, match=r"\(position not in INPUTS: .*\bpositions\b"
    ):  # a typo: the names listed
        scoring.Metric("Gap", "test", False, None, lambda position, fps: 0.0, "a typo")


def test_a_metric_that_does_not_return_one_number_is_named(metrics_restored):
    """A per-take array, a missing return (None), a complex or a string result: a TypeError naming the metric
    (they were numpy's / float()'s message without the key, or, for a complex value and a string, a number kept
    silently: the real part, float('1.0')); a 0-d torch tensor or numpy scalar is read as its number."""
    import numpy as np

    scoring = metrics_restored
    torch_value = torch.tensor(2.0)
    results = {
        "per take": np.array([1.0, 2.0]),
        "no return": None,
        "complex": np.complex128(1j),
        "string": "1.0",
        "tensor": torch_value,
        "scalar": np.float32(2.0),
    }
    for name, result in results.items():
        scoring.register_metric(
            name, scoring.Metric(name, "test", None, ("positions",), lambda g, t, s, r=result: r, "d")
        )
    gen = scoring.Takes([np.zeros((3, 2, 3))])
    truth = scoring.GroundTruth(gen, fps=10)
    for name in ("per take", "no return", "complex", "string"):
        with pytest.raises(TypeError, match=rf"^metric '{name}': compute returned .*, not one real number$"):
            scoring.evaluate(gen, truth, metrics=[name])
    assert scoring.evaluate(gen, truth, metrics=["tensor", "scalar"]).values() == {
        "tensor": 2.0,
        "scalar": 2.0,
    }


def test_a_model_class_mistake_is_named_where_it_is_made(tmp_path, monkeypatch):
    """A class without presets, with an unknown representation or registered under another name than its own:
    one error naming the class (they were AttributeError "module ... has no attribute 'PRESETS'", a KeyError
    'euler' deep in the harness, and a checkpoint that did not load); a subclass of a shipped model in a module
    of its own gets its base's presets."""
    from beatlite import models
    from beatlite.models.base import GestureModel
    from beatlite.models.camn import PRESETS as CAMN_PRESETS

    monkeypatch.setattr(models, "MODELS", dict(models.MODELS))
    (tmp_path / "newcomer_models.py").write_text(
        textwrap.dedent(
            """
            from beatlite.models.base import GestureModel
            from beatlite.models.camn import CaMN

            class NoPresets(GestureModel):
                name = "no_presets"

            class MyCaMN(CaMN):
                name = "my_camn"
            """
        )
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    import newcomer_models

    with pytest.raises(
        TypeError, match=r"NoPresets: no presets: set its class attribute presets .*newcomer_models"
    ):
        models.presets(newcomer_models.NoPresets)
    assert models.presets(newcomer_models.MyCaMN) == {k: dict(v) for k, v in CAMN_PRESETS.items()}

    with pytest.raises(
        TypeError, match=r"Typo: representation must be one of \['dirvec126', 'euler141'\], got 'euler'"
    ):

        class Typo(GestureModel):
            representation = "euler"

    models.register_model("mine", "newcomer_models:MyCaMN")
    with pytest.raises(
        ValueError, match=r"'mine' is registered as newcomer_models:MyCaMN, whose name is 'my_camn'"
    ):
        models.build_model("mine")
    with pytest.raises(
        ValueError, match=r"CaMNConfig: preset must be one of \['paper', 'tiny'\], got 'smal'"
    ):
        models.build_model("camn", preset="smal")


def test_a_notebook_cell_run_twice_registers_again(monkeypatch, metrics_restored):
    """A cell that defines a model class and a metric function and registers them, run twice: the second run
    replaces the entries (it raised "already registered" / "already a metric"); another class or function under
    a taken name is still refused."""
    from beatlite import models

    scoring = metrics_restored
    monkeypatch.setattr(models, "MODELS", dict(models.MODELS))
    cell = textwrap.dedent(MODULE).replace('name = "seed_mean"', 'name = "cell_model"') + textwrap.dedent(
        """
        def cell_speed(positions):
            return 1.0

        register_model("cell_model", SeedMean)
        register_metric("Cell speed", Metric("Cell speed", "test", None, None, cell_speed, "d"))
        """
    )
    runs = []
    for _ in range(2):
        namespace = {"__name__": "__main__", "register_model": models.register_model}
        namespace.update(register_metric=scoring.register_metric, Metric=scoring.Metric)
        exec(compile(cell, "<cell>", "exec"), namespace)
        runs.append(namespace)
    assert models.model_class("cell_model") is runs[1]["SeedMean"] is not runs[0]["SeedMean"]
    assert scoring.METRICS["Cell speed"].compute is runs[1]["cell_speed"]
    with pytest.raises(ValueError, match="already registered"):
        models.register_model("cell_model", "throwaway_model:SeedMean")
    with pytest.raises(ValueError, match="already a metric"):
        scoring.register_metric(
            "Cell speed", scoring.Metric("Cell speed", "test", None, ("positions",), len, "d")
        )
