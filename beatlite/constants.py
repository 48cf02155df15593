"""The numbers every part of beatlite agrees on: frame rate, sample rate, window length and stride.

One home for them: import these names, never retype the numbers.

>>> from beatlite.constants import FPS, WINDOW_LENGTH, WINDOW_STRIDE
>>> FPS, WINDOW_LENGTH, WINDOW_STRIDE
(15, 34, 10)

==================== ======= ======================================================================
name                 value   meaning
==================== ======= ======================================================================
``FPS``              15      model frame rate, frames per second (BEAT §4 and HA2G §4.1 resample
                             the motion to 15 fps)
``SR``               16000   model audio sample rate, Hz, mono (BEAT §4 "downsample it to 16KHZ")
``WINDOW_LENGTH``    34      frames of one training / evaluation window (BEAT §4: "2f = 34 frames";
                             HA2G §4.1: "34 frames with stride of 10 frames")
``WINDOW_STRIDE``    10      hop between consecutive training windows, frames (HA2G §4.1)
``N_PRE``            4       seed ("pre-pose") frames a model is given before it generates
``GENERATION_STRIDE`` 30     hop between generation units of a whole take (``WINDOW_LENGTH - N_PRE``)
``N_SPEAKERS``       30      size of the speaker embedding (BEAT's 30 speakers; index = id - 1)
==================== ======= ======================================================================

Taught in ``notebooks/01_beat_formats.ipynb`` (frame rates) and ``notebooks/04_metrics.ipynb``
(windows).
"""

from __future__ import annotations

FPS = 15
SR = 16000
WINDOW_LENGTH = 34
WINDOW_STRIDE = 10
N_PRE = 4
GENERATION_STRIDE = WINDOW_LENGTH - N_PRE
N_SPEAKERS = 30

__all__ = ["FPS", "GENERATION_STRIDE", "N_PRE", "N_SPEAKERS", "SR", "WINDOW_LENGTH", "WINDOW_STRIDE"]
