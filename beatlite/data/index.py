"""Index a BEAT-format folder into a table of takes that tells the truth about loading.

A *take* is every file sharing one stem, e.g. ``2_scott_0_1_1.bvh``, ``.wav``,
``.json``, ``.TextGrid``, ``.txt`` and ``.csv`` (each possibly ``.gz``, detected
from the bytes as the readers do). The index works on real BEAT's layout
(``{speaker_id}/{stem}.*``, also nested as ``beat_english_v0.2.1/2/...``), on a
flat folder, and on BEAT2's (``smplxflame_30/{stem}.npz``, ``wave16k/``, ``textgrid/``; the splits from its
``train_test_split.csv``, :func:`beatlite.io.smplx.read_beat2_split`). :attr:`TakeRecord.format` says which
format each take is in.

A take's files are those :func:`beatlite.io.load_take` reads given its motion file
(:func:`beatlite.io.take.take_files`: beside it; a BEAT2 take's audio and TextGrid also in ``wave16k/`` and
``textgrid/`` beside its folder); a file of the take elsewhere is a problem, not used. Every file is checked by
the code :func:`beatlite.io.load_take` runs: the BVH is
read (rows included) at the frame rate loading will use
(:func:`beatlite.io.take.read_take_motion`: clean-factor rates reconciled with the
audio), the WAV header is sniffed and bounded (:func:`beatlite.io.audio.audio_info`,
no samples decoded), the face JSON is mapped to :data:`~beatlite.io.ARKIT_51` by
name, and TextGrid, ``.txt`` and ``.csv`` bodies are parsed (they are small). So
``usable`` implies that ``load_take`` succeeds. Problems (a ``.wav`` without
``.bvh``, a name that does not parse, an unreadable file, modalities whose
durations disagree by more than :data:`MAX_DURATION_GAP` seconds -- the TextGrid
of an ``_a``/``_b`` half is not compared, it spans the whole sequence -- and the
readers' warnings) are recorded in :attr:`TakeRecord.problems`; indexing never
raises for them.

Usage (the doctests skip the last two lines: the path is relative to the repository root):

>>> from beatlite.data.index import index_folder
>>> idx = index_folder("data_samples")  # doctest: +SKIP
>>> print(idx.where(split="test").to_markdown())  # doctest: +SKIP

Taught in notebooks/00_setup_and_tour.ipynb, sections 2 (what is in the data folder) and 4 (running everything on the real BEAT dataset).
"""

from __future__ import annotations

import io
import math
import os
import re
import warnings
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

from beatlite.io.names import split_take_file

#: File extension (lower case, without ``.gz``) -> modality name.
MODALITIES: dict[str, str] = {
    "bvh": "motion",
    "wav": "audio",
    "json": "face",
    "textgrid": "text",
    "txt": "semantic",
    "csv": "emotion",
    "npz": "motion",  # BEAT2's SMPL-X parameters (beatlite.io.smplx)
}
#: Modalities without which a take cannot be used for training.
REQUIRED = ("motion", "audio")
#: Modalities whose durations are compared (seconds).
TIMED = ("motion", "audio", "face", "text")
#: Largest allowed disagreement between two modality durations, seconds.
MAX_DURATION_GAP = 1.0


