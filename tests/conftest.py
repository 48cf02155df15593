"""Shared pytest fixtures."""

from __future__ import annotations

import atexit
import os
import shutil
import tempfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
REAL_SAMPLES = Path(os.environ.get("BEATLITE_REAL_SAMPLES", REPO.parent / "shared" / "real_samples"))
# torch.compile's kernels (inductor) are cached in a folder of this test session's own, under this clone's build/,
# for this process and the ones it starts, and removed at its end: not in the machine-wide /tmp/torchinductor_$USER
# nor in a folder a later run reuses, where an entry half-written by a killed process (a 0-byte ``.so``: "file too
# short" at every later compile of that kernel) or by another checkout's code would fail every later run. The tests
# that compile pay for compiling each run, as on a fresh clone of another machine.
if "TORCHINDUCTOR_CACHE_DIR" not in os.environ:
    (REPO / "build").mkdir(exist_ok=True)
    INDUCTOR_CACHE = Path(tempfile.mkdtemp(prefix="torchinductor_", dir=REPO / "build"))
    atexit.register(shutil.rmtree, INDUCTOR_CACHE, True)
    os.environ["TORCHINDUCTOR_CACHE_DIR"] = str(INDUCTOR_CACHE)


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


#: Three train takes of data_samples/ (three speakers): the small corpus of the model contract suite.
SMALL_TAKES = ("2_scott_0_9_9", "4_lawrence_0_11_11", "6_carla_0_13_13")


@pytest.fixture(scope="session")
def small_store_windows(data_samples: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple:
    """A window store of :data:`SMALL_TAKES` (built once per session) and its train windows:
    ``(store view of every key, the same windows from build_windows)``, one statistics and vocabulary."""
    from beatlite.data.index import index_folder
    from beatlite.data.store import build_store
    from beatlite.data.windows import build_windows

    index = index_folder(data_samples).where(stem=list(SMALL_TAKES))
    store = build_store(index, tmp_path_factory.mktemp("small_store"), workers=0)
    reference = build_windows(index, split="train", vocab=store.vocab, cache=False)
    return store.windows("train", stats=reference.normalizers), reference
