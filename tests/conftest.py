"""Shared pytest fixtures."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
REAL_SAMPLES = Path(os.environ.get("BEATLITE_REAL_SAMPLES", REPO.parent / "shared" / "real_samples"))


@pytest.fixture(scope="session")
def real_samples() -> Path:
    """Folder of real BEAT files (``../shared/real_samples``); skips when absent (a user's fresh clone)."""
    if not REAL_SAMPLES.is_dir():
        pytest.skip(f"real sample files not found at {REAL_SAMPLES} (only present beside the CI checkout)")
    return REAL_SAMPLES


@pytest.fixture(scope="session")
def data_samples() -> Path:
    """The embedded BEAT-format corpus ``data_samples/``."""
    path = REPO / "data_samples"
    if not any(path.glob("*.wav")):
        pytest.fail("data_samples/ holds no takes: run `python -m beatlite.synth --out data_samples`")
    return path