@dataclass
class TakeRecord:
    """One take of the index: name fields, files, durations and problems.

    Attributes
    ----------
    stem : str
        File name without extensions, e.g. ``"2_scott_0_1_1"``.
    speaker_id : int or None
        BEAT speaker id 1..30 (``None`` when the name does not parse; likewise below).
    speaker : str or None
        Speaker name, e.g. ``"scott"``.
    language : str or None
        ``"english"``, ``"chinese"``, ``"spanish"`` or ``"japanese"`` (as ``parse_take_name`` says).
    session_type : int or None
        BEAT recording type 0..7 (even = speech/self-talk, odd = conversation).
    conversation : bool or None
        True for conversation sessions.
    sequence : int or None
        Sequence id (the name's start field).
    half : str or None
        ``"a"`` / ``"b"`` for the halves of split sequences of the 1-hour speakers, else None.
    emotion : int or None
        Emotion id 0..7 implied by the sequence id.
    emotion_name : str or None
        ``"neutral"``, ``"happiness"``, ...
    split : str or None
        ``"train"``, ``"val"``, ``"test"`` (BEAT's rule) or ``None``; for a take listed in the
        ``train_test_split.csv`` of its BEAT2 root (the nearest folder holding one above its motion file, up to the
        indexed folder), its ``type`` there (also ``"additional"``).
    files : dict str -> Path
        Modality (``"motion"``, ``"audio"``, ``"face"``, ``"text"``, ``"semantic"``,
        ``"emotion"``) -> file path.
    durations : dict str -> float
        Modality -> duration in seconds as loading sees it (motion: rows / the rate
        loading uses; audio: frames / samplerate; face: frames / fps; text: ``xmax``).
    problems : list of str
        Human-readable explanations; empty when the take is consistent. Readers'
        warnings appear as ``"warning: ..."``.
    bvh_fps : float or None
        Rate of the BVH rows to load the take with, when it is not the header's own:
        the override given to :func:`index_folder`, or the rate reconciled from the
        files (e.g. 15 for 15 fps rows under a 120 fps header). Windows and
        statistics pass it to :func:`beatlite.io.load_take`.

    Examples
    --------
    >>> record = TakeRecord("2_scott_0_1_1", speaker_id=2, split="test", durations={"motion": 14.8, "audio": 14.8})
    >>> record.stem, record.split, record.duration
    ('2_scott_0_1_1', 'test', 14.8)
    """

    stem: str
    speaker_id: int | None = None
    speaker: str | None = None
    language: str | None = None
    session_type: int | None = None
    conversation: bool | None = None
    sequence: int | None = None
    half: str | None = None
    emotion: int | None = None
    emotion_name: str | None = None
    split: str | None = None
    files: dict[str, Path] = field(default_factory=dict)
    durations: dict[str, float] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)
    bvh_fps: float | None = None

    @property
    def format(self) -> str:
        """``"beat2"`` when the motion is BEAT2's SMPL-X ``.npz``, else ``"beat"``."""
        motion = self.files.get("motion")
        return "beat2" if motion is not None and motion.name.endswith(".npz") else "beat"

    @property
    def duration(self) -> float:
        """Seconds :func:`beatlite.io.load_take` produces (within one frame at the model rate).

        The shortest of motion, audio and face when the motion duration is known (loading
        cuts to the shortest); else the audio's, face's or TextGrid's; else 0.0.
        """
        if "motion" in self.durations:
            return float(min(self.durations[m] for m in ("motion", "audio", "face") if m in self.durations))
        for modality in ("audio", "face", "text"):
            if modality in self.durations:
                return float(self.durations[modality])
        return 0.0

    @property
    def ok(self) -> bool:
        """True when no problem was found."""
        return not self.problems

    @property
    def usable(self) -> bool:
        """True when the take can feed training windows.

        The name parsed, motion and audio files exist, every file present was read by
        the code :func:`beatlite.io.load_take` runs (or not read: ``read_durations=False``),
        and the timed modalities agree within :data:`MAX_DURATION_GAP`. So a usable take
        loads. Missing optional files (face, text, annotations) are problems but do not
        make a take unusable; an unreadable one does (loading would raise).
        """
        blocking = ("durations disagree", "unreadable")
        return (
            self.speaker_id is not None
            and all(m in self.files for m in REQUIRED)
            and not any(p.startswith(blocking) for p in self.problems)
        )

    def has(self, modality: str) -> bool:
        """Whether the file of ``modality`` (a key of :data:`MODALITIES` values) exists."""
        return modality in self.files

    def path(self, modality: str) -> Path:
        """Path of the ``modality`` file; ``KeyError`` naming the take when absent."""
        try:
            return self.files[modality]
        except KeyError:
            raise KeyError(f"take {self.stem!r} has no {modality} file (has {sorted(self.files)})") from None

    def to_row(self) -> dict[str, Any]:
        """Flat dict of the record (one table row): fields, ``dur_<modality>``, ``has_<modality>``, ``bvh_fps``."""
        row: dict[str, Any] = {
            "stem": self.stem,
            "speaker_id": self.speaker_id,
            "speaker": self.speaker,
            "language": self.language,
            "session_type": self.session_type,
            "sequence": self.sequence,
            "emotion": self.emotion,
            "emotion_name": self.emotion_name,
            "split": self.split,
            "format": self.format,
            "duration": round(self.duration, 3),
        }
        for modality in dict.fromkeys(MODALITIES.values()):
            row[f"has_{modality}"] = modality in self.files
        for modality in TIMED:
            value = self.durations.get(modality)
            row[f"dur_{modality}"] = None if value is None else round(value, 3)
        row["bvh_fps"] = self.bvh_fps
        row["problems"] = "; ".join(self.problems)
        return row


