"""Evaluate gesture models on whole test takes: the results table of BEAT Tables 4/5 and HA2G Tables 1/3/4.

Usage (skipped by the doctests: it loads every shipped checkpoint and runs for minutes):

>>> from beatlite.train.evaluation import evaluate_models      # doctest: +SKIP
>>> res = evaluate_models(["mean_pose", "camn_tiny", "s2g_tiny"])  # doctest: +SKIP
>>> print(res.to_markdown())                                     # doctest: +SKIP

Every model generates each test take whole (:func:`beatlite.train.generate`, seeded by
the first 4 ground-truth frames). All rows are then scored in one **common space**, the
TED-43 skeleton of HA2G (:mod:`beatlite.skeleton.ted`), so that Euler models (CaMN, the
baselines) and direction models (HA2G) are comparable:

- Euler rows: denormalised ``spine_neck_141`` degrees -> 228-channel BEAT motion (other
  joints at rest, root at the origin) -> forward kinematics -> ``beat_to_ted43`` -> 42 unit
  bone directions (exactly how :mod:`beatlite.data.windows` makes ``"dirvec"``).
- Direction rows: mean added back and renormalised.
- Positions for SRGR / BeatAlign / L1div: the directions chained with fixed bone lengths
  (those of the BEAT rest skeleton in TED-43, cm), root at the origin, for every row
  (ground truth included).

Metrics (``COLUMNS``):

=============  ====================================================================================
``FGD``        Fréchet distance of ``load_extractor("dirvec")`` features of 34-frame windows
               (stride 10, mean-subtracted directions) of all test takes vs the ground truth's
``SRGR``       paper variant on TED-43 positions, delta 10 cm, ground-truth semantic scores
``BeatAlign``  audio onsets vs joint-speed minima (positions, sigma 0.3 s), mean over takes
``BC``         HA2G Beat Consistency on the whole takes (sigma 0.1 s, MAAC of the train windows)
``Diversity``  HA2G Diversity: mean L1 distance of extractor features of 500 random window pairs
``L1div``      BEAT L1div on TED-43 positions (cm summed over 43 x 3 per frame)
=============  ====================================================================================

Two ground-truth rows: ``Ground truth`` (the dataset's TED-43 directions, the FGD reference,
FGD 0 by definition) and ``Ground truth (141 Euler channels)`` (only the channels the Euler
models predict, the rest at rest pose: the floor an Euler model can reach).
Nothing is cached outside ``build/`` (the window caches of :mod:`beatlite.data.windows`).

Taught in notebooks/05_camn.ipynb, section 6 (evaluation on the test split) and notebooks/07_benchmark.ipynb, section 1 (one evaluation, one common space).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from beatlite.constants import FPS, SR, WINDOW_LENGTH
from beatlite.data.normalize import Normalizers
from beatlite.metrics.scoring import ARROWS, METRICS, GroundTruth, Takes, describe, evaluate

COLUMNS: tuple[str, ...] = ("FGD", "SRGR", "BeatAlign", "BC", "Diversity", "L1div")
"""The results table's columns, in order: keys of :data:`beatlite.metrics.scoring.METRICS`
(each names its variant and parameters; the table caption lists them)."""

RECORD_COLUMNS: tuple[str, ...] = (
    *COLUMNS,
    "FGD (BEAT AE)",
    "FGD (reference)",
    "SRGR (reference)",
    "BeatAlign (reference)",
    "BC (ha2g)",
)
"""The metrics of the recorded seed table (``checkpoints/results_seeds.json``): :data:`COLUMNS`, then
the variants the papers' code computes (FGD in BEAT's Euler space and with scipy's square root, BEAT's
SRGR and BeatAlign on Euler angles, HA2G's BC on 34-frame clips) for the side-by-side tables of
notebooks 06-07."""

GROUND_TRUTH = "Ground truth"
GROUND_TRUTH_141 = "Ground truth (141 Euler channels)"


@dataclasses.dataclass
class ResultRow:
    """One row of the results table.

    Attributes
    ----------
    label : str
        Display name (e.g. ``"CaMN w/o audio"``).
    source : str
        Checkpoint name, ``"ground_truth"`` or ``"<given>"`` for a model passed in.
    representation : str
        ``"euler141"``, ``"dirvec126"`` or ``"ground_truth"``.
    metrics : dict of str -> float
        Values of :data:`COLUMNS` (NaN where undefined).
    seconds : float
        Wall time to generate all test takes (0 for ground-truth rows).
    fingerprint : str
        Data fingerprint stored in the checkpoint ("" when unknown).
    stale : bool
        The checkpoint was trained on other data than the evaluated corpus' train split
        (marked with a dagger in the table).
    """

    label: str
    source: str
    representation: str
    metrics: dict[str, float]
    seconds: float = 0.0
    fingerprint: str = ""
    stale: bool = False


@dataclasses.dataclass
class ModelResults:
    """Rows of :func:`evaluate_models` with the evaluation settings.

    Attributes
    ----------
    rows : list of ResultRow
    info : dict
        Split, takes, frames, window counts, extractor path, total seconds.
    """

    rows: list[ResultRow]
    info: dict[str, Any]

    def get(self, label_or_source: str) -> ResultRow:
        """The row with this label or checkpoint name (``KeyError`` if none)."""
        for row in self.rows:
            if label_or_source in (row.label, row.source):
                return row
        raise KeyError(f"no row {label_or_source!r}; have {[r.label for r in self.rows]}")

    def value(self, row: str, metric: str) -> float:
        """``get(row).metrics[metric]``."""
        return self.get(row).metrics[metric]

    def to_markdown(self, columns: Sequence[str] | None = None, *, caption: bool = True) -> str:
        """A Markdown table: one row per model, its metrics, generation seconds.

        Parameters
        ----------
        columns : sequence of str, optional
            Metric keys to show, in order (default :attr:`columns`, all that were scored); the
            header names the variant (``"SRGR (reference) ↑"``). A key a row was not scored with
            shows as ``—``.
        caption : bool
            Append the variant and parameters of every column.

        Returns
        -------
        str

        Examples
        --------
        >>> res = ModelResults([ResultRow("A", "a", "ground_truth", {"SRGR": 0.25, "BC": math.nan})], {})
        >>> print(res.to_markdown(["SRGR", "BC"], caption=False))
        | method | SRGR ↑ | BC ↑ | gen. s |
        |---|---|---|---|
        | A | 0.250 | — |  |
        """
        from beatlite.report import markdown_table

        columns = self.columns if columns is None else tuple(columns)
        unknown = [key for key in columns if key not in METRICS]
        if unknown:
            raise ValueError(f"unknown metric keys {unknown}; known: {sorted(METRICS)}")
        rows = []
        for row in self.rows:
            cells = [row.label + (" †" if row.stale else "")]
            cells += [fmt_metric(row.metrics.get(key, math.nan), key) for key in columns]
            cells.append(f"{row.seconds:.2f}" if row.representation != "ground_truth" else "")
            rows.append(cells)
        text = markdown_table(["method", *column_headers(columns), "gen. s"], rows)
        if any(row.stale for row in self.rows):
            text += "\n\n† trained on another version of the data than the one evaluated: retrain it."
        return text + ("\n\n" + describe(columns) if caption else "")

    @property
    def columns(self) -> tuple[str, ...]:
        """The metric keys of the table, in order (:data:`COLUMNS` unless chosen otherwise)."""
        return tuple(self.info.get("columns", COLUMNS))

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly dict: ``{"columns", "rows": [...], "info"}`` (NaN written as None)."""
        return {
            "columns": [
                {"name": key, "higher_is_better": METRICS[key].higher_is_better} for key in self.columns
            ],
            "rows": [
                {
                    **dataclasses.asdict(r),
                    "metrics": {k: (None if not math.isfinite(v) else v) for k, v in r.metrics.items()},
                }
                for r in self.rows
            ],
            "info": self.info,
        }


