"""Evaluate gesture models on whole test takes: the results table of BEAT Tables 4/5 and HA2G Tables 1/3/4.

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
"""

from __future__ import annotations

import dataclasses
import math
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

FPS = 15
SR = 16000
WINDOW = 34
WINDOW_STRIDE = 10

COLUMNS: tuple[tuple[str, bool], ...] = (
    ("FGD", False),
    ("SRGR", True),
    ("BeatAlign", True),
    ("BC", True),
    ("Diversity", True),
    ("L1div", True),
)
"""Metric name -> higher is better, in table order."""

LABELS: dict[str, str] = {
    "mean_pose": "Mean pose",
    "random_clip": "Random clip",
    "s2g_tiny": "S2G-style",
    "trimodal_tiny": "Trimodal-style",
    "seq2seq_tiny": "Seq2Seq-style",
    "a2g_tiny": "A2G-style",
    "joint_embedding_tiny": "Joint Embedding-style",
    "camn_tiny": "CaMN",
    "camn_tiny_no_cascade": "CaMN w/o cascade",
    "camn_tiny_no_text": "CaMN w/o text",
    "camn_tiny_no_audio": "CaMN w/o audio",
    "camn_tiny_no_speaker": "CaMN w/o speaker ID",
    "camn_tiny_no_face": "CaMN w/o face",
    "camn_tiny_no_emotion": "CaMN w/o emotion",
    "camn_tiny_no_semantic": "CaMN w/o semantic weighting",
    "ha2g_tiny": "HA2G",
    "ha2g_tiny_holistic": "HA2G w/o hierarchy (holistic)",
    "ha2g_tiny_single_audio": "HA2G single audio feature",
    "ha2g_tiny_no_contrastive": "HA2G w/o contrastive loss",
    "ha2g_tiny_no_physical": "HA2G w/o physical loss",
}
"""Shipped checkpoint name -> row label, in the default row order."""

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

    def to_markdown(self) -> str:
        """A Markdown table: one row per model, the metrics of :data:`COLUMNS`, generation seconds."""
        head = ["method", *[f"{n} {'↑' if up else '↓'}" for n, up in COLUMNS], "gen. s"]
        lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        for row in self.rows:
            label = row.label + (" †" if row.stale else "")
            cells = [label, *[fmt_metric(row.metrics.get(n, math.nan), n) for n, _ in COLUMNS]]
            cells.append(f"{row.seconds:.2f}" if row.representation != "ground_truth" else "")
            lines.append("| " + " | ".join(cells) + " |")
        if any(row.stale for row in self.rows):
            lines.append("")
            lines.append("† trained on another version of the data than the one evaluated: retrain it.")
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly dict: ``{"columns", "rows": [...], "info"}`` (NaN written as None)."""
        return {
            "columns": [{"name": n, "higher_is_better": up} for n, up in COLUMNS],
            "rows": [
                {
                    **dataclasses.asdict(r),
                    "metrics": {k: (None if not math.isfinite(v) else v) for k, v in r.metrics.items()},
                }
                for r in self.rows
            ],
            "info": self.info,
        }


def fmt_metric(v: float, name: str) -> str:
    """``v`` as printed in the results tables: 2 decimals for FGD/Diversity/L1div, 3 for the rest."""
    if not math.isfinite(v):
        return "—"
    if name in ("FGD", "Diversity", "L1div"):
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
    semantic : list of (T,) float
    audio : list of (S,) float32, 16 kHz
    norm : dict
        ``pose_mean``/``pose_std`` (141,) degrees, ``dirvec_mean`` (126,), ``bone_lengths`` (42,) cm:
        train-split statistics the windows were normalised with.
    change_angle : (41,) float64
        HA2G's MAAC per angle pair from the train windows (for BC).
    vocab : tuple of str
        The vocabulary the word ids refer to.
    audio_beats : list of (K,) float64
        Onset times (s) of each take's audio (:func:`beatlite.metrics.audio_beats` defaults),
        computed once and shared by BeatAlign and BC; filled by :func:`load_test_set` (or on
        first use when empty).
    fingerprint : str
        :func:`beatlite.train.data_fingerprint` of the train windows ("" = unknown): checkpoints
        trained on other data are flagged as stale.
    """

    takes: list[str]
    streams: list[dict[str, Any]]
    gt_directions: list[np.ndarray]
    gt_directions_141: list[np.ndarray]
    semantic: list[np.ndarray]
    audio: list[np.ndarray]
    norm: dict[str, np.ndarray]
    change_angle: np.ndarray
    vocab: tuple[str, ...]
    split: str = "test"
    audio_beats: list[np.ndarray] = dataclasses.field(default_factory=list)
    fingerprint: str = ""

    def beats(self) -> list[np.ndarray]:
        """:attr:`audio_beats`, computed now if empty."""
        if len(self.audio_beats) != len(self.audio):
            from beatlite.metrics import audio_beats

            self.audio_beats = [audio_beats(np.asarray(y, np.float64), SR) for y in self.audio]
        return self.audio_beats

    @property
    def n_frames(self) -> int:
        """Total frames over all takes."""
        return int(sum(s["pose"].shape[0] for s in self.streams))


