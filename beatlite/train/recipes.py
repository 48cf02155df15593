"""How every shipped checkpoint is trained: one table of recipes and one :func:`retrain`.

Usage (skipped by the doctests: ``retrain`` trains a model for minutes):

>>> from beatlite.train.recipes import RECIPES, retrain     # doctest: +SKIP
>>> RECIPES["camn_tiny"].epochs                              # doctest: +SKIP
40
>>> seconds = retrain("camn_tiny", seed=2022, out_dir="build/seeds/2022")  # doctest: +SKIP

A :class:`Recipe` names a model of :data:`beatlite.models.MODELS`, its ``tiny`` preset
overrides (the ablation switches) and the harness settings (:class:`beatlite.train.TrainConfig`).
Every recipe trains on the train windows of ``$BEATLITE_DATA`` (default ``data_samples/``:
34-frame windows, stride 10) and validates on the val windows. Word vectors are the offline
PPMI+SVD vectors of :func:`beatlite.data.vocab.word_vectors`, drawn with the same seed.

Every learned recipe scores each epoch by FGD on the validation takes and exports the best epoch
(``select_best``, as BEAT's reference trainer does). Epochs and learning rates were chosen on that
validation FGD within the budget of 3 minutes per model on 2 cores (``BEATLITE_THREADS=2``):
the Euler models (CaMN, S2G, Trimodal, like for like) train 40 epochs at lr 2e-3 (:data:`LR`),
HA2G 25 epochs at lr 2e-3 (:data:`HA2G_EPOCHS`). That is 32x the reference's batch-scaled
6.25e-5: the reference trains 100+ epochs on 30 h of data, we have minutes. All use batch 32
(48 and 64 were hardly faster per epoch, CaMN 202 s for 60 epochs at 48 vs 216 s at 32 on 2 threads: the
convolutions over raw audio cost the same per window).

Taught in notebooks/05_camn.ipynb, sections 4 (training) and 7 (the ablation study), and notebooks/07_benchmark.ipynb, section 1.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any, NamedTuple

from beatlite import models, paths
from beatlite.data.index import index_folder
from beatlite.data.store import build_store
from beatlite.data.vocab import corpus_vocab, take_sentences, word_vectors
from beatlite.metrics.beats import warm_up
from beatlite.models import build_model, model_class, presets
from beatlite.models.ha2g_ablations import ABLATIONS as HA2G_SWITCHES
from beatlite.train.config import TrainConfig
from beatlite.train.testset import fgd_scorer, load_test_set

SEED = 2021
"""Seed of every shipped checkpoint (the reference's ``random_seed``)."""


class PaperRow(NamedTuple):
    """The row of a published table that a checkpoint reproduces.

    Attributes
    ----------
    paper : str
        ``"BEAT"`` (Liu et al., ECCV 2022) or ``"HA2G"`` (Liu et al., CVPR 2022).
    table : str
        ``"Table 4"``, ...: the keys of the ``PAPER_*`` dicts of :mod:`beatlite.train.evaluation` are its rows.
    row : str or None
        The paper's row label; None for an ablation of that study the paper has no row for.
    """

    paper: str
    table: str
    row: str | None


@dataclasses.dataclass(frozen=True)
class Recipe:
    """How one shipped checkpoint is trained.

    Attributes
    ----------
    model : str
        A key of :data:`beatlite.models.MODELS`.
    label : str
        The row label of the checkpoint in every results table (``"CaMN w/o audio"``).
    overrides : mapping
        Config fields on top of the ``tiny`` preset (the ablation switches).
    epochs, batch_size : int
        :class:`beatlite.train.TrainConfig` fields.
    lr : float
        Generator learning rate (the discriminator's is 0.2 times it).
    lr_schedule : str
        :attr:`beatlite.train.TrainConfig.lr_schedule` (``"constant"`` or ``"cosine"``).
    select_best : bool
        Score every epoch by FGD on the validation takes
        (:func:`beatlite.train.testset.fgd_scorer`) and export the best epoch, as BEAT's
        reference trainer does; ``False`` exports the last epoch.
    paper_rows : tuple of PaperRow
        The published rows this checkpoint stands for (:func:`paper_rows` collects a table's).
    gpu_batch_size : int or None
        The batch :func:`recipe_train_config` (the ``fit`` command) trains with on CUDA when no batch size is
        given; ``None``: ``batch_size`` on every device. On a GPU a step's time grows far less than its batch
        (README, "Using real BEAT"). The shipped numbers are the CPU's, at ``batch_size``.
    gpu_lr : float or None
        The generator learning rate at ``gpu_batch_size`` (``None``: ``lr`` scaled to it, :func:`scaled_lr`).

    Examples
    --------
    The shipped CaMN checkpoint: 40 epochs at lr 2e-3 (:data:`LR`), reading words, standing for two
    published rows of BEAT:

    >>> recipe = RECIPES["camn_tiny"]
    >>> recipe.model, recipe.epochs, recipe.lr, recipe.uses_text
    ('camn', 40, 0.002, True)
    >>> [(row.table, row.row) for row in recipe.paper_rows]
    [('Table 4', 'CaMN'), ('Table 5', 'full cascaded')]
    >>> RECIPES["s2g_tiny"].uses_text  # audio only
    False
    """

    model: str
    label: str
    overrides: Mapping[str, Any] = dataclasses.field(default_factory=dict)
    epochs: int = 60
    batch_size: int = 32
    lr: float = 1e-3
    lr_schedule: str = "constant"
    select_best: bool = True
    paper_rows: tuple[PaperRow, ...] = ()
    gpu_batch_size: int | None = None
    gpu_lr: float | None = None

    @property
    def uses_text(self) -> bool:
        """Whether the model reads word ids (then it gets the vocabulary size and word vectors).

        Asked of the model class (:meth:`beatlite.models.base.GestureModel.keys_for`) with the
        recipe's ``tiny`` config, so a new model needs no entry here.
        """
        from beatlite.models.base import config_from_preset

        cls = model_class(self.model)
        config = config_from_preset(cls.config_class, presets(self.model), "tiny", **self.overrides)
        return "word" in cls.keys_for(config)


CAMN_ABLATIONS: dict[str, tuple[str, dict[str, Any]]] = {
    "camn_tiny": ("CaMN", {}),
    "camn_tiny_no_cascade": ("CaMN w/o cascade", {"cascade": False}),
    "camn_tiny_no_text": ("CaMN w/o text", {"use_text": False}),
    "camn_tiny_no_audio": ("CaMN w/o audio", {"use_audio": False}),
    "camn_tiny_no_speaker": ("CaMN w/o speaker ID", {"use_speaker": False}),
    "camn_tiny_no_face": ("CaMN w/o face", {"use_face": False}),
    "camn_tiny_no_emotion": ("CaMN w/o emotion", {"use_emotion": False}),
    "camn_tiny_no_semantic": ("CaMN w/o semantic weighting", {"semantic_weighting": False}),
}
"""Shipped CaMN checkpoints: name -> (row label, config overrides of the ``tiny`` preset) (BEAT Table 5)."""

BEAT_TABLE5_ROWS: dict[str, str] = {
    "camn_tiny": "full cascaded", "camn_tiny_no_cascade": "w/o cascaded", "camn_tiny_no_text": "w/o text",
    "camn_tiny_no_audio": "w/o audio", "camn_tiny_no_speaker": "w/o speaker ID", "camn_tiny_no_face": "w/o face",
    "camn_tiny_no_emotion": "w/o emotion", "camn_tiny_no_semantic": "w/o semantic",
}  # fmt: skip
"""The row of BEAT's Table 5 (CaMN ablations) of each CaMN checkpoint."""

EPOCHS = 40
"""Epochs of the CaMN, S2G and Trimodal checkpoints (see :data:`LR`)."""
LR = 2e-3
"""Learning rate of the CaMN, S2G and Trimodal checkpoints. At 1e-3 CaMN's validation FGD falls
almost linearly from epoch 20 to 60 (seed 2021: 4.0 -> 1.84 at epoch 58); at 2e-3 it gets as far in
40 epochs (seed 2021: 1.93 at epoch 39; seed 2022: 1.71 at epoch 33, vs 2.97 after 60 epochs at
1e-3), which fits the 3-minute budget. A cosine decay over 45 epochs at 1e-3 stalled at 3.9 (both
seeds): this model needs its learning rate late in training. Seq2Seq, A2G and Joint Embedding use the
same (Seq2Seq seed 2021: best validation FGD 7.18 at 2e-3, 8.39 at 1e-3; both curves are noisy)."""

HA2G_EPOCHS = 25
"""Epochs of the HA2G checkpoints (an epoch costs about 1.9 CaMN epochs). At 2e-3 the validation FGD
is flat within noise after epoch 16 (seed 2021: best 3.19 at epoch 22 of 30)."""
HA2G_LR = 2e-3
"""HA2G's learning rate: at 1e-3 its validation FGD was still falling steeply at epoch 30 (seed 2021:
6.6 at epoch 24, 3.71 at 29; test FGD 5.45); at 2e-3 the same seed reached 2.57 (test 3.52)."""
DIFFGESTURE_EPOCHS = 60
"""Epochs of the DiffGesture checkpoint (about 21 steps of 32 windows each on ``data_samples/``). Seed 2021, one
thread on a shared 2-core machine: 268 s. When the preset was chosen, test FGD 4.4 with the tiny preset's DDIM 25
steps (4.6 with 10, 5.3 with 100, 10.2 with DDPM's 500; 7.2 after 40 epochs); today's three seeds are in
``checkpoints/results_seeds.md`` ("DiffGesture-style"). The paper's epsilon-prediction on unscaled directions sampled far
from the data with this budget (test FGD 2174 after 40 epochs): see :mod:`beatlite.models.diffgesture`."""
DIFFGESTURE_LR = 1e-3
"""DiffGesture's learning rate. ``select_best`` is off: scoring an epoch by validation FGD samples every
validation window (DDIM, two network passes per step for the guidance), which costs about as much as the epoch."""


HA2G_LABELS: dict[str, str] = {
    "full": "HA2G",
    "holistic": "HA2G w/o hierarchy (holistic)",
    "single_audio": "HA2G single audio feature",
    "mid_only": "HA2G f_a^mid only",
    "high_only": "HA2G f_a^high only",
    "no_high_negatives": "HA2G w/o f_a-^high (high-level negatives)",
    "no_low_mid_negatives": "HA2G w/o f_a-^low,mid (low/mid-level negatives)",
    "no_text": "HA2G w/o text",
    "no_hand_hierarchy": "HA2G w/o hand hierarchy",
    "no_body_hierarchy": "HA2G w/o body hierarchy",
    "same_audio": "HA2G same audio f_a^h",
    "no_contrastive": "HA2G w/o contrastive loss",
    "no_physical": "HA2G w/o physical loss",
}
"""Table row label of each HA2G ablation switch (the rows of HA2G Tables 3-4)."""

HA2G_PAPER_ROWS: dict[str, tuple[PaperRow, ...]] = {
    "full": (PaperRow("HA2G", "Table 1", "HA2G"), PaperRow("HA2G", "Table 3", "HA2G Full"),
             PaperRow("HA2G", "Table 4", "HA2G Full")),
    "single_audio": (PaperRow("HA2G", "Table 3", "f_a^low only (T3)"),),
    "mid_only": (PaperRow("HA2G", "Table 3", "f_a^mid only (T3)"),),
    "high_only": (PaperRow("HA2G", "Table 3", "f_a^high only (T3)"),),
    "no_high_negatives": (PaperRow("HA2G", "Table 3", "w/o high-level negatives (T3)"),),
    "no_low_mid_negatives": (PaperRow("HA2G", "Table 3", "w/o low/mid-level negatives (T3)"),),
    "no_text": (PaperRow("HA2G", "Table 3", "w/o text (T3)"),),
    "no_contrastive": (PaperRow("HA2G", "Table 3", None),),
    "holistic": (PaperRow("HA2G", "Table 4", "Holistic (T4)"),),
    "no_hand_hierarchy": (PaperRow("HA2G", "Table 4", "w/o hand hierarchy (T4)"),),
    "no_body_hierarchy": (PaperRow("HA2G", "Table 4", "w/o body hierarchy (T4)"),),
    "same_audio": (PaperRow("HA2G", "Table 4", "Same audio f_a^h (T4)"),),
    "no_physical": (PaperRow("HA2G", "Table 4", "w/o L_phy (T4)"),),
}  # fmt: skip
"""The published rows of each HA2G ablation switch: Table 3 ablates the audio learner, Table 4 the pose inferer
(the keys of :data:`beatlite.train.evaluation.PAPER_HA2G_ABLATIONS`; None: a switch the paper has no row for); the
full model is the reference row of both and HA2G's row of Table 1."""

HA2G_ABLATIONS: dict[str, tuple[str, dict[str, Any]]] = {
    ("ha2g_tiny" if name == "full" else f"ha2g_tiny_{name}"): (HA2G_LABELS[name], dict(overrides))
    for name, overrides in HA2G_SWITCHES.items()
}
"""Shipped HA2G checkpoints: name -> (row label, config overrides of the ``tiny`` preset) (HA2G Tables 3-4),
one per switch of :data:`beatlite.models.ha2g_ablations.ABLATIONS`. HA2G-ASR (Table 3) has none: it
needs a pretrained ASR network."""


CAMN_GPU_BATCH, CAMN_GPU_LR = 256, 5e-4
"""The CaMN recipes' batch and generator learning rate on CUDA (:attr:`Recipe.gpu_batch_size`,
:attr:`Recipe.gpu_lr`): the reference trainer's, for real BEAT (docs/reference_code.md#camn-training), not the
recipe's 2e-3 at batch 32 scaled up (1.6e-2). What they score, on ``data_samples/`` or real BEAT, is unmeasured."""

RECIPES: dict[str, Recipe] = {
    "mean_pose": Recipe("mean_pose", "Mean pose", epochs=0),
    "random_clip": Recipe("random_clip", "Random clip", epochs=0),
    "s2g_tiny": Recipe(
        "s2g", "S2G-style", epochs=EPOCHS, lr=LR,
        paper_rows=(PaperRow("BEAT", "Table 4", "S2G"), PaperRow("HA2G", "Table 1", "Speech2Gesture")),
    ),
    "trimodal_tiny": Recipe(
        "trimodal", "Trimodal-style", epochs=EPOCHS, lr=LR,
        paper_rows=(PaperRow("BEAT", "Table 4", "MultiContext"), PaperRow("HA2G", "Table 1", "Trimodal")),
    ),
    "seq2seq_tiny": Recipe(
        "seq2seq", "Seq2Seq-style", epochs=EPOCHS, lr=LR,
        paper_rows=(PaperRow("BEAT", "Table 4", "Seq2Seq"), PaperRow("HA2G", "Table 1", "Attention Seq2Seq")),
    ),
    # A2G and Joint Embedding evaluate with their sampled codes (their configs' default eval_z="sample", as their
    # reference code does; "mean" is the extra option). No override here: overrides mark the ablation rows.
    "a2g_tiny": Recipe("a2g", "A2G-style", epochs=EPOCHS, lr=LR, paper_rows=(PaperRow("BEAT", "Table 4", "A2G"),)),
    "joint_embedding_tiny": Recipe(
        "joint_embedding", "Joint Embedding-style", epochs=EPOCHS, lr=LR,
        paper_rows=(PaperRow("HA2G", "Table 1", "Joint Embedding"),),
    ),
    **{
        name: Recipe(
            "camn", label, kw, epochs=EPOCHS, lr=LR,
            paper_rows=((PaperRow("BEAT", "Table 4", "CaMN"),) if name == "camn_tiny" else ())
            + (PaperRow("BEAT", "Table 5", BEAT_TABLE5_ROWS[name]),),
            gpu_batch_size=CAMN_GPU_BATCH, gpu_lr=CAMN_GPU_LR,
        )
        for name, (label, kw) in CAMN_ABLATIONS.items()
    },
    **{
        name: Recipe("ha2g", label, kw, epochs=HA2G_EPOCHS, lr=HA2G_LR, paper_rows=HA2G_PAPER_ROWS[switch])
        for switch, (name, (label, kw)) in zip(HA2G_SWITCHES, HA2G_ABLATIONS.items(), strict=True)
    },
    # no paper row: DiffGesture's published TED Expressive values could not be checked against its text here
    "diffgesture_tiny": Recipe(
        "diffgesture", "DiffGesture-style", epochs=DIFFGESTURE_EPOCHS, lr=DIFFGESTURE_LR, select_best=False,
    ),
}  # fmt: skip
"""Every trained checkpoint (``checkpoints/<name>.pt``) -> its :class:`Recipe`, in table row order.

Adding a model: :func:`beatlite.models.register_model`, then :func:`register_recipe`
(``docs/architecture.md``, "Adding a model")."""


#: The labels of the ground truth's rows in the results tables (no recipe may take them).
GROUND_TRUTH = "Ground truth"
GROUND_TRUTH_141 = "Ground truth (141 Euler channels)"


def register_recipe(name: str, recipe: Recipe) -> None:
    """Add checkpoint ``name`` trained by ``recipe`` to :data:`RECIPES` (its row joins the tables).

    Checked here, before any data work: the model's ``tiny`` config with the recipe's ``overrides`` and the
    training settings (:class:`~beatlite.train.TrainConfig`'s checks) are built once (this imports the model).

    Raises
    ------
    ValueError
        The recipe's model is not registered; ``name`` is taken by another recipe; its ``label`` is another
        recipe's or a ground-truth row's (labels key the results tables and the seed record); an override that
        is not a field of the model's config; a training setting ``TrainConfig`` refuses; ``epochs=0`` for a
        model with trainable parameters (only untrained baselines have 0 epochs: :func:`retrain` and the ``fit``
        command refuse ``epochs < 1`` for a recipe with ``epochs > 0``, and would train nothing for this one).

    Examples
    --------
    A slower S2G-style run as a row of its own (removed again at the end); a label already in the tables is
    refused:

    >>> register_recipe("s2g_slow", Recipe("s2g", "S2G (lr 1e-4)", epochs=5, lr=1e-4))
    >>> label_of("s2g_slow"), RECIPES["s2g_slow"].epochs
    ('S2G (lr 1e-4)', 5)
    >>> del RECIPES["s2g_slow"]
    >>> register_recipe("s2g_again", Recipe("s2g", "CaMN"))
    Traceback (most recent call last):
    ...
    ValueError: register_recipe: 's2g_again': label 'CaMN' is already the row of camn_tiny (a label keys the results tables and the seed record: give another)
    """
    from beatlite.models.base import config_from_preset

    if recipe.model not in models.MODELS:
        raise ValueError(f"register_recipe: model {recipe.model!r} is not registered (register_model first)")
    if name in RECIPES and RECIPES[name] != recipe:
        raise ValueError(f"register_recipe: {name!r} is already a recipe ({RECIPES[name]})")
    owner = next((n for n, r in RECIPES.items() if r.label == recipe.label and n != name), None)
    if owner is not None or recipe.label in (GROUND_TRUTH, GROUND_TRUTH_141):
        raise ValueError(
            f"register_recipe: {name!r}: label {recipe.label!r} is already the row of {owner or 'the ground truth'} "
            "(a label keys the results tables and the seed record: give another)"
        )
    try:
        cls = model_class(recipe.model)
        config = config_from_preset(cls.config_class, presets(recipe.model), "tiny", **dict(recipe.overrides))
        TrainConfig(
            epochs=recipe.epochs, batch_size=recipe.batch_size, lr=recipe.lr, lr_schedule=recipe.lr_schedule
        )
        if recipe.gpu_batch_size is not None or recipe.gpu_lr is not None:
            gpu_batch = recipe.batch_size if recipe.gpu_batch_size is None else recipe.gpu_batch_size
            TrainConfig(batch_size=gpu_batch, lr=recipe.gpu_lr)  # (checks both)
    except (TypeError, ValueError) as error:
        raise ValueError(f"register_recipe: {name!r}: {error}") from error
    if recipe.epochs < 1 and cls(config).trainable:  # (0 epochs: an untrained baseline's recipe)
        raise ValueError(
            f"register_recipe: {name!r}: epochs=0 for {recipe.model!r}, a model with trainable parameters: it would "
            "export untrained weights; give epochs >= 1 (0 is for models without any, as mean_pose and random_clip)"
        )
    RECIPES[name] = recipe


def label_of(name: str) -> str:
    """The table row label of checkpoint ``name`` (its recipe's; the name itself when it has none).

    Examples
    --------
    >>> label_of("camn_tiny_no_audio"), label_of("my_model")
    ('CaMN w/o audio', 'my_model')
    """
    return RECIPES[name].label if name in RECIPES else name


def paper_rows(
    paper: str, tables: Sequence[str], names: Sequence[str] | None = None
) -> dict[str, str | None]:
    """The checkpoints that stand for rows of ``paper``'s ``tables`` and their row labels.

    Parameters
    ----------
    paper : str
        ``"BEAT"`` or ``"HA2G"`` (:attr:`PaperRow.paper`).
    tables : sequence of str
        E.g. ``["Table 5"]`` or ``["Table 3", "Table 4"]``.
    names : sequence of str, optional
        Keys of :data:`RECIPES` to look at (default all).

    Returns
    -------
    dict
        Checkpoint name -> the paper's row label (None: an ablation of that study without a published row),
        table by table in the order of ``tables``, within a table in :data:`RECIPES` order; a checkpoint in two
        tables comes once, at its first.

    Examples
    --------
    >>> paper_rows("BEAT", ["Table 4"])["trimodal_tiny"]
    'MultiContext'
    >>> list(paper_rows("HA2G", ["Table 3", "Table 4"]).items())[:2]
    [('ha2g_tiny', 'HA2G Full'), ('ha2g_tiny_single_audio', 'f_a^low only (T3)')]
    """
    names = list(RECIPES) if names is None else list(names)
    found: dict[str, str | None] = {}
    for table in tables:
        for name in names:
            for row in RECIPES[name].paper_rows:
                if (row.paper, row.table) == (paper, table) and name not in found:
                    found[name] = row.row
    return found


SPEECH_INPUTS: dict[str, str] = {
    "audio": "audio (waveform)", "mel": "audio (mel spectrogram)", "word": "text",
    "speaker": "speaker ID", "emotion": "emotion", "face": "face",
}  # fmt: skip
"""The batch keys that carry the speech and its speaker, as :func:`describe_row` names them (the seed pose,
``pose``/``dirvec``, is left out: every model reads it)."""


def describe_row(name: str) -> str:
    """One line on recipe ``name``'s row, generated from the registries (never written by hand).

    The row label, the model class's one-line summary (:data:`beatlite.models.MODELS`), the speech inputs
    its ``tiny`` config reads (:meth:`~beatlite.models.base.GestureModel.keys_for`, named by
    :data:`SPEECH_INPUTS`) and the published rows it stands for (:attr:`Recipe.paper_rows`).

    Examples
    --------
    >>> print(describe_row("s2g_tiny"))
    **S2G-style** (`s2g_tiny`): Audio-only convolutional generator in the style of Speech2Gesture. Reads: audio (mel spectrogram). Stands for: BEAT Table 4 "S2G", HA2G Table 1 "Speech2Gesture".
    >>> print(describe_row("mean_pose"))
    **Mean pose** (`mean_pose`): Frozen mean pose: `forward` returns the training mean (z-scored units) on every frame. Reads: no speech input.
    """
    import re

    from beatlite.models.base import config_from_preset

    recipe = RECIPES[name]
    cls = model_class(recipe.model)
    summary = (cls.__doc__ or cls.__name__).strip().splitlines()[0]
    summary = re.sub(r"\s*\((see the )?module docstring\)", "", summary).rstrip(".").replace("``", "`") + "."
    config = config_from_preset(cls.config_class, presets(recipe.model), "tiny", **recipe.overrides)
    reads = [SPEECH_INPUTS[k] for k in cls.keys_for(config) if k in SPEECH_INPUTS]
    text = f"**{recipe.label}** (`{name}`): {summary} Reads: {', '.join(reads) or 'no speech input'}."
    rows = [f'{r.paper} {r.table} "{r.row}"' for r in recipe.paper_rows if r.row is not None]
    return text + (f" Stands for: {', '.join(rows)}." if rows else "")


def describe_rows(names: Sequence[str]) -> str:
    """:func:`describe_row` of each recipe of ``names`` as a Markdown list (one ``- `` line each).

    Examples
    --------
    >>> text = describe_rows(["mean_pose", "s2g_tiny"])
    >>> [line.split(":")[0] for line in text.splitlines()]  # one line per recipe, then describe_row's text
    ['- **Mean pose** (`mean_pose`)', '- **S2G-style** (`s2g_tiny`)']
    """
    return "\n".join(f"- {describe_row(n)}" for n in names)


@dataclasses.dataclass
class TrainingData:
    """What every recipe trains on (built once by :func:`training_data`): the window store's train and
    validation windows (an index read batch by batch: memory flat in the corpus size)."""

    index: Any
    vocab: Any
    train: Any
    val: Any
    sentences: Any
    meta: dict[str, Any]
    store: Any = None

    @functools.cached_property
    def val_takes(self) -> Any:
        """The whole validation takes that :func:`~beatlite.train.testset.fgd_scorer` generates
        (an :class:`~beatlite.train.testset.EvaluationSet` for FGD alone, prepared on first use, then shared)."""

        return load_test_set(self.index, split="val", vocab=self.vocab, store=self.store, fgd_only=True)


def training_data(data: str | Path | None = None, *, progress: bool = False) -> TrainingData:
    """Index ``data`` (default ``$BEATLITE_DATA``; cached), build or update its window store
    (:func:`beatlite.data.store.build_store`, only changed takes) and open its train/val windows.

    ``meta`` (what :func:`retrain` stores in the checkpoint) holds the train split's normalisation statistics, the
    vocabulary and ``"data"``, the folder as :func:`beatlite.paths.shareable` names it (``"data_samples"``, or the
    folder's name: no absolute path of this machine).

    ``progress`` shows the store's tqdm bar over the takes it builds. ``ValueError`` when no usable take is in
    the val split (or a reader's ``FormatError``). The vocabulary and the word vectors'
    sentences come from the usable takes only, as the windows do (an unusable take's TextGrid may not read).
    """

    root = Path(data) if data is not None else paths.data_dir()
    index = index_folder(root)
    usable = index.where(usable=True)
    if len(usable) and not len(usable.where(split="val")):
        raise ValueError(
            f"training_data: {root} has no usable take of the 'val' split, which training validates on (the "
            "validation FGD picks the best epoch); BEAT's names put in it speech sequences 57-64 and the last of each "
            "emotion block of the 4-hour speakers, their conversation 12, and speech 5-8 and the '_b' halves of the "
            "other speakers (beatlite.io.names.split_of; BEAT2: train_test_split.csv)"
        )
    vocab = corpus_vocab(index)
    store = build_store(index, vocab=vocab, progress=progress)
    train = store.windows("train", vocab=vocab)
    val = store.windows("val", vocab=vocab, stats=train.normalizers)
    meta = {
        **train.normalizers.to_meta(),
        "vocab": list(vocab.itos),
        "data": paths.shareable(root),  # the folder's name or repository path; the fingerprint identifies it
    }
    return TrainingData(index, vocab, train, val, take_sentences(usable), meta, store)


def build_recipe_model(name: str, data: TrainingData, *, seed: int = SEED, preset: str = "tiny") -> Any:
    """The freshly initialised model of recipe ``name`` (torch seeded with ``seed``; word vectors set), of
    ``preset`` (a key of :func:`beatlite.models.presets`; the recipes' ``"tiny"`` by default) with the recipe's
    switches on top.

    ``seed`` also goes to configs with a ``seed`` field (:class:`~beatlite.models.baselines.RandomClip`'s
    choice of clips). Of ``data`` only ``vocab`` and ``sentences`` are read, for a recipe that reads words.

    Examples
    --------
    Seq2Seq reads words: its embedding has one row per token of the vocabulary (3 words and the 4 special
    tokens), and the same seed builds the same weights.

    >>> import torch
    >>> from beatlite.data.vocab import Vocab
    >>> words = [["hello", "world"], ["hello", "again"], ["world", "again", "hello"]]
    >>> data = TrainingData(None, Vocab(["hello", "world", "again"]), None, None, words, {})
    >>> a, b = (build_recipe_model("seq2seq_tiny", data, seed=3) for _ in range(2))
    >>> type(a).__name__, a.config.vocab_size
    ('Seq2Seq', 7)
    >>> all(torch.equal(x, y) for x, y in zip(a.state_dict().values(), b.state_dict().values()))
    True
    >>> build_recipe_model("seq2seq_tiny", data, preset="paper").config.preset
    'paper'
    """
    import torch

    recipe = _recipe(name)
    kw = dict(recipe.overrides)
    if recipe.uses_text:
        kw["vocab_size"] = len(data.vocab)
    if "seed" in {f.name for f in dataclasses.fields(model_class(recipe.model).config_class)}:
        kw["seed"] = seed  # models that draw from numpy (the random clip row)
    torch.manual_seed(seed)
    model = build_model(recipe.model, preset=preset, **kw)
    if recipe.uses_text and hasattr(model, "set_word_vectors"):
        model.set_word_vectors(word_vectors(data.vocab, data.sentences, dim=model.config.word_dim, seed=seed))
    return model


def scaled_lr(recipe: Recipe, batch_size: int, rule: str = "linear") -> float | None:
    """The generator learning rate of ``recipe`` at another batch size.

    Parameters
    ----------
    recipe : Recipe
        Its ``lr`` belongs to its ``batch_size`` (``None``: :class:`beatlite.train.TrainConfig`'s default,
        ``5e-4 * batch_size / 256``).
    batch_size : int
        Windows per step.
    rule : {"linear", "sqrt"}
        ``"linear"``: the rate times ``batch_size / recipe.batch_size`` (Goyal et al. 2017, "Accurate, large
        minibatch SGD"); ``"sqrt"``: times its square root (the rule Malladi et al. 2022, "On the SDEs and
        scaling rules for adaptive gradient algorithms", derive for Adam).

    Returns
    -------
    float or None
        None where the recipe has no ``lr`` and the rule is linear (TrainConfig's default is that rule).

    Examples
    --------
    >>> recipe = Recipe("camn", "CaMN", batch_size=32, lr=2e-3)
    >>> scaled_lr(recipe, 128), scaled_lr(recipe, 128, "sqrt")
    (0.008, 0.004)
    """
    if rule not in ("linear", "sqrt"):
        raise ValueError(f"lr scaling rule must be 'linear' or 'sqrt', got {rule!r}")
    if int(batch_size) < 1:
        raise ValueError(f"batch_size must be >= 1, got {batch_size}")
    ratio = int(batch_size) / recipe.batch_size
    if recipe.lr is None and rule == "linear":
        return None
    base = recipe.lr if recipe.lr is not None else TrainConfig(batch_size=recipe.batch_size).learning_rate
    return base * (ratio if rule == "linear" else math.sqrt(ratio))


def recipe_train_config(
    name: str,
    *,
    seed: int = SEED,
    epochs: int | None = None,
    checkpoint: str | Path | None = None,
    resume: bool = False,
    progress: bool = True,
    device: str = "cpu",
    checkpoint_every: int | None = None,
    batch_size: int | None = None,
    data_on_device: str = "auto",
    amp: bool = False,
    compile: str | None = None,  # noqa: A002
    val_every: int | None = None,
    deterministic: bool = True,
    lr_scaling: str = "linear",
    audio_matmul: str = "auto",
    lr: float | None = None,
    preset: str = "tiny",
) -> TrainConfig:
    """The :class:`~beatlite.train.TrainConfig` :func:`retrain` trains recipe ``name`` with (its parameters;
    ``checkpoint``: the full checkpoint's path), with the device resolved: what the ``fit`` command checks
    before it indexes anything (``preset``, the model's size, is checked here too, :func:`check_preset`, though
    the config does not hold it).

    Raises
    ------
    ValueError
        An unknown recipe or preset, a value ``TrainConfig`` refuses, a device this machine lacks
        (:meth:`~beatlite.train.TrainConfig.torch_device`), or ``epochs < 1`` for a recipe that trains (its
        ``epochs > 0``: zero epochs would export weights never trained).

    Examples
    --------
    >>> config = recipe_train_config("camn_tiny", batch_size=64, lr_scaling="sqrt")
    >>> config.epochs == RECIPES["camn_tiny"].epochs, config.lr == scaled_lr(RECIPES["camn_tiny"], 64, "sqrt")
    (True, True)
    >>> config = recipe_train_config("camn_tiny", device="cpu")
    >>> config.batch_size, config.lr, RECIPES["camn_tiny"].gpu_batch_size, RECIPES["camn_tiny"].gpu_lr  # (CUDA's)
    (32, 0.002, 256, 0.0005)
    >>> recipe_train_config("camn_tiny", epochs=0)
    Traceback (most recent call last):
    ...
    ValueError: camn_tiny: epochs must be >= 1 (the recipe's: 40); 0 would export untrained weights
    """
    recipe = _recipe(name)
    epochs = recipe.epochs if epochs is None else int(epochs)
    if recipe.epochs > 0 and epochs < 1:
        raise ValueError(
            f"{name}: epochs must be >= 1 (the recipe's: {recipe.epochs}); {epochs} would export untrained weights"
        )
    check_preset(name, preset)
    # the device resolved once (one this machine lacks: ValueError), before the batch and rate it decides
    cuda = TrainConfig(device=device).torch_device().type == "cuda"
    batch = recipe.batch_size if batch_size is None else int(batch_size)
    rate = None if lr is None else float(lr)
    if cuda and batch_size is None and recipe.gpu_batch_size:
        batch = recipe.gpu_batch_size
        rate = recipe.gpu_lr if rate is None else rate
    return TrainConfig(
        epochs=epochs,
        batch_size=batch,
        lr=scaled_lr(recipe, batch, lr_scaling) if rate is None else rate,
        lr_schedule=recipe.lr_schedule,
        seed=seed,
        checkpoint=checkpoint,
        resume=resume,
        progress=progress,
        device=device,
        checkpoint_every=checkpoint_every,
        data_on_device=data_on_device,
        amp=amp,
        compile=compile,
        val_every=val_every,
        deterministic=deterministic,
        audio_matmul=audio_matmul,
    )


def retrain(
    name: str,
    *,
    seed: int = SEED,
    epochs: int | None = None,
    out_dir: str | Path | None = None,
    data: TrainingData | None = None,
    resume: bool = False,
    progress: bool = True,
    device: str = "cpu",
    extractor: str | Path | None = None,
    checkpoint_every: int | None = None,
    batch_size: int | None = None,
    data_on_device: str = "auto",
    amp: bool = False,
    compile: str | None = None,  # noqa: A002
    val_every: int | None = None,
    deterministic: bool = True,
    lr_scaling: str = "linear",
    audio_matmul: str = "auto",
    lr: float | None = None,
    preset: str = "tiny",
) -> float:
    """Train recipe ``name`` and export its inference checkpoint.

    Parameters
    ----------
    name : str
        A key of :data:`RECIPES`.
    seed : int
        Weights, dropout, shuffles and word vectors.
    epochs : int, optional
        Default the recipe's.
    out_dir : str or Path, optional
        Where the float16 inference copy ``<name>.pt`` goes; default ``checkpoints/`` (the
        shipped one). The full training checkpoint (optimiser and RNG states, resumable) goes to
        ``build/train/<name>.pt``, or ``<out_dir>/train/<name>.pt`` when ``out_dir`` is given.
    data : TrainingData, optional
        Default :func:`training_data` (pass it to train several recipes on one index).
    resume : bool
        Continue the full training checkpoint up to ``epochs`` (same losses as one run).
    progress : bool
        Show the tqdm bar.
    device : str
        :attr:`beatlite.train.TrainConfig.device` (``"cpu"``, ``"cuda"``, ``"auto"``).
    extractor : str or Path, optional
        The FGD extractor of the per-epoch validation score (default the shipped
        ``checkpoints/fgd_dirvec.pt``, trained on ``data_samples/``).
    checkpoint_every : int, optional
        :attr:`beatlite.train.TrainConfig.checkpoint_every` (mid-epoch checkpoints, resumable).
    batch_size : int, optional
        Windows per step instead of the recipe's (its :attr:`Recipe.gpu_batch_size` and ``gpu_lr`` on CUDA,
        else its ``batch_size`` and ``lr``); the learning rates scale with it as ``lr_scaling`` says (:func:`scaled_lr`). Not the recipe the
        shipped numbers were measured with (``bench/batch_scaling.py`` measures what it changes).
    data_on_device : {"auto", "always", "never"}
        :attr:`beatlite.train.TrainConfig.data_on_device` (the store's streams held on the GPU).
    amp : bool
        :attr:`beatlite.train.TrainConfig.amp` (bfloat16 autocast). Not the precision the shipped numbers
        were measured with.
    compile : str, optional
        :attr:`beatlite.train.TrainConfig.compile` (``torch.compile`` mode or backend).
    val_every : int, optional
        :attr:`beatlite.train.TrainConfig.val_every`: validate (losses, validation FGD, best weights) every
        this many optimiser steps instead of every epoch.
    deterministic : bool
        :attr:`beatlite.train.TrainConfig.deterministic` (``False``: CUDA's faster nondeterministic kernels).
    lr_scaling : {"linear", "sqrt"}
        How the learning rates follow ``batch_size`` (:func:`scaled_lr`).
    audio_matmul : {"auto", "on", "off"}
        :attr:`beatlite.train.TrainConfig.audio_matmul` (raw-audio blocks as a matrix product; auto: on CUDA).
    lr : float, optional
        The generator learning rate at the run's batch, instead of the recipe's scaled to it (the
        discriminator's is 0.2 times it).
    preset : str
        The model's size (a key of :func:`beatlite.models.presets`), with the recipe's switches on top; the
        checkpoints of another preset than ``"tiny"`` are named :func:`run_name` (``camn_tiny-paper.pt``; in
        ``checkpoints/`` without ``out_dir``, where no results table reads them).

    Returns
    -------
    float
        Seconds spent in :func:`beatlite.train.fit` (window building excluded).
    """
    from beatlite.train.checkpoint import export_checkpoint
    from beatlite.train.distributed import distributed_rank
    from beatlite.train.training import fit

    recipe = _recipe(name)
    stem = run_name(name, preset)
    if out_dir is None:
        export, full = paths.checkpoints_dir() / f"{stem}.pt", paths.build_dir() / "train" / f"{stem}.pt"
    else:
        export, full = Path(out_dir) / f"{stem}.pt", Path(out_dir) / "train" / f"{stem}.pt"
    config = recipe_train_config(
        name,
        seed=seed,
        epochs=epochs,
        checkpoint=full,
        resume=resume,
        progress=progress,
        device=device,
        checkpoint_every=checkpoint_every,
        batch_size=batch_size,
        data_on_device=data_on_device,
        amp=amp,
        compile=compile,
        val_every=val_every,
        deterministic=deterministic,
        lr_scaling=lr_scaling,
        audio_matmul=audio_matmul,
        lr=lr,
        preset=preset,
    )  # bad values raise here, before any data work
    data = training_data() if data is None else data
    model = build_recipe_model(name, data, seed=seed, preset=preset)
    score = None
    if recipe.select_best and config.epochs > 0:
        from beatlite.metrics.extractor import load_extractor

        features = load_extractor("dirvec", extractor)
        score = fgd_scorer(normalizers=data.train.normalizers, takes=data.val_takes, extractor=features)
    start = time.perf_counter()
    fit(model, data.train, config, data.val, meta=data.meta, val_score=score)
    seconds = time.perf_counter() - start
    if distributed_rank()[0] == 0:  # under torchrun, process 0 writes
        export_checkpoint(full, export)
    return seconds


def _retrain_in_worker(
    name: str, seed: int, out_dir: str | None, epochs: int | None
) -> tuple[str, int, float]:
    import os

    os.environ["BEATLITE_THREADS"] = "1"
    return name, seed, retrain(name, seed=seed, epochs=epochs, out_dir=out_dir, progress=False)


def retrain_many(
    runs: Sequence[tuple[str, int, str | Path | None]],
    *,
    jobs: int = 1,
    epochs: int | None = None,
    on_done: Callable[[str, int, float], None] | None = None,
) -> dict[tuple[str, int], float]:
    """Run :func:`retrain` for every ``(name, seed, out_dir)`` of ``runs``.

    Parameters
    ----------
    runs : sequence of (str, int, str or Path or None)
        Recipe name, seed and ``out_dir`` of :func:`retrain` (``None`` = ``checkpoints/``).
    jobs : int
        Training processes at once. ``1`` trains here, one after the other, on one
        :func:`training_data`; ``> 1`` starts that many worker processes with one torch thread
        each (right for an otherwise idle machine with that many cores: two busy processes on
        two cores slow each other down). The numbers do not depend on ``jobs``.
    epochs : int, optional
        Override every recipe's epochs (quick checks).
    on_done : callable, optional
        ``on_done(name, seed, seconds)`` after each run (in this process).

    Returns
    -------
    dict (name, seed) -> seconds of training
    """
    for name, _, _ in runs:
        _recipe(name)
    if jobs < 1:
        raise ValueError(f"jobs must be >= 1, got {jobs}")
    done: dict[tuple[str, int], float] = {}

    def record(name: str, seed: int, seconds: float) -> None:
        done[(name, seed)] = seconds
        if on_done is not None:
            on_done(name, seed, seconds)

    if jobs == 1 or len(runs) < 2:
        data = training_data() if runs else None
        for name, seed, out in runs:
            record(name, seed, retrain(name, seed=seed, epochs=epochs, out_dir=out, data=data))
        return done
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    warm_up()  # librosa's numba code compiled here once, not by the workers at once (a corrupted cache)
    with ProcessPoolExecutor(jobs, mp_context=multiprocessing.get_context("spawn")) as pool:
        futures = [
            pool.submit(_retrain_in_worker, name, seed, None if out is None else str(out), epochs)
            for name, seed, out in runs
        ]
        for future in as_completed(futures):
            record(*future.result())
    return done


def run_name(name: str, preset: str = "tiny") -> str:
    """The stem of the checkpoints of recipe ``name`` trained at ``preset``: ``name`` for the recipes'
    ``"tiny"``, else ``name-preset``.

    >>> run_name("camn_tiny"), run_name("camn_tiny", "paper")
    ('camn_tiny', 'camn_tiny-paper')
    """
    return name if preset == "tiny" else f"{name}-{preset}"


def check_preset(name: str, preset: str) -> None:
    """``ValueError`` unless ``preset`` is a preset of recipe ``name``'s model.

    >>> check_preset("camn_tiny", "paper")
    >>> check_preset("camn_tiny", "huge")
    Traceback (most recent call last):
    ...
    ValueError: camn_tiny: camn has no preset 'huge' (its presets: paper, tiny)
    """
    model = _recipe(name).model
    if preset not in presets(model):
        raise ValueError(
            f"{name}: {model} has no preset {preset!r} (its presets: {', '.join(sorted(presets(model)))})"
        )


def _recipe(name: str) -> Recipe:
    if name not in RECIPES:
        raise ValueError(f"unknown checkpoint name {name!r}; known: {sorted(RECIPES)}")
    return RECIPES[name]
