"""Opening text files that may be gzipped, finding ``x.ext`` or ``x.ext.gz``, and sniffing bytes.

Every reader of :mod:`beatlite.io` goes through these helpers, so ``take.bvh``
and ``take.bvh.gz`` are read the same way.

Used in notebooks/01_beat_formats.ipynb, section 2 (``read_text`` prints the raw BVH header).
"""

from __future__ import annotations

import gzip
import io
import math
import os
import tokenize
import zipfile
import zlib
from pathlib import Path
from typing import IO

from beatlite.io.errors import FormatError

GZIP_MAGIC = b"\x1f\x8b"
LFS_POINTER_PREFIX = b"version https://git-lfs.github.com/spec/"


def is_gzip(path: str | os.PathLike[str]) -> bool:
    """True when the file starts with the gzip magic bytes ``1f 8b`` (whatever its name).

    Examples
    --------
    >>> import gzip, tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "no_suffix"
    >>> _ = path.write_bytes(gzip.compress(b"hello"))
    >>> is_gzip(path), read_bytes(path)  # recognised by its magic bytes, whatever its name
    (True, b'hello')
    >>> tmp.cleanup()
    """
    with open(path, "rb") as f:
        return f.read(2) == GZIP_MAGIC


#: What a corrupt or truncated gzip stream raises while it is read.
GZIP_ERRORS = (gzip.BadGzipFile, EOFError, zlib.error)


#: A gzipped input may inflate to at most this many times its compressed size (plus 1 MiB): beatlite's own
#: corpus files inflate 7-19x (BVH with 3 decimals, facial JSON); a gzip "bomb" (e.g. 1.7 MB inflating to
#: 700 MB) is refused while it is read, so memory and time stay bounded by the file on disk.
GZIP_MAX_RATIO = 100


#: A ZIP member may inflate beyond :data:`GZIP_MAX_RATIO` times its stored size only up to this many bytes (so that
#: small arrays of zeros, which compress 1000-fold, stay readable); past it the ratio bound applies.
ZIP_SMALL_MEMBER_BYTES = 64 * 2**20


def zip_members(
    path: Path, max_member_bytes: int | None = None, suffix: str = ""
) -> dict[str, zipfile.ZipInfo]:
    """The members of the ZIP archive at ``path`` by name (less ``suffix``, e.g. ``".npy"``), checked from its directory before anything is inflated.

    Refused, a :class:`FormatError` naming the member as the field: a member larger than ``max_member_bytes``
    uncompressed (None: no such bound), one stored in more bytes than the file has, or one (or all together)
    inflating to more than :data:`ZIP_SMALL_MEMBER_BYTES` and more than :data:`GZIP_MAX_RATIO` times its stored
    size (the file's size for all together): a decompression bomb. Used by the ``.npz`` reader
    (:func:`beatlite.io.smplx.read_smplx`) and the checkpoint loaders (``torch.save`` stores members uncompressed).

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "bomb.zip"
    >>> with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
    ...     z.writestr("zeros", bytes(65 * 2**20))  # 65 MiB of zeros in 64 KB
    >>> zip_members(path)
    Traceback (most recent call last):
    ...
    beatlite.io.errors.FormatError: ..., field 'zeros': 68157440 bytes uncompressed (1... x the stored size): refused as a likely decompression bomb
    >>> tmp.cleanup()
    """
    try:
        with zipfile.ZipFile(path) as z:
            infos = {i.filename.removesuffix(suffix): i for i in z.infolist()}
    except (zipfile.BadZipFile, OSError, EOFError) as exc:
        raise FormatError(path, f"a damaged ZIP archive ({exc})") from None
    size = path.stat().st_size
    total = sum(i.file_size for i in infos.values())
    for name, info in infos.items():
        ratio = info.file_size / max(info.compress_size, 1)
        if info.compress_size > size:
            raise FormatError(
                path, f"{info.compress_size} bytes stored in a {size}-byte file: damaged", field=name
            )
        if (max_member_bytes is not None and info.file_size > max_member_bytes) or (
            info.file_size > ZIP_SMALL_MEMBER_BYTES and ratio > GZIP_MAX_RATIO
        ):
            raise FormatError(
                path,
                f"{info.file_size} bytes uncompressed ({ratio:.0f} x the stored size): refused as a likely "
                "decompression bomb",
                field=name,
            )
    if total > ZIP_SMALL_MEMBER_BYTES and total > GZIP_MAX_RATIO * size:
        raise FormatError(
            path,
            f"its members inflate to {total} bytes, {total / size:.0f} x the file's size: refused as a likely "
            "decompression bomb",
        )
    return infos