def column_headers(keys: Sequence[str]) -> list[str]:
    """``"FGD ↓"``, ``"SRGR ↑"``, ``"Jerk (GENEA)"``: each metric key with the arrow of its better direction
    (none for a descriptive metric, ``higher_is_better=None``).

    Examples
    --------
    >>> column_headers(["FGD", "SRGR", "Jerk (GENEA)"])
    ['FGD ↓', 'SRGR ↑', 'Jerk (GENEA)']
    """
    return [key + ARROWS[METRICS[key].higher_is_better] for key in keys]


def fmt_metric(v: float, key: str) -> str:
    """``v`` as printed in the results tables: 2 decimals for FGD/Diversity/L1div, 3 for the rest."""
    if not math.isfinite(v):
        return "—"
    if METRICS[key].name in ("FGD", "Diversity", "L1div"):
        return f"{v:.2f}" if abs(v) < 100 else f"{v:.1f}"
    return f"{v:.3f}"


# ------------------------------------------------------------------------------------ the test set
@dataclasses.dataclass(eq=False)
class EvaluationSet:
    """Whole test takes prepared once for :func:`evaluate_models`.

    Attributes
    ----------
    takes : list of str
        Take stems.
    streams : list of dict
        Per take, the whole-take inputs of :func:`beatlite.train.generation.generate_sequence`:
        ``pose`` (T, 141) z-scored, ``dirvec`` (T, 126), ``audio`` (S,), ``mel`` (M, 128),
        ``face`` (T, 51), ``word``/``emotion`` (T,) int64, ``semantic`` (T,), ``speaker`` int.
    gt_directions : list of (T, 42, 3) float64
        The dataset's TED-43 unit bone directions (full motion).
    gt_directions_141 : list of (T, 42, 3) float64
        The same computed from the 141 Euler channels only (other joints at rest).
    gt_euler : list of (T, 141) float64
        The ground truth's ``spine_neck_141`` Euler degrees (the reference metric variants).
    semantic : list of (T,) float
    audio : list of (S,) float32, 16 kHz
    normalizers : Normalizers
        The train split's fitted normalisers the streams were normalised with.
    change_angle : (41,) float64
        HA2G's MAAC per angle pair from the train windows (for BC).
    vocab : tuple of str
        The vocabulary the word ids refer to.
    audio_beats : list of (K,) float64
        Onset times (s) of each take's audio (:func:`beatlite.metrics.audio_beats` defaults),
        computed once and shared by BeatAlign and BC (:meth:`beats`).
    fingerprint : str
        :func:`beatlite.train.data_fingerprint` of the train windows ("" = unknown): checkpoints
        trained on other data are flagged as stale.
    train_speakers : tuple of int
        Speaker indices of the train windows (HA2G's sampled protocol draws from them).
    mean_speed : (43,) float64, cm/s, optional
        Mean speed of each TED-43 joint over the train windows in the common positions space (EMAGE's
        ``avg_vel``, for ``"BC (emage)"``).
    """

    takes: list[str]
    streams: list[dict[str, Any]]
    gt_directions: list[np.ndarray]
    gt_directions_141: list[np.ndarray]
    gt_euler: list[np.ndarray]
    semantic: list[np.ndarray]
    audio: list[np.ndarray]
    normalizers: Normalizers
    change_angle: np.ndarray
    vocab: tuple[str, ...]
    split: str = "test"
    audio_beats: list[np.ndarray] = dataclasses.field(default_factory=list)
    fingerprint: str = ""
    train_speakers: tuple[int, ...] = ()
    mean_speed: np.ndarray | None = None

    def beats(self) -> list[np.ndarray]:
        """:attr:`audio_beats`, computed now if empty."""
        if len(self.audio_beats) != len(self.audio):
            from beatlite.metrics import audio_beats

            self.audio_beats = [audio_beats(y, SR) for y in self.audio]
        return self.audio_beats

    def ground_truth(self, extractor: Any, euler_extractor: Any = None) -> GroundTruth:
        """The :class:`~beatlite.metrics.scoring.GroundTruth` every row is scored against
        (``euler_extractor``: the Euler autoencoder of ``"FGD (BEAT AE)"``, optional)."""
        takes = directions_takes(
            self.gt_directions, self, extractor, euler=self.gt_euler, euler_extractor=euler_extractor
        )
        return GroundTruth(
            takes,
            semantic=self.semantic,
            audio=self.audio,
            audio_beats=self.beats(),
            change_angle=self.change_angle,
            mean_direction=self.normalizers.dirvec.mean,
            mean_speed=self.mean_speed,
        )

    @property
    def n_frames(self) -> int:
        """Total frames over all takes."""
        return int(sum(s["pose"].shape[0] for s in self.streams))


