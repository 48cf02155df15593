"""Readers and writers for every file of a BEAT take.

Every reader accepts ``name.ext`` or ``name.ext.gz``, never writes, and raises
:class:`FormatError` (a ``ValueError``) naming the file and the line, column
or field for a malformed file, and :class:`FormatWarning` for a readable but
inconsistent one. What a reader allocates is bounded by the size of its input.
Every writer is atomic.

==================  ====================================================
``bvh``             :func:`read_bvh`, :func:`write_bvh`, :func:`read_bvh_header`
``audio``           :func:`read_audio`, :func:`audio_info`, :func:`write_wav`
``facial``          :func:`read_facial`, :func:`select_blendshapes`, :func:`write_facial`, :data:`ARKIT_51`
``textgrid``        :func:`read_textgrid`, :func:`read_words`, :func:`words_to_frames`, :func:`write_textgrid`
``semantic``        :func:`read_semantic`, :func:`semantic_to_frames`, :func:`write_semantic`
``emotion``         :func:`read_emotion`, :func:`emotion_to_frames`, :func:`write_emotion`
``names``           :func:`parse_take_name`, :data:`EMOTIONS`, :data:`SPEAKER_NAMES`
``take``            :func:`load_take` -> :class:`Take`
``textfile``        :func:`open_text`, :func:`read_text`, :func:`resolve`
``atomic``          :func:`atomic_write`
==================  ====================================================

Taught in notebooks/01_beat_formats.ipynb (BEAT's file formats), sections 1-11.
"""

from beatlite.io.atomic import atomic_write
from beatlite.io.audio import audio_info, read_audio, write_wav
from beatlite.io.bvh import read_bvh, read_bvh_header, write_bvh
from beatlite.io.emotion import EmotionSegment, emotion_to_frames, read_emotion, write_emotion
from beatlite.io.errors import AlignmentWarning, BVHWarning, FormatError, FormatWarning
from beatlite.io.facial import ARKIT_51, ARKIT_52, Facial, read_facial, select_blendshapes, write_facial
from beatlite.io.motion import Motion
from beatlite.io.names import EMOTIONS, LANGUAGES, SPEAKER_NAMES, TakeName, parse_take_name, split_of
from beatlite.io.semantic import SemanticSegment, read_semantic, semantic_to_frames, write_semantic
from beatlite.io.take import Take, load_take
from beatlite.io.textfile import open_text, read_text, resolve
from beatlite.io.textgrid import (
    Interval,
    WordIntervals,
    read_textgrid,
    read_words,
    words_to_frames,
    write_textgrid,
)

__all__ = [
    "ARKIT_51",
    "ARKIT_52",
    "EMOTIONS",
    "LANGUAGES",
    "SPEAKER_NAMES",
    "AlignmentWarning",
    "BVHWarning",
    "EmotionSegment",
    "Facial",
    "FormatError",
    "FormatWarning",
    "Interval",
    "Motion",
    "SemanticSegment",
    "Take",
    "TakeName",
    "WordIntervals",
    "atomic_write",
    "audio_info",
    "emotion_to_frames",
    "load_take",
    "open_text",
    "parse_take_name",
    "read_audio",
    "read_bvh",
    "read_bvh_header",
    "read_emotion",
    "read_facial",
    "read_semantic",
    "read_text",
    "read_textgrid",
    "read_words",
    "resolve",
    "select_blendshapes",
    "semantic_to_frames",
    "split_of",
    "words_to_frames",
    "write_bvh",
    "write_emotion",
    "write_facial",
    "write_semantic",
    "write_textgrid",
    "write_wav",
]
