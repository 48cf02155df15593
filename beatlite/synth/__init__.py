"""The generator of ``data_samples/``: a synthetic, BEAT-format co-speech gesture corpus.

``python -m beatlite.synth --out data_samples [--seed 0] [--fps 30] [--full-rate]``

Takes are spoken word by word with espeak-ng (exact word times), gestured procedurally on the
BEAT skeleton (beats whose stroke ends on word onsets, scripted semantic gestures on keywords,
emotion- and speaker-dependent style) and written in BEAT's formats and names. The generative
rules and every planted effect are described in ``data_samples/README.md``.

Usage (skipped by the doctests: it needs espeak-ng and writes a take under ``out/``):

>>> from beatlite.synth import TakeSpec, generate_take  # doctest: +SKIP
>>> generate_take(TakeSpec(2, 0, 65, 10.0), "out", seed=0)  # doctest: +SKIP

No notebook teaches the generator: notebooks/00_setup_and_tour.ipynb, section 2 introduces the corpus it writes, and ``data_samples/README.md`` describes its rules.
"""

from beatlite.synth.corpus import TakeResult, TakeSpec, corpus_specs, generate_corpus, generate_take
from beatlite.synth.speech import EspeakNotFoundError
from beatlite.synth.styles import (
    EMOTION_NAMES,
    EMOTION_STYLES,
    SEMANTIC_SCORES,
    SPEAKERS,
    EmotionStyle,
    SpeakerStyle,
)

__all__ = [
    "EMOTION_NAMES",
    "EMOTION_STYLES",
    "SEMANTIC_SCORES",
    "SPEAKERS",
    "EmotionStyle",
    "EspeakNotFoundError",
    "SpeakerStyle",
    "TakeResult",
    "TakeSpec",
    "corpus_specs",
    "generate_corpus",
    "generate_take",
]
