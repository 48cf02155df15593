"""Where beatlite finds its data, checkpoints and outputs.

Every function reads the environment at call time (no global state):

- ``BEATLITE_DATA``: the BEAT-format folder to use (default: the repository's
  ``data_samples/``). Point it at a real BEAT download to run everything on it.
- ``BEATLITE_MODE``: ``lecture`` (default; load shipped checkpoints) or ``full``
  (train live).
- ``BEATLITE_THREADS``: torch CPU threads (default 1; see :func:`n_threads`).
- ``BEATLITE_BUILD``: output folder of the main job (default ``build/``).
- ``BEATLITE_PYVISTA``: ``off`` forces matplotlib instead of pyvista (see :mod:`beatlite.viz.probe`).
- ``BEATLITE_INTERACTIVE``: ``off`` means no widgets (text progress bars, static 3D images) even in a
  Jupyter kernel (see :func:`beatlite.notebook.interactive`).

Taught in notebooks/00_setup_and_tour.ipynb, sections 1 (the environment) and 4 (running everything on the real BEAT dataset).
"""

from __future__ import annotations

import os
from pathlib import Path

MODES = ("lecture", "full")


def repo_root() -> Path:
    """The repository root (the folder that holds ``beatlite/``).

    Examples
    --------
    >>> (repo_root() / "beatlite" / "paths.py").is_file()
    True
    """
    return Path(__file__).resolve().parent.parent


def data_dir() -> Path:
    """The BEAT-format data folder: ``$BEATLITE_DATA`` (``~`` expanded) or ``<repo>/data_samples``.

    Examples
    --------
    The variable is read at every call, so a notebook can switch corpora without restarting:

    >>> from unittest import mock
    >>> with mock.patch.dict(os.environ, {"BEATLITE_DATA": "/data/beat_english_v0.2.1"}):
    ...     data_dir().as_posix()
    '/data/beat_english_v0.2.1'
    >>> with mock.patch.dict(os.environ, {"BEATLITE_DATA": ""}):
    ...     data_dir() == repo_root() / "data_samples"
    True
    """
    env = os.environ.get("BEATLITE_DATA")
    return Path(env).expanduser() if env else repo_root() / "data_samples"


def checkpoints_dir() -> Path:
    """Folder of the shipped checkpoints: ``<repo>/checkpoints`` (no variable moves it).

    Examples
    --------
    >>> checkpoints_dir().relative_to(repo_root()).as_posix()
    'checkpoints'
    """
    return repo_root() / "checkpoints"


def build_dir() -> Path:
    """Output folder of the main job: ``$BEATLITE_BUILD`` (``~`` expanded) or ``<repo>/build``.

    Examples
    --------
    >>> from unittest import mock
    >>> with mock.patch.dict(os.environ, {"BEATLITE_BUILD": "/scratch/run1"}):
    ...     build_dir().as_posix(), cache_dir().as_posix()
    ('/scratch/run1', '/scratch/run1/cache')
    >>> with mock.patch.dict(os.environ, {"BEATLITE_BUILD": ""}):
    ...     build_dir().relative_to(repo_root()).as_posix()
    'build'
    """
    env = os.environ.get("BEATLITE_BUILD")
    return Path(env).expanduser() if env else repo_root() / "build"


def cache_dir() -> Path:
    """Folder for derived caches (the index cache, the window stores): ``<build>/cache``.

    Examples
    --------
    >>> cache_dir() == build_dir() / "cache"
    True
    """
    return build_dir() / "cache"


def mode() -> str:
    """``"lecture"`` (load checkpoints, the default) or ``"full"`` (train live) from ``$BEATLITE_MODE``.

    Case and surrounding spaces are ignored; an empty value means ``"lecture"``.

    Raises
    ------
    ValueError
        Any other value.

    Examples
    --------
    >>> from unittest import mock
    >>> with mock.patch.dict(os.environ, {"BEATLITE_MODE": " Full "}):
    ...     mode()
    'full'
    >>> with mock.patch.dict(os.environ, {"BEATLITE_MODE": "train"}):
    ...     mode()
    Traceback (most recent call last):
    ...
    ValueError: BEATLITE_MODE must be one of ('lecture', 'full'), got 'train'
    """
    return env_choice("BEATLITE_MODE", MODES)


def env_choice(name: str, choices: tuple[str, ...]) -> str:
    """The value of environment variable ``name``, one of ``choices`` (case and surrounding spaces ignored;
    unset or empty: ``choices[0]``), read at every call.

    Raises
    ------
    ValueError
        Any other value, naming the variable and the choices.

    Examples
    --------
    >>> from unittest import mock
    >>> with mock.patch.dict(os.environ, {"BEATLITE_DEMO": " B "}):
    ...     env_choice("BEATLITE_DEMO", ("a", "b")), env_choice("BEATLITE_UNSET_DEMO", ("a", "b"))
    ('b', 'a')
    """
    value = os.environ.get(name, "").strip().lower() or choices[0]
    if value not in choices:
        raise ValueError(f"{name} must be one of {choices}, got {value!r}")
    return value


def n_threads() -> int:
    """Torch CPU threads from ``$BEATLITE_THREADS`` (default 1).

    One thread is the safe default on a shared 2-core machine: two OpenMP
    threads next to any other busy process spin-wait and run 10x slower.

    Raises
    ------
    ValueError
        The value is not an integer >= 1.

    Examples
    --------
    >>> from unittest import mock
    >>> with mock.patch.dict(os.environ, {"BEATLITE_THREADS": "4"}):
    ...     n_threads()
    4
    >>> with mock.patch.dict(os.environ, {"BEATLITE_THREADS": "0"}):
    ...     n_threads()
    Traceback (most recent call last):
    ...
    ValueError: BEATLITE_THREADS must be a positive integer, got '0'
    """
    value = os.environ.get("BEATLITE_THREADS", "1")
    try:
        n = int(value)
    except ValueError:
        raise ValueError(f"BEATLITE_THREADS must be a positive integer, got {value!r}") from None
    if n < 1:
        raise ValueError(f"BEATLITE_THREADS must be a positive integer, got {value!r}")
    return n