#: What reading a damaged ZIP member raises: a bad entry, corrupt deflate data, an unknown compression method
#: (``NotImplementedError``), an encrypted member (``RuntimeError``).
ZIP_MEMBER_ERRORS = (zipfile.BadZipFile, OSError, EOFError, zlib.error, NotImplementedError, RuntimeError)


def npy_header(
    fh: IO[bytes], size: int, path: Path, *, field: str | None = None, where: str = "file"
) -> tuple[tuple[int, ...], object]:
    """``(shape, dtype)`` of the ``.npy`` that ``fh`` (at its start, ``size`` bytes in all) holds, checked before
    numpy reads it: numpy allocates the shape a header claims before it reads a byte of data, so a shape needing
    more bytes than the ``where`` holds is refused, as is an object dtype (a pickle).

    Raises
    ------
    FormatError
        An unreadable header, an object dtype, or a shape larger than the bytes present (``field``, else
        ``"dtype"`` / ``"shape"``).

    Examples
    --------
    >>> import numpy as np
    >>> buf = io.BytesIO()
    >>> np.save(buf, np.zeros((3, 2), np.float32))
    >>> size = buf.tell()
    >>> _ = buf.seek(0)
    >>> npy_header(buf, size, Path("x.npy"))
    ((3, 2), dtype('float32'))
    >>> _ = buf.seek(0)
    >>> npy_header(buf, size - 4, Path("x.npy"))  # one float32 missing
    Traceback (most recent call last):
    ...
    beatlite.io.errors.FormatError: x.npy, field 'shape': the header's shape (3, 2) float32 needs 24 bytes, the file holds 20
    """
    import numpy as np

    fmt = np.lib.format
    try:
        read = fmt.read_array_header_1_0 if fmt.read_magic(fh) == (1, 0) else fmt.read_array_header_2_0
        shape, _, dtype = read(fh)
    except (ValueError, OSError, EOFError, tokenize.TokenError) as exc:
        raise FormatError(
            path, f"not a readable .npy header ({' '.join(str(exc).split())})", field=field
        ) from None
    if dtype.hasobject:
        raise FormatError(
            path, "a pickled object array (never loaded: it could run code)", field=field or "dtype"
        )
    need, have = math.prod(shape) * dtype.itemsize, size - fh.tell()
    if need > have:
        raise FormatError(
            path,
            f"the header's shape {shape} {dtype} needs {need} bytes, the {where} holds {have}",
            field=field or "shape",
        )
    return shape, dtype


class _CheckedGzip(gzip.GzipFile):
    """A gzip stream whose corrupt or truncated data, or inflation beyond :data:`GZIP_MAX_RATIO`, raises
    :class:`FormatError` naming the file."""

    def __init__(self, path: Path) -> None:
        super().__init__(filename=path, mode="rb")
        self.path = path
        self.limit = GZIP_MAX_RATIO * path.stat().st_size + 2**20
        self.inflated = 0

    def _checked(self, method: str, *args: int) -> bytes:
        if method == "read" and (not args or args[0] is None or args[0] < 0):  # read all: in bounded steps
            return b"".join(iter(lambda: self._checked("read", 2**20), b""))
        try:
            data = getattr(super(), method)(*args)
        except GZIP_ERRORS as exc:
            raise FormatError(self.path, f"cannot decompress gzip data: {exc}") from None
        if method != "peek":
            self.inflated += len(data)
            if self.inflated > self.limit:
                raise FormatError(
                    self.path,
                    f"gzip data inflate to more than {GZIP_MAX_RATIO}x the file's {self.path.stat().st_size} bytes "
                    "(beatlite.io.textfile.GZIP_MAX_RATIO): refused as a likely decompression bomb",
                )
        return data

    def read(self, size: int = -1) -> bytes:
        return self._checked("read", size)

    def read1(self, size: int = -1) -> bytes:
        return self._checked("read1", size)

    def readline(self, size: int = -1) -> bytes:
        if size is None or size < 0:  # a line with no newline (zeros) inflated unchecked: stop past the limit
            size = max(self.limit - self.inflated, 0) + 1
        return self._checked("readline", size)

    def peek(self, n: int) -> bytes:
        return self._checked("peek", n)


def open_binary(path: str | os.PathLike[str]) -> IO[bytes]:
    r"""Open ``path`` for binary reading, decompressing gzip transparently.

    Gzip is recognised by its magic bytes, so a ``.gz`` file and a gzipped
    file without the suffix both work. Corrupt gzip data raises :class:`FormatError`.

    Examples
    --------
    >>> import gzip, tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "take.txt.gz"
    >>> _ = path.write_bytes(gzip.compress(b"abc\n"))
    >>> with open_binary(path) as f:
    ...     f.read()
    b'abc\n'
    >>> tmp.cleanup()
    """
    p = Path(path)
    if is_gzip(p):
        return _CheckedGzip(p)
    return open(p, "rb")


