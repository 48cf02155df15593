"""BEAT2's SMPL-X motion files (``.npz``) and its split list (``train_test_split.csv``).

One ``.npz`` per take, as PantoMatrix's ``beat_format_save`` writes them (Liu et al., EMAGE, CVPR 2024):

=====================  ==========================  ==================================================
key                    shape, dtype                meaning
=====================  ==========================  ==================================================
``poses``              (T, 165) float32            axis-angle (radians) of the 55 SMPL-X joints
                                                   (:data:`beatlite.skeleton.smplx.SMPLX_JOINTS`),
                                                   each relative to its parent
``trans``              (T, 3) float32              root translation, metres
``betas``              (300,) float32              body shape (the SMPL-X model turns it into a mesh)
``expressions``        (T, 100) float32            FLAME face expression coefficients
``model``              str                         ``"smplx2020"``
``gender``             str                         ``"neutral"``
``mocap_frame_rate``   int                         30
=====================  ==========================  ==================================================

:func:`read_smplx` reads one with ``allow_pickle=False``; every problem (not an npz, a Git-LFS pointer, a
pickled object array, a missing key, a wrong shape, a non-finite value, an unbounded decompression, an array header
claiming more bytes than its member holds) is one
:class:`~beatlite.io.errors.FormatError` naming the file and the key. ``poses``, ``trans`` and
``mocap_frame_rate`` are required (a prediction file needs no more); ``betas`` and ``expressions`` may be absent.
:func:`write_smplx` writes the same layout atomically.

A BEAT2 folder (``beat_english_v2.0.0/``) holds ``smplxflame_30/{take}.npz``, ``wave16k/{take}.wav``,
``textgrid/{take}.TextGrid`` and ``train_test_split.csv`` (:func:`read_beat2_split`); :func:`beatlite.io.load_take`
and :func:`beatlite.data.index_folder` read it (the motion retargeted to BEAT's skeleton,
:func:`beatlite.skeleton.smplx.smplx_to_beat`).

Taught in notebooks/01_beat_formats.ipynb, section 12 (BEAT and BEAT2 side by side: 12.1-12.2 the file and its
165 numbers, 12.4 the face).
"""

from __future__ import annotations

import csv
import dataclasses
import os
import tokenize
import zipfile
from collections.abc import Callable
from pathlib import Path

import numpy as np

from beatlite.io.bvh import FRAME_RATE_RANGE
from beatlite.io.errors import FormatError
from beatlite.io.textfile import ZIP_MEMBER_ERRORS, describe_bytes, npy_header, zip_members

__all__ = ["BEAT2_SPLITS", "SMPLXMotion", "read_beat2_split", "read_smplx", "write_smplx"]

#: The ``type`` values of BEAT2's ``train_test_split.csv``.
BEAT2_SPLITS = ("train", "val", "test", "additional")

_MAX_MEMBER_BYTES = 4 * 2**30  # one array of a 76 h take set at 30 fps is < 200 MB; more is not a BEAT2 file
_STRINGS = ("model", "gender")


@dataclasses.dataclass
class SMPLXMotion:
    """One SMPL-X motion: BEAT2's ``.npz`` in memory.

    Attributes
    ----------
    poses : (T, 55, 3) float64
        Axis-angle rotations in radians, each joint relative to its parent
        (:data:`beatlite.skeleton.smplx.SMPLX_JOINTS` order); given as (T, 165) or (T, 55, 3).
    trans : (T, 3) float64, metres
    fps : float
    betas : (B,) float64 or None
    expressions : (T, E) float64 or None
    model, gender : str
        As the file says (``"smplx2020"``, ``"neutral"`` in BEAT2); ``""`` if absent.

    Raises
    ------
    ValueError
        Naming the field, for what :func:`read_smplx` refuses in a file (so that what :func:`write_smplx` writes
        reads back): another shape, a non-finite value, ``fps`` outside 1..100,000, expressions of another
        length, per-frame ``betas`` that differ (equal ones become one ``(B,)`` row).

    Examples
    --------
    >>> m = SMPLXMotion(np.zeros((30, 55, 3)), np.zeros((30, 3)), fps=30)
    >>> m.n_frames, m.duration, m.to_beat().channels.shape
    (30, 1.0, (30, 228))
    >>> SMPLXMotion(np.zeros((30, 3, 55)), np.zeros((30, 3)), fps=30)  # joints must be the rows
    Traceback (most recent call last):
    ...
    ValueError: SMPLXMotion: poses: expected (T, 165) or (T, 55, 3) numbers, got (30, 3, 55) float64
    """

    poses: np.ndarray
    trans: np.ndarray
    fps: float
    betas: np.ndarray | None = None
    expressions: np.ndarray | None = None
    model: str = ""
    gender: str = ""

    def __post_init__(self) -> None:
        def fail(key: str, message: str) -> ValueError:
            return ValueError(f"SMPLXMotion: {'fps' if key == 'mocap_frame_rate' else key}: {message}")

        checked = _motion_arrays(self.poses, self.trans, self.fps, self.betas, self.expressions, fail)
        self.poses, self.trans, self.fps, self.betas, self.expressions = checked

    @property
    def n_frames(self) -> int:
        """Number of frames T."""
        return int(self.poses.shape[0])

    @property
    def duration(self) -> float:
        """``T / fps`` seconds."""
        return self.n_frames / self.fps

    def positions(self, rest: object | None = None) -> np.ndarray:
        """(T, 55, 3) float64 metres: :func:`beatlite.skeleton.smplx.smplx_forward_kinematics`."""
        from beatlite.skeleton.smplx import smplx_forward_kinematics

        return smplx_forward_kinematics(self.poses, self.trans, rest)  # type: ignore[arg-type]

    def to_beat(self, rest: object | None = None) -> object:
        """The motion on BEAT's skeleton (:func:`beatlite.skeleton.smplx.smplx_to_beat`), a ``Motion``."""
        from beatlite.skeleton.smplx import smplx_to_beat

        return smplx_to_beat(self.poses, self.trans, self.fps, rest)  # type: ignore[arg-type]