class TakeIndex:
    """An ordered, immutable table of :class:`TakeRecord` rows (no pandas).

    Parameters
    ----------
    records : iterable of TakeRecord
        Rows, kept in the given order.
    root : Path, optional
        Folder the index was built from.

    Examples
    --------
    >>> idx = TakeIndex([TakeRecord("2_scott_0_1_1", speaker_id=2, split="test")])
    >>> len(idx.where(split="test")), len(idx.where(split="train"))
    (1, 0)
    """

    def __init__(self, records: Iterable[TakeRecord], root: str | Path | None = None) -> None:
        self._records = tuple(records)
        for r in self._records:
            if not isinstance(r, TakeRecord):
                raise TypeError(f"TakeIndex: records must be TakeRecord, got {type(r).__name__}")
        self.root = None if root is None else Path(root)

    # -------------------------------------------------------------- container
    def __len__(self) -> int:
        return len(self._records)

    def __iter__(self) -> Iterator[TakeRecord]:
        return iter(self._records)

    def __getitem__(self, key: int | str) -> TakeRecord:
        """Row by position or by stem (``KeyError`` listing close stems)."""
        if isinstance(key, str):
            for r in self._records:
                if r.stem == key:
                    return r
            close = [r.stem for r in self._records if key.split("_")[0] == r.stem.split("_")[0]][:5]
            raise KeyError(f"no take {key!r} in the index; same speaker: {close}")
        return self._records[key]

    def __repr__(self) -> str:
        n_bad = sum(not r.ok for r in self._records)
        return f"TakeIndex({len(self)} takes, {self.total_duration / 60:.1f} min, {n_bad} with problems)"

    @property
    def records(self) -> tuple[TakeRecord, ...]:
        """All rows."""
        return self._records

    @property
    def stems(self) -> list[str]:
        """Stems in row order."""
        return [r.stem for r in self._records]

    @property
    def total_duration(self) -> float:
        """Sum of :attr:`TakeRecord.duration`, seconds."""
        return float(sum(r.duration for r in self._records))

    def speaker_ids(self) -> list[int]:
        """Sorted distinct speaker ids."""
        return sorted({r.speaker_id for r in self._records if r.speaker_id is not None})

    # -------------------------------------------------------------- filtering
    def where(self, **criteria: Any) -> TakeIndex:
        """Rows whose attributes match every criterion.

        Parameters
        ----------
        **criteria
            ``name=value`` for any :class:`TakeRecord` attribute or property
            (``split``, ``speaker_id``, ``emotion``, ``ok``, ``usable``, ...). The
            value may be a scalar (equality), a list/tuple/set (membership) or a
            callable ``value -> bool``.

        Returns
        -------
        TakeIndex
            The matching rows, in order, with the same root.
        """
        for name in criteria:
            if not hasattr(TakeRecord, name) and name not in TakeRecord.__dataclass_fields__:
                raise ValueError(
                    f"where: unknown field {name!r}; fields: {sorted(TakeRecord.__dataclass_fields__)}"
                )

        def match(record: TakeRecord) -> bool:
            for name, wanted in criteria.items():
                value = getattr(record, name)
                if callable(wanted):
                    if not wanted(value):
                        return False
                elif isinstance(wanted, list | tuple | set | frozenset):
                    if value not in wanted:
                        return False
                elif value != wanted:
                    return False
            return True

        return TakeIndex([r for r in self._records if match(r)], self.root)

    def filter(self, predicate: Callable[[TakeRecord], bool]) -> TakeIndex:
        """Rows for which ``predicate(record)`` is true."""
        return TakeIndex([r for r in self._records if predicate(r)], self.root)

    def problems(self) -> dict[str, list[str]]:
        """Stem -> problems, for flagged takes only."""
        return {r.stem: list(r.problems) for r in self._records if r.problems}

    # -------------------------------------------------------------- export
    def to_rows(self) -> list[dict[str, Any]]:
        """One flat dict per take (see :meth:`TakeRecord.to_row`)."""
        return [r.to_row() for r in self._records]

    def to_markdown(self, columns: Iterable[str] | None = None, *, max_rows: int | None = None) -> str:
        """A Markdown table of the index.

        Parameters
        ----------
        columns : iterable of str, optional
            Row keys to show (default: stem, speaker, language, emotion_name, split,
            duration, the ``has_*`` flags as one ``files`` column, problems).
        max_rows : int, optional
            Show at most this many rows and a final ``... (n more)`` line.
        """
        rows = self.to_rows()
        if columns is None:
            columns = [
                "stem",
                "speaker",
                "language",
                "emotion_name",
                "split",
                "duration",
                "files",
                "problems",
            ]
            for row in rows:
                row["files"] = " ".join(
                    ("npz" if m == "motion" and row["format"] == "beat2" else ext)
                    for ext, m in MODALITIES.items()
                    if ext != "npz" and row[f"has_{m}"]
                )
        columns = list(columns)
        if rows and not all(c in rows[0] for c in columns):
            missing = [c for c in columns if c not in rows[0]]
            raise ValueError(f"to_markdown: unknown columns {missing}; available: {sorted(rows[0])}")
        lines = ["| " + " | ".join(columns) + " |", "|" + "|".join("---" for _ in columns) + "|"]
        shown = rows if max_rows is None else rows[:max_rows]
        for row in shown:
            cells = ["" if row[c] is None else str(row[c]).replace("|", "\\|") for c in columns]
            lines.append("| " + " | ".join(cells) + " |")
        if len(shown) < len(rows):
            lines.append(f"... ({len(rows) - len(shown)} more)")
        return "\n".join(lines)


