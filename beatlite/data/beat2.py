"""Write a BEAT-format folder in BEAT2's layout: the bridge to the format EMAGE and the GENEA Leaderboard use.

:func:`write_beat2_folder` turns every usable take of a BEAT folder (BVH, WAV, TextGrid) into BEAT2's layout
(:mod:`beatlite.io.smplx`): ``smplxflame_30/{stem}.npz`` (the motion at 30 fps retargeted to SMPL-X by
:func:`beatlite.skeleton.smplx.beat_to_smplx`), ``wave16k/{stem}.wav`` (the audio cut to the motion),
``textgrid/{stem}.TextGrid`` and ``train_test_split.csv`` (each take's split). BEAT has no SMPL-X body shape or
FLAME face, so ``betas`` and ``expressions`` are zeros: real BEAT2 files have measured ones.

:func:`beatlite.data.examples.example_beat2_corpus` makes such a copy of the shipped ``data_samples/`` takes.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["BEAT2_FPS", "write_beat2_folder"]

#: BEAT2's frame rate (``mocap_frame_rate``).
BEAT2_FPS = 30


def write_beat2_folder(
    src: str | os.PathLike[str], dst: str | os.PathLike[str], *, rest: object | None = None, index: Any = None
) -> list[str]:
    """Write the usable takes of BEAT folder ``src`` into BEAT2's layout under ``dst``.

    Parameters
    ----------
    src : str or PathLike
        A BEAT-format folder (:func:`beatlite.data.index_folder` reads it; its index cache is used).
    dst : str or PathLike
        The BEAT2 root to create or extend (``smplxflame_30/``, ``wave16k/``, ``textgrid/``,
        ``train_test_split.csv``; every file written atomically). An existing ``train_test_split.csv`` keeps its
        rows; the takes written here replace theirs or are added.
    rest : SMPLXRest, optional
        The SMPL-X body (default :func:`beatlite.skeleton.smplx.approximate_rest`).
    index : TakeIndex, optional
        ``src`` already indexed (default :func:`beatlite.data.index_folder` ``(src)``).

    Returns
    -------
    list of str
        The stems written, in index order.

    Examples
    --------
    >>> import tempfile
    >>> from beatlite.data.examples import example_corpus
    >>> src, dst = example_corpus(), tempfile.TemporaryDirectory()
    >>> write_beat2_folder(src.name, dst.name)
    ['2_scott_0_1_1', '2_scott_0_9_9']
    >>> sorted(p.relative_to(dst.name).as_posix() for p in Path(dst.name).rglob("*_1_1.*"))
    ['smplxflame_30/2_scott_0_1_1.npz', 'textgrid/2_scott_0_1_1.TextGrid', 'wave16k/2_scott_0_1_1.wav']
    >>> src.cleanup(), dst.cleanup()
    (None, None)
    """
    from beatlite.data.index import index_folder
    from beatlite.io import load_take, write_wav
    from beatlite.io.atomic import atomic_write
    from beatlite.io.smplx import SMPLXMotion, read_beat2_split, write_smplx
    from beatlite.skeleton.smplx import beat_to_smplx

    out = Path(dst)
    split_csv = out / "train_test_split.csv"
    splits = (
        read_beat2_split(split_csv) if split_csv.is_file() else {}
    )  # (a bad one: FormatError, nothing written)
    for folder in ("smplxflame_30", "wave16k", "textgrid"):
        (out / folder).mkdir(parents=True, exist_ok=True)
    stems = []
    for record in index_folder(src) if index is None else index:
        if not record.usable:
            continue
        take = load_take(record.path("motion"), fps=BEAT2_FPS, bvh_fps=record.bvh_fps)
        poses, trans = beat_to_smplx(take.motion, rest)  # type: ignore[arg-type]
        motion = SMPLXMotion(poses, trans, BEAT2_FPS, np.zeros(300), np.zeros((take.n_frames, 100)))
        write_smplx(out / "smplxflame_30" / f"{record.stem}.npz", motion)
        if take.audio is not None:
            write_wav(out / "wave16k" / f"{record.stem}.wav", take.audio, take.sr)
        if record.has("text"):
            source = record.path("text")
            with atomic_write(out / "textgrid" / (record.stem + source.name[len(record.stem) :]), "wb") as f:
                with open(source, "rb") as g:
                    shutil.copyfileobj(g, f)
        splits[record.stem] = record.split or "train"
        stems.append(record.stem)
    with atomic_write(split_csv) as f:
        f.write("\n".join(["id,type", *(f"{stem},{split}" for stem, split in splits.items())]) + "\n")
    return stems