def _members(path: Path) -> dict[str, zipfile.ZipInfo]:
    """The ``.npy`` members of an npz, checked for size before anything is decompressed."""
    with open(path, "rb") as f:
        head = f.read(64)
    if not head.startswith(b"PK\x03\x04"):
        raise FormatError(path, f"not an .npz file (a ZIP archive of .npy arrays): {describe_bytes(head)}")
    return zip_members(path, _MAX_MEMBER_BYTES, suffix=".npy")


#: What a damaged member raises while numpy reads it: :data:`~beatlite.io.textfile.ZIP_MEMBER_ERRORS`, and a
#: header numpy's tokenizer cannot read.
_DAMAGED = (*ZIP_MEMBER_ERRORS, tokenize.TokenError)


def _check_header(zf: zipfile.ZipFile, info: zipfile.ZipInfo, path: Path, key: str) -> None:
    """The member's ``.npy`` header, read before numpy reads it (:func:`~beatlite.io.textfile.npy_header`: a shape
    needing more bytes than the member holds, an object dtype). A member that is no ``.npy`` (numpy gives its
    bytes) is left to the checks of its key."""
    try:
        with zf.open(info) as fh:
            if fh.read(len(np.lib.format.MAGIC_PREFIX)) != np.lib.format.MAGIC_PREFIX:
                return
            fh.seek(0)
            npy_header(fh, info.file_size, path, field=key, where="member")
    except _DAMAGED as exc:
        raise FormatError(path, f"not a readable array ({' '.join(str(exc).split())})", field=key) from None


def _array(z: np.lib.npyio.NpzFile, path: Path, key: str) -> np.ndarray:
    try:
        value = z[key]
    except ValueError as exc:  # "Object arrays cannot be loaded when allow_pickle=False"
        if "allow_pickle" in str(exc) or "pickle" in str(exc):
            raise FormatError(
                path, "a pickled object array (never loaded: it could run code)", field=key
            ) from None
        raise FormatError(path, f"not a readable array ({exc})", field=key) from None
    except _DAMAGED as exc:
        raise FormatError(path, f"not a readable array ({exc})", field=key) from None
    return value


def _numeric(
    fail: Callable[[str, str], Exception], key: str, value: np.ndarray, shape: str, ok: bool
) -> np.ndarray:
    if value.dtype.kind not in "fiu" or not ok:
        raise fail(key, f"expected {shape} numbers, got {value.shape} {value.dtype}")
    value = value.astype(np.float64)
    if not np.isfinite(value).all():
        bad = np.argwhere(~np.isfinite(value))[0].tolist()
        raise fail(key, f"non-finite value at index {bad}")
    return value


