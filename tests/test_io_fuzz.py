"""Seeded fuzzing of every reader (issue 14): mutated inputs raise only FormatError or OSError, never hang,
never allocate without bound and never modify the input.

Seed files are written with beatlite's own writers; each reader gets :data:`N_PER_READER` inputs, each made by
1-3 random mutations (byte flips, truncation, deleted or repeated slices, extreme numbers such as ``1e400``,
``1e-320`` or a 5000-digit integer, deep nesting, CR-only or CRLF line ends, gzip, UTF-16, binary header fields).
Guards per input: a wall-clock alarm (:data:`HANG_LIMIT_S`, a hang detector, not a speed target) and the peak of
:mod:`tracemalloc` (numpy registers its buffers there), at most :data:`MEMORY_SLACK` bytes plus
:data:`MEMORY_PER_BYTE` times the decompressed input size, itself at most ``GZIP_MAX_RATIO`` times the file's.
"""

from __future__ import annotations

import contextlib
import gzip
import re
import signal
import threading
import tracemalloc
import warnings
import zlib
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest

from beatlite.io import (
    ARKIT_51,
    EmotionSegment,
    FormatError,
    Interval,
    Motion,
    SemanticSegment,
    audio_info,
    parse_take_name,
    read_audio,
    read_bvh,
    read_bvh_header,
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
from beatlite.io.textfile import GZIP_MAX_RATIO
from beatlite.skeleton.core import Skeleton

SEED = 14
N_PER_READER = 220
HANG_LIMIT_S = 20.0
MEMORY_SLACK = 48 * 2**20
MEMORY_PER_BYTE = 64
NASTY = [
    b"1e400",
    b"-1e400",
    b"1e-320",
    b"nan",
    b"inf",
    b"9" * 5000,
    b"9" * 400,
    b"-1",
    b"0",
    b"4294967295",
    b"\x00",
    b"\r",
    b"\n",
    b"{",
    b"}",
    b"[",
    b'"',
    b"\xff\xfe",
    "\u00b2".encode(),
    b"true",
    b'"0.5"',
    b"JOINT Hips",
    b"CHANNELS 3 Xrotation Yrotation Xposition",
]
_NUMBER = re.compile(rb"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")


# ----------------------------------------------------------------------------- mutations
def _slice(data: bytes, rng: np.random.Generator) -> tuple[int, int]:
    a = int(rng.integers(0, len(data) + 1))
    return a, min(len(data), a + int(rng.integers(1, 64)))


def _replace_number(data: bytes, rng: np.random.Generator) -> bytes:
    spans = [m.span() for m in _NUMBER.finditer(data[:200_000])]
    if not spans:
        return data
    a, b = spans[int(rng.integers(len(spans)))]
    return data[:a] + NASTY[int(rng.integers(len(NASTY)))] + data[b:]


def _header_field(data: bytes, rng: np.random.Generator) -> bytes:
    at = int(rng.integers(0, max(1, min(len(data), 64) - 3)))
    width = int(rng.choice([2, 4]))
    value = int(rng.choice([0, 1, 2**16 - 1, 2**32 - 1, int(rng.integers(0, 2**31))]))
    return data[:at] + (value % 2 ** (8 * width)).to_bytes(width, "little") + data[at + width :]


MUTATIONS: list[Callable[[bytes, np.random.Generator], bytes]] = [
    lambda d, r: bytes(x if r.random() > 8 / max(len(d), 1) else int(r.integers(256)) for x in d),  # flips
    lambda d, r: d[: int(r.integers(0, len(d) + 1))],  # truncate
    lambda d, r: (lambda a, b: d[:a] + d[b:])(*_slice(d, r)),  # delete a slice
    lambda d, r: (lambda a, b: d[:b] + d[a:b] * int(r.integers(2, 50)) + d[b:])(*_slice(d, r)),  # repeat one
    lambda d, r: (lambda a: d[:a] + NASTY[int(r.integers(len(NASTY)))] + d[a:])(
        int(r.integers(0, len(d) + 1))
    ),
    _replace_number,
    _replace_number,
    lambda d, r: d.replace(b"\n", b"\r" if r.random() < 0.5 else b"\r\n"),  # line endings
    lambda d, r: gzip.compress(d, mtime=0),
    lambda d, r: (lambda z: z[: int(r.integers(0, len(z) + 1))])(gzip.compress(d, mtime=0)),  # broken gzip
    _header_field,
    lambda d, r: d.decode("utf-8", "replace").encode("utf-16"),
    lambda d, r: b"[" * 60_000 + d + b"]" * 60_000,  # deep nesting
    lambda d, r: b"",
]


def mutate(data: bytes, rng: np.random.Generator, max_ops: int = 3) -> bytes:
    """1 to ``max_ops`` random mutations of ``data`` (deterministic for a generator state)."""
    for _ in range(int(rng.integers(1, max_ops + 1))):
        data = MUTATIONS[int(rng.integers(len(MUTATIONS)))](data, rng)
    return data


# ----------------------------------------------------------------------------- seed files
def seed_files(folder: Path) -> dict[str, list[Path]]:
    """Valid inputs per reader kind, written with beatlite's writers (plain and gzipped)."""
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(SEED)
    skel = Skeleton(
        names=("Hips", "Spine", "Head"),
        parents=np.array([-1, 0, 1]),
        offsets=np.array([[0.0, 0, 0], [0, 10, 0], [0, 8, 0]]),
        channels=(
            ("Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation", "Yrotation"),
            ("Xrotation", "Yrotation", "Zrotation"),
            ("Zrotation", "Yrotation", "Xrotation"),
        ),
        end_sites={2: np.array([0.0, 5.0, 0.0])},
    )
    out: dict[str, list[Path]] = {k: [] for k in ("bvh", "wav", "json", "TextGrid", "txt", "csv")}
    for suffix in ("", ".gz"):
        p = folder / f"m.bvh{suffix}"
        write_bvh(p, Motion(skel, np.round(rng.normal(size=(20, 12)) * 30, 3), 120), precision=3)
        out["bvh"].append(p)
        p = folder / f"a.wav{suffix}"
        write_wav(p, 0.3 * np.sin(np.arange(4000) / 7.0), 16000)
        out["wav"].append(p)
        p = folder / f"f.json{suffix}"
        write_facial(p, ARKIT_51, np.round(rng.uniform(size=(6, 51)), 3), fps=60)
        out["json"].append(p)
        p = folder / f"t.TextGrid{suffix}"
        write_textgrid(p, {"words": [Interval(0.1, 0.4, "hi"), Interval(0.5, 0.9, "there")]}, 1.0)
        out["TextGrid"].append(p)
        p = folder / f"s.txt{suffix}"
        write_semantic(
            p, [SemanticSegment("01_beat_align", 0.0, 1.5, 1.5, 0.5, "go"), SemanticSegment("x", 2, 3, 1, 1)]
        )
        out["txt"].append(p)
        p = folder / f"e.csv{suffix}"
        write_emotion(p, [EmotionSegment("take", 0.0, 2.0, 2.0, 3), EmotionSegment("take", 2.0, 3.0, 1.0, 0)])
        out["csv"].append(p)
    p = folder / "stereo.wav"
    write_wav(p, 0.2 * np.stack([np.sin(np.arange(2400) / 3.0)] * 2, axis=1), 48000, subtype="PCM_24")
    out["wav"].append(p)
    return out


READERS: list[tuple[str, str, Callable[[Path], object]]] = [
    ("read_bvh", "bvh", read_bvh),
    ("read_bvh_header", "bvh", read_bvh_header),
    ("read_audio", "wav", read_audio),
    ("audio_info", "wav", audio_info),
    ("read_facial", "json", lambda p: read_facial(p, names=ARKIT_51)),
    ("read_textgrid", "TextGrid", read_textgrid),
    ("read_semantic", "txt", read_semantic),
    ("read_emotion", "csv", read_emotion),
]


# ----------------------------------------------------------------------------- guards
class Hang(Exception):
    pass


@contextlib.contextmanager
def hang_guard(seconds: float) -> Iterator[None]:
    """Raise :class:`Hang` after ``seconds`` of wall time (POSIX main thread; elsewhere no guard)."""
    if not hasattr(signal, "setitimer") or threading.current_thread() is not threading.main_thread():
        yield
        return

    def alarm(signum: int, frame: object) -> None:
        raise Hang(f"no answer after {seconds} s")

    previous = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def _decompressed_size(data: bytes) -> int:
    try:
        return len(gzip.decompress(data)) if data[:2] == b"\x1f\x8b" else len(data)
    except (OSError, EOFError, zlib.error):
        return len(data)


def run_guarded(reader: Callable[[Path], object], path: Path) -> str:
    """Call ``reader(path)``: ``"ok"``, ``"FormatError"`` or ``"OSError"``; fail on anything else."""
    data = path.read_bytes()
    before = (data, path.stat().st_mtime_ns, path.stat().st_mode, sorted(path.parent.iterdir()))
    tracemalloc.reset_peak()
    base = tracemalloc.get_traced_memory()[0]
    outcome = "ok"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            with hang_guard(HANG_LIMIT_S):
                reader(path)
        except FormatError:
            outcome = "FormatError"
        except OSError:
            outcome = "OSError"
        except Exception as exc:  # noqa: BLE001 - the point of the test
            pytest.fail(f"{path.name}: {type(exc).__name__}: {str(exc)[:300]} (input {data[:80]!r}...)")
    peak = tracemalloc.get_traced_memory()[1] - base
    # bounded by the file on disk: a gzipped input may inflate to GZIP_MAX_RATIO times its size (plus 1 MiB)
    limit = MEMORY_SLACK + MEMORY_PER_BYTE * min(_decompressed_size(data), GZIP_MAX_RATIO * len(data) + 2**20)
    assert peak <= limit, f"{path.name}: peak {peak} bytes > {limit} for {len(data)} input bytes"
    after = (path.read_bytes(), path.stat().st_mtime_ns, path.stat().st_mode, sorted(path.parent.iterdir()))
    assert after == before, f"{path.name}: the reader changed its input or its folder"
    return outcome


# ----------------------------------------------------------------------------- tests
@pytest.fixture(scope="module")
def seeds(tmp_path_factory: pytest.TempPathFactory) -> dict[str, list[Path]]:
    return seed_files(tmp_path_factory.mktemp("seeds"))


@pytest.mark.parametrize(("name", "kind", "reader"), READERS, ids=[r[0] for r in READERS])
def test_reader_survives_mutations(
    name: str, kind: str, reader: Callable[[Path], object], seeds: dict[str, list[Path]], tmp_path: Path
) -> None:
    rng = np.random.default_rng([SEED, READERS.index((name, kind, reader))])
    sources = [p.read_bytes() for p in seeds[kind]]
    counts = {"ok": 0, "FormatError": 0, "OSError": 0}
    ext = "." + kind
    tracemalloc.start()
    try:
        for i in range(N_PER_READER):
            path = tmp_path / f"in{i:03d}{ext}"
            path.write_bytes(mutate(sources[i % len(sources)], rng))
            counts[run_guarded(reader, path)] += 1
            path.unlink()
    finally:
        tracemalloc.stop()
    assert sum(counts.values()) == N_PER_READER >= 200
    assert counts["FormatError"] >= N_PER_READER // 10  # the mutations do break files
    print(f"fuzz {name}: {counts}")


def test_take_names_survive_mutations() -> None:
    rng = np.random.default_rng([SEED, 99])
    alphabet = list("0123456789_abcdeflnorstwy.") + [
        "\u00b2",
        "\u0662",
        "\uff11",
        "\x00",
        "/",
        " ",
        "9" * 4400,
    ]
    counts = {"ok": 0, "FormatError": 0}
    for _ in range(N_PER_READER):
        name = "2_scott_0_1_1"
        for _ in range(int(rng.integers(1, 4))):
            at = int(rng.integers(0, len(name) + 1))
            token = alphabet[int(rng.integers(len(alphabet)))]
            name = name[:at] + token + name[at + int(rng.integers(0, 3)) :]
        try:
            parse_take_name(name)
            counts["ok"] += 1
        except FormatError:
            counts["FormatError"] += 1
    assert sum(counts.values()) == N_PER_READER and counts["FormatError"] > 0
    print(f"fuzz parse_take_name: {counts}")