def rest_bone_lengths() -> np.ndarray:
    """(42,) float64 cm: TED-43 bone lengths of the BEAT rest skeleton (the common positions space)."""
    from beatlite.skeleton.beat import beat_skeleton
    from beatlite.skeleton.kinematics import rest_pose
    from beatlite.skeleton.ted import TED_BONES, beat_to_ted43

    ted = beat_to_ted43(rest_pose(beat_skeleton())[None])[0]
    bones = np.asarray(TED_BONES)
    return np.linalg.norm(ted[bones[:, 1]] - ted[bones[:, 0]], axis=-1)


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
    from beatlite.io.motion import Motion
    from beatlite.skeleton.beat import beat_skeleton, expand_subset
    from beatlite.skeleton.directions import positions_to_directions
    from beatlite.skeleton.ted import TED_BONES, beat_to_ted43

    euler = np.asarray(euler, dtype=np.float64)
    if euler.ndim != 2 or euler.shape[1] != 141:
        raise ValueError(f"euler must be (T, 141) degrees, got shape {euler.shape}")
    skeleton = beat_skeleton()
    motion = Motion(skeleton, expand_subset(euler, "spine_neck_141", skeleton), FPS)
    return positions_to_directions(beat_to_ted43(motion.positions()), np.asarray(TED_BONES))


