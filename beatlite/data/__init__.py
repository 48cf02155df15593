"""Dataset index, vocabulary and aligned training windows (NumPy; torch only in ``torch_dataset``).

=====================  =============================================================
``index``               :func:`index_folder` -> :class:`TakeIndex` of :class:`TakeRecord` (cached: ``index_cache``)
``fingerprint``         one fingerprint of files (content) + overrides + parameters, the same on every machine
``vocab``               :class:`Vocab` (PAD/SOS/EOS/UNK = 0..3), offline word vectors
``normalize``           :class:`Normalizer` (train-split mean/std)
``windows``             :func:`build_windows` -> :class:`Windows` (the batch contract in memory: the teaching view)
``store``               :func:`build_store` -> :class:`WindowStore` (per-take streams on disk, same batches: what
                        training, evaluation and scoring read)
``torch_dataset``       ``WindowDataset``, ``window_loader`` (imports torch; import it explicitly)
=====================  =============================================================

Taught in notebooks/03_audio_and_text_features.ipynb, sections 5-7 (raw wave, words to frames, vocabulary) and notebooks/05_camn.ipynb, section 1 (a batch of training windows).
"""

from __future__ import annotations

from beatlite.data.index import TakeIndex, TakeRecord, index_folder
from beatlite.data.normalize import Normalizer
from beatlite.data.store import StoreWindows, WindowStore, build_store
from beatlite.data.vocab import EOS, PAD, SOS, UNK, Vocab, build_vocab, corpus_vocab, word_vectors
from beatlite.data.windows import WINDOW_KEYS, Windows, build_windows, window_starts

__all__ = [
    "EOS",
    "PAD",
    "SOS",
    "UNK",
    "WINDOW_KEYS",
    "Normalizer",
    "StoreWindows",
    "TakeIndex",
    "TakeRecord",
    "Vocab",
    "WindowStore",
    "Windows",
    "build_store",
    "build_vocab",
    "corpus_vocab",
    "build_windows",
    "index_folder",
    "window_starts",
    "word_vectors",
]
