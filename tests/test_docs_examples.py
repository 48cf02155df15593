"""Every public function and class of beatlite has a doctested Example (a ``>>>`` line in its docstring), or a
reason in :data:`ALLOWED`; ``pytest --doctest-modules beatlite`` runs them. Public: a name without a leading ``_``,
defined in a module whose own name has no leading ``_`` (not imported into it)."""

from __future__ import annotations

import importlib
import inspect
import pkgutil

import pytest

PACKAGES = ("beatlite",)

_RECORD = (
    "a record (or warning, error) made and shown by the Example of the function that returns or raises it"
)
_CONFIG = "a config dataclass of documented fields: its model's Example builds it"
_CHECK = "run by beatlite.models.testing.check_model, whose Example covers it"
_TRAINS = "trains from a window store (tens of seconds on 2 cores): tests/test_models_contract.py runs it"
_DDP = "needs a torchrun process group: tests/test_train_distributed.py runs it"
_CORPUS = "loads a split or trains on a corpus (tens of seconds on 2 cores): the notebooks and tests run it"

# Names without an Example, each with its reason.
ALLOWED: dict[str, str] = {
    **dict.fromkeys(
        [
            "beatlite.models.a2g.A2GConfig", "beatlite.models.base.ModelConfig", "beatlite.models.base.TextConfig",
            "beatlite.models.base.AdversarialConfig", "beatlite.models.baselines.MeanPoseConfig",
            "beatlite.models.baselines.RandomClipConfig", "beatlite.models.baselines.S2GConfig",
            "beatlite.models.baselines.TrimodalConfig", "beatlite.models.camn.CaMNConfig",
            "beatlite.models.diffgesture.DiffGestureConfig", "beatlite.models.ha2g.HA2GConfig",
            "beatlite.models.joint_embedding.JointEmbeddingConfig", "beatlite.models.seq2seq.Seq2SeqConfig",
            "beatlite.synth.speech.Voice", "beatlite.synth.styles.EmotionStyle", "beatlite.synth.styles.SpeakerStyle",
        ],
        _CONFIG,
    ),
    **dict.fromkeys(
        [
            "beatlite.models.ha2g_losses.AngleStatistics", "beatlite.stats.correlations.CorrelationResult",
            "beatlite.stats.correlations.GroupEffectResult", "beatlite.stats.emotion_clusters.RotationWindows",
            "beatlite.stats.emotion_clusters.Separability", "beatlite.stats.emotion_clusters.EmotionFeatures",
            "beatlite.stats.semantic.ScoreHistogram", "beatlite.synth.corpus.Speech",
            "beatlite.synth.corpus.TakeResult", "beatlite.synth.plan.TimedWord", "beatlite.synth.plan.Beat",
            "beatlite.synth.plan.Gesture", "beatlite.synth.plan.Plan", "beatlite.synth.speech.EspeakNotFoundError",
            "beatlite.synth.speech.SpokenWord", "beatlite.train.evaluation.ResultRow",
            "beatlite.train.generation.GeneratedTake", "beatlite.train.recipes.PaperRow",
            "beatlite.train.seeds.Effect", "beatlite.train.training.FitResult",
            "beatlite.viz.animation.SkeletonAnimation", "beatlite.viz.check.FigureWarning",
            "beatlite.viz.check.FigureError", "beatlite.viz.check.FigureProblem", "beatlite.viz.probe.RenderProbe",
            "beatlite.report.Claim", "beatlite.report.Closeness", "beatlite.score.ScoreResult",
            "beatlite.score.ScoreWarning",
        ],
        _RECORD,
    ),
    **dict.fromkeys(
        [
            "beatlite.models.testing.check_gradients", "beatlite.models.testing.check_determinism",
            "beatlite.models.testing.check_generate_modes", "beatlite.models.testing.check_checkpoint",
            "beatlite.models.testing.check_no_host_reads",
        ],
        _CHECK,
    ),
    **dict.fromkeys(
        [
            "beatlite.models.testing.check_store_training", "beatlite.models.testing.check_bf16_training",
            "beatlite.models.testing.check_compiled_training",
        ],
        _TRAINS,
    ),
    **dict.fromkeys(
        [
            "beatlite.train.distributed.wrap_for_ddp", "beatlite.train.distributed.sync_on_last",
            "beatlite.train.distributed.wait_for_all", "beatlite.train.distributed.rng_states",
            "beatlite.train.distributed.sum_over_processes",
        ],
        _DDP,
    ),
    **dict.fromkeys(
        [
            "beatlite.train.evaluation.evaluate_models", "beatlite.train.recipes.TrainingData",
            "beatlite.train.recipes.training_data", "beatlite.train.recipes.retrain",
            "beatlite.train.recipes.retrain_many", "beatlite.train.seeds.ship_median_seeds",
            "beatlite.train.seeds.train_seeds", "beatlite.train.seeds.evaluate_seeds",
            "beatlite.train.testset.load_test_set", "beatlite.train.testset.train_change_angle",
            "beatlite.train.testset.train_mean_speed", "beatlite.train.testset.generated_directions",
            "beatlite.train.testset.SampledProtocol", "beatlite.train.testset.fgd_scorer",
            "beatlite.train.testset.directions_takes", "beatlite.train.testset.score_directions",
        ],
        _CORPUS,
    ),
    **dict.fromkeys(
        [
            "beatlite.score.trim_test_set", "beatlite.score.load_split", "beatlite.score.export_checkpoint_takes",
            "beatlite.score.export_ground_truth", "beatlite.score.self_check", "beatlite.score.main",
        ],
        _CORPUS + " (score_folder's Example loads one split, once for all of beatlite.score)",
    ),
    "beatlite.viz.animation.ffmpeg_available": "shutil.which('ffmpeg'): its value depends on the machine",
    "beatlite.viz.probe.probe_command": "the command the render probe runs, a hook the tests replace",
    "beatlite.viz.figures.plot_onsets": "its first onset_strength call compiles librosa's numba code (8.7 s here)",
}  # fmt: skip