# ---------------------------------------------------------------------- headers
def _open_text(path: Path) -> IO[str]:
    """Text stream of ``path``, gzip detected from the bytes as the readers do."""
    from beatlite.io.textfile import open_binary

    return io.TextIOWrapper(open_binary(path), encoding="utf-8", errors="replace")


def bvh_duration(path: str | Path) -> float:
    """Duration of a BVH file from its header, ``Frames`` x ``Frame Time``, seconds.

    Uses :func:`beatlite.io.read_bvh_header` (reads the HIERARCHY, not the motion rows).
    This is what the header claims; the index itself reports the rows at the rate
    loading uses (:func:`beatlite.io.take.read_take_motion`), which differs for files
    whose ``Frame Time`` or ``Frames`` is wrong (docs/reference_code.md#bvh-header).

    Examples
    --------
    >>> from beatlite.paths import repo_root
    >>> round(bvh_duration(repo_root() / "data_samples" / "2_scott_0_1_1.bvh.gz"), 3)  # Frames x Frame Time
    14.8
    """
    from beatlite.io import read_bvh_header

    _, n_frames, frame_time = read_bvh_header(path)
    return float(n_frames) * float(frame_time)


def wav_duration(path: str | Path) -> float:
    """Duration of a WAV (or gzipped WAV) file from its header, seconds.

    Checked exactly as :func:`beatlite.io.read_audio` checks it (:func:`beatlite.io.audio.audio_info`:
    sniffed bytes, bounded rate, channels and size), decoding no samples.

    Examples
    --------
    >>> from beatlite.paths import repo_root
    >>> wav_duration(repo_root() / "data_samples" / "2_scott_0_1_1.wav")
    14.8
    """
    from beatlite.io.audio import audio_info

    return float(audio_info(path).duration)


def face_duration(path: str | Path) -> float:
    """Duration of a BEAT facial JSON as :func:`beatlite.io.read_facial` reads it: frames / fps, seconds.

    The fps comes from the median spacing of the frames' ``time`` values (60 in BEAT).

    Examples
    --------
    >>> from beatlite.paths import repo_root
    >>> round(face_duration(repo_root() / "data_samples" / "2_scott_0_1_1.json.gz"), 3)
    14.8
    """
    from beatlite.io import read_facial

    facial = read_facial(path)
    return facial.n_frames / facial.fps


_XMAX = re.compile(r"^\s*xmax\s*=\s*([-+0-9.eE]+)")


def textgrid_duration(path: str | Path) -> float:
    """The ``xmax`` of a Praat TextGrid (long or short text format), seconds.

    Examples
    --------
    >>> from beatlite.paths import repo_root
    >>> textgrid_duration(repo_root() / "data_samples" / "2_scott_0_1_1.TextGrid")
    14.8
    """
    from beatlite.io.errors import FormatError

    path = Path(path)
    with _open_text(path) as f:
        head = [line for _, line in zip(range(12), f)]
    if "textgrid" not in "".join(head[:2]).lower():
        raise FormatError(path, "not a TextGrid (no 'Object class = \"TextGrid\"' line)", line=2)
    for lineno, line in enumerate(head, start=1):
        m = _XMAX.match(line)
        if m:
            return _finite_xmax(path, m.group(1), lineno)
    # short format: File type, Object class, blank, xmin, xmax
    numbers = [
        (lineno, line.strip())
        for lineno, line in enumerate(head, start=1)
        if lineno > 1 and line.strip() and not line.strip().startswith(("Object", '"'))
    ]
    if len(numbers) < 2:
        raise FormatError(path, "no xmax in the first lines", field="xmax")
    return _finite_xmax(path, numbers[1][1], numbers[1][0])


