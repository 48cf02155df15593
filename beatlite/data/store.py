"""A window store on disk: each take's aligned streams stored once, windows sliced at batch time.

:func:`build_windows` reads every window of a split of this store into RAM (about 244 KB per window, the
16 kHz audio repeated 3.4 times at stride 10), so its memory grows with the corpus. The
store keeps, per take, one ``.npy`` file per stream (memory-mappable, read by byte range),
and a split's windows are only an index ``(take, start)``; a batch reads the rows it needs
of the streams it is asked for (``keys=``) and derives the rest:

=============  ====================  ==================================================================
stream (file)  on disk               batch keys
=============  ====================  ==================================================================
``pose_raw``   (T, 141) float64      ``pose_raw`` (float32) and ``pose`` (z-scored with the train stats)
``dirs``       (T, 126) float64      ``dirvec`` (unit directions minus their train mean)
``audio``      (N,) int16            ``audio`` (``q * audio_scale`` float32, 16 kHz)
``mel``        (M, 128) float32      ``mel`` (log-mel of the whole take, computed once)
``face``       (T, 51) float32       ``face``
``word``       (T,) int32            ``word`` (take-local ids mapped to the vocabulary at batch time)
``emotion``    (T,) int8             ``emotion`` (int64)
``semantic``   (T,) float32          ``semantic``
``positions``  (T, 47, 3) float32    ``positions`` (only in a store built with ``positions=True``)
=============  ====================  ==================================================================

Batches equal the windows cut from each take's features (:func:`beatlite.data.windows.take_features`,
:func:`~beatlite.data.windows.sliding_windows`) bit for bit except ``audio``: it is stored as 16-bit PCM with a per-take step
``audio_scale``, so ``|audio - stored| <= audio_scale / 2 + 2**-24 |audio|`` (half a step plus
float32 rounding). ``audio_scale = 2**-15`` when the take's samples lie in ``[-1, 32767/32768]``
(then ``q * 2**-15`` is exact in float32 and the bound is ``2**-16 ~ 1.5e-5``), else
``peak / 32767`` (resampling overshoot above 1). Audio that is already 16-bit PCM at
the model rate (``data_samples/``) is stored exactly. The train statistics are accumulated
per take (count, sum, centred sum of squares; Chan et al.'s pairwise update) and equal
:meth:`Normalizer.fit` over all train frames up to float rounding.

The folder holds ``store.json`` (version, parameters, take stems in index order, the
vocabulary) and ``takes/{stem}/`` with the ``.npy`` files and ``meta.json`` (shapes, audio step,
word marks, statistics and a fingerprint of the source files and parameters); each JSON file carries the
sha256 of its content (``digest``: a corrupt one is a ``FormatError``, rebuilt by the next build). Building is
incremental: takes whose fingerprint matches are kept, the others are rebuilt in worker
processes; every file is written atomically, ``meta.json`` last.

Examples
--------
>>> from beatlite.data import index_folder  # doctest: +SKIP
>>> store = build_store(index_folder("data_samples"), workers=2, progress=True)  # doctest: +SKIP
>>> train = store.windows("train", keys=("pose", "audio", "word", "speaker"))  # doctest: +SKIP
>>> batch = train.batch([0, 5, 9]); batch["audio"].shape  # doctest: +SKIP
(3, 36266)
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import shutil
import warnings
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from beatlite.constants import FPS, SR, WINDOW_LENGTH, WINDOW_STRIDE
from beatlite.data.fingerprint import json_digest
from beatlite.data.normalize import MIN_STD, Normalizer, Normalizers
from beatlite.data.windows import (
    MEL_SETTINGS,
    POSE_SUBSET,
    audio_samples,
    audio_start,
    mel_frames,
    take_features,
    window_starts,
)
from beatlite.io.errors import FormatError

if TYPE_CHECKING:
    from beatlite.data.index import TakeIndex, TakeRecord
    from beatlite.data.vocab import Vocab

#: Bump when the layout or the content of the files changes (older entries are rebuilt).
STORE_VERSION = 2
#: Streams of a take: file name -> dtype on disk.
STREAMS = {
    "pose_raw": "<f8",
    "dirs": "<f8",
    "audio": "<i2",
    "mel": "<f4",
    "face": "<f4",
    "word": "<i4",
    "emotion": "<i1",
    "semantic": "<f4",
    "positions": "<f4",
}
#: Batch key -> stream it is read from (None: per-take or index values).
KEY_STREAM = {
    "pose": "pose_raw",
    "pose_raw": "pose_raw",
    "positions": "positions",
    "dirvec": "dirs",
    "audio": "audio",
    "mel": "mel",
    "face": "face",
    "word": "word",
    "emotion": "emotion",
    "semantic": "semantic",
    "speaker": None,
    "take": None,
    "start": None,
}
#: First take-local word id (0..3 are PAD, SOS, EOS, UNK and keep their meaning).
_FIRST_LOCAL_WORD = 4


# ---------------------------------------------------------------------- per take (worker side)
class _WordRecorder(Mapping):
    """A vocabulary that gives every distinct raw word mark a take-local id (4, 5, ...).

    :func:`beatlite.io.words_to_frames` looks words up with ``vocab.get(mark, unk)``; mapping the
    local ids through ``vocab.get(mark, UNK)`` later gives exactly the ids of the real vocabulary.
    """

    def __init__(self) -> None:
        self.marks: list[str] = []
        self._ids: dict[str, int] = {}

    def get(self, word: str, default: Any = None) -> int:  # type: ignore[override]
        if word not in self._ids:
            self._ids[word] = _FIRST_LOCAL_WORD + len(self.marks)
            self.marks.append(word)
        return self._ids[word]

    def __getitem__(self, word: str) -> int:
        return self.get(word)

    def __iter__(self) -> Iterator[str]:
        return iter(self.marks)

    def __len__(self) -> int:
        return len(self.marks)


def quantize_audio(audio: np.ndarray) -> tuple[np.ndarray, float]:
    """16-bit PCM of a float waveform: ``(q (N,) int16, step)`` with ``audio ~= q * step``.

    ``step = 2**-15`` (exact for audio read from 16-bit PCM) unless the peak exceeds
    ``32767 / 32768`` (e.g. after resampling), then ``peak / 32767``. Error ``<= step / 2``.

    >>> q, step = quantize_audio(np.array([0.5, -1.0, 0.25], np.float32))
    >>> q.tolist(), step == 2**-15
    ([16384, -32768, 8192], True)
    """
    y = np.asarray(audio, dtype=np.float64)
    if y.size and not np.all(np.isfinite(y)):
        raise ValueError("quantize_audio: audio has NaN or infinite samples")
    fits = y.size == 0 or (y.max() <= 32767 / 32768 and y.min() >= -1.0)
    step = 2.0**-15 if fits else float(np.abs(y).max()) / 32767
    q = np.clip(np.rint(y / step), -32768, 32767).astype(np.int16)
    return q, step


def take_fingerprint(record: TakeRecord, params: Mapping[str, Any]) -> str:
    """:func:`beatlite.data.fingerprint.take_fingerprint` with :data:`STORE_VERSION`: the take's files
    (content), its ``bvh_fps`` override and the store parameters.

    Examples
    --------
    >>> from beatlite.data.index import index_take
    >>> from beatlite.paths import repo_root
    >>> record = index_take("2_scott_0_1_1", {"motion": [repo_root() / "data_samples" / "2_scott_0_1_1.bvh.gz"]})
    >>> fp = take_fingerprint(record, store_params())
    >>> len(fp), fp == take_fingerprint(record, store_params(fps=30))
    (64, False)
    """
    from beatlite.data.fingerprint import take_fingerprint as fingerprint

    return fingerprint(record, {**params, "version": STORE_VERSION})


def _moments(x: np.ndarray) -> dict[str, Any]:
    """Count, per-dimension sum and centred sum of squares of (T, D) rows (float64)."""
    x = np.asarray(x, dtype=np.float64)
    mean = x.mean(axis=0) if len(x) else np.zeros(x.shape[1])
    return {"n": int(len(x)), "sum": x.sum(axis=0).tolist(), "m2": ((x - mean) ** 2).sum(axis=0).tolist()}


@contextlib.contextmanager
def _writing(folder: Path, *, remove: bool = False) -> Iterator[None]:
    """Re-raise an ``OSError`` of writing under ``folder`` (a full disk, a read-only or missing folder) as
    one that names it (numpy's own is a bare ``N requested and M written``); ``remove``: remove ``folder``
    first (a take's partial entry: no space held by files that nothing will read)."""
    try:
        yield
    except OSError as e:
        if remove:
            shutil.rmtree(folder, ignore_errors=True)
        reason = (
            f"cannot write the window store {folder} ({e.strerror or e}): free space there, or give a "
            "writable one"
        )
        raise OSError(*(() if e.errno is None else (e.errno,)), reason) from None


def _save_npy(path: Path, array: np.ndarray) -> None:
    from beatlite.io.atomic import atomic_write

    with atomic_write(path, "wb") as f:
        np.save(f, array, allow_pickle=False)


def build_take(record: TakeRecord, folder: str | Path, params: Mapping[str, Any]) -> dict[str, Any]:
    """Compute one take's streams (:func:`take_features`) and write them under ``folder``; returns its meta.

    ``meta.json`` is removed first and written last, so a half-written entry is never taken as valid.
    Runs in the worker processes of :func:`build_store`.

    Examples
    --------
    >>> import tempfile
    >>> from beatlite.data.index import index_folder
    >>> from beatlite.paths import repo_root
    >>> index = index_folder(repo_root() / "data_samples", recursive=False, cache=False, read_durations=False)
    >>> tmp = tempfile.TemporaryDirectory()
    >>> meta = build_take(index["2_scott_0_1_1"], tmp.name, store_params())
    >>> meta["n_frames"], sorted(p.name for p in Path(tmp.name).glob("*.npy"))[:3]
    (222, ['audio.npy', 'dirs.npy', 'emotion.npy'])
    >>> tmp.cleanup()
    """
    folder = Path(folder)
    with _writing(folder):
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "meta.json").unlink(missing_ok=True)
    recorder = _WordRecorder()
    f = take_features(
        record,
        fps=params["fps"],
        sr=params["sr"],
        vocab=recorder,
        word_rule=params["word_rule"],
        positions=params["positions"],
    )
    audio, step = quantize_audio(f.audio)
    streams = {
        "pose_raw": f.pose_raw.astype("<f8"),
        "dirs": f.dirs.astype("<f8"),
        "audio": audio,
        "mel": f.mel.astype("<f4"),
        "face": f.face.astype("<f4"),
        "word": f.word.astype("<i4"),
        "emotion": f.emotion.astype("<i1"),
        "semantic": f.semantic.astype("<f4"),
    }
    if params["positions"]:
        streams["positions"] = f.positions.astype("<f4")
    meta = {
        "stem": record.stem,
        "split": record.split,
        "speaker": f.speaker,
        "n_frames": f.n_frames,
        "audio_scale": step,
        "word_marks": recorder.marks,
        "shapes": {k: list(v.shape) for k, v in streams.items()},
        "pose_moments": _moments(f.pose_raw),
        "dirs_moments": _moments(f.dirs),
        "fingerprint": take_fingerprint(record, params),
    }
    meta["digest"] = json_digest(meta, "digest")
    from beatlite.io.atomic import atomic_write

    with _writing(folder, remove=True):
        for name, arr in streams.items():
            _save_npy(folder / f"{name}.npy", np.ascontiguousarray(arr, dtype=STREAMS[name]))
        with atomic_write(folder / "meta.json") as fh:
            json.dump(meta, fh)
    return meta


# ---------------------------------------------------------------------- reading
def _read_json(path: Path) -> dict[str, Any]:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise FormatError(path, f"not a readable JSON file: {e}") from None
    if not isinstance(data, dict):
        raise FormatError(path, f"expected a JSON object, got {type(data).__name__}")
    return data


def _check_digest(data: Mapping[str, Any], path: Path) -> None:
    """FormatError naming ``path`` unless ``data`` (its JSON object) carries the :func:`~beatlite.data.fingerprint.json_digest` of itself."""
    if data.get("digest") != json_digest(data, "digest"):
        raise FormatError(
            path,
            "content does not match its digest (corrupt, or written by an older beatlite): build the store",
        )


def _need(data: Mapping[str, Any], path: Path, *fields: str) -> None:
    for field in fields:
        if field not in data:
            raise FormatError(path, "missing field", field=field)


@dataclass(frozen=True)
class StreamFile:
    """Where the rows of one ``.npy`` stream lie: data ``offset`` (bytes), ``dtype``, ``shape``, and which file
    that is (``ident``: its device and inode, so that rows are never read from a file that replaced it).

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "pose.npy"
    >>> np.save(path, np.arange(12, dtype=np.float32).reshape(4, 3))
    >>> stream = StreamFile.open(path, "float32", (4, 3))
    >>> stream.shape, stream.read(1, 3)  # rows 1 and 2, read from the file
    ((4, 3), array([[3., 4., 5.],
           [6., 7., 8.]], dtype=float32))
    >>> tmp.cleanup()
    """

    path: Path
    offset: int
    dtype: np.dtype
    shape: tuple[int, ...]
    ident: tuple[int, int] = (0, 0)

    @classmethod
    def open(cls, path: Path, dtype: str, shape: Sequence[int]) -> StreamFile:
        """Parse the ``.npy`` header and check it against the expected dtype/shape and the file size."""
        try:
            with open(path, "rb") as f:
                version = np.lib.format.read_magic(f)
                read_header = {
                    (1, 0): np.lib.format.read_array_header_1_0,
                    (2, 0): np.lib.format.read_array_header_2_0,
                }.get(version)
                if read_header is None:
                    raise ValueError(f".npy format version {version} (expected 1.0 or 2.0)")
                header = read_header(f)  # (shape, fortran, dtype)
                offset = f.tell()
                st = os.fstat(f.fileno())
        # (numpy parses the header as a Python literal: ValueError, SyntaxError, tokenize.TokenError, ...)
        except Exception as e:
            raise FormatError(path, f"not a readable .npy file: {e}") from None
        got_shape, fortran, got_dtype = header
        if fortran or got_dtype != np.dtype(dtype) or tuple(got_shape) != tuple(shape):
            raise FormatError(
                path,
                f"holds {got_dtype.str} {tuple(got_shape)}{' (Fortran order)' if fortran else ''}, "
                f"meta.json says {np.dtype(dtype).str} {tuple(shape)}",
            )
        size = offset + int(np.prod(shape, dtype=np.int64)) * got_dtype.itemsize
        if st.st_size != size:
            raise FormatError(path, f"{st.st_size} bytes, expected {size} (truncated or padded)")
        return cls(path, offset, got_dtype, tuple(int(s) for s in shape), (st.st_dev, st.st_ino))

    def row_bytes(self) -> int:
        return int(np.prod(self.shape[1:], dtype=np.int64)) * self.dtype.itemsize

    def read(self, start: int, stop: int) -> np.ndarray:
        """Rows ``[start, stop)`` (clipped to the array), read with one ``pread`` (no memory map)."""
        start, stop = max(0, start), min(stop, self.shape[0])
        n = max(0, stop - start)
        rb = self.row_bytes()
        buf = os.pread(_FILES.fd(self.path, self.ident), n * rb, self.offset + start * rb)
        if len(buf) != n * rb:
            raise FormatError(self.path, f"short read at row {start}: file changed since it was opened")
        return np.frombuffer(buf, dtype=self.dtype).reshape(n, *self.shape[1:])

    def memmap(self) -> np.ndarray:
        """The whole array as a read-only memory map."""
        return np.load(self.path, mmap_mode="r", allow_pickle=False)


class _FileCache:
    """A small per-process cache of open read-only file descriptors (reset after a fork), one per path: the
    descriptor of the file ``ident`` (device, inode) names; one of a file since replaced at that path (a rebuilt
    take) is closed, and a path that no longer holds that file is a ``FormatError``."""

    def __init__(self, size: int = 128) -> None:
        self.size = size
        self._fds: dict[Path, tuple[int, tuple[int, int]]] = {}
        self._pid = os.getpid()

    def fd(self, path: Path, ident: tuple[int, int]) -> int:
        if os.getpid() != self._pid:  # a forked DataLoader worker: open its own descriptors
            self._fds, self._pid = {}, os.getpid()
        fd, held = self._fds.pop(path, (None, None))
        if fd is not None and held != ident:  # the file at this path was replaced (a rebuilt take)
            os.close(fd)
            fd = None
        if fd is None:
            if len(self._fds) >= self.size:
                os.close(self._fds.pop(next(iter(self._fds)))[0])
            fd = os.open(path, os.O_RDONLY)
            st = os.fstat(fd)
            if (st.st_dev, st.st_ino) != tuple(ident):
                os.close(fd)
                raise FormatError(path, "replaced since the store was opened (open it again)")
        self._fds[path] = (fd, ident)  # most recently used last
        return fd


_FILES = _FileCache()


@dataclass
class StoreTake:
    """One take of a store: its folder, meta data and (lazily parsed) stream files.

    Examples
    --------
    >>> from pathlib import Path
    >>> from beatlite.data.examples import example_corpus
    >>> from beatlite.data.index import index_folder
    >>> tmp = example_corpus()  # a test and a train take of data_samples/, copied to a temporary folder
    >>> index = index_folder(tmp.name, cache=False)
    >>> store = build_store(index, Path(tmp.name) / "store")
    >>> take = store.take("2_scott_0_1_1")
    >>> take.stem, take.n_frames, take.stream("pose_raw").shape
    ('2_scott_0_1_1', 222, (222, 141))
    >>> tmp.cleanup()
    """

    folder: Path
    meta: dict[str, Any]

    @classmethod
    def open(cls, folder: Path) -> StoreTake:
        path = folder / "meta.json"
        meta = _read_json(path)
        _need(meta, path, "stem", "split", "speaker", "n_frames", "audio_scale", "word_marks", "shapes")
        _need(meta, path, "pose_moments", "dirs_moments", "fingerprint")
        _check_digest(meta, path)
        return cls(folder, meta)

    @property
    def stem(self) -> str:
        return str(self.meta["stem"])

    @property
    def n_frames(self) -> int:
        return int(self.meta["n_frames"])

    def stream(self, name: str) -> StreamFile:
        """The checked :class:`StreamFile` of stream ``name`` (FormatError naming the file if bad)."""
        files = self.__dict__.setdefault("_files", {})
        if name not in files:
            shapes = self.meta["shapes"]
            if name not in shapes:
                raise KeyError(f"store take {self.stem} has no stream {name!r} (has {sorted(shapes)})")
            files[name] = StreamFile.open(self.folder / f"{name}.npy", STREAMS[name], shapes[name])
        return files[name]

    def __getstate__(self) -> dict[str, Any]:  # parsed headers are cheap to redo in a worker
        return {"folder": self.folder, "meta": self.meta}


def _combine(moments: Sequence[Mapping[str, Any]], path: Path) -> tuple[int, np.ndarray, np.ndarray]:
    """Pooled (count, mean, population variance) of per-take moments (Chan et al. pairwise update)."""
    n = np.array([m["n"] for m in moments], dtype=np.float64)
    if n.sum() == 0:
        raise ValueError(f"store {path}: no train frames to compute statistics from")
    sums = np.array([m["sum"] for m in moments], dtype=np.float64)
    m2 = np.array([m["m2"] for m in moments], dtype=np.float64)
    mean = sums.sum(axis=0) / n.sum()
    take_means = sums / np.maximum(n, 1)[:, None]
    total_m2 = m2.sum(axis=0) + (n[:, None] * (take_means - mean) ** 2).sum(axis=0)
    return int(n.sum()), mean, total_m2 / n.sum()


# ---------------------------------------------------------------------- the store
class WindowStore:
    """An opened store: per-take streams on disk, the vocabulary and the build parameters.

    Use :func:`build_store` to make or update one and :meth:`open` to reopen it without an index.

    Attributes
    ----------
    folder : Path
    params : dict
        ``fps``, ``sr``, ``positions``, ``word_rule``, ``mel`` settings, ``subset``.
    takes : list of StoreTake
        In index order.
    vocab : Vocab
        The vocabulary the ``word`` key maps to (default ``corpus_vocab(index)`` at build time).

    Examples
    --------
    >>> from pathlib import Path
    >>> from beatlite.data.examples import example_corpus
    >>> from beatlite.data.index import index_folder
    >>> tmp = example_corpus()  # a test and a train take of data_samples/, copied to a temporary folder
    >>> index = index_folder(tmp.name, cache=False)
    >>> store = build_store(index, Path(tmp.name) / "store")
    >>> len(store), store.n_frames("test")
    (2, 222)
    >>> WindowStore.open(Path(tmp.name) / "store").params == store.params  # reopened without an index
    True
    >>> tmp.cleanup()
    """

    def __init__(self, folder: Path, params: dict[str, Any], takes: list[StoreTake], vocab: Vocab) -> None:
        self.folder = Path(folder)
        self.params = dict(params)
        self.takes = list(takes)
        self.vocab = vocab
        self._by_stem = {t.stem: t for t in self.takes}

    @classmethod
    def open(cls, folder: str | Path) -> WindowStore:
        """Read ``store.json`` and every take's ``meta.json`` (FormatError naming a bad file)."""
        from beatlite.data.vocab import Vocab

        folder = Path(folder)
        path = folder / "store.json"
        if not path.is_file():
            raise FileNotFoundError(
                f"WindowStore.open: {path} does not exist (make the store with build_store)"
            )
        data = _read_json(path)
        _need(data, path, "version", "params", "takes", "vocab")
        if data["version"] != STORE_VERSION:
            raise FormatError(path, f"store version {data['version']}, this beatlite reads {STORE_VERSION}")
        _check_digest(data, path)
        takes = [StoreTake.open(folder / "takes" / stem) for stem in data["takes"]]
        return cls(folder, data["params"], takes, Vocab(data["vocab"]))

    def __len__(self) -> int:
        return len(self.takes)

    def __repr__(self) -> str:
        return f"WindowStore({len(self)} takes, {self.n_frames()} frames at {self.params['fps']:g} fps, {self.folder})"

    def take(self, stem: str) -> StoreTake:
        """The entry of take ``stem``."""
        return self._by_stem[stem]

    def n_frames(self, split: str | None = None) -> int:
        """Frames of the takes of ``split`` (None: all)."""
        return sum(t.n_frames for t in self._select(split))

    def disk_bytes(self) -> int:
        """Bytes of all files of the store."""
        return sum(p.stat().st_size for p in self.folder.rglob("*") if p.is_file())

    def _select(self, split: str | None) -> list[StoreTake]:
        if split not in ("train", "val", "test", None):
            raise ValueError(f"WindowStore: split must be 'train', 'val', 'test' or None, got {split!r}")
        return [t for t in self.takes if split is None or t.meta["split"] == split]

    def windows_fingerprint(
        self, stems: Iterable[str], *, split: str | None, length: int, stride: int, vocab: Vocab
    ) -> str:
        """:func:`beatlite.data.fingerprint.windows_fingerprint` of windows cut from the takes ``stems`` (in this
        store's order; ``length = stride = 0`` for whole takes) with word ids of ``vocab``."""
        from beatlite.data.fingerprint import windows_fingerprint

        chosen = set(stems)
        takes = [t.meta["fingerprint"] for t in self.takes if t.stem in chosen]
        return windows_fingerprint(takes, split=split, length=length, stride=stride, vocab=vocab.itos)

    def statistics(self, split: str = "train") -> Normalizers:
        """The :class:`Normalizers` of ``split`` (pose mean/std, direction mean with std 1), from per-take moments.

        Equal to ``Normalizer.fit`` over all frames of the split up to float rounding
        (``std < MIN_STD`` -> 1, as there).
        """
        takes = self._select(split)
        if not takes:
            raise ValueError(f"WindowStore.statistics: no take of split {split!r} in {self.folder}")
        _, mean, var = _combine([t.meta["pose_moments"] for t in takes], self.folder)
        std = np.sqrt(var)
        pose = Normalizer(mean, np.where(std < MIN_STD, 1.0, std))
        _, dmean, _ = _combine([t.meta["dirs_moments"] for t in takes], self.folder)
        return Normalizers(pose, Normalizer(dmean, np.ones_like(dmean)))

    def windows(
        self,
        split: str | None,
        *,
        length: int = WINDOW_LENGTH,
        stride: int = WINDOW_STRIDE,
        keys: Sequence[str] | None = None,
        stats: Normalizers | None = None,
        vocab: Vocab | None = None,
    ) -> StoreWindows:
        """The windows of ``split`` as an index (take, start) over this store (see :class:`StoreWindows`).

        Parameters
        ----------
        split : {"train", "val", "test"} or None
        length, stride : int
            Window length and hop, frames (34 and 10).
        keys : sequence of str, optional
            Batch keys to read (default: all the store has); e.g. CaMN
            ``("pose", "audio", "face", "word", "emotion", "semantic", "speaker")``.
        stats : Normalizers, optional
            Default: :meth:`statistics` of the train split.
        vocab : Vocab, optional
            Default: the store's vocabulary.
        """
        if stats is None:
            stats = self.statistics("train")
        return StoreWindows(self, split, length=length, stride=stride, keys=keys, stats=stats, vocab=vocab)

    def whole_take(
        self,
        stem: str,
        *,
        keys: Sequence[str] | None = None,
        stats: Normalizers | None = None,
        vocab: Vocab | None = None,
    ) -> dict[str, Any]:
        """One take at full length, as ``build_windows(..., whole_takes=True).item(i)`` (evaluation mode).

        Per-frame keys are (T, ...), ``audio`` (audio_samples(T),), ``mel`` (mel_frames(len(audio)), 128),
        ``speaker``/``start`` scalars, ``take`` the stem.
        """
        take = self.take(stem)
        stats = self.statistics("train") if stats is None else stats
        view = StoreWindows(
            self, None, length=take.n_frames, stride=1, keys=keys, stats=stats, vocab=vocab, stems=(stem,)
        )
        return view.item(0)


class StoreWindows:
    """The windows of one split of a :class:`WindowStore`: an index ``(take, start)`` read at batch time.

    Behaves like :class:`beatlite.data.windows.Windows` in windowed mode: ``len(w)``,
    ``w.keys()``, ``w.batch(indices)`` (the batch contract of ``docs/architecture.md``),
    ``w.item(i)``, ``w.normalizers``, ``w.params``. ``w["pose"]`` reads every
    window of the split into memory (as ``Windows`` holds them); prefer ``batch``.

    ``stems`` restricts the view to these takes (whatever their split).

    Attributes
    ----------
    take_ids : (N,) int64
        Position of each window's take in ``store.takes``.
    starts : (N,) int64
        First frame of each window.

    Examples
    --------
    >>> from pathlib import Path
    >>> from beatlite.data.examples import example_corpus
    >>> from beatlite.data.index import index_folder
    >>> tmp = example_corpus()  # a test and a train take of data_samples/, copied to a temporary folder
    >>> index = index_folder(tmp.name, cache=False)
    >>> windows = build_store(index, Path(tmp.name) / "store").windows("test")
    >>> len(windows)  # 34-frame windows every 10 frames of a 222-frame take
    19
    >>> batch = windows.batch(np.array([0, 5]), keys=("pose", "word"))
    >>> batch["pose"].shape, batch["word"].shape
    ((2, 34, 141), (2, 34))
    >>> tmp.cleanup()
    """

    def __init__(
        self,
        store: WindowStore,
        split: str | None,
        *,
        length: int,
        stride: int,
        keys: Sequence[str] | None,
        stats: Normalizers,
        vocab: Vocab | None,
        stems: Sequence[str] | None = None,
    ) -> None:
        for name, v in (("length", length), ("stride", stride)):
            if not isinstance(v, int | np.integer) or v < 1:
                raise ValueError(f"StoreWindows: {name} must be a positive int, got {v!r}")
        available = [k for k in KEY_STREAM if KEY_STREAM[k] is None or KEY_STREAM[k] in _streams_of(store)]
        self._keys = tuple(available if keys is None else keys)
        unknown = [k for k in self._keys if k not in available]
        if unknown:
            raise KeyError(f"StoreWindows: keys {unknown} not in the store (available: {available})")
        self.store = store
        if not isinstance(stats, Normalizers):
            raise TypeError(f"StoreWindows: stats must be Normalizers, got {type(stats).__name__}")
        self.normalizers = stats
        self.vocab = store.vocab if vocab is None else vocab
        positions = {t.stem: i for i, t in enumerate(store.takes)}
        ids, starts = [], []
        chosen = store._select(split) if stems is None else [store.take(stem) for stem in stems]
        self._stems = [
            t.stem for t in chosen
        ]  # windows or not: a short train take still feeds the statistics
        for t in chosen:
            s = window_starts(t.n_frames, int(length), int(stride))
            ids.append(np.full(len(s), positions[t.stem], np.int64))
            starts.append(s)
        self.take_ids = np.concatenate(ids) if ids else np.zeros(0, np.int64)
        self.starts = np.concatenate(starts) if starts else np.zeros(0, np.int64)
        if len(self.starts) == 0:
            raise ValueError(f"StoreWindows: no take of split {split!r} is at least {length} frames long")
        self.length = int(length)
        fps, sr = store.params["fps"], store.params["sr"]
        self.n_audio = audio_samples(self.length, fps, sr)
        self.n_mel = mel_frames(self.n_audio)
        self.params = {**store.params, "split": split, "length": self.length, "stride": int(stride)}
        self.params.update({"whole_takes": False, "vocab_size": len(self.vocab), "store": str(store.folder)})
        self.whole_takes = False
        self._word_tables: dict[int, np.ndarray] = {}

    @property
    def fingerprint(self) -> str:
        """16 hex digits identifying these windows, the same on every machine and equal to the
        :attr:`Windows.fingerprint <beatlite.data.windows.Windows.fingerprint>` of the same takes and
        parameters (:func:`beatlite.data.fingerprint.windows_fingerprint`: the takes' files by content,
        overrides, store parameters, split, length, stride, vocabulary). What
        :func:`beatlite.train.training.data_fingerprint` reads, so training can resume on the same data.
        The takes are all those of the view, a take shorter than one window too (a train take feeds the
        statistics). The statistics are left out (their float bits vary across machines; they derive from the
        takes)."""
        return self.store.windows_fingerprint(
            self._stems,
            split=self.params["split"],
            length=self.length,
            stride=self.params["stride"],
            vocab=self.vocab,
        )

    # mapping-like access, as Windows -------------------------------------------
    def keys(self) -> list[str]:
        """Batch keys this view reads, in contract order."""
        return [k for k in KEY_STREAM if k in self._keys]

    def __len__(self) -> int:
        return int(len(self.starts))

    def __iter__(self) -> Iterator[str]:
        return iter(self.keys())

    def __contains__(self, key: object) -> bool:
        return key in self._keys

    def __getitem__(self, key: str | int) -> Any:
        """``w["pose"]``: the key for every window (reads them all); ``w[i]``: item ``i``."""
        if isinstance(key, int | np.integer):
            return self.item(int(key))
        return self.batch(None, keys=[key])[key]

    def __repr__(self) -> str:
        return f"StoreWindows({len(self)} windows of {self.length} frames, split={self.params['split']!r}, keys={self.keys()})"

    def item(self, i: int) -> dict[str, Any]:
        """Window ``i`` as a dict (arrays without the leading N axis)."""
        if not -len(self) <= i < len(self):
            raise IndexError(f"StoreWindows.item: index {i} out of range for {len(self)} windows")
        return {k: v[0] for k, v in self.batch([i % len(self)]).items()}

    def _word_table(self, take_id: int) -> np.ndarray:
        """Take-local word id -> vocabulary id (0..3 unchanged)."""
        if take_id not in self._word_tables:
            from beatlite.data.vocab import UNK

            marks = self.store.takes[take_id].meta["word_marks"]
            ids = [self.vocab.get(m, UNK) for m in marks]
            self._word_tables[take_id] = np.array([0, 1, 2, 3, *ids], dtype=np.int64)
        return self._word_tables[take_id]

    def _word_ids(self, take_id: int, local: np.ndarray) -> np.ndarray:
        """Vocabulary ids of take-local word ids (FormatError naming word.npy for an id the take has no mark of)."""
        table = self._word_table(take_id)
        bad = local[(local < 0) | (local >= len(table))]
        if bad.size:
            path = self.store.takes[take_id].folder / "word.npy"
            raise FormatError(path, f"word id {int(bad[0])} outside the take's {len(table)} ids (corrupt)")
        return table[local]

    def batch(
        self, indices: Sequence[int] | np.ndarray | None = None, *, keys: Sequence[str] | None = None
    ) -> dict[str, np.ndarray]:
        """Batch dict (the contract) of the given windows (default all), reading only ``keys``."""
        idx = np.arange(len(self)) if indices is None else np.asarray(indices, dtype=np.int64).reshape(-1)
        if idx.size and (idx.min() < -len(self) or idx.max() >= len(self)):
            raise IndexError(f"StoreWindows.batch: indices out of range for {len(self)} windows")
        idx = idx % max(len(self), 1)
        keys = self.keys() if keys is None else [k for k in KEY_STREAM if k in keys]
        missing = [k for k in (keys or []) if k not in self._keys]
        if missing:
            raise KeyError(f"StoreWindows.batch: keys {missing} not in this view ({self.keys()})")
        raw = self._read(idx, {KEY_STREAM[k] for k in keys} - {None})
        return {k: self._key_values(k, idx, raw) for k in keys}

    def _key_values(self, k: str, idx: np.ndarray, raw: dict[str, np.ndarray]) -> np.ndarray:
        """Batch key ``k`` of the windows ``idx`` from their raw streams (normalised, mapped to the vocabulary)."""
        takes = self.store.takes
        if k == "word":
            rows = [self._word_ids(int(t), w) for t, w in zip(self.take_ids[idx], raw["word"])]
            return np.stack(rows).reshape(len(idx), self.length)
        if k == "speaker":
            return np.array([takes[t].meta["speaker"] for t in self.take_ids[idx]], np.int64)
        if k == "take":
            return np.array([takes[t].stem for t in self.take_ids[idx]])
        if k == "start":
            return self.starts[idx].copy()
        return self._row_values(k, raw[KEY_STREAM[k]])

    def _row_values(self, k: str, rows: np.ndarray) -> np.ndarray:
        """Rows (any leading shape) of the stream of a per-frame key ``k`` other than ``word`` as its batches
        hold them: ``pose`` and ``dirvec`` z-scored with this view's statistics, float32; ``emotion`` int64; the
        other streams float32. Elementwise, so a whole take's rows give its windows' values."""
        if k == "pose":
            return self.normalizers.pose.transform(rows).astype(np.float32)
        if k == "dirvec":
            return self.normalizers.dirvec.transform(rows).astype(np.float32)
        if k == "emotion":
            return rows.astype(np.int64)
        return rows.astype(np.float32, copy=False)

    def _read(self, idx: np.ndarray, streams: set[str]) -> dict[str, np.ndarray]:
        """Rows of ``streams`` for the windows ``idx``: frame streams (B, L, ...), audio (B, n), mel (B, M, 128)."""
        takes = self.store.takes
        fps, sr, hop = self.store.params["fps"], self.store.params["sr"], MEL_SETTINGS["hop_length"]
        out: dict[str, np.ndarray] = {}
        for name in streams:
            shape = tuple(takes[0].meta["shapes"][name][1:])
            if name == "audio":
                out[name] = np.zeros((len(idx), self.n_audio), np.float32)
            elif name == "mel":
                out[name] = np.zeros((len(idx), self.n_mel, *shape), np.float32)
            else:
                out[name] = np.empty(
                    (len(idx), self.length, *shape), np.dtype(STREAMS[name]).newbyteorder("=")
                )
        for b, (t_id, s) in enumerate(zip(self.take_ids[idx], self.starts[idx])):
            take, s = takes[t_id], int(s)
            a0 = audio_start(s, fps, sr)
            for name in streams:
                if name == "audio":
                    q = take.stream("audio").read(a0, a0 + self.n_audio)
                    out[name][b, : len(q)] = q * np.float64(take.meta["audio_scale"])
                elif name == "mel":
                    rows = take.stream("mel").read(a0 // hop, a0 // hop + self.n_mel)
                    out[name][b, : len(rows)] = rows
                    if 0 < len(rows) < self.n_mel:  # as build_windows: repeat the last row
                        out[name][b, len(rows) :] = rows[-1]
                else:
                    out[name][b] = take.stream(name).read(s, s + self.length)
        return out


def _streams_of(store: WindowStore) -> set[str]:
    return set(store.takes[0].meta["shapes"]) if store.takes else set()


# ---------------------------------------------------------------------- building
def store_params(*, fps: float = FPS, sr: int = SR, positions: bool = False, word_rule: str = "span") -> dict:
    """The parameters that decide a store's content (they enter every take's fingerprint).

    Examples
    --------
    >>> params = store_params(fps=30)
    >>> params["fps"], params["sr"], params["word_rule"]
    (30.0, 16000, 'span')
    """
    return {
        "fps": float(fps),
        "sr": int(sr),
        "positions": bool(positions),
        "word_rule": str(word_rule),
        "mel": dict(MEL_SETTINGS),
        "subset": POSE_SUBSET,
    }


def default_store_folder(index: TakeIndex, params: Mapping[str, Any]) -> Path:
    """``cache_dir()/store/{hash of the corpus folder and params}``.

    Examples
    --------
    >>> from beatlite.data.index import TakeIndex
    >>> folder = default_store_folder(TakeIndex([], root="data_samples"), store_params())
    >>> folder.parent.name, len(folder.name)
    ('store', 16)
    """
    from beatlite.paths import cache_dir

    root = index.root if index.root is not None else Path(next(iter(index)).path("motion")).parent
    key = json.dumps({"root": str(Path(root).resolve()), **params}, sort_keys=True)
    return cache_dir() / "store" / hashlib.sha256(key.encode()).hexdigest()[:16]


def _is_current(folder: Path, record: TakeRecord, params: Mapping[str, Any]) -> bool:
    """Whether ``folder`` holds a complete entry of ``record`` built from the same files and parameters, in the
    split the index gives it now (BEAT2's ``train_test_split.csv`` can move a take without changing its files)."""
    try:
        take = StoreTake.open(folder)
        if take.meta["fingerprint"] != take_fingerprint(record, params) or take.meta["split"] != record.split:
            return False
        for name in take.meta["shapes"]:
            take.stream(name)
    except (OSError, FormatError, KeyError):
        return False
    return True


def open_if_current(index: TakeIndex, folder: str | Path, params: Mapping[str, Any]) -> WindowStore | None:
    """The store in ``folder`` opened as it is, if it holds exactly the usable takes of ``index``, every one built
    from the same files and parameters (``params``: :func:`store_params`); else ``None``. Writes nothing (it
    waits while a build of that store is under way).

    Examples
    --------
    >>> from pathlib import Path
    >>> from beatlite.data.examples import example_corpus
    >>> from beatlite.data.index import index_folder
    >>> tmp = example_corpus()  # a test and a train take of data_samples/, copied to a temporary folder
    >>> index = index_folder(tmp.name, cache=False)
    >>> folder = Path(tmp.name) / "store"
    >>> open_if_current(index, folder, store_params()) is None  # not built yet
    True
    >>> _ = build_store(index, folder)
    >>> len(open_if_current(index, folder, store_params()).takes)
    2
    >>> open_if_current(index.where(split="test"), folder, store_params()) is None  # it has another take too
    True
    >>> tmp.cleanup()
    """
    from beatlite.io.atomic import exclusive_lock

    folder = Path(folder)
    records = [r for r in index if r.usable]
    if not (folder / ".build.lock").is_file():
        return None
    with exclusive_lock(folder / ".build.lock"):
        try:
            manifest = _read_json(folder / "store.json")
            _check_digest(manifest, folder / "store.json")
            listed = list(manifest["takes"])
        except (FormatError, KeyError, TypeError):
            return None
        if sorted(listed) != sorted(r.stem for r in records):
            return None
        if not all(_is_current(folder / "takes" / r.stem, r, dict(params)) for r in records):
            return None
        return WindowStore.open(folder)


def _text_fingerprint(index: TakeIndex) -> str:
    """sha256 over (stem, name, content) of every TextGrid of the index (what ``build_vocab`` reads)."""
    from beatlite.data.fingerprint import file_digest

    h = hashlib.sha256()
    for r in index:
        if "text" in r.files:
            h.update(f"{r.stem}|{Path(r.files['text']).name}|{file_digest(r.files['text'])}\n".encode())
    return h.hexdigest()


def _stored_vocab(path: Path, text_fp: str) -> Vocab | None:
    """The vocabulary of an existing ``store.json`` if it was built from the same TextGrids, else None."""
    from beatlite.data.vocab import Vocab

    try:
        data = _read_json(path)
        _check_digest(data, path)
        if data.get("vocab_fingerprint") == text_fp and data.get("version") == STORE_VERSION:
            return Vocab(data["vocab"])
    except (FormatError, KeyError, TypeError, ValueError):
        pass
    return None


def _run_builds(
    todo: list[TakeRecord], folder: Path, params: dict, workers: int | None, progress: bool
) -> None:
    """:func:`build_take` of every record, in ``workers`` spawned processes (in this process for 1)."""
    from concurrent.futures import FIRST_EXCEPTION, ProcessPoolExecutor, wait
    from multiprocessing import get_context

    from beatlite.data.index import default_workers, spawnable
    from beatlite.notebook import progress as progress_bar

    if workers is None:
        workers = default_workers(p for r in todo for p in r.files.values())
    n = spawnable(min(len(todo), workers), "build_store")
    todo = sorted(todo, key=lambda r: -r.duration if r.duration else 0.0)  # long takes first: balance
    with progress_bar(total=len(todo), desc="store takes", unit="take", disable=not progress) as bar:
        if n <= 1:
            for r in todo:
                build_take(r, folder / "takes" / r.stem, params)
                bar.update()
            return
        with ProcessPoolExecutor(n, mp_context=get_context("spawn")) as pool:
            pending = {pool.submit(build_take, r, folder / "takes" / r.stem, params) for r in todo}
            while pending:
                done, pending = wait(pending, return_when=FIRST_EXCEPTION)
                for fut in done:
                    error = fut.exception()  # a reader's FormatError, pickled back from the worker
                    if error is not None:
                        for other in pending:
                            other.cancel()
                        raise error
                    bar.update()


def _usable_records(index: TakeIndex) -> list[TakeRecord]:
    """The usable takes of ``index`` (the others skipped with one warning); ``ValueError`` if none."""
    records = [r for r in index if r.usable]
    skipped = [r.stem for r in index if not r.usable]
    if skipped:
        warnings.warn(f"build_store: skipping {len(skipped)} unusable takes: {skipped[:5]}", stacklevel=3)
    if not records:
        raise ValueError(f"build_store: no usable takes ({len(index)} takes indexed)")
    noted = [
        (r.stem, p.removeprefix("warning: ")) for r in records for p in r.problems if p.startswith("warning:")
    ]
    if noted:  # e.g. a BVH with fewer rows than its header says, read at the rate its audio implies
        stems = sorted({stem for stem, _ in noted})
        warnings.warn(
            f"build_store: {len(stems)} takes are used although their readers warned ({', '.join(stems[:5])}); "
            f"the first: {noted[0][1]}",
            stacklevel=3,
        )
    return records


def _write_manifest(
    folder: Path, index: TakeIndex, records: list[TakeRecord], params: dict, vocab: Vocab | None
) -> None:
    """``store.json``: version, parameters, takes and vocabulary (``build_vocab`` of the stored (usable) takes,
    reused while none of their TextGrids changed; an unusable take's may not read). Not written again when it
    holds that already (a current store on read-only media opens)."""
    from beatlite.data.index import TakeIndex
    from beatlite.data.vocab import corpus_vocab
    from beatlite.io.atomic import atomic_write

    text_fp = None
    if vocab is None:
        stored = TakeIndex(records, index.root)  # the usable takes
        text_fp = _text_fingerprint(stored)
        vocab = _stored_vocab(folder / "store.json", text_fp) or corpus_vocab(stored)
    manifest = {
        "version": STORE_VERSION,
        "params": params,
        "takes": [r.stem for r in records],
        "vocab": list(vocab.itos[_FIRST_LOCAL_WORD:]),
        "vocab_fingerprint": text_fp,
    }
    manifest["digest"] = json_digest(manifest, "digest")
    text = json.dumps(manifest, indent=1)
    with contextlib.suppress(OSError, UnicodeDecodeError):
        if (folder / "store.json").read_text(encoding="utf-8") == text:
            return
    with atomic_write(folder / "store.json") as f:
        f.write(text)


def build_store(
    index: TakeIndex,
    folder: str | Path | None = None,
    *,
    fps: float = FPS,
    sr: int = SR,
    positions: bool = False,
    word_rule: str = "span",
    vocab: Vocab | None = None,
    workers: int | None = None,
    progress: bool = False,
) -> WindowStore:
    """Make or update the window store of every usable take of ``index``; returns it opened.

    Takes whose entry is complete and whose fingerprint (files' content, ``bvh_fps`` override, parameters,
    :data:`STORE_VERSION`) matches are kept; the others are rebuilt; entries of takes no longer
    in the index are removed. A store that is current is opened without writing anything (it may lie on
    read-only media). Memory: one take per worker (plus O(number of takes) meta data).

    Parameters
    ----------
    index : TakeIndex
        The corpus (:func:`beatlite.data.index.index_folder`); unusable takes are skipped with a warning.
    folder : str or Path, optional
        Store folder (default :func:`default_store_folder`, under ``cache_dir()``).
    fps, sr : float, int
        Model frame rate (15) and audio rate (16000 Hz).
    positions : bool
        Also store joint positions (the ``positions`` key).
    word_rule : {"span", "onset", "beat"}
        Word-to-frame rule.
    vocab : Vocab, optional
        Default :func:`beatlite.data.vocab.build_vocab` of the usable takes (the ones stored).
    workers : int, optional
        Worker processes (spawned; 0 or 1: in this process). Default
        :func:`beatlite.data.index.default_workers` of the files to read: ``os.cpu_count()`` for a
        real corpus (a script then needs an ``if __name__ == "__main__":`` guard), 1 for ``data_samples/``.
    progress : bool
        Show a tqdm bar over the takes being built.

    Returns
    -------
    WindowStore

    Raises
    ------
    ValueError
        Bad parameters or no usable take. A take that cannot be read raises its reader's
        ``FormatError``.
    OSError
        A file that cannot be written (a full disk, a read-only folder), naming the store folder or the take's
        entry in it (whose partial files are removed: a later build with space equals a fresh one).

    Examples
    --------
    >>> from pathlib import Path
    >>> from beatlite.data.examples import example_corpus
    >>> from beatlite.data.index import index_folder
    >>> tmp = example_corpus()  # a test and a train take of data_samples/, copied to a temporary folder
    >>> index = index_folder(tmp.name, cache=False)
    >>> store = build_store(index, Path(tmp.name) / "store")
    >>> [t.stem for t in store.takes], len(store.vocab) > 4
    (['2_scott_0_1_1', '2_scott_0_9_9'], True)
    >>> build_store(index, Path(tmp.name) / "store").takes[0].meta == store.takes[0].meta  # unchanged: kept
    True
    >>> tmp.cleanup()
    """
    if not isinstance(sr, int | np.integer) or sr < 1 or not fps > 0:
        raise ValueError(f"build_store: fps and sr must be positive (sr an int), got {fps!r}, {sr!r}")
    if workers is not None and (not isinstance(workers, int) or workers < 0):
        raise ValueError(f"build_store: workers must be a non-negative int or None, got {workers!r}")
    records = _usable_records(index)
    params = store_params(fps=fps, sr=sr, positions=positions, word_rule=word_rule)
    folder = Path(folder) if folder is not None else default_store_folder(index, params)
    from beatlite.io.atomic import exclusive_lock

    with contextlib.ExitStack() as held:
        with _writing(folder):  # other processes building this store wait, then find it current
            (folder / "takes").mkdir(parents=True, exist_ok=True)
            held.enter_context(exclusive_lock(folder / ".build.lock"))
        todo = [r for r in records if not _is_current(folder / "takes" / r.stem, r, params)]
        _run_builds(todo, folder, params, workers, progress)  # (build_take names the entry it cannot write)
        keep = {r.stem for r in records}
        with _writing(folder):
            for stale in (folder / "takes").iterdir():
                if stale.is_dir() and stale.name not in keep:
                    shutil.rmtree(stale)
            _write_manifest(folder, index, records, params, vocab)
        return WindowStore.open(folder)
