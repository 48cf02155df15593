"""The README's ``fit`` command on a BEAT-rate corpus: wall time, peak memory and where the time goes.

It makes (or reuses, ``--corpus``) a corpus of ``--hours`` of BEAT-rate takes with
:func:`bench_scale.make_corpus`, then runs the command the README gives for real data,
``python -m beatlite.train fit RECIPE --data CORPUS --out OUT --epochs 1 --device cpu``, twice on the
same ``OUT``: ``fresh`` (index, window store, FGD extractor and training all from nothing) and
``again`` (index cached, store current, extractor kept: only training). Each run is started from a
fresh measuring process, so that its peak RSS (``ru_maxrss`` of the largest process of the command's
tree: the main process, the store-build workers, the extractor's process) is its own, as ``/usr/bin/time
-v`` reports it.

Where the time goes is read from the command's own lines, each stamped with the second it arrived:
``prepare_s`` (index and store: until the extractor's first line, or until training starts),
``extractor_s`` (the seconds the extractor prints when it writes itself), and ``train_s`` (the seconds
``fit`` prints for training and its validations).

Usage: ``python bench/bench_fit_command.py [--hours 4] [--recipe camn_tiny] [--corpus DIR] [--keep DIR]
[--json FILE] [--fit-args="--device cuda --preset paper ..."]``: ``--fit-args`` (one string, given with ``=``)
is appended to the command, so its flags override the defaults (``--device cuda``: the command on a GPU,
``bash bench/gpu_session.sh fit``). A 4-hour corpus needs about 8 GB of temporary disk and about 10 minutes on
2 cores.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("BEATLITE_THREADS", "1")

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_scale import make_corpus, run_step  # noqa: E402

from beatlite.io.atomic import write_json  # noqa: E402
from beatlite.paths import n_threads, record_about  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
EXTRACTOR_START = "training the FGD extractor"
EXTRACTOR_WROTE = re.compile(r"^wrote .*fgd_dirvec\.pt .* in (\d+) s")
TRAINED = re.compile(r"^\S+: ([0-9.]+) s of training; wrote ")


def fit_command(
    recipe: str, corpus: Path, out: Path, extractor_epochs: int | None = None, fit_args: str = ""
) -> list[str]:
    """The README's command for real data, as an argument list (``extractor_epochs``: None for fit's default;
    ``fit_args``: more flags, appended, so that they override the defaults).

    >>> fit_command("camn_tiny", Path("c"), Path("o"), 2, "--device cuda --preset paper")[4:]
    ['camn_tiny', '--data', 'c', '--out', 'o', '--epochs', '1', '--device', 'cpu', '--extractor-epochs', '2', '--device', 'cuda', '--preset', 'paper']
    """
    extra = [] if extractor_epochs is None else ["--extractor-epochs", str(extractor_epochs)]
    return [sys.executable, "-m", "beatlite.train", "fit", recipe, "--data", str(corpus), "--out", str(out),
            "--epochs", "1", "--device", "cpu", *extra, *shlex.split(fit_args)]  # fmt: skip


def phases(lines: list[tuple[float, str]], wall_s: float) -> dict[str, float | None]:
    """Seconds of each phase from the command's ``(arrival second, line)`` pairs (None: the phase did not run).

    >>> phases([(30.0, "training the FGD extractor on c -> o (100 epochs on the train windows)"),
    ...         (400.0, "wrote o/fgd_dirvec.pt (1.00 MB) in 369 s; ..."),
    ...         (460.0, "camn_tiny: 58.0 s of training; wrote o/camn_tiny.pt")], 461.0)
    {'prepare_s': 30.0, 'extractor_s': 369.0, 'train_s': 58.0}
    """
    started = next((t for t, line in lines if line.startswith(EXTRACTOR_START)), None)
    wrote = next((float(m[1]) for _, line in lines if (m := EXTRACTOR_WROTE.match(line))), None)
    train = next((float(m[1]) for _, line in lines if (m := TRAINED.match(line))), None)
    prepare = started if started is not None else (None if train is None else wall_s - train)
    return {"prepare_s": prepare, "extractor_s": wrote, "train_s": train}


# fit's bar, e.g. "camn:  33%|###  | 1/3 [00:09<00:18, 4.5s/epoch, rec=0.4]"
EPOCH_BAR = re.compile(r" (\d+)/(\d+) \[[^]]*epoch")


def epoch_ends(lines: list[tuple[float, str]]) -> list[float]:
    """The second each epoch of fit's training ended (its checkpoint written), from the ``(arrival second, line)``
    pairs: the arrival of the last state of fit's bar at each count (after the extractor's lines).

    The bar redraws its line after a carriage return, which the reader (text mode) takes as a line end, and
    a line ending so arrives with the next write: the last state at count k arrives when the bar moves to k+1,
    after epoch k's validation and checkpoint.

    >>> bar = "camn: {}/3 [00:0{}<?, {}s/epoch, rec={}]"
    >>> epoch_ends([(5.0, bar.format(0, 0, "?", "?")), (5.1, bar.format(0, 4, "?", 0.5)), (8.0, bar.format(1, 4, 4, 0.5)),
    ...             (8.1, bar.format(1, 7, 4, 0.4)), (11.0, bar.format(2, 7, 3.5, 0.4)), (11.1, bar.format(2, 9, 3.5, 0.3)),
    ...             (11.2, bar.format(3, 9, 3.3, 0.3)), (11.3, "camn_tiny: 10.4 s of training; wrote o")])
    [5.1, 8.1, 11.1]
    """
    start = max((i for i, (_, line) in enumerate(lines) if EXTRACTOR_WROTE.match(line)), default=-1) + 1
    last: dict[int, float] = {}
    for t, line in lines[start:]:
        if (m := EPOCH_BAR.search(line)) and int(m[1]) < int(m[2]):
            last[int(m[1])] = t
    return [last[k] for k in sorted(last)]


def measure(command: list[str], **popen: object) -> tuple[dict, list[tuple[float, str]]]:
    """Run ``command`` as this process's only child (call it once per fresh process, so that the peak is the
    command's own): its wall and CPU seconds and peak RSS (``ru_maxrss`` of the largest process of its tree,
    KiB and GiB), and its output lines with the second each arrived. ``RuntimeError`` with the output's end
    when it fails."""
    tic = time.perf_counter()
    child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, bufsize=1,
                             **popen)  # fmt: skip
    lines = []
    for line in child.stdout:  # (text mode ends a line at \r too: every state of a progress bar is a line)
        lines.append((time.perf_counter() - tic, line.rstrip("\n")))
    if child.wait() != 0:
        tail = "\n".join(line for _, line in lines[-40:])
        raise RuntimeError(f"{' '.join(command)} exited {child.returncode}:\n{tail}")
    wall = time.perf_counter() - tic
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return {
        "wall_s": wall,
        "cpu_s": usage.ru_utime + usage.ru_stime,
        "peak_rss_kib": usage.ru_maxrss,
        "peak_rss_gib": usage.ru_maxrss / 2**20,
    }, lines


def step_fit(
    recipe: str, corpus: Path, out: Path, extractor_epochs: int | None = None, fit_args: str = ""
) -> dict:
    """Run the command once (in this fresh process's only child): its wall seconds, peak RSS and phases, and
    its last 16 output lines with the second each arrived."""
    got, lines = measure(fit_command(recipe, corpus, out, extractor_epochs, fit_args))
    tail = [line.replace(str(out), "<run>").replace(str(corpus), "<corpus>") for _, line in lines[-16:]]
    at = [round(t, 2) for t, _ in lines[-16:]]  # (when each arrived: the epochs' progress lines time them)
    ends = epoch_ends(lines)
    return {**got, **phases(lines, got["wall_s"]), "epoch_ends_s": [round(t, 2) for t in ends],
            "epoch_s": [round(b - a, 2) for a, b in zip(ends, ends[1:])],  # (every epoch after the first)
            "output_tail": tail, "output_tail_at_s": at}  # fmt: skip


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--hours", type=float, default=4.0, help="corpus size to make (default 4)")
    p.add_argument("--recipe", default="camn_tiny", help="the recipe fit trains (default camn_tiny)")
    p.add_argument("--corpus", type=Path, default=None, help="use this corpus instead of making one")
    p.add_argument("--data", type=Path, default=REPO / "data_samples", help="source of the corpus made")
    p.add_argument("--workers", type=int, default=2, help="processes making the corpus")
    p.add_argument("--keep", type=Path, default=None, help="keep the corpus and the run under this folder")
    p.add_argument(
        "--json", type=Path, default=None, help="write the runs, command, revision and machine here"
    )
    p.add_argument("--extractor-epochs", type=int, default=None, help="passed to fit (default: fit's own)")
    p.add_argument(
        "--fit-args", default="", help='more fit flags, one string: --fit-args="--device cuda ..."'
    )
    p.add_argument("--step", nargs=3, metavar=("RECIPE", "CORPUS", "OUT"), help=argparse.SUPPRESS)
    args = p.parse_args()
    if args.step:
        step = step_fit(
            args.step[0], Path(args.step[1]), Path(args.step[2]), args.extractor_epochs, args.fit_args
        )
        print(json.dumps(step))
        return 0
    if args.keep is not None:
        args.keep.mkdir(parents=True, exist_ok=True)
    about = {
        **record_about(threads=n_threads()),
        "fit_command": " ".join(
            [
                "python",
                *fit_command(
                    args.recipe, Path("<corpus>"), Path("<run>"), args.extractor_epochs, args.fit_args
                )[1:],
            ]
        ),
        "hours": args.hours if args.corpus is None else None,
    }  # fmt: skip  (before the corpus is made: the load average is what else ran)
    base = Path(tempfile.mkdtemp(prefix="bench_fit_command_", dir=args.keep))
    try:
        corpus = args.corpus
        if corpus is None:
            corpus = base / "corpus"
            print(f"making a {args.hours:g}-hour corpus in {corpus}", flush=True)
            make_corpus(args.data, corpus, args.hours, args.workers)
        runs = {}
        for name in ("fresh", "again"):
            epochs = (
                [] if args.extractor_epochs is None else ["--extractor-epochs", str(args.extractor_epochs)]
            )
            more = [f"--fit-args={args.fit_args}"] if args.fit_args else []
            runs[name] = run_step(
                ["--step", args.recipe, str(corpus), str(base / "run"), *epochs, *more], __file__
            )
            print(
                f"{name}: {json.dumps({k: v for k, v in runs[name].items() if k != 'output_tail'})}",
                flush=True,
            )
            if args.json is not None:  # after every run: a run stopped later keeps what it measured
                write_json(args.json, {**about, "runs": runs})
    finally:
        if args.keep is None:
            shutil.rmtree(base, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
