"""Fingerprints of data: the same files and parameters give the same hex digits on every machine.

One home for "is this the same data?": the window store (and the windows read from it), the FGD extractor's
record of what it was trained on and the stale-checkpoint checks all call :func:`take_fingerprint`
or :func:`takes_fingerprint`. A fingerprint hashes

- each file's **content** (sha256 of its bytes; never its modification time, which a fresh clone
  or a copy changes, nor derived floats, whose last bits differ across CPUs and library builds),
- the file's name and modality, the take's stem and its per-take BVH frame-rate override
  (:attr:`beatlite.data.index.TakeRecord.bvh_fps`: it changes what loading reads), and
- the parameters of whatever is built (JSON, sorted keys) with :data:`FINGERPRINT_VERSION`.

Hashing a file is paid once per file version: :func:`file_digest` remembers digests by
(path, size, mtime_ns) in this process, and :func:`beatlite.data.index.index_folder`'s cache keeps
them across processes, so an unchanged corpus is not read again.

>>> import tempfile, pathlib
>>> p = pathlib.Path(tempfile.mkdtemp()) / "a.txt"
>>> _ = p.write_bytes(b"beat")
>>> file_digest(p) == hashlib.sha256(b"beat").hexdigest()
True
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from beatlite.data.index import TakeRecord

#: Bump when the way fingerprints are computed changes (every cache keyed by them is then rebuilt).
FINGERPRINT_VERSION = 2
#: A file modified less than this many seconds before it was looked at may change again within the
#: file system's timestamp granularity without its (size, mtime) changing ("racy", as git calls it):
#: its digest and index entry are not remembered.
SETTLE_S = 2.0
_CHUNK = 1 << 20
_DIGESTS: dict[tuple[str, int, int, int], str] = {}


def file_key(path: str | os.PathLike[str]) -> tuple[str, int, int, int]:
    """(resolved path, size, mtime_ns, ctime_ns): what decides whether a remembered digest still holds.

    The change time is there because the modification time can be set back (``touch -r``, ``os.utime``,
    an archive or a copy that keeps times) after a same-size edit, which then looked unchanged; setting it
    back changes the change time, which no user call sets.

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> p = Path(tmp.name) / "a.txt"
    >>> _ = p.write_bytes(b"beat")
    >>> key = file_key(p)
    >>> key[0] == str(p.resolve()), key[1], len(key)  # (resolved path, size in bytes, mtime_ns, ctime_ns)
    (True, 4, 4)
    >>> tmp.cleanup()
    """
    st = Path(path).stat()
    return (str(Path(path).resolve()), int(st.st_size), int(st.st_mtime_ns), int(st.st_ctime_ns))


def settled(key: tuple[str, int, int] | tuple[str, int, int, int], now_ns: int | None = None) -> bool:
    """Whether a file with this :func:`file_key` was last modified at least :data:`SETTLE_S` ago.

    Examples
    --------
    >>> key = ("/data/take.bvh", 100, 1_000_000_000)  # modified at t = 1 s
    >>> settled(key, now_ns=2_000_000_000), settled(key, now_ns=4_000_000_000)  # SETTLE_S = 2 s
    (False, True)
    """
    now_ns = time.time_ns() if now_ns is None else now_ns
    return key[2] <= now_ns - int(SETTLE_S * 1e9)


def file_digest(path: str | os.PathLike[str]) -> str:
    """sha256 (64 hex digits) of a file's bytes, read in 1 MiB chunks (memory flat).

    Remembered by :func:`file_key` for the life of the process (:func:`remember_digest` primes it from
    a cache), so a file is read again only when it changed; files modified in the last
    :data:`SETTLE_S` seconds are not remembered (they are hashed on every call).

    Examples
    --------
    >>> import hashlib, tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> p = Path(tmp.name) / "a.txt"
    >>> _ = p.write_bytes(b"beat")
    >>> file_digest(p) == hashlib.sha256(b"beat").hexdigest()
    True
    >>> tmp.cleanup()
    """
    key = file_key(path)
    digest = _DIGESTS.get(key)
    if digest is None:
        h = hashlib.sha256()
        with open(path, "rb") as f:
            while chunk := f.read(_CHUNK):
                h.update(chunk)
        digest = h.hexdigest()
        if settled(key):
            _DIGESTS[key] = digest
    return digest


def remember_digest(key: tuple[str, int, int, int], digest: str) -> None:
    """Prime :func:`file_digest` with a digest computed earlier for the file of this :func:`file_key`.

    Examples
    --------
    >>> import os, tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> p = Path(tmp.name) / "a.txt"
    >>> _ = p.write_bytes(b"beat")
    >>> os.utime(p, ns=(10**9, 10**9))  # modified long ago: digests are remembered
    >>> remember_digest(file_key(p), "0" * 64)  # e.g. from the index cache
    >>> file_digest(p) == "0" * 64  # taken from memory, the file is not read again
    True
    >>> tmp.cleanup()
    """
    if settled(key):
        _DIGESTS[(str(key[0]), *(int(k) for k in key[1:]))] = str(digest)  # (JSON gives lists: a tuple again)


def _params_hash(params: Mapping[str, Any]) -> Any:
    text = json.dumps({**params, "fingerprint_version": FINGERPRINT_VERSION}, sort_keys=True, default=str)
    return hashlib.sha256(text.encode())


def _update_with_take(h: Any, record: TakeRecord) -> None:
    for modality in sorted(record.files):
        p = Path(record.files[modality])
        h.update(f"{record.stem}|{modality}|{p.name}|{file_digest(p)}\n".encode())
    if record.bvh_fps is not None:  # a per-take frame-rate override changes what loading reads
        h.update(f"{record.stem}|bvh_fps|{float(record.bvh_fps)!r}\n".encode())


def take_fingerprint(record: TakeRecord, params: Mapping[str, Any]) -> str:
    """64 hex digits identifying one take's files (content), its ``bvh_fps`` override and ``params``.

    Parameters
    ----------
    record : TakeRecord
        The take (its ``files`` are hashed by content).
    params : Mapping
        JSON-serialisable parameters of what is built from the take (frame rate, audio rate, ...).

    Examples
    --------
    >>> import tempfile
    >>> from beatlite.data.index import TakeRecord
    >>> tmp = tempfile.TemporaryDirectory()
    >>> bvh = Path(tmp.name) / "2_scott_0_1_1.bvh"
    >>> _ = bvh.write_bytes(b"HIERARCHY")
    >>> record = TakeRecord("2_scott_0_1_1", files={"motion": bvh})
    >>> a = take_fingerprint(record, {"fps": 15})
    >>> len(a), a == take_fingerprint(record, {"fps": 15}), a == take_fingerprint(record, {"fps": 30})
    (64, True, False)
    >>> tmp.cleanup()
    """
    h = _params_hash(params)
    _update_with_take(h, record)
    return h.hexdigest()


def takes_fingerprint(records: Iterable[TakeRecord], params: Mapping[str, Any]) -> str:
    """64 hex digits identifying several takes (in stem order) and ``params``: a split, a corpus.

    Examples
    --------
    >>> import tempfile
    >>> from beatlite.data.index import TakeRecord
    >>> tmp = tempfile.TemporaryDirectory()
    >>> records = []
    >>> for stem in ("2_scott_0_1_1", "2_scott_0_9_9"):
    ...     _ = (Path(tmp.name) / f"{stem}.bvh").write_bytes(stem.encode())
    ...     records.append(TakeRecord(stem, files={"motion": Path(tmp.name) / f"{stem}.bvh"}))
    >>> takes_fingerprint(records, {}) == takes_fingerprint(records[::-1], {})  # stem order, whatever the input order
    True
    >>> tmp.cleanup()
    """
    h = _params_hash(params)
    for record in sorted(records, key=lambda r: r.stem):
        _update_with_take(h, record)
    return h.hexdigest()


def json_digest(data: Mapping[str, Any], skip: str) -> str:
    """sha256 (64 hex digits) of a JSON object's fields other than ``skip`` (sorted keys): what a store's
    ``meta.json``/``store.json`` (``digest``) and an index cache entry (``check``) carry, so that a flipped bit
    that still parses (a digit, a letter) is seen.

    >>> json_digest({"n": 1, "digest": "?"}, "digest") == json_digest({"n": 1}, "digest") != json_digest({"n": 2}, "digest")
    True
    """
    body = {k: v for k, v in data.items() if k != skip}
    return hashlib.sha256(json.dumps(body, sort_keys=True).encode()).hexdigest()


def vocab_hash(vocab: Iterable[str]) -> str:
    """sha256 (64 hex digits) of a vocabulary's words in id order (``Vocab.itos``).

    >>> vocab_hash(["<pad>", "hello"]) == vocab_hash(["<pad>", "hello"]) != vocab_hash(["hello", "<pad>"])
    True
    """
    return hashlib.sha256("\n".join(vocab).encode()).hexdigest()


def windows_fingerprint(
    take_fingerprints: Iterable[str], *, split: str | None, length: int, stride: int, vocab: Iterable[str]
) -> str:
    """16 hex digits identifying a set of windows, whichever route cut them (the window store's
    :class:`~beatlite.data.store.StoreWindows` or the in-memory :class:`~beatlite.data.windows.Windows`).

    Parameters
    ----------
    take_fingerprints : iterable of str
        :func:`beatlite.data.store.take_fingerprint` of each take the windows were cut from, in index order (one
        shorter than a window too: a train take feeds the statistics).
    split : str or None
    length, stride : int
        Window length and stride in frames.
    vocab : iterable of str
        The vocabulary the word ids refer to (``Vocab.itos``).

    Examples
    --------
    >>> a = windows_fingerprint(["ab" * 32], split="test", length=34, stride=10, vocab=["<pad>", "hello"])
    >>> len(a), a == windows_fingerprint(["ab" * 32], split="test", length=34, stride=5, vocab=["<pad>", "hello"])
    (16, False)
    """
    h = _params_hash(
        {"split": split, "length": int(length), "stride": int(stride), "vocab": vocab_hash(vocab)}
    )
    for fp in take_fingerprints:
        h.update(f"{fp}\n".encode())
    return h.hexdigest()[:16]