def read_bytes(path: str | os.PathLike[str]) -> bytes:
    r"""The whole (decompressed) content of ``path`` as bytes.

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "plain.txt"
    >>> _ = path.write_bytes(b"\x00\x01")
    >>> read_bytes(path)
    b'\x00\x01'
    >>> tmp.cleanup()
    """
    p = Path(path)
    with open_binary(p) as f:
        try:
            return f.read()
        except (OSError, *GZIP_ERRORS) as exc:  # corrupt or truncated gzip stream
            raise FormatError(p, f"cannot decompress gzip data: {exc}") from None


#: Byte-order marks, longest first (UTF-32 LE starts with the UTF-16 LE mark).
BOMS: tuple[tuple[bytes, str], ...] = (
    (b"\xff\xfe\x00\x00", "utf-32"),
    (b"\x00\x00\xfe\xff", "utf-32"),
    (b"\xef\xbb\xbf", "utf-8-sig"),
    (b"\xff\xfe", "utf-16"),
    (b"\xfe\xff", "utf-16"),
)


def bom_encoding(head: bytes) -> str | None:
    r"""The encoding a byte-order mark at the start of ``head`` announces (``None`` without one).

    Examples
    --------
    >>> bom_encoding(b"\xef\xbb\xbfxmin"), bom_encoding(b"\xff\xfex\x00"), bom_encoding(b"xmin")
    ('utf-8-sig', 'utf-16', None)
    """
    return next((enc for bom, enc in BOMS if head.startswith(bom)), None)


def decode_text(data: bytes, path: str | os.PathLike[str] | None, encoding: str = "utf-8") -> str:
    r"""Decode ``data``; a byte that is not valid ``encoding`` raises :class:`FormatError` naming its line.

    For ``encoding="utf-8"`` (the default) or ``"auto"`` a byte-order mark decides:
    UTF-8, UTF-16 (as Praat writes them) or UTF-32 files with a BOM are all read,
    and the BOM is dropped.

    Examples
    --------
    >>> decode_text("File type".encode("utf-16"), None)  # Praat's UTF-16 with its BOM
    'File type'
    >>> decode_text(b"ok\n\xff\n", "take.txt")
    Traceback (most recent call last):
        ...
    beatlite.io.errors.FormatError: take.txt, line 2: ...
    """
    if encoding == "auto" or encoding.lower().replace("_", "-") == "utf-8":
        encoding = bom_encoding(data[:4]) or "utf-8-sig"
    try:
        return data.decode(encoding)
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise FormatError(
            path,
            f"byte {exc.start} is not valid {encoding} text ({describe_bytes(data[:64])})",
            line=line,
        ) from None


def read_text(path: str | os.PathLike[str], encoding: str = "utf-8") -> str:
    r"""The whole text of ``path`` (``.gz`` transparent), universal newlines (CRLF becomes LF).

    Parameters
    ----------
    path : str or PathLike
        File to read.
    encoding : str
        Text encoding; ``"utf-8"`` and ``"auto"`` also accept UTF-16/32 files with a BOM.

    Returns
    -------
    str
        The text with ``\r\n`` and ``\r`` turned into ``\n`` and any BOM removed.

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "take.TextGrid"
    >>> _ = path.write_bytes(b"\xef\xbb\xbfa\r\nb\rc\n")
    >>> read_text(path)  # BOM dropped, newlines universal
    'a\nb\nc\n'
    >>> tmp.cleanup()
    """
    text = decode_text(read_bytes(path), path, encoding)
    if "\r" in text:
        text = text.replace("\r\n", "\n").replace("\r", "\n")
    return text


def open_text(path: str | os.PathLike[str], encoding: str = "utf-8") -> IO[str]:
    r"""Open ``path`` as a text stream (``.gz`` transparent, universal newlines).

    Decoding errors surface as ``UnicodeDecodeError`` while reading; use
    :func:`read_text` to get a :class:`FormatError` that names the line.

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "take.txt"
    >>> _ = path.write_bytes(b"one\r\ntwo\r\n")
    >>> with open_text(path) as f:
    ...     f.readlines()
    ['one\n', 'two\n']
    >>> tmp.cleanup()
    """
    if encoding.lower().replace("_", "-") == "utf-8":
        encoding = "utf-8-sig"
    return io.TextIOWrapper(open_binary(path), encoding=encoding, newline=None)