@functools.cache
def rest_bone_lengths() -> np.ndarray:
    """(42,) float64 cm: TED-43 bone lengths of the BEAT rest skeleton (the common positions space)."""
    from beatlite.skeleton.beat import beat_skeleton
    from beatlite.skeleton.kinematics import rest_pose
    from beatlite.skeleton.ted import TED_BONES, beat_to_ted43

    ted = beat_to_ted43(rest_pose(beat_skeleton())[None])[0]
    bones = np.asarray(TED_BONES)
    lengths = np.linalg.norm(ted[bones[:, 1]] - ted[bones[:, 0]], axis=-1)
    lengths.setflags(write=False)
    return lengths


def euler_to_directions(euler: np.ndarray) -> np.ndarray:
    """TED-43 unit bone directions of ``spine_neck_141`` Euler angles.

    Parameters
    ----------
    euler : (T, 141) float, degrees
        Denormalised CaMN-layout channels; every other BEAT channel is 0 (rest), root at the origin.

    Returns
    -------
    (T, 42, 3) float64 unit vectors (the construction of ``build_windows``' ``"dirvec"``).
    """
    from beatlite.skeleton.beat import expand_subset

    euler = np.asarray(euler, dtype=np.float64)
    if euler.ndim != 2 or euler.shape[1] != 141:
        raise ValueError(f"euler must be (T, 141) degrees, got shape {euler.shape}")
    return channels_to_directions(expand_subset(euler, "spine_neck_141"))


def channels_to_directions(channels: np.ndarray) -> np.ndarray:
    """TED-43 unit bone directions of full BEAT motion rows on beatlite's BEAT skeleton.

    Parameters
    ----------
    channels : (T, 228) float
        :func:`beatlite.skeleton.beat.beat_skeleton` channel rows (root position cm, rotations degrees,
        ``Xrotation Yrotation Zrotation``).

    Returns
    -------
    (T, 42, 3) float64 unit vectors: forward kinematics -> ``beat_to_ted43`` -> bone directions.
    """
    from beatlite.io.motion import Motion
    from beatlite.skeleton.beat import beat_skeleton
    from beatlite.skeleton.directions import positions_to_directions
    from beatlite.skeleton.ted import TED_BONES, beat_to_ted43

    motion = Motion(beat_skeleton(), channels, FPS)
    return positions_to_directions(beat_to_ted43(motion.positions()), np.asarray(TED_BONES))


def directions_to_ted_positions(directions: np.ndarray, lengths: np.ndarray | None = None) -> np.ndarray:
    """(T, 42, 3) unit directions -> (T, 43, 3) cm TED-43 positions, root at the origin.

    ``lengths`` (42,) cm default to :func:`rest_bone_lengths` (the common positions space).
    """
    from beatlite.skeleton.directions import directions_to_positions
    from beatlite.skeleton.ted import TED_BONES

    lengths = rest_bone_lengths() if lengths is None else lengths
    return directions_to_positions(directions, np.asarray(TED_BONES), lengths, np.zeros(3))


