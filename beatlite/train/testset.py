"""The test takes and scoring one model on them in the common space of the results tables.

:func:`load_test_set` prepares a split's whole takes once (:class:`EvaluationSet`: streams, ground-truth
directions, Euler angles, audio onsets, the train split's MAAC and mean speed); :func:`generate_takes`
generates every take with a model (:func:`beatlite.train.generation.generate_sequences`) and converts it to
TED-43 directions (:func:`beatlite.skeleton.ted.euler_to_directions`); :func:`directions_takes` /
:func:`score_directions` give a row's :class:`~beatlite.metrics.scoring.Takes` and its metrics;
:func:`fgd_scorer` is the validation FGD that :mod:`beatlite.train.recipes` selects epochs with. The results
table over many models is :mod:`beatlite.train.evaluation`.

Taught in notebooks/05_camn.ipynb, section 6 and notebooks/07_benchmark.ipynb, section 1.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from beatlite import paths
from beatlite.constants import FPS, SR, WINDOW_LENGTH, WINDOW_STRIDE
from beatlite.data.index import index_folder
from beatlite.data.normalize import Normalizers
from beatlite.data.store import build_store
from beatlite.data.vocab import corpus_vocab
from beatlite.data.windows import sliding_windows
from beatlite.io.errors import FormatError
from beatlite.metrics.beats import audio_beats, mean_angle_change, position_speed
from beatlite.metrics.consistency import default_angle_pairs, prepare_directions
from beatlite.metrics.frechet import fgd
from beatlite.metrics.scoring import GroundTruth, Takes, evaluate
from beatlite.skeleton.rotations import euler_to_6d
from beatlite.skeleton.ted import directions_to_ted_positions, euler_to_directions

# torch stays lazy (beatlite.train.generation and .checkpoint, beatlite.metrics.extractor import it): this
# module imports without torch, so beatlite.score and the notebooks read a test set without paying for it.


# ------------------------------------------------------------------------------------ the test set
@dataclasses.dataclass(eq=False)
class EvaluationSet:
    """Whole test takes prepared once for :func:`~beatlite.train.evaluation.evaluate_models`.

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
    change_angle : (41,) float64 or None
        HA2G's MAAC per angle pair from the train windows (for BC); None in a set loaded for FGD alone
        (:func:`load_test_set` ``fgd_only``).
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
    folder : str
        The data folder the takes were read from (the index's root, absolute; "" = unknown): the scores'
        captions name it.

    Examples
    --------
    :func:`load_test_set` makes one from a corpus' window store; a one-take set built by hand (a 54-frame
    take of the mean pose, the shipped checkpoints' train statistics) shows the layout:

    >>> from beatlite.train.checkpoint import load_checkpoint
    >>> normalizers = Normalizers.from_meta(load_checkpoint(paths.checkpoints_dir() / "mean_pose.pt")["meta"])
    >>> n = 54  # frames of the one take, 3.6 s at 15 fps
    >>> test = EvaluationSet(
    ...     takes=["take"], streams=[{"pose": np.zeros((n, 141), np.float32)}],
    ...     gt_directions=[np.zeros((n, 42, 3))], gt_directions_141=[np.zeros((n, 42, 3))],
    ...     gt_euler=[np.zeros((n, 141))], semantic=[np.zeros(n)], audio=[np.zeros(n * SR // FPS, np.float32)],
    ...     normalizers=normalizers, change_angle=np.ones(41), vocab=())
    >>> test.n_frames, len(test.takes), test.streams[0]["pose"].shape
    (54, 1, (54, 141))
    """

    takes: list[str]
    streams: list[dict[str, Any]]
    gt_directions: list[np.ndarray]
    gt_directions_141: list[np.ndarray]
    gt_euler: list[np.ndarray]
    semantic: list[np.ndarray]
    audio: list[np.ndarray]
    normalizers: Normalizers
    change_angle: np.ndarray | None
    vocab: tuple[str, ...]
    split: str = "test"
    audio_beats: list[np.ndarray] = dataclasses.field(default_factory=list)
    fingerprint: str = ""
    train_speakers: tuple[int, ...] = ()
    mean_speed: np.ndarray | None = None
    folder: str = ""

    @classmethod
    def example(cls, n_frames: int = 54) -> EvaluationSet:
        """A one-take set of ``n_frames`` still frames (every stream and target 0, silent audio) with the shipped
        mean-pose checkpoint's normalisers: the set the Examples of this module score and generate on.

        Examples
        --------
        >>> test = EvaluationSet.example(34)  # one FGD window
        >>> test.takes, test.gt_directions[0].shape, len(test.audio[0])
        (['take'], (34, 42, 3), 36266)
        """
        from beatlite.train.checkpoint import load_checkpoint

        meta = load_checkpoint(paths.checkpoints_dir() / "mean_pose.pt")["meta"]
        n = int(n_frames)
        return cls(
            takes=["take"], streams=[{"pose": np.zeros((n, 141), np.float32)}],
            gt_directions=[np.zeros((n, 42, 3))], gt_directions_141=[np.zeros((n, 42, 3))],
            gt_euler=[np.zeros((n, 141))], semantic=[np.zeros(n)], audio=[np.zeros(n * SR // FPS, np.float32)],
            normalizers=Normalizers.from_meta(meta), change_angle=np.ones(41), vocab=(),
        )  # fmt: skip

    def beats(self) -> list[np.ndarray]:
        """:attr:`audio_beats`, computed now if empty."""
        if len(self.audio_beats) != len(self.audio):
            self.audio_beats = [audio_beats(y, SR) for y in self.audio]
        return self.audio_beats

    def ground_truth(
        self, extractor: Any, euler_extractor: Any = None, rot6d_extractor: Any = None
    ) -> GroundTruth:
        """The :class:`~beatlite.metrics.scoring.GroundTruth` every row is scored against
        (``euler_extractor``: the Euler autoencoder of ``"FGD (BEAT AE)"``; ``rot6d_extractor``: the 6D one of
        ``"FGD (rot6d)"``; both optional)."""
        if self.change_angle is None:
            raise ValueError(
                f"EvaluationSet.ground_truth: the {self.split!r} takes were loaded for FGD alone (load_test_set("
                "fgd_only=True): no train change angle or mean speed); load them with fgd_only=False to score them"
            )
        takes = directions_takes(
            self.gt_directions, self, extractor, euler=self.gt_euler, euler_extractor=euler_extractor,
            rot6d_extractor=rot6d_extractor,
        )  # fmt: skip
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


def load_test_set(
    index: Any = None, *, split: str = "test", vocab: Any = None, store: Any = None, fgd_only: bool = False
) -> EvaluationSet:
    """Load the whole takes of ``split`` from the window store, with train-split normalisation.

    Parameters
    ----------
    index : TakeIndex, optional
        Default :func:`beatlite.data.index.index_folder` of :func:`beatlite.paths.data_dir`.
    split : {"test", "val", "train"}
        Takes to evaluate on.
    vocab : Vocab, optional
        Default :func:`beatlite.data.vocab.corpus_vocab` of ``index`` (what ``fit`` and ``retrain-all``
        train with).
    store : WindowStore, optional
        Default :func:`beatlite.data.store.build_store` of ``index`` (built once, then only takes
        whose files changed are rebuilt). The statistics are the store's train statistics
        (:meth:`~beatlite.data.store.WindowStore.statistics`); the train windows are never held in memory.
    fgd_only : bool
        Only what FGD needs (:func:`fgd_scorer`, ``fit``'s validation): no audio onsets, and no pass over the
        train windows for the change angle and mean speed of BC and the speed metrics (``change_angle`` and
        ``mean_speed`` None, :meth:`EvaluationSet.ground_truth` refuses the set): the time of a pass over
        every train window, which grows with the corpus, and of the onset detection.

    Returns
    -------
    EvaluationSet
    """
    index = index_folder(paths.data_dir()) if index is None else index
    vocab = corpus_vocab(index) if vocab is None else vocab
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
        change_angle=None if fgd_only else train_change_angle(train),
        mean_speed=None if fgd_only else train_mean_speed(train),
        vocab=tuple(vocab.itos),
        split=split,
        fingerprint=train.fingerprint,
        folder="" if getattr(index, "root", None) is None else str(Path(index.root).resolve()),
        train_speakers=tuple(
            sorted({int(store.takes[i].meta["speaker"]) for i in np.unique(train.take_ids)})
        ),
    )
    if not fgd_only:
        test.beats()
    return test


def clip_test_set(test: EvaluationSet, *, stride: int = WINDOW_STRIDE) -> EvaluationSet:
    """HA2G's per-clip protocol: every 34-frame window (``stride`` apart) of every take becomes a take of its own.

    HA2G's evaluator generates each 34-frame test clip on its own, seeded with that clip's first 4 ground-truth
    frames, and scores the clips (FGD on their features, BC with each clip's own audio onsets); beatlite's tables
    generate whole takes (units chained by their own seeds). Evaluating on this set (``evaluate_models(...,
    test=clip_test_set(test))``) generates and scores exactly HA2G's clips, with every metric.

    Parameters
    ----------
    test : EvaluationSet
        Whole takes (:func:`load_test_set`).
    stride : int
        Frames between clip starts (10: the FGD windows of the tables, :data:`beatlite.constants.WINDOW_STRIDE`).

    Returns
    -------
    EvaluationSet
        Takes named ``{stem}@{start}``; streams cut by :func:`beatlite.train.generation.unit_streams`, as a unit
        of generation is (frames, the audio samples of the clip's 34 / 15 s, its 70 log-mel frames); the train
        statistics shared.

    Examples
    --------
    A 54-frame take holds the 34-frame clips starting at 0, 10 and 20 (``(54 - 34) // 10 + 1 = 3``):

    >>> n = 54  # frames of the one take, 3.6 s at 15 fps
    >>> test = EvaluationSet.example(n)  # one take of still frames, the shipped mean-pose normalisers
    >>> clips = clip_test_set(test)
    >>> clips.takes, clips.streams[0]["pose"].shape, clips.audio[0].shape
    (['take@0', 'take@10', 'take@20'], (34, 141), (36266,))
    """
    from beatlite.train.generation import unit_streams

    clips: dict[str, list[Any]] = {
        k: [] for k in ("takes", "streams", "dirs", "dirs141", "euler", "sem", "audio")
    }
    for k, stem in enumerate(test.takes):
        n = test.gt_directions[k].shape[0]
        for s in range(0, n - WINDOW_LENGTH + 1, stride):
            frames = slice(s, s + WINDOW_LENGTH)
            clips["takes"].append(f"{stem}@{s}")
            clips["streams"].append(unit_streams(test.streams[k], s, tuple(test.streams[k])))
            clips["dirs"].append(test.gt_directions[k][frames])
            clips["dirs141"].append(test.gt_directions_141[k][frames])
            clips["euler"].append(test.gt_euler[k][frames])
            clips["sem"].append(test.semantic[k][frames])
            clips["audio"].append(unit_streams({"audio": test.audio[k]}, s, ("audio",))["audio"])
    if not clips["takes"]:
        raise ValueError(f"clip_test_set: no take has {WINDOW_LENGTH} frames")
    out = dataclasses.replace(
        test, takes=clips["takes"], streams=clips["streams"], gt_directions=clips["dirs"],
        gt_directions_141=clips["dirs141"], gt_euler=clips["euler"], semantic=clips["sem"], audio=clips["audio"],
        audio_beats=[],
    )  # fmt: skip
    out.beats()
    return out


def _dirvec_batches(train: Any, batch_size: int = 1024) -> Any:
    """The train windows' ``dirvec`` (B, 34, 126) float64, ``batch_size`` windows at a time: memory flat in
    the corpus size (``train``: a :class:`~beatlite.data.windows.Windows` or a store's ``StoreWindows``)."""
    for start in range(0, len(train), batch_size):
        idx = np.arange(start, min(len(train), start + batch_size))
        yield np.asarray(train.batch(idx, keys=("dirvec",))["dirvec"], np.float64)


def train_change_angle(train: Any) -> np.ndarray:
    """(41,) MAAC per HA2G angle pair over the train windows (beat consistency's normaliser, HA2G eq. 10).

    Read in batches (:func:`_dirvec_batches`); every window has ``length - 1`` frame steps, so the pooled
    :func:`beatlite.metrics.beats.mean_angle_change` is the batch means' average weighted by window counts.
    """
    pairs, total = default_angle_pairs(), 0.0
    for batch in _dirvec_batches(train):
        # mean added back without re-normalising here: prepare_directions normalises once (as HA2G does)
        dirs = train.normalizers.dirvec.inverse_transform(batch)
        total = total + mean_angle_change([prepare_directions(w) for w in dirs], pairs) * len(batch)
    return total / len(train)


def train_mean_speed(train: Any) -> np.ndarray:
    """(43,) float64 cm/s: mean speed of each TED-43 joint over the train windows (central differences within
    each window, positions of the common space), EMAGE's per-joint ``avg_vel`` for ``"BC (emage)"``.

    Read in batches (:func:`_dirvec_batches`); the mean over windows and frames is pooled from their sums.
    """
    total, count = 0.0, 0
    for batch in _dirvec_batches(train):
        dirs = train.normalizers.inverse_transform(batch, "dirvec126")
        n, length = dirs.shape[:2]
        positions = directions_to_ted_positions(dirs.reshape(n * length, 42, 3)).reshape(n, length, 43, 3)
        speeds = [position_speed(w, FPS) for w in positions]  # (frames, 43) each
        total = total + sum(v.sum(axis=0) for v in speeds)
        count += sum(len(v) for v in speeds)
    return total / count


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
    """Generate every take of ``test`` with ``model`` (the generation of :func:`~beatlite.train.evaluation.evaluate_models`).

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

    Examples
    --------
    The shipped mean-pose baseline on a one-take set (as :class:`EvaluationSet` builds it): its 54 frames as 42
    bone directions of unit length and as 141 Euler channels.

    >>> n = 54  # frames of the one take, 3.6 s at 15 fps
    >>> test = EvaluationSet.example(n)  # one take of still frames, the shipped mean-pose normalisers
    >>> import torch
    >>> from beatlite.train.checkpoint import load_model
    >>> model = load_model("mean_pose")[0]
    >>> with torch.no_grad():
    ...     directions, euler = generate_takes(model, test, None)
    >>> directions[0].shape, euler[0].shape, bool(np.allclose(np.linalg.norm(directions[0], axis=-1), 1.0))
    ((54, 42, 3), (54, 141), True)
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
    :func:`~beatlite.train.evaluation.evaluate_models`, with ``columns=("FGD", "BC (ha2g)", "Diversity")`` for HA2G's columns
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
    column of :func:`~beatlite.train.evaluation.evaluate_models` but on the ``val`` takes (so the test split stays unseen).

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
    """(N, F) float64 extractor features of the mean-subtracted 34-frame windows (stride 10) of all takes.

    Parameters
    ----------
    directions : list of (T_k, 42, 3) float
        Per take, TED-43 unit bone directions.
    test : EvaluationSet
        Its ``normalizers.dirvec`` mean is subtracted (the train split's).
    extractor : callable
        (N, 34, 126) float32 -> (N, F).

    Examples
    --------
    A 54-frame take has 3 windows; a take holding the train mean direction on every frame is all zeros once the
    mean is subtracted. An extractor that flattens the windows shows both (one-take set as :class:`EvaluationSet`
    builds it):

    >>> n = 54  # frames of the one take, 3.6 s at 15 fps
    >>> test = EvaluationSet.example(n)  # one take of still frames, the shipped mean-pose normalisers
    >>> normalizers = test.normalizers
    >>> mean = np.broadcast_to(normalizers.dirvec.mean.reshape(42, 3), (n, 42, 3))
    >>> features = direction_features([mean], test, lambda w: w.reshape(len(w), -1))
    >>> features.shape, float(np.abs(features).max())
    ((3, 4284), 0.0)
    """
    return _window_features(directions, "dirvec126", test, extractor)


def euler_features(euler: list[np.ndarray], test: EvaluationSet, extractor: Any) -> np.ndarray:
    """(N, F) float64 features of the z-scored (train statistics) 34-frame Euler windows (stride 10).

    Parameters
    ----------
    euler : list of (T_k, 141) float, degrees
    test : EvaluationSet
        Its ``normalizers.pose`` z-scores the windows (the train split's statistics).
    extractor : callable
        (N, 34, 141) float32 -> (N, F).

    Examples
    --------
    A take one train standard deviation above the train mean on every channel z-scores to 1 everywhere
    (one-take set as :class:`EvaluationSet` builds it, a flattening extractor):

    >>> n = 54  # frames of the one take, 3.6 s at 15 fps
    >>> test = EvaluationSet.example(n)  # one take of still frames, the shipped mean-pose normalisers
    >>> normalizers = test.normalizers
    >>> above = np.tile(normalizers.pose.mean + normalizers.pose.std, (n, 1))
    >>> features = euler_features([above], test, lambda w: w.reshape(len(w), -1))
    >>> features.shape, bool(np.allclose(features, 1.0))
    ((3, 4794), True)
    """
    return _window_features(euler, "euler141", test, extractor)


def rot6d_features(euler: list[np.ndarray], extractor: Any) -> np.ndarray:
    """(N, F) float64 features of the 34-frame windows (stride 10) of the 6D rotations of the Euler channels
    (:func:`beatlite.metrics.extractor.space_input`; the extractor normalises its input itself).

    Parameters
    ----------
    euler : list of (T_k, 141) float, degrees
    extractor : callable
        (N, 34, 282) float32 -> (N, F): 47 joints x 6.

    Examples
    --------
    A 54-frame take at rest has 3 windows; a joint at rest is the identity rotation, whose 6D representation
    is its first two columns, ``(1, 0, 0)`` and ``(0, 1, 0)``. An extractor that flattens the windows shows it:

    >>> features = rot6d_features([np.zeros((54, 141))], lambda w: w.reshape(len(w), -1))
    >>> features.shape, bool(np.allclose(features[:, :6], [1.0, 0.0, 0.0, 0.0, 1.0, 0.0]))
    ((3, 9588), True)
    """
    windows = sliding_windows([euler_to_6d(x) for x in euler])
    if not len(windows):
        raise ValueError(f"no take has {WINDOW_LENGTH} frames: cannot cut FGD windows")
    return np.asarray(extractor(windows.astype(np.float32)), np.float64)


def _window_features(
    takes: list[np.ndarray], representation: str, test: EvaluationSet, extractor: Any
) -> np.ndarray:
    """``extractor`` features of the 34-frame windows (stride 10) of every take, normalised with the
    train statistics of ``representation``."""
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
    rot6d_extractor: Any = None,
) -> Takes:
    """A row's :class:`~beatlite.metrics.scoring.Takes`: TED-43 positions, directions, features (+ Euler,
    + the Euler autoencoder's features when both ``euler`` and ``euler_extractor`` are given, + the 6D
    autoencoder's with ``euler`` and ``rot6d_extractor``)."""
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
        rot6d_features=None
        if euler is None or rot6d_extractor is None
        else rot6d_features(euler, rot6d_extractor),
    )


def score_directions(
    directions: list[np.ndarray],
    test: EvaluationSet,
    extractor: Any,
    truth: GroundTruth,
    *,
    euler: list[np.ndarray] | None = None,
    columns: Sequence[str],
    seed: int = 0,
    euler_extractor: Any = None,
    rot6d_extractor: Any = None,
) -> dict[str, float]:
    """The metrics of ``columns`` for one row's per-take directions (T, 42, 3) (NaN where undefined)."""
    takes = directions_takes(
        directions,
        test,
        extractor,
        euler=euler,
        euler_extractor=euler_extractor,
        rot6d_extractor=rot6d_extractor,
    )
    values = evaluate(takes, truth, metrics=columns, seed=seed).values()
    return {key: values[key] for key in columns}


def load_checkpoint_for(source: str, test: EvaluationSet) -> tuple[Any, Normalizers | None, str, bool]:
    """(model, its training normalisers, data fingerprint, stale?) of a checkpoint name or path.

    Warns when the checkpoint was trained on other data than ``test``'s train split; a text model whose
    vocabulary differs from the test set's, or normalisation statistics in its meta that do not make
    :class:`~beatlite.data.normalize.Normalizers`, are a :class:`~beatlite.io.FormatError` (field ``meta.vocab``,
    ``meta``), as are the checkpoint's own problems (:func:`beatlite.train.checkpoint.load_model`).

    Examples
    --------
    The shipped mean-pose checkpoint against a set with its own train statistics (as :class:`EvaluationSet`
    builds it), then against one whose statistics differ (another corpus): stale, with a warning.

    >>> n = 54  # frames of the one take, 3.6 s at 15 fps
    >>> test = EvaluationSet.example(n)  # one take of still frames, the shipped mean-pose normalisers
    >>> normalizers = test.normalizers
    >>> model, stats, fingerprint, stale = load_checkpoint_for("mean_pose", test)
    >>> type(model).__name__, stats.matches(normalizers), stale
    ('MeanPose', True, False)
    >>> import warnings
    >>> from beatlite.data.normalize import Normalizer
    >>> shifted = Normalizers(Normalizer(normalizers.pose.mean + 1.0, normalizers.pose.std), normalizers.dirvec)
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     stale = load_checkpoint_for("mean_pose", dataclasses.replace(test, normalizers=shifted))[3]
    >>> stale, "was trained on other data" in str(caught[0].message)
    (True, True)
    """
    from beatlite.train.checkpoint import load_model

    model, data = load_model(source)
    meta = data.get("meta") or {}
    try:
        norms = Normalizers.in_meta(meta)
    except (ValueError, TypeError, KeyError) as exc:  # statistics of other shapes, non-finite, not arrays
        raise FormatError(source, f"not usable normalisation statistics: {exc}", field="meta") from None
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
    if vocab is not None and (not isinstance(vocab, list | tuple) or tuple(vocab) != test.vocab):
        size = f"{len(vocab)} words" if isinstance(vocab, list | tuple) else f"a {type(vocab).__name__}"
        raise FormatError(
            source,
            f"the checkpoint was trained with a different vocabulary ({size}) than the test set's "
            f"({len(test.vocab)}); retrain it (python -m beatlite.train retrain-all)",
            field="meta.vocab",
        )


def generated_euler(
    model: Any, test: EvaluationSet, normalizers: Normalizers | None = None
) -> list[np.ndarray]:
    """An Euler model's generation of every take of ``test``, in ``spine_neck_141`` degrees.

    The same generation as :func:`~beatlite.train.evaluation.evaluate_models` (whole takes, seeded by the first 4 ground-truth
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

    Examples
    --------
    The shipped mean-pose baseline on a one-take set: every frame is its pose in degrees,
    ``z * std + mean`` with the train statistics.

    >>> n = 54  # frames of the one take, 3.6 s at 15 fps
    >>> test = EvaluationSet.example(n)  # one take of still frames, the shipped mean-pose normalisers
    >>> normalizers = test.normalizers
    >>> euler = generated_euler("mean_pose", test)
    >>> from beatlite.train.checkpoint import load_model
    >>> pose = load_model("mean_pose")[0].mean.numpy()
    >>> euler[0].shape, bool(np.allclose(euler[0], normalizers.inverse_transform(pose, "euler141")))
    ((54, 141), True)
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