def _motion_arrays(
    poses: object,
    trans: object,
    fps: object,
    betas: object,
    expressions: object,
    fail: Callable[[str, str], Exception],
) -> tuple[np.ndarray, np.ndarray, float, np.ndarray | None, np.ndarray | None]:
    """The rules of a BEAT2 motion, one set for :func:`read_smplx`, :class:`SMPLXMotion` and :func:`write_smplx`:
    ``(poses (T, 55, 3), trans (T, 3), fps, betas (B,) or None, expressions (T, E) or None)``, float64, or
    ``fail(key, message)`` raised, ``key`` the file's (``"mocap_frame_rate"`` for the rate)."""
    poses, trans, rate = np.asarray(poses), np.asarray(trans), np.asarray(fps)
    n = poses.shape[0] if poses.ndim else 0
    poses = _numeric(fail, "poses", poses, "(T, 165) or (T, 55, 3)", poses.ndim in (2, 3) and n >= 1
                     and poses.shape[1:] in ((165,), (55, 3)))  # fmt: skip
    trans = _numeric(fail, "trans", trans, f"({n}, 3)", trans.shape == (n, 3))
    fps = float(_numeric(fail, "mocap_frame_rate", rate, "a positive scalar", rate.size == 1).ravel()[0])
    low, high = FRAME_RATE_RANGE  # the frame rates a BVH may have
    if not low <= fps <= high:
        raise fail(
            "mocap_frame_rate",
            f"frame rate {fps:g} fps is outside {low:g}..{high:g} fps (as a BVH's frame time)",
        )
    if betas is not None:
        b = np.asarray(betas)
        betas = _numeric(fail, "betas", b, "(B,) or (T, B)", b.ndim in (1, 2) and b.size > 0)
        if betas.ndim == 2:  # per-frame copies of one shape
            if not np.allclose(betas, betas[:1]):
                raise fail("betas", "per-frame betas differ between frames (one body shape expected)")
            betas = betas[0]
    if expressions is not None:
        e = np.asarray(expressions)
        expressions = _numeric(fail, "expressions", e, f"({n}, E)", e.ndim == 2 and e.shape[0] == n)
    return poses.reshape(n, 55, 3), trans, fps, betas, expressions  # type: ignore[return-value]


def read_smplx(path: str | os.PathLike[str]) -> SMPLXMotion:
    """Read a BEAT2 SMPL-X ``.npz`` (see the module docstring for its keys).

    Parameters
    ----------
    path : str or PathLike

    Returns
    -------
    SMPLXMotion
        ``poses`` reshaped to (T, 55, 3), everything float64.

    Raises
    ------
    FormatError
        Naming the file and the key: a missing or misshapen array, non-finite values, a pickled object, a
        member too large, a frame rate outside the range a BVH's frame time may give (1 to 100,000 fps).

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "2_scott_0_1_1.npz"
    >>> write_smplx(path, SMPLXMotion(np.zeros((60, 55, 3)), np.zeros((60, 3)), fps=30, betas=np.zeros(300)))
    >>> m = read_smplx(path)
    >>> m.poses.shape, m.fps, m.betas.shape, m.model
    ((60, 55, 3), 30.0, (300,), 'smplx2020')
    >>> _ = path.write_text("version https://git-lfs.github.com/spec/v1\\noid sha256:0\\nsize 1\\n")
    >>> read_smplx(path)
    Traceback (most recent call last):
    ...
    beatlite.io.errors.FormatError: ...: not an .npz file (a ZIP archive of .npy arrays): a Git-LFS pointer text, not the file content (run `git lfs pull`)
    >>> tmp.cleanup()
    """
    p = Path(path)
    infos = _members(p)
    for key in ("poses", "trans", "mocap_frame_rate"):
        if key not in infos:
            raise FormatError(p, f"no {key!r} array (keys: {', '.join(sorted(infos)) or 'none'})", field=key)
    with zipfile.ZipFile(p) as zf:
        for key, info in infos.items():
            _check_header(zf, info, p, key)
    try:
        z = np.load(p, allow_pickle=False)
    except (*_DAMAGED, ValueError) as exc:
        raise FormatError(p, f"not a readable npz ({exc})") from None
    with z:
        raw = {key: _array(z, p, key) for key in infos}

    def fail(key: str, message: str) -> FormatError:
        return FormatError(p, message, field=key)

    motion = _motion_arrays(raw["poses"], raw["trans"], raw["mocap_frame_rate"], raw.get("betas"),
                            raw.get("expressions"), fail)  # fmt: skip
    strings = {}
    for key in _STRINGS:
        value = raw.get(key, np.array(""))
        if value.dtype.kind not in "US" or value.size != 1:
            raise FormatError(p, f"expected a string, got {value.shape} {value.dtype}", field=key)
        strings[key] = str(value.ravel()[0].decode() if value.dtype.kind == "S" else value.ravel()[0])
    return SMPLXMotion(*motion, **strings)