def resolve(path_or_stem: str | os.PathLike[str], ext: str) -> Path:
    """Find the file for ``path_or_stem`` with extension ``ext``, plain or gzipped.

    Parameters
    ----------
    path_or_stem : str or PathLike
        Either a file that exists (``take.bvh``, ``take.bvh.gz``) or a stem
        (``data/2_scott_0_1_1``) to which ``ext`` and ``ext + ".gz"`` are appended.
    ext : str
        Extension with or without the dot, e.g. ``".bvh"`` or ``"TextGrid"``.
        Matching falls back to a case-insensitive comparison (``.textgrid``).

    Returns
    -------
    Path
        The first of ``stem + ext``, ``stem + ext + ".gz"`` that exists.

    Raises
    ------
    FileNotFoundError
        Naming every path tried.

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> _ = (Path(tmp.name) / "take.bvh.gz").write_bytes(b"")
    >>> _ = (Path(tmp.name) / "take.textgrid").write_bytes(b"")
    >>> resolve(Path(tmp.name) / "take", ".bvh").name, resolve(Path(tmp.name) / "take", "TextGrid").name
    ('take.bvh.gz', 'take.textgrid')
    >>> tmp.cleanup()
    """
    if not ext.startswith("."):
        ext = "." + ext
    p = Path(path_or_stem)
    name = p.name
    low = name.lower()
    if p.is_file() and (low.endswith(ext.lower()) or low.endswith(ext.lower() + ".gz")):
        return p
    stem = str(p)
    tried = [Path(stem + ext), Path(stem + ext + ".gz")]
    for cand in tried:
        if cand.is_file():
            return cand
    folder = p.parent
    if folder.is_dir():
        wanted = {(name + ext).lower(), (name + ext + ".gz").lower()}
        matches = sorted(c for c in folder.iterdir() if c.name.lower() in wanted and c.is_file())
        if matches:
            return matches[0]
    raise FileNotFoundError(f"no file {tried[0]} or {tried[1]}")


#: File signatures (magic bytes) -> what :func:`describe_bytes` calls them, checked in order.
_MAGIC: tuple[tuple[bytes, str | object], ...] = (
    (
        b"RIFF",
        lambda head: "a RIFF/WAVE file" if head[8:12] == b"WAVE" else f"a RIFF file of type {head[8:12]!r}",
    ),
    (b"RF64", "an RF64 WAVE file"),
    (b"fLaC", "FLAC audio"),
    (b"OggS", "an Ogg file"),
    (GZIP_MAGIC, "gzip-compressed data"),
    (b"PK\x03\x04", "a ZIP archive"),
    (b"\x89PNG", "a PNG image"),
    (b"\xff\xd8\xff", "a JPEG image"),
    (b"%PDF", "a PDF document"),
)


def describe_bytes(head: bytes) -> str:
    r"""A short human description of what the first bytes of a file look like.

    Used in error messages: ``"an empty file"``, ``"a Git-LFS pointer (run
    `git lfs pull`)"``, ``"MP3 audio"``, ``"an HTML page"``, ``"binary data"`` ...

    Examples
    --------
    >>> describe_bytes(b""), describe_bytes(b"<!DOCTYPE html><html>")
    ('an empty file', 'an HTML page (a download that returned a web page?)')
    >>> describe_bytes(b"version https://git-lfs.github.com/spec/v1\n")
    'a Git-LFS pointer text, not the file content (run `git lfs pull`)'
    """
    if not head:
        return "an empty file"
    stripped = head.lstrip(b"\xef\xbb\xbf").lstrip()
    if head.startswith(LFS_POINTER_PREFIX):
        return "a Git-LFS pointer text, not the file content (run `git lfs pull`)"
    if (bom := bom_encoding(head)) in ("utf-16", "utf-32"):  # before MP3: FF FE looks like a sync word
        return f"{bom.upper()} text"
    if head.startswith(b"ID3") or (len(head) > 1 and head[0] == 0xFF and head[1] & 0xE0 == 0xE0):
        return "MP3 audio"
    for magic, name in _MAGIC:
        if head.startswith(magic):
            return name(head) if callable(name) else name
    if head[4:8] == b"ftyp":
        return "an MP4/M4A file"
    low = stripped[:256].lower()
    if low.startswith((b"<!doctype html", b"<html")) or b"<html" in low:
        return "an HTML page (a download that returned a web page?)"
    if low.startswith(b"<?xml"):
        return "an XML document"
    if stripped[:1] in (b"{", b"["):
        return "JSON text"
    if b"\x00" in head:
        return "binary data"
    try:
        text = head.decode("utf-8")
    except UnicodeDecodeError:
        return "binary data (not UTF-8 text)"
    first = text.strip().splitlines()[0][:40] if text.strip() else ""
    return f"text starting with {first!r}"