def public_objects(package: str) -> list[tuple[str, object]]:
    """``(dotted name, object)`` of every public function and class defined in ``package``'s modules."""
    pkg = importlib.import_module(package)
    modules = [pkg] + [
        importlib.import_module(info.name)
        for info in pkgutil.walk_packages(pkg.__path__, package + ".")
        if not info.name.rsplit(".", 1)[-1].startswith("_")
    ]
    found = []
    for module in modules:
        for name, obj in vars(module).items():
            if name.startswith("_") or not (inspect.isfunction(obj) or inspect.isclass(obj)):
                continue
            if getattr(obj, "__module__", None) == module.__name__:
                found.append((f"{module.__name__}.{name}", obj))
    return found


def lacking_examples(package: str) -> list[str]:
    """The public names of ``package`` whose docstring has no ``>>>`` line."""
    return [
        name for name, obj in public_objects(package) if ">>>" not in (obj.__doc__ or "")
    ]  # own docstring


@pytest.mark.parametrize("package", PACKAGES)
def test_every_public_function_has_an_example(package):
    assert public_objects(package), f"{package} has no public functions: the walk is broken"
    missing = [name for name in lacking_examples(package) if name not in ALLOWED]
    assert not missing, f"{len(missing)} public names of {package} lack a doctested Example:\n" + "\n".join(
        missing
    )


def test_allow_list_names_exist_and_still_lack_examples():
    everything = {name for package in PACKAGES for name, _ in public_objects(package)}
    lacking = {name for package in PACKAGES for name in lacking_examples(package)}
    assert set(ALLOWED) <= everything, set(ALLOWED) - everything
    assert set(ALLOWED) <= lacking, f"remove from ALLOWED, they have Examples now: {set(ALLOWED) - lacking}"
