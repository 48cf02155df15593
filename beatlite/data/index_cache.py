"""The cache of :func:`beatlite.data.index.index_folder`: a take's files are read again only when they changed.

Indexing reads every file of every take (about 32 CPU-s per hour of BEAT-rate corpus), so
``index_folder`` keeps, per corpus folder, one JSON file under ``cache_dir()/index/`` holding each
take's :class:`~beatlite.data.index.TakeRecord` with the key it was computed from: the take's
candidate files (path, size, mtime_ns), its ``bvh_fps`` override and :data:`INDEX_VERSION`, plus
the sha256 of each file's content (so :func:`beatlite.data.fingerprint.file_digest` does not read it
again), and the sha256 of the entry itself (``check``: an entry whose bits changed is not served). A take is
re-indexed when any part of its key differs. Files modified in the last
:data:`~beatlite.data.fingerprint.SETTLE_S` seconds are never cached (their size and mtime could
stay the same through a quick rewrite). The cache is written atomically; a broken or foreign
cache file is ignored (rebuilt), never an error.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

from beatlite.data.fingerprint import file_digest, file_key, json_digest, remember_digest, settled

if TYPE_CHECKING:
    from beatlite.data.index import TakeRecord

#: Bump when what indexing records changes (every cached record is then recomputed).
INDEX_VERSION = 4


def cache_path(root: Path, recursive: bool) -> Path:
    """``cache_dir()/index/{hash of the resolved folder and recursive}.json``.

    Examples
    --------
    >>> p = cache_path(Path("data_samples"), recursive=True)
    >>> p.parent.name, p.suffix, len(p.stem)
    ('index', '.json', 16)
    """
    from beatlite.paths import cache_dir

    key = json.dumps({"root": str(Path(root).resolve()), "recursive": bool(recursive)})
    return cache_dir() / "index" / f"{hashlib.sha256(key.encode()).hexdigest()[:16]}.json"


def take_key(files: dict[str, list[Path]], bvh_fps: float | None) -> list[Any] | None:
    """The JSON key a take's cached record must match, or None when a file is too fresh to cache.

    Examples
    --------
    >>> from beatlite.paths import repo_root
    >>> files = {"motion": [repo_root() / "data_samples" / "2_scott_0_1_1.bvh.gz"]}
    >>> key = take_key(files, None)
    >>> key[0] == INDEX_VERSION, key[1], key[2][0][0]  # version, bvh_fps override, (modality, *file_key)
    (True, None, 'motion')
    """
    keys = sorted([modality, *file_key(p)] for modality, paths in files.items() for p in paths)
    if not all(settled(tuple(k[1:])) for k in keys):
        return None
    return [INDEX_VERSION, None if bvh_fps is None else float(bvh_fps), keys]


def load(path: Path) -> dict[str, Any]:
    """``{stem: {"key": ..., "record": ..., "digests": ...}}`` of a cache file ({} if absent or unreadable).

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> load(Path(tmp.name) / "absent.json")  # absent or unreadable: empty
    {}
    >>> save(Path(tmp.name) / "index.json", {"2_scott_0_1_1": {"key": [1]}})
    >>> load(Path(tmp.name) / "index.json")
    {'2_scott_0_1_1': {'key': [1]}}
    >>> tmp.cleanup()
    """
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return {}
    if (
        not isinstance(data, dict)
        or data.get("version") != INDEX_VERSION
        or not isinstance(data.get("takes"), dict)
    ):
        return {}
    return data["takes"]


def cached_record(entry: Any, key: list[Any] | None) -> TakeRecord | None:
    """The record of a cache ``entry`` if it was computed from ``key`` (its digests primed), else None.

    Examples
    --------
    >>> from beatlite.data.index import index_take
    >>> from beatlite.paths import repo_root
    >>> files = {"motion": [repo_root() / "data_samples" / "2_scott_0_1_1.bvh.gz"]}
    >>> key = take_key(files, None)
    >>> cached = entry(index_take("2_scott_0_1_1", files), key)
    >>> cached_record(cached, key).stem, cached_record(cached, ["another key"])
    ('2_scott_0_1_1', None)
    """
    from beatlite.data.index import TakeRecord

    if key is None or not isinstance(entry, dict) or entry.get("key") != key:
        return None
    # a corrupt entry (or one written before entries had a check)
    if entry.get("check") != json_digest(entry, "check"):
        return None
    try:
        fields = dict(entry["record"])
        fields["files"] = {m: Path(p) for m, p in fields["files"].items()}
        record = TakeRecord(**fields)
        for modality, digest in entry["digests"].items():
            remember_digest(file_key(record.files[modality]), digest)
    except (KeyError, TypeError, ValueError, OSError):
        return None
    return record


def entry(record: TakeRecord, key: list[Any]) -> dict[str, Any]:
    """The cache entry of a freshly indexed record (its files hashed now, with :func:`file_digest`).

    Examples
    --------
    >>> from beatlite.data.index import index_take
    >>> from beatlite.paths import repo_root
    >>> files = {"motion": [repo_root() / "data_samples" / "2_scott_0_1_1.bvh.gz"]}
    >>> e = entry(index_take("2_scott_0_1_1", files), take_key(files, None))
    >>> sorted(e), len(e["digests"]["motion"])  # sha256 of each file (and of the entry: check)
    (['check', 'digests', 'key', 'record'], 64)
    """
    fields = dataclasses.asdict(record)
    fields["files"] = {m: str(p) for m, p in record.files.items()}
    made = {"key": key, "record": fields, "digests": {m: file_digest(p) for m, p in record.files.items()}}
    return {**made, "check": json_digest(made, "check")}


def save(path: Path, takes: dict[str, Any]) -> None:
    """Write the cache atomically (a failure to write, e.g. a read-only build folder, is ignored).

    Examples
    --------
    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = Path(tmp.name) / "index" / "cache.json"  # parent folders are made
    >>> save(path, {})
    >>> load(path), path.exists()
    ({}, True)
    >>> tmp.cleanup()
    """
    from beatlite.io.atomic import atomic_write

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_write(path) as f:
            json.dump({"version": INDEX_VERSION, "takes": takes}, f)
    except OSError:
        pass
