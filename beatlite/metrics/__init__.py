"""Evaluation metrics of co-speech gesture synthesis (numpy; torch only in ``extractor``).

==============================  ===================================================================
``fgd``, ``frechet_distance``   Fréchet Gesture Distance on extractor features (BEAT, HA2G)
``srgr``                        Semantic-Relevant Gesture Recall, ``variant="paper"|"reference"``
``beat_align``                  BEAT BeatAlign: audio onsets vs speed minima (sigma 0.3 s)
``beat_consistency``            HA2G Beat Consistency: onsets vs bone-angle-change minima (0.1 s)
``l1_diversity``, ``diversity`` BEAT L1div on poses; HA2G Diversity on features of clip pairs
``pck``, ``mae``, ``mpjpe``     extras, plus ``velocity_stats``, ``acceleration_stats``, ``jerk_stats``, ``speed_histogram``, ``hellinger_distance``
``evaluate``                    the one evaluation path: metrics by name and variant -> ``Evaluation``
``load_extractor``              the shipped FGD feature extractor (imports torch lazily)
==============================  ===================================================================

Taught in notebooks/04_metrics.ipynb (metrics), sections 1-5.
"""

from __future__ import annotations

from typing import Any

from beatlite.metrics.alignment import beat_align
from beatlite.metrics.beats import audio_beats, gaussian_alignment, mean_angle_change
from beatlite.metrics.consistency import beat_consistency
from beatlite.metrics.extras import (
    acceleration_stats,
    hellinger_distance,
    jerk_stats,
    mae,
    mpjpe,
    pck,
    speed_histogram,
    velocity_stats,
)
from beatlite.metrics.frechet import fgd, fit_gaussian, frechet_distance
from beatlite.metrics.recall import srgr
from beatlite.metrics.scoring import METRICS, Evaluation, GroundTruth, MetricResult, Takes, evaluate
from beatlite.metrics.variation import diversity, l1_diversity

__all__ = [
    "METRICS",
    "Evaluation",
    "GroundTruth",
    "Takes",
    "MetricResult",
    "audio_beats",
    "beat_align",
    "beat_consistency",
    "diversity",
    "evaluate",
    "fgd",
    "fit_gaussian",
    "frechet_distance",
    "gaussian_alignment",
    "jerk_stats",
    "l1_diversity",
    "load_extractor",
    "mae",
    "mean_angle_change",
    "mpjpe",
    "pck",
    "srgr",
    "velocity_stats",
    "acceleration_stats",
    "speed_histogram",
    "hellinger_distance",
]


def __getattr__(name: str) -> Any:
    if name == "load_extractor":
        from beatlite.metrics.extractor import load_extractor

        return load_extractor
    raise AttributeError(f"module 'beatlite.metrics' has no attribute {name!r}")