def _finite_xmax(path: Path, text: str, line: int) -> float:
    """``float(text)``, or a :class:`FormatError` naming the line for text that is no finite number."""
    from beatlite.io.errors import FormatError

    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise FormatError(path, f"xmax {text!r} is not a finite number of seconds", line=line, field="xmax")
    return value


def _check_face(path: Path) -> float:
    from beatlite.io import ARKIT_51, read_facial

    facial = read_facial(path, names=ARKIT_51)  # as load_take reads it
    return facial.n_frames / facial.fps


def _check_text(path: Path) -> float:
    from beatlite.io.take import read_take_words

    return float(read_take_words(path).xmax or 0.0)


def _check_semantic(path: Path) -> None:
    from beatlite.io import read_semantic

    read_semantic(path)


def _check_emotion(path: Path) -> None:
    from beatlite.io import read_emotion

    read_emotion(path)


#: Modality -> the check load_take's reader makes, returning the duration (None: untimed).
_CHECKS: dict[str, Callable[[Path], float | None]] = {
    "audio": wav_duration,
    "face": _check_face,
    "text": _check_text,
    "semantic": _check_semantic,
    "emotion": _check_emotion,
}


# ---------------------------------------------------------------------- index
def _scan(root: Path, recursive: bool) -> dict[str, dict[str, list[Path]]]:
    """stem -> modality -> paths (sorted: BEAT's ``.bvh[.gz]`` before an ``.npz``, as :func:`beatlite.io.take.take_files`
    prefers it; plain files before ``.gz``)."""
    found: dict[str, dict[str, list[Path]]] = {}
    if recursive:
        walker = (
            (Path(d), files)
            for d, dirs, files in os.walk(root)
            if not any(part.startswith(".") for part in Path(d).relative_to(root).parts)
        )
    else:
        walker = iter([(root, [p.name for p in root.iterdir() if p.is_file()])])
    for folder, names in walker:
        for name in names:
            stem, ext = split_take_file(name)
            if ext is None or name.startswith(".") or name == "train_test_split.csv":  # BEAT2's split list
                continue
            found.setdefault(stem, {}).setdefault(MODALITIES[ext], []).append(folder / name)
    for by_modality in found.values():
        for paths in by_modality.values():
            paths.sort(key=lambda p: (split_take_file(p.name)[1] == "npz", p.suffix.lower() == ".gz", str(p)))
    return found


def _name_fields(stem: str) -> tuple[dict[str, Any], str | None]:
    """Parsed name fields for a TakeRecord, or ({}, problem)."""
    from beatlite.io.names import parse_take_name

    try:
        name = parse_take_name(stem)
    except (ValueError, KeyError, IndexError) as e:
        return {}, f"bad name: {e}"
    fields = {
        "speaker_id": int(name.speaker_id),
        "speaker": name.speaker,
        "language": name.language,
        "session_type": int(name.session_type),
        "conversation": bool(name.conversation),
        "sequence": int(name.start),
        "half": name.half,
        "emotion": None if name.emotion is None else int(name.emotion),
        "emotion_name": name.emotion_name,
        "split": name.split,
    }
    return fields, None


def _loaded_files(files: dict[str, list[Path]]) -> dict[str, Path]:
    """Modality -> the file :func:`beatlite.io.load_take` reads for the take of this motion file
    (:func:`beatlite.io.take.take_files`); ``{}`` without a motion file."""
    from beatlite.io.take import take_files

    if "motion" not in files:
        return {}
    try:
        _, paths = take_files(files["motion"][0])
    except FileNotFoundError:  # removed since the scan
        return {}
    return {MODALITIES[ext[1:].lower()]: path for ext, path in paths.items()}


def _list_files(record: TakeRecord, files: dict[str, list[Path]]) -> None:
    """Fill ``record.files`` with the files loading reads; duplicates, files loading would not find and missing
    files become problems."""
    from beatlite.io.take import BEAT2_FOLDERS

    loaded = _loaded_files(files)
    for modality, paths in files.items():
        if loaded and modality not in loaded:
            where = "beside the motion file"
            folder = {MODALITIES[e[1:].lower()]: f for e, f in BEAT2_FOLDERS.items()}.get(modality)
            if folder and files["motion"][0].name.endswith(".npz"):
                where += f" or in {folder}/ beside its folder"
            record.problems.append(
                f"{modality} file {paths[0]} is not {where}, where load_take looks: not used"
            )
            continue
        if loaded:
            paths = [loaded[modality], *(p for p in paths if p != loaded[modality])]
        record.files[modality] = paths[0]
        if len(paths) > 1:
            others = ", ".join(str(p) for p in paths[1:])
            record.problems.append(f"duplicate {modality} files: using {paths[0]}, ignoring {others}")
    for ext, modality in MODALITIES.items():
        if ext == "npz" or (modality == "face" and record.format == "beat2"):  # BEAT2's face is in its .npz
            continue
        if modality not in record.files:
            shown = "TextGrid" if ext == "textgrid" else ("bvh or .npz" if ext == "bvh" else ext)
            record.problems.append(f"missing {modality} (.{shown}) file")