def load_test_set(
    index: Any = None, *, split: str = "test", vocab: Any = None, store: Any = None
) -> EvaluationSet:
    """Load the whole takes of ``split`` from the window store, with train-split normalisation.

    Parameters
    ----------
    index : TakeIndex, optional
        Default :func:`beatlite.data.index.index_folder` of :func:`beatlite.paths.data_dir`.
    split : {"test", "val", "train"}
        Takes to evaluate on.
    vocab : Vocab, optional
        Default :func:`beatlite.data.vocab.build_vocab` of ``index`` (what ``retrain-all`` uses).
    store : WindowStore, optional
        Default :func:`beatlite.data.store.build_store` of ``index`` (built once, then only takes
        whose files changed are rebuilt). The statistics are the store's train statistics
        (:meth:`~beatlite.data.store.WindowStore.statistics`); the train windows are never held in memory.

    Returns
    -------
    EvaluationSet
    """
    from beatlite.data.index import index_folder
    from beatlite.data.store import build_store
    from beatlite.data.vocab import build_vocab
    from beatlite.paths import data_dir

    index = index_folder(data_dir()) if index is None else index
    vocab = build_vocab(index) if vocab is None else vocab
    store = build_store(index, vocab=vocab) if store is None else store
    train = store.windows("train", vocab=vocab)  # an index of (take, start): read in batches below
    norms = train.normalizers
    stems = [t.stem for t in store.takes if t.meta["split"] == split]
    if not stems:
        raise ValueError(f"load_test_set: no usable take of split {split!r} in {store.folder}")
    items = [store.whole_take(stem, stats=norms, vocab=vocab) for stem in stems]
    keys = ("pose", "dirvec", "audio", "mel", "face", "word", "emotion", "semantic")
    test = EvaluationSet(
        takes=stems,
        streams=[{**{k: item[k] for k in keys}, "speaker": int(item["speaker"])} for item in items],
        gt_directions=[norms.inverse_transform(item["dirvec"], "dirvec126") for item in items],
        gt_directions_141=[euler_to_directions(item["pose_raw"]) for item in items],
        gt_euler=[np.asarray(item["pose_raw"], np.float64) for item in items],
        semantic=[np.asarray(item["semantic"], np.float64) for item in items],
        audio=[np.asarray(item["audio"], np.float32) for item in items],
        normalizers=norms,
        change_angle=train_change_angle(train),
        mean_speed=train_mean_speed(train),
        vocab=tuple(vocab.itos),
        split=split,
        fingerprint=train.fingerprint,
        train_speakers=tuple(
            sorted({int(store.takes[i].meta["speaker"]) for i in np.unique(train.take_ids)})
        ),
    )
    test.beats()
    return test


def train_change_angle(train: Any, batch_size: int = 1024) -> np.ndarray:
    """(41,) MAAC per HA2G angle pair over the train windows (beat consistency's normaliser, HA2G eq. 10).

    ``train`` is a :class:`~beatlite.data.windows.Windows` or a store's
    :class:`~beatlite.data.store.StoreWindows`; its ``dirvec`` is read ``batch_size`` windows at a
    time (memory flat) and the per-window sums of :func:`beatlite.metrics.beats.mean_angle_change`
    are pooled (every window has ``length - 1`` frame steps, so the pooled mean is the batch means'
    average weighted by their window counts).
    """
    from beatlite.metrics.beats import mean_angle_change
    from beatlite.metrics.consistency import default_angle_pairs, prepare_directions

    pairs, n = default_angle_pairs(), len(train)
    total = np.zeros(len(pairs))
    for start in range(0, n, batch_size):
        idx = np.arange(start, min(n, start + batch_size))
        batch = train.batch(idx, keys=("dirvec",))
        # mean added back without re-normalising here: prepare_directions normalises once (as HA2G does)
        dirs = train.normalizers.dirvec.inverse_transform(np.asarray(batch["dirvec"], np.float64))
        total += mean_angle_change([prepare_directions(w) for w in dirs], pairs) * len(idx)
    return total / n


def train_mean_speed(train: Any) -> np.ndarray:
    """(43,) float64 cm/s: mean speed of each TED-43 joint over the train windows (central differences within
    each window, positions of the common space), EMAGE's per-joint ``avg_vel`` for ``"BC (emage)"``."""
    from beatlite.metrics.beats import position_speed

    dirs = train.normalizers.inverse_transform(np.asarray(train["dirvec"], np.float64), "dirvec126")
    n, length = dirs.shape[:2]
    positions = directions_to_ted_positions(dirs.reshape(n * length, 42, 3)).reshape(n, length, 43, 3)
    return np.mean([position_speed(w, FPS) for w in positions], axis=(0, 1))


# ------------------------------------------------------------------------------------ generation
def generated_directions(
    model: Any, test: EvaluationSet, normalizers: Normalizers | None = None
) -> list[np.ndarray]:
    """Generate every take of ``test`` with ``model`` and return its TED-43 directions.

    The takes are generated whole as :func:`beatlite.train.generate` does (34-frame units,
    stride 30, seeded by the first 4 ground-truth frames), all takes' units batched together
    (:func:`beatlite.train.generation.generate_sequences`).

    Parameters
    ----------
    model : GestureModel
        Trained, in eval mode.
    test : EvaluationSet
    normalizers : Normalizers, optional
        The statistics the model was trained with (its checkpoint's); default ``test.normalizers``.
        The seed frames and outputs are in these units.

    Returns
    -------
    list of (T, 42, 3) float64 unit vectors, one per take.
    """
    directions, _ = generate_takes(model, test, normalizers)
    return directions


def generate_takes(
    model: Any, test: EvaluationSet, normalizers: Normalizers | None
) -> tuple[list[np.ndarray], list[np.ndarray] | None]:
    """Generate every take of ``test`` with ``model`` (the generation of :func:`evaluate_models`).

    Parameters
    ----------
    model : GestureModel
        In eval mode (call under ``torch.no_grad()``).
    test : EvaluationSet
    normalizers : Normalizers or None
        The model's training statistics (default ``test.normalizers``).

    Returns
    -------
    (directions, euler)
        Per take (T, 42, 3) unit directions, and (T, 141) Euler degrees (None for direction models).
    """
    from beatlite.train.generation import generate_sequences

    norms = test.normalizers if normalizers is None else normalizers
    if hasattr(model, "reset"):
        model.reset()  # RandomClip: restart its deterministic draws
    streams = (
        test.streams
        if norms is test.normalizers
        else [_in_units(s, test.normalizers, norms) for s in test.streams]
    )
    poses = generate_sequences(model, streams)
    if model.representation == "euler141":
        euler = [norms.inverse_transform(p, "euler141") for p in poses]
        return [euler_to_directions(e) for e in euler], euler
    return [norms.inverse_transform(p, "dirvec126") for p in poses], None


