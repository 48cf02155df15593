"""Move motion between BEAT and BEAT2: ``python -m beatlite.convert SRC DST``.

=====================================  ==================================================================
``SRC -> DST``                         what happens
=====================================  ==================================================================
``take.bvh[.gz] -> take.npz``          BEAT's skeleton resampled to ``--fps`` (default 30, BEAT2's rate) and
                                       retargeted to SMPL-X (:func:`beatlite.skeleton.smplx.beat_to_smplx`);
                                       the bone-direction errors are reported
``take.npz -> take.bvh``               BEAT2 retargeted to BEAT's skeleton (:func:`~beatlite.skeleton.smplx
                                       .smplx_to_beat`); ``--skeleton smplx`` writes SMPL-X's own skeleton
                                       instead (no retargeting: to open BEAT2 files in Blender)
``BEAT folder -> BEAT2 folder``        :func:`beatlite.data.beat2.write_beat2_folder` (30 fps: ``--fps`` is refused);
                                       each take that is not usable is skipped and named with its problems
=====================================  ==================================================================

``--model SMPLX_NEUTRAL.npz`` (and the file's ``betas``) gives the body's rest skeleton
(:func:`~beatlite.skeleton.smplx.rest_from_model`); without it beatlite's approximation is used
(:func:`~beatlite.skeleton.smplx.approximate_rest`). Every file is written atomically; a bad input is one
``error:`` line and exit code 2.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["convert", "main"]


def _rest(model: str | Path | None, betas: np.ndarray | None = None) -> Any:
    from beatlite.skeleton.smplx import approximate_rest, rest_from_model

    return approximate_rest() if model is None else rest_from_model(model, betas)


def _is_bvh(path: Path) -> bool:
    return path.name.endswith((".bvh", ".bvh.gz"))


def convert(
    src: str | Path,
    dst: str | Path,
    *,
    fps: float = 30.0,
    skeleton: str = "beat",
    model: str | Path | None = None,
) -> dict[str, Any]:
    """Convert one file or a folder (see the module docstring) and say what was lost.

    Parameters
    ----------
    src, dst : str or Path
        ``.bvh``/``.bvh.gz`` <-> ``.npz``, or a BEAT folder -> a BEAT2 folder.
    fps : float
        Frame rate of a written ``.npz``, finite and > 0 (the BVH is resampled; rotations along the shorter
        arc); a folder is written at BEAT2's 30 fps (another ``fps`` is a ``ValueError``).
    skeleton : {"beat", "smplx"}
        The skeleton of a written ``.bvh``.
    model : str or Path, optional
        An SMPL-X model ``.npz`` for the rest skeleton.

    Returns
    -------
    dict
        ``{"frames", "fps", "bone_errors_deg": {bone: (mean, max)}, "no_counterpart": [...]}`` for BVH -> npz
        (the SMPL-X joints without a BEAT joint), ``{"frames", "fps"}`` for npz -> BVH, ``{"takes": [...],
        "skipped": {stem: [problem, ...]}}`` for a folder (the takes written; those not usable, with their problems).

    Examples
    --------
    >>> import tempfile
    >>> from beatlite.paths import repo_root
    >>> tmp = tempfile.TemporaryDirectory()
    >>> report = convert(repo_root() / "data_samples" / "2_scott_0_1_1.bvh.gz", Path(tmp.name) / "t.npz")
    >>> report["frames"], report["fps"], report["no_counterpart"]
    (444, 30.0, ['jaw', 'left_eye_smplhf', 'right_eye_smplhf'])
    >>> max(m for _, m in report["bone_errors_deg"].values()) < 5  # the wrists' other children, in degrees
    True
    >>> convert(Path(tmp.name) / "t.npz", Path(tmp.name) / "t.bvh")
    {'frames': 444, 'fps': 30.0}
    >>> convert(Path(tmp.name) / "t.bvh", Path(tmp.name) / "t0.npz", fps=0)
    Traceback (most recent call last):
    ...
    ValueError: convert: fps must be finite and > 0, got 0
    >>> tmp.cleanup()
    """
    from beatlite.io import FormatError

    src, dst = Path(src), Path(dst)
    if skeleton not in ("beat", "smplx"):
        raise ValueError(f"convert: skeleton must be 'beat' or 'smplx', got {skeleton!r}")
    if not (np.isfinite(fps) and fps > 0):
        raise ValueError(f"convert: fps must be finite and > 0, got {fps!r}")
    if src.is_dir():
        from beatlite.data.beat2 import BEAT2_FPS, write_beat2_folder
        from beatlite.data.index import index_folder

        if fps != BEAT2_FPS:
            raise ValueError(
                f"convert: a folder is written at BEAT2's {BEAT2_FPS} fps; fps={fps!r} is for a file"
            )
        index = index_folder(src)
        skipped = {r.stem: list(r.problems) for r in index if not r.usable}
        return {"takes": write_beat2_folder(src, dst, rest=_rest(model), index=index), "skipped": skipped}
    if _is_bvh(src) and dst.suffix == ".npz":
        return _bvh_to_npz(src, dst, fps, _rest(model))
    if src.suffix == ".npz" and _is_bvh(dst):
        return _npz_to_bvh(src, dst, skeleton, model)
    raise FormatError(
        src, f"cannot convert {src.name} to {dst.name}: give .bvh -> .npz, .npz -> .bvh, or two folders"
    )


def _bvh_to_npz(src: Path, dst: Path, fps: float, rest: Any) -> dict[str, Any]:
    """BEAT BVH -> BEAT2 ``.npz`` at ``fps``, with the bone-direction errors of the retargeting."""
    from beatlite.io import read_bvh
    from beatlite.io.motion import Motion
    from beatlite.io.smplx import SMPLXMotion, write_smplx
    from beatlite.io.take import resample_frames, rotation_columns
    from beatlite.score import beat_channels
    from beatlite.skeleton.beat import beat_skeleton
    from beatlite.skeleton.smplx import BEAT_COUNTERPARTS, SMPLX_JOINTS, beat_to_smplx, bone_direction_errors

    source = read_bvh(src)
    motion = Motion(beat_skeleton(), beat_channels(source, src), source.fps)
    if source.fps != fps:
        channels = resample_frames(motion.channels, source.fps, fps, angle_columns=rotation_columns(motion))
        motion = Motion(motion.skeleton, channels, fps)
    poses, trans = beat_to_smplx(motion, rest)
    write_smplx(dst, SMPLXMotion(poses, trans, fps, betas=np.zeros(300)))
    errors = bone_direction_errors(motion, poses, trans, rest)
    return {
        "frames": motion.n_frames,
        "fps": float(fps),
        "bone_errors_deg": {k: (float(v.mean()), float(v.max())) for k, v in errors.items()},
        "no_counterpart": [n for n in SMPLX_JOINTS if n not in BEAT_COUNTERPARTS],
    }


def _npz_to_bvh(src: Path, dst: Path, skeleton: str, model: str | Path | None) -> dict[str, Any]:
    """BEAT2 ``.npz`` -> BVH of BEAT's skeleton (retargeted) or of SMPL-X's own (``skeleton="smplx"``)."""
    from beatlite.io import write_bvh
    from beatlite.io.smplx import read_smplx
    from beatlite.skeleton.smplx import smplx_skeleton_motion, smplx_to_beat

    smplx = read_smplx(src)
    rest = _rest(model, smplx.betas if model is not None else None)
    to_bvh = smplx_skeleton_motion if skeleton == "smplx" else smplx_to_beat
    write_bvh(dst, to_bvh(smplx.poses, smplx.trans, smplx.fps, rest))  # type: ignore[arg-type]
    return {"frames": smplx.n_frames, "fps": smplx.fps}


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m beatlite.convert", description=__doc__.split("\n")[0])
    p.add_argument("src", help="a .bvh[.gz], a BEAT2 .npz, or a BEAT folder")
    p.add_argument("dst", help="a .npz, a .bvh, or the BEAT2 folder to write")
    p.add_argument(
        "--fps", type=float, help="frame rate of a written .npz file (default 30; a folder is always 30)"
    )
    p.add_argument("--skeleton", choices=("beat", "smplx"), default="beat", help="skeleton of a written .bvh")
    p.add_argument(
        "--model", help="an SMPL-X model .npz for the rest skeleton (default: beatlite's approximation)"
    )
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: 0 on success, 2 when the input cannot be converted (one ``error:`` line).

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments after ``python -m beatlite.convert`` (default: ``sys.argv[1:]``).

    Returns
    -------
    int
        The exit code. On success it prints the file's frames and frame rate (for BVH -> npz also the five
        largest bone-direction errors in degrees), or the takes written and skipped for a folder.

    Examples
    --------
    :func:`convert` shows a conversion; here the two refusals a user meets first, as exit code 2 and one line on
    stderr (captured to show it): a rate for a BVH, which keeps its source's, and a pair of files that are not
    BVH and npz:

    >>> import contextlib, io
    >>> err = io.StringIO()
    >>> with contextlib.redirect_stderr(err):
    ...     main(["data_samples/2_scott_0_1_1.bvh.gz", "out.bvh", "--fps", "60"])
    ...     main(["data_samples/2_scott_0_1_1.wav", "out.npz"])
    2
    2
    >>> print(err.getvalue(), end="")
    error: --fps is the rate of a written .npz; out.bvh keeps its source's rate
    error: data_samples/2_scott_0_1_1.wav: cannot convert 2_scott_0_1_1.wav to out.npz: give .bvh -> .npz, .npz -> .bvh, or two folders
    """
    from beatlite.io import FormatError

    args = _parser().parse_args(argv)
    try:
        if args.fps is not None and _is_bvh(Path(args.dst)):
            raise ValueError(f"--fps is the rate of a written .npz; {args.dst} keeps its source's rate")
        fps = 30.0 if args.fps is None else args.fps
        report = convert(args.src, args.dst, fps=fps, skeleton=args.skeleton, model=args.model)
    except (
        FormatError,
        OSError,
        ValueError,
    ) as exc:  # OSError: a missing file, a folder given as a file, ...
        print(f"error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    if "takes" in report:
        for stem, problems in report["skipped"].items():
            print(f"skipped {stem} (not usable): {'; '.join(problems)}")
        print(f"{len(report['takes'])} takes written to {args.dst}, {len(report['skipped'])} skipped")
    else:
        print(f"{args.dst}: {report['frames']} frames at {report['fps']:g} fps")
    if "bone_errors_deg" in report:
        worst = sorted(report["bone_errors_deg"].items(), key=lambda kv: -kv[1][1])[:5]
        print("bone-direction error after retargeting (degrees, mean / max over frames), the five largest:")
        for bone, (mean, top) in worst:
            print(f"  {bone:32s} {mean:6.2f} / {top:6.2f}")
        print(
            f"SMPL-X joints without a BEAT counterpart (left at rest): {', '.join(report['no_counterpart'])}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