def on_data_samples() -> bool:
    """Whether :func:`data_dir` is the repository's own synthetic ``data_samples/`` folder.

    Notebooks assert the effects planted in ``data_samples/`` only when this is true; on any other
    BEAT-format folder they report the same quantities without asserting them.

    Examples
    --------
    >>> from unittest import mock
    >>> with mock.patch.dict(os.environ, {"BEATLITE_DATA": str(repo_root() / "data_samples")}):
    ...     on_data_samples()
    True
    >>> with mock.patch.dict(os.environ, {"BEATLITE_DATA": "/data/beat_english_v0.2.1"}):
    ...     on_data_samples()
    False
    """
    return data_dir().resolve() == (repo_root() / "data_samples").resolve()


def shareable(path: str | os.PathLike[str]) -> str:
    """``path`` as the files beatlite writes for others record it (checkpoints, score reports, results tables):
    never an absolute path of this machine, which would name its home folder, user or host.

    Relative to the repository root when inside it (``"checkpoints/fgd_dirvec.pt"``, ``"data_samples"``,
    ``"build/seeds/2022/camn_tiny.pt"``), else to :func:`build_dir` as ``"$BEATLITE_BUILD/..."``; a relative
    path that stays below the working folder as given (``"my_outputs"``); anything else by its last component,
    the file's or folder's name (``"beat_english_v0.2.1"``).

    >>> shareable(repo_root() / "checkpoints" / "camn_tiny.pt"), shareable("/somewhere/else/beat_v2")
    ('checkpoints/camn_tiny.pt', 'beat_v2')
    """
    given = Path(path).expanduser()
    if not given.is_absolute() and ".." not in given.parts:
        return given.as_posix()
    full = Path(os.path.abspath(given))
    for root, prefix in ((repo_root(), ""), (build_dir(), "$BEATLITE_BUILD/")):
        for candidate in (full, full.resolve()):
            try:
                rel = candidate.relative_to(Path(os.path.abspath(root)).resolve())
            except ValueError:
                continue
            if prefix:
                return prefix + rel.as_posix() if rel.parts else prefix.rstrip("/")
            return rel.as_posix() if rel.parts else "."
    return full.name or "."


def code_revision() -> str:
    """The repository's commit, for the records the benchmarks write: ``git rev-parse --short HEAD``, with
    ``+changes`` when tracked files differ from it, or ``"unknown"`` outside a git checkout.

    Examples
    --------
    The value differs from checkout to checkout; its form does not:

    >>> import re
    >>> re.fullmatch(r"[0-9a-f]{4,40}([+]changes)?|unknown", code_revision()) is not None
    True
    """
    import subprocess

    def git(*args: str) -> str:
        done = subprocess.run(["git", *args], cwd=repo_root(), capture_output=True, text=True, timeout=30)
        return done.stdout.strip() if done.returncode == 0 else ""

    try:
        head = git("rev-parse", "--short", "HEAD")
        changed = bool(git("status", "--porcelain", "--untracked-files=no"))
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return (head + ("+changes" if changed else "")) if head else "unknown"


def record_about(**machine_fields: object) -> dict[str, object]:
    """The head of every benchmark record: ``command`` (``python`` and this process's arguments), ``revision``
    (:func:`code_revision`), ``date`` (YYYY-MM-DD) and ``machine`` (:func:`machine`, with ``machine_fields``
    replacing its fields, e.g. ``threads=None`` for a process that trains nothing itself).

    Call it when the run starts: before the run writes its record (a tracked file, which would make the
    revision read ``+changes``) and before its own work loads the machine (the load average is what else ran).

    >>> about = record_about(threads=None)
    >>> sorted(about), about["machine"]["threads"]
    (['command', 'date', 'machine', 'revision'], None)
    """
    import sys
    import time

    return {"command": " ".join(["python", *sys.argv]), "revision": code_revision(),
            "date": time.strftime("%Y-%m-%d"), "machine": {**machine(), **machine_fields}}  # fmt: skip


def machine() -> dict[str, object]:
    """What ran a benchmark record, in every record's ``machine`` field: host name, CPU model and count,
    the vector instructions torch's CPU kernels use (``torch.backends.cpu.get_cpu_capability()``: ``"AVX2"``,
    ``"AVX512"``, ...; two CPUs that /proc/cpuinfo names alike, e.g. "AMD EPYC", can differ there, and then
    train at different speeds and round differently), the 1-minute load average when asked (other jobs slow a
    timing down), torch's version and CPU threads, and the CUDA device's name (``None`` without one).

    >>> sorted(machine())
    ['cpu', 'cpu_capability', 'cpus', 'cuda', 'host', 'load_average', 'threads', 'torch']
    """
    import contextlib
    import platform

    import torch

    cpu = platform.processor() or platform.machine()
    with contextlib.suppress(OSError):
        names = [line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines()
                 if line.startswith("model name")]  # fmt: skip
        cpu = names[0] if names else cpu
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else None
    cuda = torch.cuda.get_device_name(0) if torch.cuda.is_available() else None
    return {"host": platform.node(), "cpu": cpu, "cpu_capability": torch.backends.cpu.get_cpu_capability(),
            "cpus": os.cpu_count(), "load_average": load, "torch": torch.__version__,
            "threads": torch.get_num_threads(), "cuda": cuda}  # fmt: skip