class SampledProtocol:
    """HA2G's evaluation-code protocol, as a model the tables can score.

    HA2G's code scores generated clips with a style code *sampled* for a *random training speaker*
    (``HA2G.generate(..., protocol="sampled")``); beatlite's tables use z = mu and the take's own speaker.
    Pass ``(label, SampledProtocol(model, test.train_speakers, seed), normalizers)`` to
    :func:`evaluate_models`, with ``columns=("FGD", "BC (ha2g)", "Diversity")`` for HA2G's columns
    (BC on 34-frame clips). Every evaluation restarts the draws from ``seed`` (same numbers each time).
    """

    def __init__(self, model: Any, speakers: Sequence[int], seed: int = 0) -> None:
        import torch

        if not speakers:
            raise ValueError("SampledProtocol needs the training speakers (EvaluationSet.train_speakers)")
        self.model, self.speakers, self.seed = model, tuple(int(s) for s in speakers), int(seed)
        self.generator = torch.Generator().manual_seed(self.seed)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.model, name)

    def reset(self) -> None:
        """Restart the draws (called before every evaluation)."""
        self.generator.manual_seed(self.seed)

    def generate(self, batch: Any) -> Any:
        return self.model.generate(
            batch, protocol="sampled", speakers=self.speakers, generator=self.generator
        )


def _in_units(stream: dict[str, Any], have: Normalizers, want: Normalizers) -> dict[str, Any]:
    """The take's seed streams re-expressed in the model's normalisation when it differs."""
    if have.matches(want, rtol=0, atol=0):
        return stream
    out = dict(stream)
    for rep, key in (("euler141", "pose"), ("dirvec126", "dirvec")):
        out[key] = want.transform(have.inverse_transform(stream[key], rep), rep).astype(np.float32)
    return out


def fgd_scorer(
    split: str = "val",
    *,
    index: Any = None,
    vocab: Any = None,
    normalizers: Normalizers | None = None,
    extractor: Any = None,
    takes: EvaluationSet | None = None,
) -> Callable[[Any], float]:
    """A ``val_score`` for :func:`beatlite.train.fit`: FGD of a model's generation of ``split``'s whole takes.

    BEAT's reference trainer validates every epoch by FGD on the validation set and keeps the
    best epoch (docs/reference_code.md#camn-training); this is that score, computed exactly as the ``FGD``
    column of :func:`evaluate_models` but on the ``val`` takes (so the test split stays unseen).

    Parameters
    ----------
    split : str
        Takes to generate (``"val"``).
    index, vocab
        As :func:`load_test_set` (pass the training vocabulary).
    normalizers : Normalizers, optional
        The statistics the model trains with; default the split's.
    extractor : callable, optional
        Default ``load_extractor("dirvec")``.
    takes : EvaluationSet, optional
        The prepared takes (default ``load_test_set(index, split=split, vocab=vocab)``).

    Returns
    -------
    callable
        ``score(model) -> float`` (model in eval mode; call under ``torch.no_grad()``).
    """
    from beatlite.metrics import fgd
    from beatlite.metrics.extractor import load_extractor

    takes = load_test_set(index, split=split, vocab=vocab) if takes is None else takes
    extractor = load_extractor("dirvec") if extractor is None else extractor
    real = direction_features(takes.gt_directions, takes, extractor)

    def score(model: Any) -> float:
        return float(
            fgd(direction_features(generated_directions(model, takes, normalizers), takes, extractor), real)
        )

    return score


# ------------------------------------------------------------------------------------ scoring
def direction_features(directions: list[np.ndarray], test: EvaluationSet, extractor: Any) -> np.ndarray:
    """(N, F) float64 extractor features of the mean-subtracted 34-frame windows (stride 10) of all takes."""
    return _window_features(directions, "dirvec126", test, extractor)


def euler_features(euler: list[np.ndarray], test: EvaluationSet, extractor: Any) -> np.ndarray:
    """(N, F) float64 features of the z-scored (train statistics) 34-frame Euler windows (stride 10)."""
    return _window_features(euler, "euler141", test, extractor)


def _window_features(
    takes: list[np.ndarray], representation: str, test: EvaluationSet, extractor: Any
) -> np.ndarray:
    """``extractor`` features of the 34-frame windows (stride 10) of every take, normalised with the
    train statistics of ``representation``."""
    from beatlite.data.windows import sliding_windows

    windows = sliding_windows([test.normalizers.transform(x, representation) for x in takes])
    if not len(windows):
        raise ValueError(f"no take has {WINDOW_LENGTH} frames: cannot cut FGD windows")
    return np.asarray(extractor(windows.astype(np.float32)), np.float64)


