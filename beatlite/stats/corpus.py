"""Per-take streams used by the dataset statistics (motion energy, audio energy, face activity).

:func:`load_corpus` loads every usable take of an index once at 15 fps and keeps
only what the statistics need, so all figures/tables share one pass over the data.

Taught in notebooks/02_dataset_statistics.ipynb, section 3 (``load_corpus`` loads the takes the analyses share).
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from beatlite.constants import FPS, SR

if TYPE_CHECKING:
    from beatlite.data.index import TakeIndex, TakeRecord

#: Joints whose speed measures gesture energy: CaMN's 9 body joints plus both wrists.
ENERGY_JOINTS = (
    "Spine",
    "Neck",
    "Neck1",
    "RightShoulder",
    "RightArm",
    "RightForeArm",
    "RightHand",
    "LeftShoulder",
    "LeftArm",
    "LeftForeArm",
    "LeftHand",
)


@dataclass
class CorpusTake:
    """What the statistics need from one take, aligned at ``fps``.

    Attributes
    ----------
    stem, split, language : str
    speaker_id : int
    emotion : int
        Take-level emotion id 0..7 (from the name).
    fps : float
    rotations : (T, 141) float32, degrees
        ``spine_neck_141`` Euler angles.
    speed : (T,) float32, cm/s
        Gesture energy: mean speed of :data:`ENERGY_JOINTS`, root fixed at the origin
        (root translation and rotation removed), first frame copies the second.
    audio_rms : (T,) float32
        RMS of the waveform over each frame's samples.
    face_activity : (T,) float32 or None, 1/s
        Mean absolute rate of change of the 51 blendshape weights (None without JSON).
    emotion_frames : (T,) int64
    semantic : (T,) float32, score in [0, 1]
    semantic_scores : (S,) float32
        Score of every annotated semantic segment.
    word_starts, word_ends : (W,) float64 seconds; words : tuple of str
    conversation : bool
        A conversation take (its take-level ``emotion`` is 0 from the name; the turns' emotions are in
        ``emotion_frames``).

    Examples
    --------
    A 14.8-s take of ``data_samples/`` at 15 fps: every per-frame stream has 14.8 x 15 = 222 frames, and
    every word has a start and an end.

    >>> from beatlite.data.index import index_folder
    >>> from beatlite.paths import repo_root
    >>> index = index_folder(repo_root() / "data_samples", recursive=False, cache=False, read_durations=False)
    >>> take = corpus_take(index["2_scott_0_1_1"])
    >>> take.n_frames, take.rotations.shape, take.speed.shape, take.audio_rms.shape, take.face_activity.shape
    (222, (222, 141), (222,), (222,), (222,))
    >>> len(take.words) == len(take.word_starts) == len(take.word_ends), take.words[:4]
    (True, ('my', 'idea', 'is', 'to'))
    """

    stem: str
    split: str | None
    language: str | None
    speaker_id: int
    emotion: int
    fps: float
    rotations: np.ndarray
    speed: np.ndarray
    audio_rms: np.ndarray
    face_activity: np.ndarray | None
    emotion_frames: np.ndarray
    semantic: np.ndarray
    semantic_scores: np.ndarray
    word_starts: np.ndarray
    word_ends: np.ndarray
    words: tuple[str, ...]
    conversation: bool = False

    @property
    def n_frames(self) -> int:
        return int(self.rotations.shape[0])


def joint_speed(positions: np.ndarray, fps: float) -> np.ndarray:
    """Mean joint speed per frame, (T,) float64 in cm/s, from (T, J, 3) cm positions.

    Backward differences; frame 0 repeats frame 1 (0 for a single frame).

    >>> p = np.zeros((3, 1, 3)); p[:, 0, 0] = [0.0, 1.0, 3.0]
    >>> joint_speed(p, fps=10).tolist()
    [10.0, 10.0, 20.0]
    """
    pos = np.asarray(positions, dtype=np.float64)
    if pos.ndim != 3 or pos.shape[2] != 3:
        raise ValueError(f"joint_speed: positions must be (T, J, 3), got {pos.shape}")
    if pos.shape[0] < 2:
        return np.zeros(pos.shape[0])
    v = np.linalg.norm(np.diff(pos, axis=0), axis=2).mean(axis=1) * fps
    return np.concatenate([v[:1], v])


def frame_rms(audio: np.ndarray, n_frames: int, fps: float, sr: int) -> np.ndarray:
    """RMS of ``audio`` over the samples ``[floor(i*sr/fps), floor((i+1)*sr/fps))`` of each frame, (T,).

    Frames beyond the audio get 0.

    Parameters
    ----------
    audio : (N,) float, samples at ``sr``
    n_frames : int
        T, frames wanted.
    fps : float
        Frame rate, frames per second.
    sr : int
        Sample rate of ``audio``, Hz.

    Returns
    -------
    (T,) float64, RMS in the units of ``audio`` (full scale for BEAT's WAVs).

    Examples
    --------
    8 samples at 8 Hz cut into 2-fps frames of 4 samples: a +-1 square wave, then a +-3 one, then no audio.

    >>> frame_rms(np.array([1.0, -1, 1, -1, 3, -3, 3, -3]), 3, fps=2, sr=8).tolist()
    [1.0, 3.0, 0.0]
    """
    y = np.asarray(audio, dtype=np.float64)
    edges = np.floor(np.arange(n_frames + 1) * sr / fps + 1e-9).astype(np.int64)
    edges = np.minimum(edges, len(y))
    csum = np.concatenate([[0.0], np.cumsum(y * y)])
    counts = np.diff(edges)
    energy = np.diff(csum[edges])
    return np.sqrt(np.divide(energy, counts, out=np.zeros(n_frames), where=counts > 0))


def corpus_take(record: TakeRecord, *, fps: float = FPS, sr: int = SR) -> CorpusTake:
    """Load one take (:func:`beatlite.io.load_take`, at the index's ``record.bvh_fps``) and compute its streams.

    Parameters
    ----------
    record : TakeRecord
        A row of :func:`beatlite.data.index.index_folder` with a motion file.
    fps : float
        Frame rate of the streams, frames per second (default 15, the models' rate).
    sr : int
        Sample rate the audio is resampled to before its per-frame RMS, Hz.

    Returns
    -------
    CorpusTake
        Every stream cut to the shortest modality.

    Examples
    --------
    A take is as long as the shortest of its files: ``record.duration`` seconds x ``fps`` frames.

    >>> from beatlite.data.index import index_folder
    >>> from beatlite.data.examples import example_corpus
    >>> tmp = example_corpus()
    >>> record = index_folder(tmp.name, cache=False)["2_scott_0_9_9"]
    >>> take = corpus_take(record, fps=15)
    >>> take.stem, take.split, record.duration, take.n_frames
    ('2_scott_0_9_9', 'train', 14.8, 222)
    >>> take = corpus_take(record, fps=30)
    >>> take.n_frames, bool(take.speed.min() >= 0)
    (444, True)
    >>> tmp.cleanup()
    """
    from beatlite.io import load_take
    from beatlite.skeleton import forward_kinematics, subset_columns

    take = load_take(record.path("motion"), fps=fps, audio_sr=sr, bvh_fps=record.bvh_fps)
    motion = take.motion
    audio = np.asarray(take.audio)
    n = take.n_frames  # load_take already cut every modality to the shortest one
    skel = motion.skeleton
    channels = motion.channels[:n].copy()
    root = skel.channel_starts[0]
    channels[:, root : root + len(skel.channels[0])] = 0.0  # gestures relative to the body
    world = forward_kinematics(skel, channels)[:, skel.indices(ENERGY_JOINTS)]
    face_activity = None
    if take.face is not None:
        face = np.asarray(take.face, dtype=np.float64)[:n]
        if n >= 2:
            rate = np.abs(np.diff(face, axis=0)).mean(axis=1) * fps
            face_activity = np.concatenate([rate[:1], rate]).astype(np.float32)
        else:
            face_activity = np.zeros(n, np.float32)
    words = take.words
    segments = take.semantic_segments or []
    return CorpusTake(
        stem=record.stem,
        split=record.split,
        language=record.language,
        speaker_id=int(record.speaker_id),
        emotion=int(record.emotion or 0),
        fps=float(fps),
        rotations=motion.channels[:n, subset_columns(skel, "spine_neck_141")].astype(np.float32),
        speed=joint_speed(world, fps).astype(np.float32),
        audio_rms=frame_rms(audio, n, fps, sr).astype(np.float32),
        face_activity=face_activity,
        emotion_frames=np.asarray(take.emotion, dtype=np.int64)[:n],
        semantic=np.asarray(take.semantic, dtype=np.float32)[:n],
        semantic_scores=np.array([s.score for s in segments], dtype=np.float32),
        word_starts=np.zeros(0) if words is None else np.asarray(words.starts, dtype=np.float64),
        word_ends=np.zeros(0) if words is None else np.asarray(words.ends, dtype=np.float64),
        words=() if words is None else tuple(words.words),
        conversation=bool(record.conversation),
    )


def iter_corpus(
    index: TakeIndex,
    *,
    fps: float = FPS,
    sr: int = SR,
    splits: tuple[str, ...] | None = None,
    skipped: list[str] | None = None,
) -> Iterator[CorpusTake]:
    """:func:`corpus_take` of every usable take of ``index`` (optionally only some splits), one at a time.

    Holds one take in memory, so analyses that reduce each take as it comes (e.g.
    :func:`beatlite.stats.emotion_separability`, which keeps 81 features per 2-s window)
    stream over a corpus of any size. A take that fails to load is skipped; its
    ``"stem: error"`` is appended to ``skipped`` when a list is given.

    Parameters
    ----------
    index : TakeIndex
    fps : float
        Frame rate of the streams, frames per second.
    sr : int
        Audio sample rate, Hz.
    splits : tuple of str, optional
        Keep only the takes of these splits (``"train"``, ``"val"``, ``"test"``, ...).
    skipped : list, optional
        Receives ``"stem: error"`` of each take that failed to load.

    Yields
    ------
    CorpusTake
        In index order.

    Examples
    --------
    Of the two example takes, only one is in the train split; a take whose motion file broke after
    indexing is skipped and named.

    >>> from beatlite.data.index import index_folder
    >>> from beatlite.data.examples import example_corpus
    >>> from pathlib import Path
    >>> tmp = example_corpus()
    >>> index = index_folder(tmp.name, cache=False)
    >>> [t.stem for t in iter_corpus(index, splits=("train",))]
    ['2_scott_0_9_9']
    >>> _ = (Path(tmp.name) / "2_scott_0_1_1.bvh.gz").write_bytes(b"not a BVH")
    >>> skipped = []
    >>> [t.stem for t in iter_corpus(index, skipped=skipped)], [s.split(":")[0] for s in skipped]
    (['2_scott_0_9_9'], ['2_scott_0_1_1'])
    >>> tmp.cleanup()
    """
    for r in index:
        if not r.usable or (splits is not None and r.split not in splits):
            continue
        try:
            take = corpus_take(r, fps=fps, sr=sr)
        except (OSError, ValueError) as e:  # FormatError is a ValueError and names the file
            if skipped is not None:
                skipped.append(f"{r.stem}: {e}")
            continue
        yield take


def load_corpus(
    index: TakeIndex, *, fps: float = FPS, sr: int = SR, splits: tuple[str, ...] | None = None
) -> list[CorpusTake]:
    """:func:`corpus_take` of every usable take of ``index`` (optionally only some splits), in order.

    A take that fails to load (e.g. a broken motion row the header check could not see) is
    skipped with a warning naming it; ``ValueError`` if no take is left. Memory grows with the
    corpus (about 0.6 KB per frame, 30 MB per hour at 15 fps, mostly the 141 rotations): for
    large corpora pass :func:`iter_corpus` to the analyses that accept an iterable.

    Parameters
    ----------
    index : TakeIndex
    fps : float
        Frame rate of the streams, frames per second.
    sr : int
        Audio sample rate, Hz.
    splits : tuple of str, optional
        Keep only the takes of these splits.

    Returns
    -------
    list of CorpusTake
        In index order.

    Examples
    --------
    Two 14.8-s takes: 2 x 222 frames at 15 fps, the index's total duration.

    >>> from beatlite.data.index import index_folder
    >>> from beatlite.data.examples import example_corpus
    >>> tmp = example_corpus()
    >>> index = index_folder(tmp.name, cache=False)
    >>> takes = load_corpus(index)
    >>> [t.stem for t in takes], sum(t.n_frames for t in takes) / 15, index.total_duration
    (['2_scott_0_1_1', '2_scott_0_9_9'], 29.6, 29.6)
    >>> tmp.cleanup()
    """
    failed: list[str] = []
    takes = list(iter_corpus(index, fps=fps, sr=sr, splits=splits, skipped=failed))
    if failed:
        warnings.warn(f"load_corpus: skipped {len(failed)} unreadable takes: {failed[:3]}", stacklevel=2)
    if not takes:
        raise ValueError(
            f"load_corpus: no readable usable takes in the index ({len(index)} takes, splits={splits})"
        )
    return takes


def analysis_subset(
    index: TakeIndex, *, max_minutes: float = 30.0, per_group: int = 2, max_speakers: int = 4
) -> TakeIndex:
    """The takes the per-take analyses of notebook 02 load: all of a small corpus, a sample of a big one.

    Loading a take at 15 fps costs about 20 s per hour of 120-fps BVH, so on a corpus longer than
    ``max_minutes`` the analyses use a sample that keeps every emotion and split present:

    - speech takes only (conversation takes are neutral, so they add no emotion contrast), unless
      the corpus has none;
    - the ``max_speakers`` speakers with the most speech takes (ties: lower id first);
    - for each (speaker, emotion, split), the first ``per_group`` takes by sequence id.

    Parameters
    ----------
    index : TakeIndex
        The indexed corpus (unusable takes are dropped).
    max_minutes : float
        Corpora up to this many minutes of usable takes are returned whole.
    per_group : int
        Takes kept per (speaker, emotion, split) in a big corpus.
    max_speakers : int
        Speakers kept in a big corpus.

    Returns
    -------
    TakeIndex
        The chosen takes, in index order.

    Examples
    --------
    Skipped by the doctests (needs a big corpus); on real BEAT-4english this keeps at most
    4 x 8 x 3 x 2 = 192 one-minute speech takes:

    >>> analysis_subset(index_folder("/data/beat_english_v0.2.1"))  # doctest: +SKIP
    """
    if per_group < 1 or max_speakers < 1:
        raise ValueError(
            f"analysis_subset: per_group and max_speakers must be >= 1, got {per_group}, {max_speakers}"
        )
    usable = index.where(usable=True)
    if usable.total_duration / 60 <= max_minutes:
        return usable
    speech = usable.where(conversation=False)
    pool = speech if len(speech) else usable
    counts: dict[int | None, int] = {}
    for r in pool:
        counts[r.speaker_id] = counts.get(r.speaker_id, 0) + 1
    speakers = sorted(counts, key=lambda s: (-counts[s], s if s is not None else -1))[:max_speakers]
    kept: set[str] = set()
    groups: dict[tuple, list] = {}
    for r in pool.where(speaker_id=speakers):
        groups.setdefault((r.speaker_id, r.emotion, r.split), []).append(r)
    for members in groups.values():
        members.sort(key=lambda r: (r.sequence if r.sequence is not None else 0, r.stem))
        kept.update(r.stem for r in members[:per_group])
    return pool.filter(lambda r: r.stem in kept)