def _check_motion(record: TakeRecord, bvh_fps: float | None) -> None:
    """Read the BVH as load_take will (rate reconciled with the other files); set duration and ``bvh_fps``."""
    from beatlite.io.bvh import parse_frame_time, read_bvh_header
    from beatlite.io.take import read_take_motion, reference_duration

    path = record.files["motion"]
    reference = reference_duration(record.durations, record.half)
    motion = read_take_motion(path, bvh_fps=bvh_fps, reference_s=reference)
    record.durations["motion"] = motion.duration
    _check_skeleton(motion)
    if record.format == "beat2":  # the .npz states its rate
        record.bvh_fps = None if bvh_fps is None else motion.fps
        return
    # with an override the header's Frame Time is not read (it may be the wrong value the override replaces)
    if bvh_fps is not None or motion.fps != parse_frame_time(repr(read_bvh_header(path)[2])):
        record.bvh_fps = motion.fps


def _check_skeleton(motion: Any) -> None:
    """Run, on the first frame, the skeleton code every window build runs (the ``spine_neck_141`` columns and the
    TED-43 joints), so that a BVH of another skeleton under a BEAT name is unusable with the joint it lacks."""
    from beatlite.data.windows import POSE_SUBSET
    from beatlite.skeleton.beat import subset_columns
    from beatlite.skeleton.ted import beat_to_ted43

    try:
        subset_columns(motion.skeleton, POSE_SUBSET)
        beat_to_ted43(motion.skeleton, motion.channels[:1])
    except (KeyError, ValueError) as exc:
        raise ValueError(f"not BEAT's skeleton: {str(exc).strip(chr(34))}") from None