def directions_takes(
    directions: list[np.ndarray],
    test: EvaluationSet,
    extractor: Any,
    *,
    euler: list[np.ndarray] | None = None,
    euler_extractor: Any = None,
) -> Takes:
    """A row's :class:`~beatlite.metrics.scoring.Takes`: TED-43 positions, directions, features (+ Euler,
    + the Euler autoencoder's features when both ``euler`` and ``euler_extractor`` are given)."""
    if len(directions) != len(test.takes):
        raise ValueError(f"directions has {len(directions)} takes, the test set {len(test.takes)}")
    for i, (d, s) in enumerate(zip(directions, test.streams, strict=True)):
        if d.shape != (s["pose"].shape[0], 42, 3):
            raise ValueError(f"directions[{i}] must be ({s['pose'].shape[0]}, 42, 3), got {d.shape}")
    return Takes(
        positions=[directions_to_ted_positions(d) for d in directions],
        directions=list(directions),
        euler=euler,
        features=direction_features(directions, test, extractor),
        euler_features=None
        if euler is None or euler_extractor is None
        else euler_features(euler, test, euler_extractor),
    )


def score_directions(
    directions: list[np.ndarray],
    test: EvaluationSet,
    extractor: Any,
    truth: GroundTruth,
    *,
    euler: list[np.ndarray] | None = None,
    columns: Sequence[str] = COLUMNS,
    seed: int = 0,
    euler_extractor: Any = None,
) -> dict[str, float]:
    """The metrics of ``columns`` for one row's per-take directions (T, 42, 3) (NaN where undefined)."""
    takes = directions_takes(directions, test, extractor, euler=euler, euler_extractor=euler_extractor)
    values = evaluate(takes, truth, metrics=columns, seed=seed).values()
    return {key: values[key] for key in columns}


def _as_entries(models: Sequence[Any] | None) -> list[tuple[str, str, Any, Normalizers | None]]:
    """Normalise ``models`` to (label, source, model or None, normalizers) entries."""
    from beatlite.paths import checkpoints_dir
    from beatlite.train.recipes import RECIPES, label_of

    if models is None:
        models = [name for name in RECIPES if (checkpoints_dir() / f"{name}.pt").is_file()]
    entries = []
    for item in models:
        if isinstance(item, str | Path):
            name = Path(item).stem if str(item).endswith(".pt") else str(item)
            entries.append((label_of(name), str(item), None, None))
        elif isinstance(item, tuple) and len(item) in (2, 3):
            norms = item[2] if len(item) == 3 else None
            if norms is not None and not isinstance(norms, Normalizers):
                raise TypeError(
                    f"the third entry of {item[0]!r} must be Normalizers, got {type(norms).__name__}"
                )
            entries.append((str(item[0]), "<given>", item[1], norms))
        else:
            raise TypeError(
                "models entries must be checkpoint names/paths or (label, model[, normalizers]) tuples, "
                f"got {type(item).__name__}"
            )
    return entries


def evaluate_models(
    models: Sequence[Any] | None = None,
    *,
    test: EvaluationSet | None = None,
    extractor: Any = None,
    ground_truth: bool = True,
    seed: int = 0,
    progress: bool = False,
    columns: Sequence[str] = COLUMNS,
    euler_extractor: Any = None,
) -> ModelResults:
    """Generate every test take with each model and score all of them in the TED-43 space.

    Parameters
    ----------
    models : sequence, optional
        Checkpoint names (``"camn_tiny"``, looked up in ``checkpoints/``) or paths, and/or
        ``(label, model)`` / ``(label, model, normalizers)`` tuples for models trained in a notebook
        (``normalizers``: the :class:`~beatlite.data.normalize.Normalizers` they were trained with;
        default the test set's). Default: every checkpoint of :data:`~beatlite.train.recipes.RECIPES`
        found in ``checkpoints/``, in that order.
    test : EvaluationSet, optional
        Default :func:`load_test_set` (``data_samples/`` test split).
    extractor : callable, optional
        (N, 34, 126) -> (N, F) features; default ``load_extractor("dirvec")``.
    ground_truth : bool
        Add the two ground-truth rows first.
    seed : int
        Seed of the Diversity pairing.
    progress : bool
        Print one line per row.
    columns : sequence of str
        Metric keys of :data:`beatlite.metrics.scoring.METRICS` to score (default :data:`COLUMNS`; e.g.
        the reference variants ``"SRGR (reference)"``, ``"BC (ha2g)"`` for a like-for-like table).
    euler_extractor : callable, optional
        (N, 34, 141) -> (N, F) features of z-scored Euler windows for ``"FGD (BEAT AE)"``; default
        ``load_extractor("pose")``, loaded only when that column is asked for.

    Returns
    -------
    ModelResults
    """
    import torch

    from beatlite.metrics.extractor import load_extractor
    from beatlite.paths import n_threads

    unknown = [key for key in columns if key not in METRICS]
    if unknown:
        raise ValueError(f"unknown metric keys {unknown}; known: {sorted(METRICS)}")
    start = time.perf_counter()
    torch.set_num_threads(n_threads())
    entries = _as_entries(models)
    test = load_test_set() if test is None else test
    extractor = load_extractor("dirvec") if extractor is None else extractor
    euler_ae = None
    if "FGD (BEAT AE)" in columns:
        euler_ae = load_extractor("pose") if euler_extractor is None else euler_extractor
    truth = test.ground_truth(extractor, euler_ae)
    scoring = {"columns": columns, "seed": seed, "euler_extractor": euler_ae}
    rows: list[ResultRow] = []
    if ground_truth:
        for label, dirs in ((GROUND_TRUTH, test.gt_directions), (GROUND_TRUTH_141, test.gt_directions_141)):
            metrics = score_directions(dirs, test, extractor, truth, euler=test.gt_euler, **scoring)
            rows.append(ResultRow(label, "ground_truth", "ground_truth", metrics))
    for label, source, model, norms in entries:
        rows.append(_model_row(label, source, model, norms, test, extractor, truth, scoring))
        if progress:
            values = ", ".join(f"{k} {v:.4g}" for k, v in rows[-1].metrics.items())
            print(f"{label}: {values} ({rows[-1].seconds:.1f} s)", flush=True)
    info = {
        "split": test.split,
        "takes": list(test.takes),
        "frames": test.n_frames,
        "windows": int(len(truth.takes.features)),
        "fps": FPS,
        "extractor": str(getattr(extractor, "meta", {}).get("path", type(extractor).__name__)),
        "common_space": "TED-43 unit bone directions; positions from BEAT rest-pose bone lengths, root at origin",
        "columns": {key: METRICS[key].describe for key in columns},
        "data_fingerprint": test.fingerprint,
        "seconds": round(time.perf_counter() - start, 2),
    }
    return ModelResults(rows, info)


