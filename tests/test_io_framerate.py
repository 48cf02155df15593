"""Frame rates that lie (issue 14): a 120 fps header over 15 fps rows, a wrong Frame Time, overrides.

The regression take is generated from ``data_samples/`` with beatlite's own writers (no file is copied):
rows decimated to 15 fps under the header a derived BEAT file keeps (``Frames: 8 x rows + 2``,
``Frame Time: 0.008333``). ``load_take``, the index, the windows and the statistics must all agree
on its full duration.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from beatlite.data.index import index_folder
from beatlite.data.windows import build_windows, window_starts
from beatlite.io import (
    BVHWarning,
    Motion,
    load_take,
    read_audio,
    read_bvh,
    read_emotion,
    read_facial,
    read_semantic,
    read_textgrid,
    write_bvh,
    write_emotion,
    write_facial,
    write_semantic,
    write_textgrid,
    write_wav,
)
from beatlite.io.bvh import infer_row_rate
from beatlite.io.take import reconcile_rate
from beatlite.stats.corpus import load_corpus

STEM = "2_scott_0_9_9"  # a train take of data_samples (speech 9-56 of a 4-hour speaker)


def _lying_bvh(path: Path, motion30: Motion) -> int:
    """Write ``motion30`` decimated to 15 fps rows under a 120 fps header; return the row count."""
    rows = Motion(motion30.skeleton, motion30.channels[::2], 15)
    write_bvh(path, rows, precision=3)
    declared = 8 * rows.n_frames + 2  # derived BEAT files: 7669 declared over 957 rows (8 x 957 + 13)
    text = path.read_text(encoding="utf-8")
    text = text.replace(
        f"Frames: {rows.n_frames}\nFrame Time: 0.066667\n", f"Frames: {declared}\nFrame Time: 0.008333\n"
    )
    assert f"Frames: {declared}" in text
    path.write_text(text, encoding="utf-8")
    return rows.n_frames


@pytest.fixture(scope="module")
def lying_take(data_samples: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, int]:
    src, out = data_samples / STEM, tmp_path_factory.mktemp("lying")
    motion = read_bvh(f"{src}.bvh.gz")
    assert motion.fps == 30.0  # data_samples stores 30 fps motion
    n_rows = _lying_bvh(out / f"{STEM}.bvh", motion)
    y, sr = read_audio(f"{src}.wav", sr=None)
    write_wav(out / f"{STEM}.wav", y, sr)
    face = read_facial(f"{src}.json.gz")
    write_facial(out / f"{STEM}.json", face.names, face.weights, times=face.times)
    tiers = read_textgrid(f"{src}.TextGrid")
    xmax = max(iv.end for tier in tiers.values() for iv in tier)
    write_textgrid(out / f"{STEM}.TextGrid", tiers, xmax)
    write_semantic(out / f"{STEM}.txt", read_semantic(f"{src}.txt"))
    write_emotion(out / f"{STEM}.csv", read_emotion(f"{src}.csv"))
    return out, n_rows


def test_read_bvh_infers_the_row_rate_with_one_warning(lying_take: tuple[Path, int]) -> None:
    folder, n_rows = lying_take
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        motion = read_bvh(folder / f"{STEM}.bvh")
    assert [w.category for w in caught] == [BVHWarning]
    message = str(caught[0].message)
    # both readings (15 fps: the full take; 120 fps: an eighth of it) and the override are named
    assert f"{n_rows / 15:.2f} s" in message and f"{n_rows / 120:.2f} s" in message
    assert "fps=120" in message and "bvh_fps=" in message
    assert motion.fps == 15.0 and motion.n_frames == n_rows
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # an override equal to the inferred rate: already resolved, silent
        assert read_bvh(folder / f"{STEM}.bvh", fps=15).n_frames == n_rows
    with pytest.warns(BVHWarning, match="using the .* rows at 120 fps"):
        assert read_bvh(folder / f"{STEM}.bvh", fps=120).fps == 120.0  # the override keeps the header rate


def _bvh_warnings(folder: Path) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        read_bvh(folder / f"{STEM}.bvh")
    return [str(w.message) for w in caught]


def test_load_take_index_windows_and_stats_agree(lying_take: tuple[Path, int], data_samples: Path) -> None:
    folder, n_rows = lying_take
    audio_s = (
        len(read_audio(folder / f"{STEM}.wav", sr=None)[0]) / read_audio(folder / f"{STEM}.wav", sr=None)[1]
    )
    with pytest.warns(BVHWarning):
        take = load_take(folder / STEM)
    # the whole take: every 15 fps row, as long as the audio (within one frame), not 1/8 of it
    assert take.n_frames == n_rows and abs(take.duration - audio_s) <= 1 / 15 + 1e-9
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the index records the readers' warnings instead of emitting them
        index = index_folder(folder)
    record = index[STEM]
    assert record.usable and record.bvh_fps == 15.0
    assert [p for p in record.problems if p.startswith("warning:")] == [
        f"warning: {p}" for p in _bvh_warnings(folder)
    ]
    assert record.durations["motion"] == pytest.approx(n_rows / 15)
    assert abs(record.duration - take.duration) <= 1 / 15 + 1e-9
    expected = len(window_starts(take.n_frames, 34, 10))
    windows = build_windows(index, split="train", cache=False)
    assert len(windows) == expected and set(windows["take"]) == {STEM}
    assert windows["start"].tolist() == window_starts(take.n_frames, 34, 10).tolist()
    (corpus,) = load_corpus(index)
    assert corpus.n_frames == take.n_frames
    # the header's reading would have kept an eighth of the take: no 34-frame window at all
    with pytest.warns(UserWarning):
        wrong = load_take(folder / STEM, bvh_fps=120)
    assert (
        wrong.n_frames == len(range(0, n_rows, 8)) and len(window_starts(wrong.n_frames, 34, 10)) < expected
    )


def test_infer_row_rate_cases() -> None:
    assert infer_row_rate(7669, 120.0, 957) == 15.0  # the file: 7669 = 8 x 957 + 13
    assert infer_row_rate(957, 15.0, 7669) == 120.0  # the other way round
    assert infer_row_rate(240, 120.0, 120) == 60.0
    assert infer_row_rate(100, 120.0, 99) is None  # a truncated file: factor 1
    assert infer_row_rate(5, 120.0, 3) is None  # 5 vs 2 x 3: 20 % off, not a clean factor
    assert infer_row_rate(7669 + 200, 120.0, 957) is None  # 2.6 % off
    assert infer_row_rate(34 * 100, 120.0, 100) is None  # factor 34 > 16
    assert infer_row_rate(32, 4.0, 2) is None  # would be 0.25 fps


def test_reconcile_rate_cases() -> None:
    assert reconcile_rate(240, 24.0, 24.0, 2.0) == 120.0  # 'Frame Time: 0.041667' over 120 fps rows
    assert reconcile_rate(240, 120.0, 120.0, 1.5) is None  # 0.5 s apart: within the 1 s gap, no question
    assert reconcile_rate(240, 120.0, 120.0, None) is None
    assert reconcile_rate(957, 15.0, 120.0, 63.9) is None  # already agrees
    assert reconcile_rate(957, 120.0, 120.0, 63.9) == 15.0
    assert reconcile_rate(1000, 30.0, 30.0, 7.0) is None  # no clean factor gives 7 s


def test_wrong_frame_time_reconciled_by_load_take(tmp_path: Path) -> None:
    from test_io_take import make_take

    stem = make_take(tmp_path, bvh_fps=120, seconds=2.0)
    bvh = Path(f"{stem}.bvh.gz")
    motion = read_bvh(bvh)
    write_bvh(bvh, Motion(motion.skeleton, motion.channels, 24))  # the same rows, 'Frame Time: 0.041667'
    with pytest.warns(BVHWarning, match=r"reading the rows at 120 fps.*bvh_fps="):
        take = load_take(stem)
    assert take.n_frames == 30 and take.motion.channels[:, 0].tolist() == (np.arange(30) * 8).tolist()
    with pytest.warns(UserWarning, match=r"motion read at 24 fps: if that rate is wrong, pass bvh_fps="):
        load_take(stem, bvh_fps=24)  # an override is obeyed (and the truncation warning says what to do)