def write_smplx(path: str | os.PathLike[str], motion: SMPLXMotion) -> None:
    """Write ``motion`` as BEAT2 does (float32 arrays, ``poses`` as (T, 165), the model and gender strings).

    Parameters
    ----------
    path : str or PathLike
        Destination ``.npz``, written atomically (:func:`beatlite.io.atomic.atomic_write`).
    motion : SMPLXMotion
        ``betas`` default ``zeros(300)``, ``expressions`` default ``zeros((T, 100))``, ``model`` default
        ``"smplx2020"``, ``gender`` default ``"neutral"`` (BEAT2's values).

    Raises
    ------
    ValueError
        Before anything is written, for what :func:`read_smplx` would refuse in the file: a value beyond float32
        (it would be written as inf), or a field changed since ``motion`` was made (e.g. ``fps = 0.5``).

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "take.npz"
    >>> write_smplx(path, SMPLXMotion(np.zeros((2, 55, 3)), np.ones((2, 3)), fps=30))
    >>> with np.load(path) as z:
    ...     sorted(z.files), z["poses"].shape, z["poses"].dtype, int(z["mocap_frame_rate"])
    (['betas', 'expressions', 'gender', 'mocap_frame_rate', 'model', 'poses', 'trans'], (2, 165), dtype('float32'), 30)
    >>> write_smplx(path, SMPLXMotion(np.zeros((2, 55, 3)), np.full((2, 3), 1e39), fps=30))  # inf as float32
    Traceback (most recent call last):
    ...
    ValueError: write_smplx: ...take.npz: trans as written (float32): non-finite value at index [0, 0]
    >>> tmp.cleanup()
    """
    from beatlite.io.atomic import atomic_write

    n = motion.n_frames
    arrays = {
        "betas": np.zeros(300) if motion.betas is None else motion.betas,
        "poses": motion.poses.reshape(n, 165),
        "expressions": np.zeros((n, 100)) if motion.expressions is None else motion.expressions,
        "trans": motion.trans,
    }
    with np.errstate(over="ignore"):  # a value beyond float32 becomes inf: refused below
        arrays = {k: np.asarray(v, dtype=np.float32) for k, v in arrays.items()}

    def fail(key: str, message: str) -> ValueError:
        return ValueError(f"write_smplx: {path}: {key} as written (float32): {message}")

    _motion_arrays(arrays["poses"], arrays["trans"], motion.fps, arrays["betas"], arrays["expressions"], fail)
    with atomic_write(path, "wb") as f:  # np.savez writes its ZIP straight into the temporary file
        np.savez(
            f,
            **arrays,
            model=np.array(motion.model or "smplx2020"),
            gender=np.array(motion.gender or "neutral"),
            mocap_frame_rate=np.array(int(motion.fps) if float(motion.fps).is_integer() else motion.fps),
        )


def read_beat2_split(path: str | os.PathLike[str]) -> dict[str, str]:
    """BEAT2's ``train_test_split.csv``: take -> ``"train"``, ``"val"``, ``"test"`` or ``"additional"``.

    Parameters
    ----------
    path : str or PathLike
        A CSV with a header naming the columns ``id`` and ``type`` (others ignored).

    Returns
    -------
    dict str -> str

    Raises
    ------
    FormatError
        Missing columns, an unknown type, or a take listed twice (naming the line).

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "train_test_split.csv"
    >>> _ = path.write_text("id,type\\n2_scott_0_1_1,test\\n2_scott_0_2_2,train\\n")
    >>> read_beat2_split(path)
    {'2_scott_0_1_1': 'test', '2_scott_0_2_2': 'train'}
    >>> tmp.cleanup()
    """
    from beatlite.io.textfile import read_text

    p = Path(path)
    rows = csv.reader(read_text(p).splitlines())
    header = [h.strip() for h in next(rows, [])]
    if "id" not in header or "type" not in header:
        raise FormatError(p, f"the header must name the columns id and type, got {header}", line=1)
    i, t = header.index("id"), header.index("type")
    out: dict[str, str] = {}
    for line, row in enumerate(rows, start=2):
        if not any(c.strip() for c in row):
            continue
        if len(row) <= max(i, t):
            raise FormatError(p, f"{len(row)} columns, the header has {len(header)}", line=line)
        take, kind = row[i].strip(), row[t].strip()
        if kind not in BEAT2_SPLITS:
            raise FormatError(
                p, f"type {kind!r} is not one of {', '.join(BEAT2_SPLITS)}", line=line, field="type"
            )
        if take in out:
            raise FormatError(p, f"take {take} is listed twice", line=line, field="id")
        out[take] = kind
    return out