def _model_row(
    label: str,
    source: str,
    model: Any,
    norms: Normalizers | None,
    test: EvaluationSet,
    extractor: Any,
    truth: GroundTruth,
    scoring: dict[str, Any],
) -> ResultRow:
    """Load (when ``model`` is None), generate and score one model's row (``scoring``: keywords of
    :func:`score_directions`)."""
    import torch

    fingerprint, stale = "", False
    if model is None:
        model, norms, fingerprint, stale = load_checkpoint_for(source, test)
    t0 = time.perf_counter()
    with torch.no_grad():
        dirs, euler = generate_takes(model, test, norms)
    seconds = time.perf_counter() - t0
    metrics = score_directions(dirs, test, extractor, truth, euler=euler, **scoring)
    return ResultRow(label, source, model.representation, metrics, seconds, fingerprint, stale)


def load_checkpoint_for(source: str, test: EvaluationSet) -> tuple[Any, Normalizers | None, str, bool]:
    """(model, its training normalisers, data fingerprint, stale?) of a checkpoint name or path.

    Warns when the checkpoint was trained on other data than ``test``'s train split; a text model whose
    vocabulary differs from the test set's is a ``ValueError``.
    """
    from beatlite.train.checkpoint import load_model

    model, data = load_model(source)
    meta = data.get("meta") or {}
    norms = Normalizers.in_meta(meta)
    _check_vocab(model, data, test, source)
    fingerprint = str(data.get("fingerprint") or "")
    if norms is not None:
        stale = not norms.matches(test.normalizers)
    else:  # trainers may fingerprint different window dicts, so the statistics come first
        stale = bool(test.fingerprint and fingerprint and fingerprint != test.fingerprint)
    if stale:
        warnings.warn(
            f"{source} was trained on other data (fingerprint {fingerprint}) than the evaluated "
            f"corpus' train split ({test.fingerprint}); retrain it (python -m beatlite.train retrain-all)",
            stacklevel=3,
        )
    return model, norms, fingerprint, stale


def _check_vocab(model: Any, data: Mapping[str, Any], test: EvaluationSet, source: str) -> None:
    """Refuse a text model whose checkpoint vocabulary differs from the test set's word ids."""
    if "word" not in tuple(getattr(model, "input_keys", ())):
        return
    vocab = (data.get("meta") or {}).get("vocab")
    if vocab is not None and tuple(vocab) != test.vocab:
        raise ValueError(
            f"{source}: the checkpoint was trained with a different vocabulary ({len(vocab)} words) than "
            f"the test set's ({len(test.vocab)}); retrain it (python -m beatlite.train retrain-all)"
        )


def write_results(results: ModelResults, stem: str | Path | None = None) -> tuple[Path, Path]:
    """Write ``<stem>.md`` and ``<stem>.json`` atomically (default ``build/results_models``)."""
    from beatlite.paths import build_dir
    from beatlite.report import write_markdown_and_json

    stem = Path(stem) if stem is not None else build_dir() / "results_models"
    info = results.info
    text = (
        f"# Gesture models on the `{info['split']}` split\n\n"
        f"{len(info['takes'])} takes, {info['frames']} frames at {info['fps']} fps, {info['windows']} FGD windows "
        f"(34 frames, stride 10). Common space: {info['common_space']}. FGD extractor: `{info['extractor']}`.\n\n"
        + results.to_markdown()
        + f"\n\nEvaluation time: {info['seconds']:.1f} s.\n"
    )
    return write_markdown_and_json(stem, text, results.to_dict())


# ------------------------------------------------------------------------------------ the papers' rows
#: BEAT (ECCV 2022) Table 4, on BEAT's 4-speaker English data: method -> metric -> value. Computed
#: with BEAT's code: FGD of its own autoencoder on 141 Euler channels, SRGR and BeatAlign on Euler
#: angles (our keys ``"SRGR (reference)"`` and ``"BeatAlign (reference)"``).
PAPER_BEAT_TABLE4: dict[str, dict[str, float]] = {
    "Seq2Seq": {"FGD": 261.3, "SRGR": 0.173, "BeatAlign": 0.729},
    "S2G": {"FGD": 256.7, "SRGR": 0.092, "BeatAlign": 0.751},
    "A2G": {"FGD": 223.8, "SRGR": 0.097, "BeatAlign": 0.766},
    "MultiContext": {"FGD": 176.2, "SRGR": 0.196, "BeatAlign": 0.776},
    "CaMN": {"FGD": 123.7, "SRGR": 0.239, "BeatAlign": 0.783},
}

