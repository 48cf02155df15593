"""Aligned, fixed-length training windows (and whole-take evaluation items) for CaMN and HA2G.

:func:`build_windows` cuts every usable take of one split into windows of
``length`` frames at ``fps`` with hop ``stride`` (BEAT: 34 frames at 15 fps,
stride 10; HA2G §4.1, docs/reference_code.md#windows) and returns a :class:`Windows` whose arrays follow the
batch contract of ``docs/architecture.md``:

=============  =======================  =============================================================
key            shape, dtype              content
=============  =======================  =============================================================
``pose``       (N, 34, 141) float32      z-scored Euler degrees of ``spine_neck_141`` (train stats)
``pose_raw``   (N, 34, 141) float32      Euler degrees
``positions``  (N, 34, 47, 3) float32    cm, the 47 ``spine_neck_141`` joints (``positions=True`` only)
``dirvec``     (N, 34, 126) float32      unit directions of the 42 TED bones minus their train mean
``audio``      (N, 36266) float32        16 kHz, ``floor(34/15*16000)`` samples from ``floor(s*16000/15)``
``mel``        (N, 70, 128) float32      log-mel (HA2G: 128 mels, n_fft 1024, hop 512, power 2, dB ref=max)
``face``       (N, 34, 51) float32       ARKit blendshape weights (zeros when the take has no JSON)
``word``       (N, 34) int64             vocabulary ids per frame (PAD=0 where no word / no TextGrid)
``emotion``    (N, 34) int64             emotion id 0..7 per frame
``semantic``   (N, 34) float32           semantic relevance score in [0, 1] per frame
``speaker``    (N,) int64                ``speaker_id - 1`` (0..29, the reference's index)
``take``       (N,) str                  stem of the source take
``start``      (N,) int64                first frame of the window in the take
=============  =======================  =============================================================

Normalisation statistics (pose mean/std, direction mean) are computed on the
**train** split only and kept with the arrays. The windows are read from the window store of the index
(:mod:`beatlite.data.store`: every take's streams cut, normalised and cached once under
:func:`beatlite.paths.cache_dir`, keyed by a fingerprint of the source files' content, the per-take overrides
and every parameter, :mod:`beatlite.data.fingerprint`): ``build_windows`` holds in memory what training reads
from the store one batch at a time.

With ``whole_takes=True`` there is one item per take, full length (the
reference's test mode); per-frame keys are then lists of (T_i, ...) arrays.

The log-mel is computed once per take (``center=True``, ``ref=max`` over the
take, as HA2G does per clip) and sliced: a window starting at audio sample
``a0`` takes the 70 mel frames from ``floor(a0 / 512)``. No window is dropped
(the reference drops near-static training windows; beatlite keeps them).

Taught in notebooks/05_camn.ipynb, section 1 (a batch of training windows); its audio features in notebooks/03_audio_and_text_features.ipynb, sections 2 (the mel spectrogram) and 5 (the raw wave for CaMN).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import tempfile
import warnings
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from beatlite.constants import FPS, SR, WINDOW_LENGTH, WINDOW_STRIDE
from beatlite.data.normalize import Normalizer, Normalizers

if TYPE_CHECKING:
    from beatlite.data.index import TakeIndex, TakeRecord
    from beatlite.data.store import WindowStore
    from beatlite.data.vocab import Vocab

#: Keys of a window batch, in contract order (``positions`` only when asked for).
WINDOW_KEYS = (
    "pose",
    "pose_raw",
    "positions",
    "dirvec",
    "audio",
    "mel",
    "face",
    "word",
    "emotion",
    "semantic",
    "speaker",
    "take",
    "start",
)
#: HA2G log-mel settings (HA2G §4.2, docs/reference_code.md#ha2g-audio).
MEL_SETTINGS = {"n_mels": 128, "n_fft": 1024, "hop_length": 512, "power": 2.0}
POSE_SUBSET = "spine_neck_141"


def window_starts(n_frames: int, length: int = WINDOW_LENGTH, stride: int = WINDOW_STRIDE) -> np.ndarray:
    """First frames of the windows of a take: ``0, stride, ...`` while ``start + length <= n_frames``.

    >>> window_starts(100, 34, 10).tolist()
    [0, 10, 20, 30, 40, 50, 60]
    """
    for name, v in (("n_frames", n_frames), ("length", length), ("stride", stride)):
        if not isinstance(v, int | np.integer) or v < (0 if name == "n_frames" else 1):
            raise ValueError(
                f"window_starts: {name} must be a {'non-negative' if name == 'n_frames' else 'positive'} int, got {v!r}"
            )
    if n_frames < length:
        return np.zeros(0, dtype=np.int64)
    return np.arange(0, n_frames - length + 1, stride, dtype=np.int64)


def sliding_windows(
    x: np.ndarray | Sequence[np.ndarray], length: int = WINDOW_LENGTH, stride: int = WINDOW_STRIDE
) -> np.ndarray:
    """Overlapping windows along the first (time) axis: the one window cutter of beatlite.

    Like ``librosa.util.frame`` but with the window axis first (the batch layout): window ``i``
    is ``x[starts[i] : starts[i] + length]`` with ``starts = window_starts(T, length, stride)``.

    Parameters
    ----------
    x : (T, ...) array, or a list of (T_i, ...) arrays (several takes)
        Per-frame values. A list is cut take by take (no window crosses two takes) and the
        windows are concatenated in take order.
    length, stride : int
        Window length and hop in frames (BEAT / HA2G: 34 and 10).

    Returns
    -------
    (N, length, ...) array, a copy with ``x``'s dtype; N = 0 when no take has ``length`` frames.

    Examples
    --------
    >>> x = np.arange(10)
    >>> sliding_windows(x, 4, 3)
    array([[0, 1, 2, 3],
           [3, 4, 5, 6],
           [6, 7, 8, 9]])
    >>> sliding_windows([x, x[:5]], 4, 3).shape  # 3 windows of the first take, 1 of the second
    (4, 4)
    """
    takes = [np.asarray(t) for t in x] if isinstance(x, list | tuple) else [np.asarray(x)]
    if not takes:
        raise ValueError("sliding_windows: got an empty list of takes")
    parts = []
    for t in takes:
        if t.ndim == 0:
            raise ValueError("sliding_windows: x must be (T, ...), got a scalar")
        starts = window_starts(int(t.shape[0]), length, stride)
        parts.append(t[starts[:, None] + np.arange(length)[None, :]])
    return np.concatenate(parts) if len(parts) > 1 else parts[0]


def audio_samples(n_frames: int, fps: float, sr: int) -> int:
    """Audio samples covering ``n_frames`` pose frames: ``floor(n_frames / fps * sr)`` (36266 for 34).

    Examples
    --------
    >>> audio_samples(34, 15, 16000)  # floor(34 / 15 * 16000)
    36266
    """
    return int(np.floor(n_frames * sr / fps + 1e-9))


def audio_start(frame: int, fps: float, sr: int) -> int:
    """First audio sample of pose frame ``frame``: ``floor(frame * sr / fps)``.

    Examples
    --------
    >>> audio_start(10, 15, 16000)  # floor(10 * 16000 / 15)
    10666
    """
    return int(np.floor(frame * sr / fps + 1e-9))


def mel_frames(n_samples: int) -> int:
    """Mel frames per clip of ``n_samples`` (HA2G): ``round((n - n_fft) / hop + 1)`` (70 for 36266).

    Examples
    --------
    >>> mel_frames(36266)  # round((36266 - 1024) / 512 + 1), n_fft 1024 and hop 512
    70
    """
    return max(1, int(round((n_samples - MEL_SETTINGS["n_fft"]) / MEL_SETTINGS["hop_length"] + 1)))


def log_mel(audio: np.ndarray, sr: int = SR) -> np.ndarray:
    """Log-mel spectrogram with HA2G settings, (M, 128) float32 dB (``power_to_db(ref=np.max)``).

    Parameters
    ----------
    audio : (N,) float
        Mono waveform in [-1, 1].
    sr : int
        Sample rate, Hz.

    Returns
    -------
    (M, 128) float32, M = 1 + N // 512 (librosa ``center=True``); max 0 dB, min -80 dB.

    Examples
    --------
    >>> t = np.arange(16000) / 16000
    >>> mel = log_mel(np.sin(2 * np.pi * 440 * t).astype(np.float32))  # 1 s of A4
    >>> mel.shape, float(mel.max()), float(mel.min())  # 1 + 16000 // 512 frames, 128 mels, [-80, 0] dB
    ((32, 128), 0.0, -80.0)
    """
    import librosa

    y = np.asarray(audio, dtype=np.float32)
    if y.ndim != 1:
        raise ValueError(f"log_mel: audio must be (N,), got {y.shape}")
    spec = librosa.feature.melspectrogram(y=y, sr=sr, **MEL_SETTINGS)
    return librosa.power_to_db(spec, ref=np.max).T.astype(np.float32)


# ---------------------------------------------------------------------- per take
@dataclass
class TakeFeatures:
    """All per-frame streams of one take at the model frame rate, aligned to ``n_frames``.

    Attributes
    ----------
    stem : str
    speaker : int
        ``speaker_id - 1``.
    pose_raw : (T, 141) float64, degrees
    dirs : (T, 126) float64, unit bone directions (not centred)
    positions : (T, 47, 3) float32 cm or None
    audio : (N,) float32, N >= audio_samples(T)
    mel : (M, 128) float32 dB (whole take)
    face : (T, 51) float32
    word : (T,) int64
    emotion : (T,) int64
    semantic : (T,) float32

    Examples
    --------
    >>> from beatlite.data.index import index_folder
    >>> from beatlite.paths import repo_root
    >>> index = index_folder(repo_root() / "data_samples", recursive=False, cache=False, read_durations=False)
    >>> f = take_features(index["2_scott_0_1_1"], mel=False)
    >>> f.n_frames, f.pose_raw.shape, f.dirs.shape, f.face.shape, f.word.shape
    (222, (222, 141), (222, 126), (222, 51), (222,))
    """

    stem: str
    speaker: int
    pose_raw: np.ndarray
    dirs: np.ndarray
    positions: np.ndarray | None
    audio: np.ndarray
    mel: np.ndarray
    face: np.ndarray
    word: np.ndarray
    emotion: np.ndarray
    semantic: np.ndarray

    @property
    def n_frames(self) -> int:
        return int(self.pose_raw.shape[0])


def take_features(
    record: TakeRecord,
    *,
    fps: float = FPS,
    sr: int = SR,
    vocab: Mapping | None = None,
    word_rule: str = "span",
    positions: bool = False,
    mel: bool = True,
) -> TakeFeatures:
    """Load one take and compute its aligned per-frame streams (see :class:`TakeFeatures`).

    ``mel=False`` skips the log-mel (``mel`` is then (0, 128)); ``vocab=None`` gives PAD words.

    The frame count is the one :func:`beatlite.io.load_take` aligned every modality to: the
    smallest of the motion frames, ``floor(audio seconds * fps)`` and the face frames (BEAT:
    truncate to the shortest modality, docs/reference_code.md#audio).

    Examples
    --------
    >>> from beatlite.data.index import index_folder
    >>> from beatlite.paths import repo_root
    >>> index = index_folder(repo_root() / "data_samples", recursive=False, cache=False, read_durations=False)
    >>> f = take_features(index["2_scott_0_1_1"])
    >>> f.n_frames, f.audio.shape[0] >= audio_samples(f.n_frames, 15, 16000), f.mel.shape[1]
    (222, True, 128)
    """
    from beatlite.io import load_take, words_to_frames
    from beatlite.skeleton import subset_columns
    from beatlite.skeleton.beat import JOINT_SUBSETS
    from beatlite.skeleton.directions import positions_to_directions
    from beatlite.skeleton.ted import TED_BONES, beat_to_ted43

    take = load_take(record.path("motion"), fps=fps, audio_sr=sr, bvh_fps=record.bvh_fps)
    motion = take.motion
    audio = np.asarray(take.audio, dtype=np.float32)
    n = take.n_frames  # load_take already cut every modality to the shortest one
    skel = motion.skeleton
    cols = subset_columns(skel, POSE_SUBSET)
    pose_raw = motion.channels[:n, cols]
    world = motion.positions()[:n]
    dirs = positions_to_directions(beat_to_ted43(world), np.asarray(TED_BONES)).reshape(n, -1)
    pos = None
    if positions:
        pos = world[:, skel.indices(JOINT_SUBSETS[POSE_SUBSET])].astype(np.float32)
    face = np.zeros((n, 51), np.float32) if take.face is None else np.asarray(take.face, np.float32)[:n]
    if take.words is not None and vocab is not None:
        # the TextGrid of a "_b" half keeps the whole sequence's times (docs/reference_code.md#textgrid)
        offset = 0.0 if record.half != "b" else (300.0 if record.conversation else 30.0)
        word = words_to_frames(take.words, n, fps, vocab, rule=word_rule, offset=offset).astype(np.int64)
    else:
        word = np.zeros(n, dtype=np.int64)
    return TakeFeatures(
        stem=record.stem,
        speaker=int(record.speaker_id) - 1,
        pose_raw=pose_raw,
        dirs=dirs,
        positions=pos,
        audio=audio,
        mel=log_mel(audio, sr) if mel else np.zeros((0, MEL_SETTINGS["n_mels"]), np.float32),
        face=face,
        word=word,
        emotion=np.asarray(take.emotion, dtype=np.int64)[:n],
        semantic=np.asarray(take.semantic, dtype=np.float32)[:n],
    )


# ---------------------------------------------------------------------- container
class Windows:
    """The windows (or whole takes) of one split, with their normalisation statistics.

    Index it like the batch dict of the contract: ``w["pose"]`` is (N, 34, 141) float32.
    With ``whole_takes=True`` per-frame keys (and ``audio``, ``mel``) give lists of
    per-take arrays instead. :meth:`item` returns one item as a dict of arrays,
    :meth:`batch` a batch dict for given indices.

    Attributes
    ----------
    normalizers : Normalizers
        The train split's fitted normalisers: ``normalizers.pose`` (141-d Euler degrees) and
        ``normalizers.dirvec`` (126-d direction mean, ``std = 1``).
    params : dict
        Parameters the windows were built with (split, length, stride, fps, sr, ...).
    whole_takes : bool
        One full-length item per take.
    path : Path or None
        The ``.npz`` the windows were loaded from or saved to (:meth:`load`, :meth:`save`); None for
        windows read from a store.

    Examples
    --------
    >>> from beatlite.data.examples import example_corpus
    >>> from beatlite.data.index import index_folder
    >>> tmp = example_corpus()  # a test and a train take of data_samples/, copied to a temporary folder
    >>> index = index_folder(tmp.name, cache=False)
    >>> windows = build_windows(index, split="test", cache=False)  # statistics from the train take
    >>> len(windows), windows["pose"].shape, windows["dirvec"].shape
    (19, (19, 34, 141), (19, 34, 126))
    >>> windows.batch(np.array([0, 1]))["audio"].shape  # audio_samples(34, 15, 16000) samples per window
    (2, 36266)
    >>> tmp.cleanup()
    """

    def __init__(
        self,
        arrays: dict[str, np.ndarray],
        *,
        normalizers: Normalizers,
        params: dict[str, Any],
        path: Path | None = None,
    ) -> None:
        self._arrays = arrays
        self.normalizers = normalizers
        self.params = dict(params)
        self.whole_takes = bool(params.get("whole_takes", False))
        self.path = path
        n = len(arrays["take"])
        if self.whole_takes:
            self._offsets = {
                k: np.concatenate([[0], np.cumsum(arrays[f"_len_{k}"])]).astype(np.int64)
                for k in ("frames", "audio", "mel")
            }
        elif any(len(arrays[k]) != n for k in self.keys()):
            raise ValueError("Windows: arrays have different numbers of rows")

    # mapping-like access -----------------------------------------------------
    def keys(self) -> list[str]:
        """Batch keys present, in contract order."""
        return [k for k in WINDOW_KEYS if k in self._arrays]

    def __len__(self) -> int:
        return int(len(self._arrays["take"]))

    def __iter__(self) -> Iterator[str]:
        """Iterate over the keys, like a dict (``len`` however counts items)."""
        return iter(self.keys())

    def get(self, key: str, default: Any = None) -> Any:
        """``self[key]`` if the key is present, else ``default`` (dict-like)."""
        return self[key] if key in self.keys() else default

    def __contains__(self, key: object) -> bool:
        return key in self.keys()

    def _span(self, key: str, i: int) -> slice:
        kind = "audio" if key == "audio" else "mel" if key == "mel" else "frames"
        off = self._offsets[kind]
        return slice(int(off[i]), int(off[i + 1]))

    def __getitem__(self, key: str | int) -> np.ndarray | list[np.ndarray] | dict[str, np.ndarray]:
        """``w["pose"]``: the array of a key (a list in whole-take mode); ``w[i]``: item ``i`` (a dict)."""
        if isinstance(key, int | np.integer):
            return self.item(int(key))
        if key not in self.keys():
            raise KeyError(f"Windows has no key {key!r}; keys: {self.keys()}")
        arr = self._arrays[key]
        if not self.whole_takes or key in ("speaker", "take", "start"):
            return arr
        return [arr[self._span(key, i)] for i in range(len(self))]

    def item(self, i: int) -> dict[str, np.ndarray]:
        """Item ``i`` as a dict (per-frame arrays without the leading N axis)."""
        if not -len(self) <= i < len(self):
            raise IndexError(f"Windows.item: index {i} out of range for {len(self)} items")
        i = i % len(self)
        out = {}
        for k in self.keys():
            arr = self._arrays[k]
            if self.whole_takes and k not in ("speaker", "take", "start"):
                out[k] = arr[self._span(k, i)]
            else:
                out[k] = arr[i]
        return out

    def batch(
        self, indices: Sequence[int] | np.ndarray | None = None, *, keys: Sequence[str] | None = None
    ) -> dict[str, np.ndarray]:
        """Batch dict (the contract) of the given windows (default all) and ``keys`` (default all);
        windowed mode only (as :meth:`beatlite.data.store.StoreWindows.batch`)."""
        if self.whole_takes:
            raise ValueError("Windows.batch: whole-take items have different lengths; use item(i)")
        missing = [k for k in keys or () if k not in self.keys()]
        if missing:
            raise KeyError(f"Windows.batch: keys {missing} not in these windows ({self.keys()})")
        idx = np.arange(len(self)) if indices is None else np.asarray(indices, dtype=np.int64)
        return {k: self._arrays[k][idx] for k in (self.keys() if keys is None else keys)}

    @property
    def fingerprint(self) -> str:
        """16 hex digits identifying the source of these windows, the same on every machine: the takes'
        files (content), per-take overrides, the parameters and the vocabulary
        (:mod:`beatlite.data.fingerprint`). The statistics are left out (their float bits vary across
        machines; they are derived from the train takes, or compared by :meth:`Normalizers.matches`)."""
        return str(self.params.get("fingerprint", ""))

    def __repr__(self) -> str:
        mode = "whole takes" if self.whole_takes else f"windows of {self.params['length']} frames"
        return f"Windows({len(self)} {mode}, split={self.params['split']!r}, keys={self.keys()})"

    # persistence ---------------------------------------------------------------
    def save(self, path: str | Path) -> Path:
        """Write arrays, statistics and parameters to one ``.npz`` (atomic). Returns the path."""
        from beatlite.io.atomic import atomic_write

        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        payload = dict(self._arrays)
        payload.update(self.normalizers.pose.to_arrays("pose"))
        payload.update(self.normalizers.dirvec.to_arrays("dirvec"))
        payload["_params"] = np.array(json.dumps(self.params, sort_keys=True))
        with atomic_write(path, "wb") as f:
            np.savez(f, **payload)
        self.path = path
        return path

    @classmethod
    def load(cls, path: str | Path) -> Windows:
        """Read windows written by :meth:`save` (no pickle)."""
        from beatlite.io.errors import FormatError

        path = Path(path)
        try:
            with np.load(path, allow_pickle=False) as z:
                data = {k: z[k] for k in z.files}
        except (OSError, ValueError) as e:
            raise FormatError(path, f"not a windows .npz: {e}") from None
        for key in ("_params", "pose_mean", "pose_std", "dirvec_mean", "dirvec_std", "take"):
            if key not in data:
                raise FormatError(path, "missing array", field=key)
        params = json.loads(str(data.pop("_params")))
        pose = Normalizer(data.pop("pose_mean"), data.pop("pose_std"))
        dirvec = Normalizer(data.pop("dirvec_mean"), data.pop("dirvec_std"))
        return cls(data, normalizers=Normalizers(pose, dirvec), params=params, path=path)


# ---------------------------------------------------------------------- building
def _usable(index: TakeIndex, split: str | None) -> list[TakeRecord]:
    chosen = [r for r in index if split is None or r.split == split]
    skipped = [r.stem for r in chosen if not r.usable]
    if skipped:
        warnings.warn(
            f"build_windows: skipping {len(skipped)} unusable takes (see TakeIndex.problems()): {skipped[:5]}",
            stacklevel=3,
        )
    return [r for r in chosen if r.usable]


def build_windows(
    index: TakeIndex,
    *,
    split: str | None,
    length: int = WINDOW_LENGTH,
    stride: int = WINDOW_STRIDE,
    fps: float = FPS,
    sr: int = SR,
    whole_takes: bool = False,
    vocab: Vocab | None = None,
    stats: Normalizers | None = None,
    positions: bool = False,
    word_rule: str = "span",
    cache: bool | str | Path = True,
    progress: bool = False,
) -> Windows:
    """Windows (or whole takes) of one split, aligned across all modalities, held in memory.

    The takes are cut, normalised and cached by the window store (:func:`beatlite.data.store.build_store`,
    the route training reads one batch at a time): this is that store's windows of ``split`` read into
    arrays (one cutting rule, one normalisation, one cache format and one fingerprint for both).

    Parameters
    ----------
    index : TakeIndex
        The indexed corpus (:func:`beatlite.data.index.index_folder`); its train split
        provides the normalisation statistics and (by default) all its TextGrids the vocabulary.
    split : {"train", "val", "test"} or None
        Takes to cut (None: all usable takes).
    length, stride : int
        Window length and hop, frames (34 and 10).
    fps : float
        Model frame rate (15).
    sr : int
        Audio sample rate (16000).
    whole_takes : bool
        One item per take, full length (evaluation mode); ``length``/``stride`` unused.
    vocab : Vocab, optional
        Word ids; default :func:`beatlite.data.vocab.corpus_vocab` of the index (its usable takes: an unusable take's
        TextGrid may not read), the vocabulary ``fit`` trains with.
    stats : Normalizers, optional
        Statistics to use instead of fitting them on the index's train split (e.g. the training
        windows' ``w.normalizers``).
    positions : bool
        Also return ``"positions"`` (N, length, 47, 3) float32 cm.
    word_rule : {"span", "onset", "beat"}
        Word-to-frame rule of :func:`beatlite.io.words_to_frames`.
    cache : bool or str or Path
        Where the store of the index's usable takes is kept: True: under ``cache_dir()/store`` (built once,
        then only changed takes; the corpus' own store, the one training builds, unless that one lists takes
        this index lacks); a folder: under it; False: a temporary folder, removed afterwards.
    progress : bool
        Show a tqdm bar over the takes the store builds.

    Returns
    -------
    Windows

    Raises
    ------
    ValueError
        Bad parameters, or no usable take in ``split``.

    Examples
    --------
    >>> from beatlite.data.examples import example_corpus
    >>> from beatlite.data.index import index_folder
    >>> tmp = example_corpus()  # a test and a train take of data_samples/, copied to a temporary folder
    >>> index = index_folder(tmp.name, cache=False)
    >>> takes = build_windows(index, split="test", whole_takes=True, cache=False)
    >>> len(takes), takes["pose"][0].shape  # one 222-frame take
    (1, (222, 141))
    >>> tmp.cleanup()
    """
    from beatlite.data.vocab import corpus_vocab

    _check_window_params(split, length, stride, fps, sr)
    records = _usable(index, split)
    if not records:
        raise ValueError(f"build_windows: no usable takes in split {split!r} ({len(index)} takes indexed)")
    if stats is None and not any(r.usable and r.split == "train" for r in index):
        raise ValueError("build_windows: the index has no usable train takes to compute statistics from")
    if stats is not None and not isinstance(stats, Normalizers):
        raise TypeError(
            f"build_windows: stats must be Normalizers (e.g. train.normalizers), got {type(stats).__name__}"
        )
    vocab = corpus_vocab(index) if vocab is None else vocab
    params: dict[str, Any] = {
        "split": split, "length": int(length), "stride": int(stride), "fps": float(fps), "sr": int(sr),
        "whole_takes": bool(whole_takes), "positions": bool(positions), "word_rule": word_rule,
        "vocab_size": len(vocab), "mel": dict(MEL_SETTINGS), "subset": POSE_SUBSET,
    }  # fmt: skip
    with _store_of(index, records, params, vocab, cache, progress, need_train=stats is None) as store:
        stats = store.statistics("train") if stats is None else stats
        stems = [r.stem for r in records]
        read = _whole_takes if whole_takes else _windows
        arrays, params["fingerprint"] = read(store, stems, stats, vocab, params)
    return Windows(arrays, normalizers=stats, params=params)


@contextlib.contextmanager
def _store_of(
    index: TakeIndex, records: list[TakeRecord], params: dict[str, Any], vocab: Vocab, cache: bool | str | Path,
    progress: bool, need_train: bool,
) -> Iterator[WindowStore]:  # fmt: skip
    """The window store to read ``records`` from, kept as ``cache`` says.

    ``cache=True`` (or a folder): the corpus' own store, the one training builds, opened read-only when it
    holds exactly the index's usable takes, all current (:func:`beatlite.data.store.open_if_current`); else a
    store of the index's usable takes beside it, built or updated (building the corpus' store from this index
    would drop the takes it lacks, or rebuild them with other overrides). ``cache=False``: a temporary store of
    ``records`` and (``need_train``) the train takes, removed afterwards.
    """
    from beatlite.data.store import build_store, default_store_folder, open_if_current, store_params

    store = store_params(fps=params["fps"], sr=params["sr"], positions=params["positions"],
                         word_rule=params["word_rule"])  # fmt: skip
    args = {**{k: store[k] for k in ("fps", "sr", "positions", "word_rule")}, "vocab": vocab, "workers": 0}
    if cache is False or cache is None:
        stems = {r.stem for r in records} | (
            {r.stem for r in index if r.split == "train"} if need_train else set()
        )
        with tempfile.TemporaryDirectory(prefix="beatlite-windows-") as tmp:
            yield build_store(index.where(usable=True, stem=stems), tmp, **args, progress=progress)
        return
    usable = index.where(usable=True)
    folder = default_store_folder(usable, store)
    if cache is not True:
        folder = Path(cache) / "store" / folder.name
    shared = open_if_current(usable, folder, store)
    if shared is not None:
        yield shared
        return
    key = "\n".join(f"{r.stem} {r.bvh_fps}" for r in sorted(usable, key=lambda r: r.stem))
    own = folder.with_name(f"{folder.name}-{hashlib.sha256(key.encode()).hexdigest()[:16]}")
    yield build_store(usable, own, **args, progress=progress)


def _windows(
    store: WindowStore, stems: list[str], stats: Normalizers, vocab: Vocab, params: dict[str, Any]
) -> tuple[dict[str, np.ndarray], str]:
    """Every window of the takes ``stems`` as arrays, and their fingerprint."""
    from beatlite.data.store import StoreWindows

    try:
        view = StoreWindows(store, None, length=params["length"], stride=params["stride"], keys=None,
                            stats=stats, vocab=vocab, stems=stems)  # fmt: skip
    except ValueError:
        raise ValueError(
            f"build_windows: no take of split {params['split']!r} is at least {params['length']} frames long "
            f"({len(stems)} takes)"
        ) from None
    fingerprint = store.windows_fingerprint(  # (the view's split is None: the split's)
        stems, split=params["split"], length=params["length"], stride=params["stride"], vocab=vocab
    )
    return view.batch(None), fingerprint


def _whole_takes(
    store: WindowStore, stems: list[str], stats: Normalizers, vocab: Vocab, params: dict[str, Any]
) -> tuple[dict[str, np.ndarray], str]:
    """The takes ``stems`` at full length, concatenated, with each one's frame, audio and mel lengths
    (``_len_frames``, ``_len_audio``, ``_len_mel``), and their fingerprint."""
    items = [store.whole_take(stem, stats=stats, vocab=vocab) for stem in stems]
    arrays = {k: np.concatenate([np.atleast_1d(item[k]) for item in items]) for k in items[0]}
    for key, name in (("frames", "pose"), ("audio", "audio"), ("mel", "mel")):
        arrays[f"_len_{key}"] = np.array([len(item[name]) for item in items], np.int64)
    return arrays, store.windows_fingerprint(stems, split=params["split"], length=0, stride=0, vocab=vocab)


def _check_window_params(split: str | None, length: int, stride: int, fps: float, sr: int) -> None:
    if split not in ("train", "val", "test", None):
        raise ValueError(f"build_windows: split must be 'train', 'val', 'test' or None, got {split!r}")
    for name, v in (("length", length), ("stride", stride), ("sr", sr)):
        if not isinstance(v, int | np.integer) or v < 1:
            raise ValueError(f"build_windows: {name} must be a positive int, got {v!r}")
    if not fps > 0:
        raise ValueError(f"build_windows: fps must be positive, got {fps!r}")