def _check_files(record: TakeRecord, bvh_fps: float | None) -> None:
    """Run every reader load_take runs; failures are ``unreadable`` problems, warnings ``warning:`` notes."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for modality, check in [*_CHECKS.items(), ("motion", None)]:
            if modality not in record.files:
                continue
            try:
                if check is None:
                    _check_motion(record, bvh_fps)
                elif (seconds := check(record.files[modality])) is not None:
                    record.durations[modality] = float(seconds)
            except Exception as e:  # noqa: BLE001 - any unreadable file becomes a problem, never a crash
                record.problems.append(f"unreadable {modality} file {record.files[modality].name}: {e}")
    from beatlite.io.errors import AlignmentWarning, FormatWarning

    for w in caught:
        if issubclass(w.category, (FormatWarning, AlignmentWarning)):
            record.problems.append(f"warning: {w.message}")
        else:  # not about the files (e.g. a library's deprecation): pass it on
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def index_take(
    stem: str, files: dict[str, list[Path]], *, read_durations: bool = True, bvh_fps: float | None = None
) -> TakeRecord:
    """Build the :class:`TakeRecord` of one take from its files; never raises for bad files.

    Parameters
    ----------
    stem : str
        Take name without extensions.
    files : dict str -> list of Path
        Modality -> candidate files. The ones :func:`beatlite.io.load_take` reads given the motion file
        (:func:`beatlite.io.take.take_files`: beside it, BEAT2's audio and TextGrid also in ``wave16k/`` and
        ``textgrid/`` beside its folder) are used, the rest flagged as duplicates; a modality whose files
        loading would not find is a problem (without motion: the first of each is used).
    read_durations : bool
        Read every file as loading would (default True); False lists files only.
    bvh_fps : float, optional
        Rate of the BVH rows (an override, kept in :attr:`TakeRecord.bvh_fps`).

    Examples
    --------
    >>> from beatlite.paths import repo_root
    >>> folder = repo_root() / "data_samples"
    >>> files = {"motion": [folder / "2_scott_0_1_1.bvh.gz"], "audio": [folder / "2_scott_0_1_1.wav"]}
    >>> record = index_take("2_scott_0_1_1", files)
    >>> record.speaker, record.split, record.usable, sorted(record.durations)
    ('scott', 'test', True, ['audio', 'motion'])
    """
    fields, problem = _name_fields(stem)
    record = TakeRecord(stem=stem, **fields)
    if problem:
        record.problems.append(problem)
    _list_files(record, files)
    if bvh_fps is not None:
        record.bvh_fps = float(bvh_fps)
    if read_durations:
        _check_files(record, bvh_fps)
        # the TextGrid of an "_a"/"_b" half spans the whole sequence (docs/reference_code.md#textgrid): not compared
        compared = {m: d for m, d in record.durations.items() if not (m == "text" and record.half)}
        if len(compared) >= 2 and max(compared.values()) - min(compared.values()) > MAX_DURATION_GAP:
            listing = ", ".join(f"{m} {d:.2f} s" for m, d in compared.items())
            record.problems.append(f"durations disagree by more than {MAX_DURATION_GAP:g} s: {listing}")
    return record


def _sort_key(record: TakeRecord) -> tuple:
    return (
        record.speaker_id is None,
        record.speaker_id or 0,
        record.session_type or 0,
        record.sequence or 0,
        record.stem,
    )


def index_folder(
    root: str | Path | None = None,
    *,
    recursive: bool = True,
    read_durations: bool = True,
    bvh_fps: Mapping[str, float] | None = None,
    cache: bool = True,
    workers: int | None = None,
) -> TakeIndex:
    """Index every take under ``root``; takes whose files did not change come from the cache.

    Parameters
    ----------
    root : str or Path, optional
        A BEAT-format folder: flat, ``{speaker_id}/{stem}.*`` or nested deeper
        (default :func:`beatlite.paths.data_dir`). Hidden folders are skipped.
    recursive : bool
        Walk sub-folders (default True).
    read_durations : bool
        Read every file as :func:`beatlite.io.load_take` would (default True: the BVH
        rows, the WAV header, the face JSON, TextGrid and annotation bodies), so that
        ``usable`` means loadable; False lists files only, which is instant.
    bvh_fps : Mapping[str, float], optional
        Per-take overrides of the BVH row rate, stem -> fps (e.g. ``{"29_hanieh_1_4_4":
        120}``); stored in :attr:`TakeRecord.bvh_fps` and used by windows and statistics.
    cache : bool
        Reuse and update the index cache (:mod:`beatlite.data.index_cache`, under
        ``cache_dir()/index/``): a take is read again only when one of its files or its override
        changed (default True; only with ``read_durations``).
    workers : int, optional
        Processes that index the takes not in the cache (spawned; 0 or 1: this process). Default
        :func:`default_workers` of their files.

    Returns
    -------
    TakeIndex
        One :class:`TakeRecord` per stem that has at least one BEAT file
        (``.bvh .wav .json .TextGrid .txt .csv``, optionally ``.gz``), sorted by
        speaker id, session type, sequence, stem; takes with bad names last.

    Raises
    ------
    FileNotFoundError
        If ``root`` is not a folder.

    Examples
    --------
    >>> from beatlite.data.examples import example_corpus
    >>> from beatlite.data.index import index_folder
    >>> tmp = example_corpus()  # a test and a train take of data_samples/, copied to a temporary folder
    >>> index = index_folder(tmp.name, cache=False)
    >>> index.stems, [r.split for r in index], all(r.usable for r in index)
    (['2_scott_0_1_1', '2_scott_0_9_9'], ['test', 'train'], True)
    >>> tmp.cleanup()
    """
    from beatlite.paths import data_dir

    root = data_dir() if root is None else Path(root)
    if not root.is_dir():
        raise FileNotFoundError(f"index_folder: {root} is not a folder")
    found = _scan(root, recursive)
    overrides = dict(bvh_fps or {})
    unknown = sorted(set(overrides) - set(found))
    if unknown:
        raise ValueError(f"index_folder: bvh_fps names takes that are not in {root}: {unknown[:5]}")
    if not (cache and read_durations):
        records = [
            index_take(s, f, read_durations=read_durations, bvh_fps=overrides.get(s))
            for s, f in found.items()
        ]
    else:
        records = _index_with_cache(root, recursive, found, overrides, workers)
    _beat2_splits(root, records)
    records.sort(key=_sort_key)
    return TakeIndex(records, root)


def _beat2_splits(root: Path, records: list[TakeRecord]) -> None:
    """Splits from BEAT2's ``train_test_split.csv`` over the name rule's: for each take, the list of its BEAT2 root,
    the nearest folder holding one above its (motion) file, up to ``root`` (a BEAT2 root may be nested in it)."""
    from beatlite.io.smplx import read_beat2_split

    lists: dict[Path, dict[str, str] | None] = {}

    def split_list(folder: Path) -> dict[str, str] | None:
        if folder not in lists:
            path = folder / "train_test_split.csv"
            lists[folder] = read_beat2_split(path) if path.is_file() else None
        return lists[folder]

    for record in records:
        file = record.files.get("motion") or next(iter(record.files.values()), None)
        folders = [] if file is None else list(file.parents)
        for folder in folders[: folders.index(root) + 1] if root in folders else [root]:
            listed = split_list(folder)
            if listed is not None:
                if record.stem in listed:
                    record.split = listed[record.stem]
                break


def _index_with_cache(
    root: Path, recursive: bool, found: dict[str, dict[str, list[Path]]], overrides: dict, workers: int | None
) -> list[TakeRecord]:
    """Records of ``found``: cached ones whose key matches, the others indexed (in parallel) and cached."""
    from beatlite.data import index_cache

    path = index_cache.cache_path(root, recursive)
    old = index_cache.load(path)
    keys = {stem: index_cache.take_key(files, overrides.get(stem)) for stem, files in found.items()}
    records = {stem: index_cache.cached_record(old.get(stem), keys[stem]) for stem in found}
    todo = [stem for stem, record in records.items() if record is None]
    for record in _index_many([(s, found[s], overrides.get(s)) for s in todo], workers):
        records[record.stem] = record  # its files' digests were computed beside it, and remembered
    new = {s: index_cache.entry(records[s], keys[s]) if s in todo else old[s] for s in found if keys[s]}
    if todo or set(new) != set(old):
        index_cache.save(path, new)
    return list(records.values())


#: Bytes of files to read above which ``index_folder`` and ``build_store`` use worker processes by default.
PARALLEL_BYTES = 256 * 2**20


def default_workers(paths: Iterable[Path]) -> int:
    """Worker processes for reading ``paths``: ``os.cpu_count()`` when they exceed :data:`PARALLEL_BYTES`,
    else 1 (spawning costs about a second per process, and a script that spawns needs an
    ``if __name__ == "__main__":`` guard: small corpora such as ``data_samples/`` need neither).

    Examples
    --------
    >>> from beatlite.paths import repo_root
    >>> default_workers((repo_root() / "data_samples").glob("*.wav"))  # a small corpus: no worker processes
    1
    """
    size = sum(Path(p).stat().st_size for p in paths)
    return (os.cpu_count() or 1) if size > PARALLEL_BYTES else 1


def spawnable(workers: int, what: str) -> int:
    """``workers``, or 1 with a warning when spawned processes cannot start here: spawning re-runs the main
    script from its file, so a script read from standard input (``python - <<EOF``, ``__main__.__file__``
    ``"<stdin>"``) would fail in every worker (``BrokenProcessPool``); ``what`` names the work in the warning.

    Examples
    --------
    >>> spawnable(1, "indexing")
    1
    """
    import sys
    import warnings

    main = getattr(sys.modules.get("__main__"), "__file__", None)
    if workers > 1 and main is not None and not Path(main).is_file():
        warnings.warn(
            f"{what}: the main script {main!r} is not a file, so worker processes cannot be spawned; "
            "working in this process (run a script file, or pass workers=0)",
            RuntimeWarning,
            stacklevel=2,
        )
        return 1
    return workers


def _index_many(
    jobs: list[tuple[str, dict[str, list[Path]], float | None]], workers: int | None
) -> list[TakeRecord]:
    """:func:`index_take` of every (stem, files, bvh_fps) job and its files' digests (remembered by
    :func:`beatlite.data.fingerprint.file_digest`), in ``workers`` spawned processes if > 1."""
    from beatlite.data.fingerprint import file_key, remember_digest

    if workers is None:
        workers = default_workers(p for _, files, _ in jobs for paths in files.values() for p in paths)
    n = spawnable(min(workers, len(jobs)), "index_folder")
    if n <= 1:
        done = [_index_take_job(job) for job in jobs]
    else:
        from concurrent.futures import ProcessPoolExecutor
        from multiprocessing import get_context

        with ProcessPoolExecutor(n, mp_context=get_context("spawn")) as pool:
            done = list(pool.map(_index_take_job, jobs, chunksize=4))
    for record, digests in done:
        for modality, digest in digests.items():
            remember_digest(file_key(record.files[modality]), digest)
    return [record for record, _ in done]


def _index_take_job(
    job: tuple[str, dict[str, list[Path]], float | None],
) -> tuple[TakeRecord, dict[str, str]]:
    """:func:`index_take` and the content digest of each file it uses (run in a worker process)."""
    from beatlite.data.fingerprint import file_digest

    stem, files, fps = job
    record = index_take(stem, files, bvh_fps=fps)
    return record, {m: file_digest(p) for m, p in record.files.items()}