#: BEAT Table 5 (ablations of CaMN), same metrics: row of the paper -> metric -> value.
PAPER_BEAT_TABLE5: dict[str, dict[str, float]] = {
    "full cascaded": {"FGD": 123.7, "SRGR": 0.239, "BeatAlign": 0.783},
    "w/o cascaded": {"FGD": 137.2, "SRGR": 0.207, "BeatAlign": 0.776},
    "w/o text": {"FGD": 149.4, "SRGR": 0.171, "BeatAlign": 0.781},
    "w/o audio": {"FGD": 155.7, "SRGR": 0.225, "BeatAlign": 0.733},
    "w/o speaker ID": {"FGD": 159.1, "SRGR": 0.207, "BeatAlign": 0.774},
    "w/o face": {"FGD": 163.3, "SRGR": 0.217, "BeatAlign": 0.767},
    "w/o emotion": {"FGD": 151.7, "SRGR": 0.231, "BeatAlign": 0.775},
    "w/o semantic": {"FGD": 151.8, "SRGR": 0.194, "BeatAlign": 0.786},
}

#: HA2G (CVPR 2022) Table 1, TED-Expressive columns: FGD and Diversity of HA2G's own extractor, BC
#: with HA2G's code on 34-frame clips (our key ``"BC (ha2g)"``).
PAPER_HA2G_TABLE1: dict[str, dict[str, float]] = {
    "Ground Truth": {"FGD": 0.0, "BC": 0.723, "Diversity": 175.231},
    "Attention Seq2Seq": {"FGD": 54.920, "BC": 0.155, "Diversity": 122.693},
    "Speech2Gesture": {"FGD": 54.650, "BC": 0.714, "Diversity": 142.489},
    "Joint Embedding": {"FGD": 64.555, "BC": 0.131, "Diversity": 120.627},
    "Trimodal": {"FGD": 12.613, "BC": 0.592, "Diversity": 154.088},
    "HA2G": {"FGD": 5.306, "BC": 0.715, "Diversity": 173.899},
}

#: HA2G Tables 3 (audio learner) and 4 (pose inferer), TED-Expressive, same metrics as Table 1.
PAPER_HA2G_ABLATIONS: dict[str, dict[str, float]] = {
    "f_a^low only (T3)": {"FGD": 6.588, "BC": 0.704, "Diversity": 171.482},
    "f_a^mid only (T3)": {"FGD": 7.212, "BC": 0.682, "Diversity": 168.223},
    "f_a^high only (T3)": {"FGD": 7.421, "BC": 0.661, "Diversity": 165.741},
    "w/o high-level negatives (T3)": {"FGD": 7.982, "BC": 0.652, "Diversity": 163.649},
    "w/o low/mid-level negatives (T3)": {"FGD": 6.998, "BC": 0.701, "Diversity": 169.021},
    "w/o text (T3)": {"FGD": 9.228, "BC": 0.619, "Diversity": 158.236},
    "HA2G-ASR (T3)": {"FGD": 5.319, "BC": 0.716, "Diversity": 173.058},
    "Holistic (T4)": {"FGD": 11.989, "BC": 0.594, "Diversity": 156.079},
    "w/o hand hierarchy (T4)": {"FGD": 10.832, "BC": 0.606, "Diversity": 158.823},
    "w/o body hierarchy (T4)": {"FGD": 5.882, "BC": 0.709, "Diversity": 173.066},
    "Same audio f_a^h (T4)": {"FGD": 6.801, "BC": 0.701, "Diversity": 170.085},
    "w/o L_phy (T4)": {"FGD": 5.907, "BC": 0.708, "Diversity": 172.651},
    "HA2G Full": {"FGD": 5.306, "BC": 0.715, "Diversity": 173.899},
}


def paper_table(rows: Mapping[str, Mapping[str, float]], *, digits: int = 3) -> str:
    """A Markdown table of a paper's published rows (one of the ``PAPER_*`` dicts above).

    Examples
    --------
    >>> print(paper_table({"CaMN": {"FGD": 123.7, "SRGR": 0.239}}, digits=1))
    | method | FGD | SRGR |
    |---|---|---|
    | CaMN | 123.7 | 0.2 |
    """
    from beatlite.report import markdown_table

    keys = list(dict.fromkeys(k for values in rows.values() for k in values))
    return markdown_table(
        ["method", *keys],
        [[m, *(float(v.get(k, math.nan)) for k in keys)] for m, v in rows.items()],
        digits=digits,
    )


def generated_euler(
    model: Any, test: EvaluationSet, normalizers: Normalizers | None = None
) -> list[np.ndarray]:
    """An Euler model's generation of every take of ``test``, in ``spine_neck_141`` degrees.

    The same generation as :func:`evaluate_models` (whole takes, seeded by the first 4 ground-truth
    frames), returned before the conversion to TED-43 directions: the input of BEAT Table 6
    (:func:`beatlite.stats.table6`).

    Parameters
    ----------
    model : GestureModel or str
        A model in eval mode, or a checkpoint name / path (then its own training normalisers are used).
    test : EvaluationSet
    normalizers : Normalizers, optional
        The statistics the model was trained with (default the checkpoint's, else ``test.normalizers``).

    Returns
    -------
    list of (T_k, 141) float64, degrees

    Raises
    ------
    ValueError
        ``model`` predicts directions (``dirvec126``): it has no Euler angles.
    """
    import torch

    if isinstance(model, str | Path):
        model, stored, _, _ = load_checkpoint_for(str(model), test)
        normalizers = stored if normalizers is None else normalizers
    if model.representation != "euler141":
        raise ValueError(f"{type(model).__name__} predicts {model.representation}, not Euler angles")
    with torch.no_grad():
        _, euler = generate_takes(model, test, normalizers)
    return euler