def directions_to_ted_positions(directions: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """(T, 42, 3) unit directions -> (T, 43, 3) cm TED-43 positions, root at the origin."""
    from beatlite.skeleton.directions import directions_to_positions
    from beatlite.skeleton.ted import TED_BONES

    return directions_to_positions(directions, np.asarray(TED_BONES), lengths, np.zeros(3))


def load_test_set(index: Any = None, *, split: str = "test", vocab: Any = None) -> EvaluationSet:
    """Load the whole takes of ``split`` with train-split normalisation (window caches in ``build/``).

    Parameters
    ----------
    index : TakeIndex, optional
        Default :func:`beatlite.data.index.index_folder` of :func:`beatlite.paths.data_dir`.
    split : {"test", "val", "train"}
        Takes to evaluate on.
    vocab : Vocab, optional
        Default :func:`beatlite.data.vocab.build_vocab` of ``index`` (what ``retrain-all`` uses).

    Returns
    -------
    EvaluationSet
    """
    from beatlite.data.index import index_folder
    from beatlite.data.vocab import build_vocab
    from beatlite.data.windows import build_windows
    from beatlite.metrics.beat_consistency import default_angle_pairs, prepare_directions
    from beatlite.metrics.beats import mean_angle_change
    from beatlite.paths import data_dir
    from beatlite.train.training import data_fingerprint

    if index is None:
        index = index_folder(data_dir())
    if vocab is None:
        vocab = build_vocab(index)
    train = build_windows(index, split="train", vocab=vocab)
    stats = (train.pose_norm, train.dir_norm)
    whole = build_windows(index, split=split, vocab=vocab, stats=stats, whole_takes=True)
    dir_mean = np.asarray(train.dir_norm.mean, dtype=np.float64)
    pairs = default_angle_pairs()
    train_dirs = np.asarray(train["dirvec"], np.float64) + dir_mean
    change_angle = mean_angle_change([prepare_directions(w) for w in train_dirs], pairs)
    norm = {
        "pose_mean": np.asarray(train.pose_norm.mean, np.float64),
        "pose_std": np.asarray(train.pose_norm.std, np.float64),
        "dirvec_mean": dir_mean,
        "bone_lengths": rest_bone_lengths(),
    }
    takes, streams, gt_dirs, gt_dirs_141, sems, audios = [], [], [], [], [], []
    for i in range(len(whole)):
        item = whole.item(i)
        t = item["pose"].shape[0]
        stream = {
            k: item[k] for k in ("pose", "dirvec", "audio", "mel", "face", "word", "emotion", "semantic")
        }
        stream["speaker"] = int(item["speaker"])
        takes.append(str(item["take"]))
        streams.append(stream)
        d = (np.asarray(item["dirvec"], np.float64) + dir_mean).reshape(t, 42, 3)
        gt_dirs.append(d / np.linalg.norm(d, axis=-1, keepdims=True))
        gt_dirs_141.append(euler_to_directions(item["pose_raw"]))
        sems.append(np.asarray(item["semantic"], np.float64))
        audios.append(np.asarray(item["audio"], np.float32))
    test = EvaluationSet(
        takes=takes,
        streams=streams,
        gt_directions=gt_dirs,
        gt_directions_141=gt_dirs_141,
        semantic=sems,
        audio=audios,
        norm=norm,
        change_angle=change_angle,
        vocab=tuple(vocab.itos),
        split=split,
        fingerprint=data_fingerprint(train),
    )
    test.beats()
    return test


# ------------------------------------------------------------------------------------ generation
def generated_directions(
    model: Any, test: EvaluationSet, norm: Mapping[str, Any] | None = None
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
    norm : mapping, optional
        The statistics the model was trained with (checkpoint ``meta``); default ``test.norm``.
        The seed frames and outputs are in these units.

    Returns
    -------
    list of (T, 42, 3) float64 unit vectors, one per take.
    """
    from beatlite.train.generation import denormalise, generate_sequences

    norm = test.norm if norm is None else {**test.norm, **dict(norm)}
    if hasattr(model, "reset"):
        model.reset()  # RandomClip: restart its deterministic draws
    poses = generate_sequences(model, [_renormalised(s, test.norm, norm) for s in test.streams])
    if model.representation == "euler141":
        return [euler_to_directions(denormalise(p, "euler141", norm)) for p in poses]
    return [denormalise(p, "dirvec126", norm) for p in poses]


def _renormalised(stream: dict[str, Any], have: Mapping[str, Any], want: Mapping[str, Any]) -> dict[str, Any]:
    """The take's seed streams re-expressed in the model's normalisation when it differs."""
    same_pose = np.allclose(have["pose_mean"], want["pose_mean"]) and np.allclose(
        have["pose_std"], want["pose_std"]
    )
    same_dir = np.allclose(have["dirvec_mean"], want["dirvec_mean"])
    if same_pose and same_dir:
        return stream
    out = dict(stream)
    raw = stream["pose"] * have["pose_std"] + have["pose_mean"]
    out["pose"] = ((raw - want["pose_mean"]) / want["pose_std"]).astype(np.float32)
    out["dirvec"] = (stream["dirvec"] + have["dirvec_mean"] - want["dirvec_mean"]).astype(np.float32)
    return out


def fgd_scorer(
    split: str = "val",
    *,
    index: Any = None,
    vocab: Any = None,
    norm: Mapping[str, Any] | None = None,
    extractor: Any = None,
    takes: EvaluationSet | None = None,
) -> Callable[[Any], float]:
    """A ``val_score`` for :func:`beatlite.train.fit`: FGD of a model's generation of ``split``'s whole takes.

    BEAT's reference trainer validates every epoch by FGD on the validation set and keeps the
    best epoch (facts B.6); this is that score, computed exactly as the ``FGD`` column of
    :func:`evaluate_models` but on the ``val`` takes (so the test split stays unseen).

    Parameters
    ----------
    split : str
        Takes to generate (``"val"``).
    index, vocab
        As :func:`load_test_set` (pass the training vocabulary).
    norm : mapping, optional
        The statistics the model trains with (its checkpoint ``meta``); default the split's.
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
    mean = takes.norm["dirvec_mean"]
    real = np.asarray(extractor(_windows(takes.gt_directions, mean)), np.float64)
    model_norm = _norm_of(norm)

    def score(model: Any) -> float:
        feats = np.asarray(
            extractor(_windows(generated_directions(model, takes, model_norm), mean)), np.float64
        )
        return float(fgd(feats, real))

    return score


# ------------------------------------------------------------------------------------ scoring
def _windows(directions: list[np.ndarray], mean: np.ndarray) -> np.ndarray:
    """(N, 34, 126) float32 mean-subtracted direction windows, stride 10, pooled over takes."""
    out = []
    for d in directions:
        x = d.reshape(d.shape[0], -1) - mean
        for s in range(0, x.shape[0] - WINDOW + 1, WINDOW_STRIDE):
            out.append(x[s : s + WINDOW])
    if not out:
        raise ValueError(f"no take has {WINDOW} frames: cannot cut FGD windows")
    return np.stack(out).astype(np.float32)


@dataclasses.dataclass(eq=False)
class _Reference:
    features: np.ndarray
    positions: list[np.ndarray]


def score_directions(
    directions: list[np.ndarray], test: EvaluationSet, extractor: Any, reference: _Reference, *, seed: int = 0
) -> dict[str, float]:
    """The metrics of :data:`COLUMNS` for one row's per-take directions (T, 42, 3)."""
    from beatlite.metrics import diversity, fgd, l1_diversity, srgr

    if len(directions) != len(test.takes):
        raise ValueError(f"directions has {len(directions)} takes, the test set {len(test.takes)}")
    for i, (d, s) in enumerate(zip(directions, test.streams, strict=True)):
        if d.shape != (s["pose"].shape[0], 42, 3):
            raise ValueError(f"directions[{i}] must be ({s['pose'].shape[0]}, 42, 3), got {d.shape}")
    lengths = test.norm["bone_lengths"]
    positions = [directions_to_ted_positions(d, lengths) for d in directions]
    feats = np.asarray(extractor(_windows(directions, test.norm["dirvec_mean"])), np.float64)
    return {
        "FGD": float(fgd(feats, reference.features)),
        "SRGR": float(srgr(positions, reference.positions, test.semantic, variant="paper", delta=10.0)),
        "BeatAlign": beat_align_cached(positions, test.beats()),
        "BC": beat_consistency_cached(directions, test.beats(), test.change_angle),
        "Diversity": float(diversity(feats, n_pairs=500, seed=seed)),
        "L1div": float(l1_diversity(positions)),
    }


def beat_align_cached(positions: list[np.ndarray], beats: list[np.ndarray], sigma: float = 0.3) -> float:
    """:func:`beatlite.metrics.beat_align` (positions, order 2, audio -> motion) with precomputed audio beats.

    Parameters
    ----------
    positions : list of (T, J, 3) float, cm
    beats : list of (K,) float, seconds
        Audio onset times of each take (``audio_beats(y, 16000)``).

    Returns
    -------
    float: mean over takes with audio beats; a take whose joints have no speed minimum scores 0.
    """
    from beatlite.metrics.beat_align import motion_beat_times
    from beatlite.metrics.beats import alignment_score

    scores = []
    for p, a in zip(positions, beats, strict=True):
        if a.size == 0:
            continue
        per_joint = [alignment_score(a, m, sigma) for m in motion_beat_times(p, FPS, order=2) if m.size]
        per_joint = [v for v in per_joint if np.isfinite(v)]
        scores.append(float(np.mean(per_joint)) if per_joint else 0.0)
    return float(np.mean(scores)) if scores else math.nan


def beat_consistency_cached(
    directions: list[np.ndarray], beats: list[np.ndarray], change_angle: np.ndarray, sigma: float = 0.1
) -> float:
    """:func:`beatlite.metrics.beat_consistency` on whole takes (threshold 0.03) with precomputed audio beats.

    Parameters
    ----------
    directions : list of (T, 42, 3) float unit vectors
    beats : list of (K,) float, seconds
    change_angle : (41,) float
        MAAC per angle pair.

    Returns
    -------
    float: mean over takes weighted by their number of audio beats, skipping takes without
    motion beats; NaN when none has both.
    """
    from beatlite.metrics.beat_consistency import default_angle_pairs, prepare_directions
    from beatlite.metrics.beats import alignment_score, angle_change_beats, angle_change_curve

    pairs = default_angle_pairs()
    total, weight = 0.0, 0
    for d, a in zip(directions, beats, strict=True):
        m = angle_change_beats(
            angle_change_curve(prepare_directions(d), pairs, change_angle), FPS, threshold=0.03
        )
        if a.size == 0 or m.size == 0:
            continue
        total += alignment_score(a, m, sigma) * a.size
        weight += a.size
    return total / weight if weight else math.nan


def _as_entries(models: Sequence[Any] | None) -> list[tuple[str, str, Any, Mapping[str, Any] | None]]:
    """Normalise ``models`` to (label, source, model or None, norm) entries."""
    from beatlite.paths import checkpoints_dir

    if models is None:
        models = [name for name in LABELS if (checkpoints_dir() / f"{name}.pt").is_file()]
    entries = []
    for item in models:
        if isinstance(item, str | Path):
            name = Path(item).stem if str(item).endswith(".pt") else str(item)
            entries.append((LABELS.get(name, name), str(item), None, None))
        elif isinstance(item, tuple) and len(item) in (2, 3):
            label, model = item[0], item[1]
            norm = item[2] if len(item) == 3 else None
            entries.append((str(label), "<given>", model, norm))
        else:
            raise TypeError(
                "models entries must be checkpoint names/paths or (label, model[, norm]) tuples, "
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
    threads: int | None = None,
    progress: bool = False,
) -> ModelResults:
    """Generate every test take with each model and score all of them in the TED-43 space.

    Parameters
    ----------
    models : sequence, optional
        Checkpoint names (``"camn_tiny"``, looked up in ``checkpoints/``) or paths, and/or
        ``(label, model)`` / ``(label, model, norm)`` tuples for models trained in a notebook
        (``norm``: the ``meta`` statistics they were trained with; default the test set's).
        Default: every shipped checkpoint of :data:`LABELS` that exists, in that order.
    test : EvaluationSet, optional
        Default :func:`load_test_set` (``data_samples/`` test split).
    extractor : callable, optional
        (N, 34, 126) -> (N, F) features; default ``load_extractor("dirvec")``.
    ground_truth : bool
        Add the two ground-truth rows first.
    seed : int
        Seed of the Diversity pairing.
    threads : int, optional
        Torch threads (default :func:`beatlite.paths.n_threads`).
    progress : bool
        Print one line per row.

    Returns
    -------
    ModelResults
    """
    import torch

    from beatlite.metrics.extractor import load_extractor
    from beatlite.paths import n_threads
    from beatlite.train.checkpoint import load_model

    start = time.perf_counter()
    torch.set_num_threads(threads if threads is not None else n_threads())
    entries = _as_entries(models)
    test = load_test_set() if test is None else test
    extractor = load_extractor("dirvec") if extractor is None else extractor
    lengths = test.norm["bone_lengths"]
    real = _windows(test.gt_directions, test.norm["dirvec_mean"])
    reference = _Reference(
        features=np.asarray(extractor(real), np.float64),
        positions=[directions_to_ted_positions(d, lengths) for d in test.gt_directions],
    )
    rows: list[ResultRow] = []
    if ground_truth:
        for label, dirs in ((GROUND_TRUTH, test.gt_directions), (GROUND_TRUTH_141, test.gt_directions_141)):
            rows.append(
                ResultRow(
                    label,
                    "ground_truth",
                    "ground_truth",
                    score_directions(dirs, test, extractor, reference, seed=seed),
                )
            )
    for label, source, model, norm in entries:
        fingerprint, stale = "", False
        if model is None:
            model, data = load_model(source)
            norm = data.get("meta") or None
            _check_vocab(model, data, test, source)
            fingerprint = str(data.get("fingerprint") or "")
            stale = _is_stale(data, test)
            if stale:
                warnings.warn(
                    f"{source} was trained on other data (fingerprint {fingerprint}) than the evaluated "
                    f"corpus' train split ({test.fingerprint}); retrain it (python -m beatlite.train retrain-all)",
                    stacklevel=2,
                )
        t0 = time.perf_counter()
        with torch.no_grad():
            dirs = generated_directions(model, test, _norm_of(norm))
        seconds = time.perf_counter() - t0
        metrics = score_directions(dirs, test, extractor, reference, seed=seed)
        rows.append(ResultRow(label, source, model.representation, metrics, seconds, fingerprint, stale))
        if progress:
            print(
                f"{label}: " + ", ".join(f"{k} {v:.4g}" for k, v in metrics.items()) + f" ({seconds:.1f} s)",
                flush=True,
            )
    info = {
        "split": test.split,
        "takes": list(test.takes),
        "frames": test.n_frames,
        "windows": int(len(real)),
        "fps": FPS,
        "extractor": str(getattr(extractor, "meta", {}).get("path", type(extractor).__name__)),
        "common_space": "TED-43 unit bone directions; positions from BEAT rest-pose bone lengths, root at origin",
        "data_fingerprint": test.fingerprint,
        "seconds": round(time.perf_counter() - start, 2),
    }
    return ModelResults(rows, info)


def _is_stale(data: Mapping[str, Any], test: EvaluationSet) -> bool:
    """Whether a checkpoint was trained on other data than ``test``'s train split.

    Compared through the train statistics stored in its ``meta`` (pose mean/std, direction
    mean; every beatlite trainer stores them) when present, else through the data fingerprint
    (trainers may fingerprint different window dicts, so the statistics come first).
    """
    meta = data.get("meta") or {}
    keys = ("pose_mean", "pose_std", "dirvec_mean")
    if all(k in meta for k in keys):
        return not all(
            np.shape(meta[k]) == np.shape(test.norm[k])
            and np.allclose(meta[k], test.norm[k], rtol=1e-5, atol=1e-6)
            for k in keys
        )
    fingerprint = str(data.get("fingerprint") or "")
    return bool(test.fingerprint and fingerprint and fingerprint != test.fingerprint)


def _norm_of(meta: Mapping[str, Any] | None) -> dict[str, np.ndarray] | None:
    if not meta:
        return None
    keys = ("pose_mean", "pose_std", "dirvec_mean")
    if not all(k in meta for k in keys):
        return None
    return {k: np.asarray(meta[k], np.float64) for k in keys}


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
