"""BEAT take names such as ``2_scott_0_1_1`` and what they imply (BEAT §3.1; docs/reference_code.md#take-names, #splits).

``<speaker id>_<speaker name>_<session type>_<start seq>_<end seq>[_a|_b]``:
session types 0..7 are (English, Chinese, Spanish, Japanese) x (speech,
conversation); speech sequence ids imply the emotion; the train/val/test
split is within each speaker, by sequence id.

Taught in notebooks/00_setup_and_tour.ipynb, section 2 (what is in the data folder: take names, emotions, splits) and its Exercises.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

from beatlite.io.errors import FormatError

__all__ = [
    "EMOTIONS",
    "LANGUAGES",
    "SPEAKER_NAMES",
    "FOUR_HOUR_SPEAKERS",
    "SPLITS",
    "TakeName",
    "parse_take_name",
    "split_take_file",
    "emotion_of",
    "split_of",
]

#: Emotion classes 0..7.
EMOTIONS: tuple[str, ...] = (
    "neutral",
    "happiness",
    "anger",
    "sadness",
    "contempt",
    "surprise",
    "fear",
    "disgust",
)
#: Languages by ``session_type // 2``.
LANGUAGES: tuple[str, ...] = ("english", "chinese", "spanish", "japanese")
#: The 30 speakers in id order 1..30 (BEAT's spelling, e.g. ``"tiffnay"``).
SPEAKER_NAMES: tuple[str, ...] = (
    "wayne", "scott", "solomon", "lawrence", "stewart", "carla", "sophie", "catherine", "miranda", "kieks",
    "nidal", "zhao", "lu", "zhang", "carlos", "jorge", "itoi", "daiki", "jaime", "li",
    "ayana", "luqi", "hailing", "kexin", "goto", "reamey", "yingqing", "tiffnay", "hanieh", "katya",
)  # fmt: skip
#: Speakers with 4 hours of data; the other 20 have 1 hour.
FOUR_HOUR_SPEAKERS: tuple[int, ...] = (1, 2, 3, 4, 6, 7, 8, 9, 11, 21)
#: Values of :attr:`TakeName.split`.
SPLITS: tuple[str, ...] = ("train", "val", "test", "test+val", "none")

# first sequence id of each emotional block of speech (65-72 happiness, ..., 111-118 disgust)
_EMOTION_BLOCKS: tuple[tuple[int, int, int], ...] = (
    (65, 72, 1),
    (73, 80, 2),
    (81, 86, 3),
    (87, 94, 4),
    (95, 102, 5),
    (103, 110, 6),
    (111, 118, 7),
)
_MAX_SPEECH = 118
_MAX_CONVERSATION = 12


def emotion_of(sequence: int, conversation: bool = False) -> int:
    """Emotion class implied by a speech sequence id (docs/reference_code.md#take-names): 1-64 neutral, 65-72 happiness, ...

    Conversation is always neutral (0); ids 0 and 1-64 are neutral.

    Examples
    --------
    >>> emotion_of(1), emotion_of(65), emotion_of(65, conversation=True)  # neutral, happiness, conversation
    (0, 1, 0)
    """
    if conversation:
        return 0
    for first, last, emotion in _EMOTION_BLOCKS:
        if first <= sequence <= last:
            return emotion
    return 0


def split_of(speaker_id: int, conversation: bool, sequence: int, half: str | None = None) -> str:
    """Train/val/test split of one sequence (docs/reference_code.md#splits).

    Parameters
    ----------
    speaker_id : int
        1..30.
    conversation : bool
        Conversation (odd session type) rather than speech.
    sequence : int
        Sequence id (1..118 speech, 1..12 conversation).
    half : {"a", "b", None}
        Half of a cut sequence (1-h speakers only).

    Returns
    -------
    str
        ``"train"``, ``"val"``, ``"test"``; ``"test+val"`` for a whole 1-h-speaker
        sequence that BEAT cuts into ``_a`` (test) and ``_b`` (val) halves;
        ``"none"`` for a sequence no split table lists.

    Examples
    --------
    >>> split_of(2, False, 1), split_of(2, False, 66)
    ('test', 'train')
    """
    if speaker_id in FOUR_HOUR_SPEAKERS:
        return _four_hour_conversation(sequence) if conversation else _four_hour_speech(sequence)
    halves = {"a": "test", "b": "val"}.get(half or "", "test+val")  # a 1-hour speaker's cut sequence
    if conversation:
        return _one_hour_conversation(speaker_id, sequence, halves)
    return _one_hour_speech(sequence, halves)


def _four_hour_conversation(sequence: int) -> str:
    if sequence == 1:
        return "test"
    if sequence == 12:
        return "val"
    return "train" if 2 <= sequence <= 11 else "none"


def _four_hour_speech(sequence: int) -> str:
    for first, last, split in ((1, 8, "test"), (9, 56, "train"), (57, 64, "val")):
        if first <= sequence <= last:
            return split
    for first, last, _ in _EMOTION_BLOCKS:
        if sequence == first:
            return "test"
        if sequence == last:
            return "val"
        if first < sequence < last:
            return "train"
    return "none"


def _one_hour_conversation(speaker_id: int, sequence: int, halves: str) -> str:
    if sequence == 1:
        return halves
    if 2 <= sequence <= 3 or (speaker_id == 29 and sequence in (0, 4)):
        return "train"
    return "none"


def _one_hour_speech(sequence: int, halves: str) -> str:
    if sequence in {first for first, _, _ in _EMOTION_BLOCKS}:
        return halves
    if 1 <= sequence <= 4:
        return "test"
    if 5 <= sequence <= 8:
        return "val"
    if 9 <= sequence <= 16 or sequence in (66, 74, 82, 88, 96, 104, 112, 118):
        return "train"
    return "none"


@dataclass(frozen=True)
class TakeName:
    """The fields of a BEAT take name such as ``2_scott_0_1_1``.

    Attributes
    ----------
    speaker_id : int
        1..30 (the loader's speaker index is ``speaker_id - 1``).
    speaker : str
        Speaker name, lower case.
    session_type : int
        0..7: ``language = LANGUAGES[type // 2]``, conversation when odd.
    language : str
        ``"english"``, ``"chinese"``, ``"spanish"`` or ``"japanese"``.
    conversation : bool
        True for conversation sessions.
    start, end : int
        First and last sequence id (equal since BEAT v0.2).
    half : {"a", "b"} or None
        Half of a cut test/val sequence.
    emotion : int
        Class 0..7 implied by the start sequence id (0 for conversation).
    emotion_name : str
        ``EMOTIONS[emotion]``.
    split : str
        One of :data:`SPLITS` (see :func:`split_of`).

    Examples
    --------
    >>> name = parse_take_name("2_scott_0_65_65")
    >>> name.speaker, name.language, name.conversation, name.emotion_name, name.split
    ('scott', 'english', False, 'happiness', 'test')
    """

    speaker_id: int
    speaker: str
    session_type: int
    language: str
    conversation: bool
    start: int
    end: int
    half: str | None
    emotion: int
    emotion_name: str
    split: str

    @property
    def stem(self) -> str:
        """The name again, e.g. ``"2_scott_0_1_1"`` (with ``_a``/``_b`` when cut)."""
        base = f"{self.speaker_id}_{self.speaker}_{self.session_type}_{self.start}_{self.end}"
        return base + (f"_{self.half}" if self.half else "")


def _int_field(path: str, text: str, field: str) -> int:
    """``int(text)`` for 1 to 6 ASCII digits (no superscripts, no 4300-digit numbers)."""
    if not (text.isascii() and text.isdigit() and len(text) <= 6):
        shown = text if len(text) <= 20 else text[:20] + "..."
        raise FormatError(
            path, f"take name {path[:60]!r}: {field} {shown!r} is not a whole number", field=field
        )
    return int(text)


#: A take's file name: its stem, then one of BEAT's extensions or BEAT2's ``npz`` (any case), optionally ``.gz``.
TAKE_FILE = re.compile(
    r"^(?P<stem>.+)\.(?P<ext>bvh|wav|json|textgrid|txt|csv|npz)(?P<gz>\.gz)?$", re.IGNORECASE
)


def split_take_file(name: str | os.PathLike[str]) -> tuple[str, str | None]:
    """The one stem rule of beatlite (index, ``load_take``, names): ``(stem, extension)`` of a file name.

    The stem is everything before a BEAT extension (``bvh wav json TextGrid txt csv``, optionally ``.gz``,
    or BEAT2's ``npz``), dots included; a name without one is all stem (a stem given as such).

    Examples
    --------
    >>> split_take_file("data/2_scott_0_1_1.bvh.gz")
    ('2_scott_0_1_1', 'bvh')
    >>> split_take_file("2_scott_0_1_1.v2.TextGrid")
    ('2_scott_0_1_1.v2', 'textgrid')
    >>> split_take_file("2_scott_0_1_1")
    ('2_scott_0_1_1', None)
    """
    base = Path(name).name
    m = TAKE_FILE.match(base)
    return (m.group("stem"), m.group("ext").lower()) if m else (base, None)


def parse_take_name(name: str | os.PathLike[str]) -> TakeName:
    """Parse a BEAT take name (a stem or a path; a BEAT extension is ignored: :func:`split_take_file`).

    Parameters
    ----------
    name : str or PathLike
        ``"2_scott_0_1_1"``, ``"data/2_scott_0_1_1.bvh.gz"`` or ``"12_zhao_0_65_65_b"``.

    Returns
    -------
    TakeName

    Raises
    ------
    FormatError
        Naming the field that is wrong (``speaker_id``, ``speaker``,
        ``session_type``, ``start``, ``end``, ``half``).

    Examples
    --------
    >>> name = parse_take_name("data/2_scott_0_1_1.bvh.gz")
    >>> name.speaker_id, name.speaker, name.session_type, name.start, name.end, name.half
    (2, 'scott', 0, 1, 1, None)
    >>> name.language, name.conversation, name.emotion_name, name.split
    ('english', False, 'neutral', 'test')
    """
    stem = split_take_file(name)[0]
    parts = stem.split("_")
    half: str | None = None
    if len(parts) == 6:
        half = parts.pop()
        if half not in ("a", "b"):
            raise FormatError(
                str(name), f"take name {stem!r}: half {half!r} must be 'a' or 'b'", field="half"
            )
    if len(parts) != 5:
        raise FormatError(
            str(name),
            f"take name {stem!r} must look like 'id_name_type_start_end[_a|_b]', e.g. '2_scott_0_1_1'",
            field="name",
        )
    speaker_id = _int_field(stem, parts[0], "speaker_id")
    if not 1 <= speaker_id <= len(SPEAKER_NAMES):
        raise FormatError(
            str(name), f"take name {stem!r}: speaker_id {speaker_id} not in 1..30", field="speaker_id"
        )
    speaker = parts[1].lower()
    if speaker != SPEAKER_NAMES[speaker_id - 1]:
        raise FormatError(
            str(name),
            f"take name {stem!r}: speaker {parts[1]!r} does not match id {speaker_id} "
            f"({SPEAKER_NAMES[speaker_id - 1]!r})",
            field="speaker",
        )
    session_type = _int_field(stem, parts[2], "session_type")
    if not 0 <= session_type <= 7:
        raise FormatError(
            str(name), f"take name {stem!r}: session_type {session_type} not in 0..7", field="session_type"
        )
    conversation = session_type % 2 == 1
    start = _int_field(stem, parts[3], "start")
    end = _int_field(stem, parts[4], "end")
    limit = _MAX_CONVERSATION if conversation else _MAX_SPEECH
    if start > limit:
        raise FormatError(str(name), f"take name {stem!r}: start {start} is above {limit}", field="start")
    if not start <= end <= limit:
        raise FormatError(str(name), f"take name {stem!r}: end {end} not in {start}..{limit}", field="end")
    emotion = emotion_of(start, conversation)
    splits = {split_of(speaker_id, conversation, seq, half) for seq in range(start, end + 1)}
    split = splits.pop() if len(splits) == 1 else "none"
    return TakeName(
        speaker_id=speaker_id,
        speaker=speaker,
        session_type=session_type,
        language=LANGUAGES[session_type // 2],
        conversation=conversation,
        start=start,
        end=end,
        half=half,
        emotion=emotion,
        emotion_name=EMOTIONS[emotion],
        split=split,
    )
