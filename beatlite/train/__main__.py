"""Command line: ``python -m beatlite.train {fit,retrain-all,results,seeds}``.

``fit RECIPE --data DIR --out DIR [--preset paper] [--epochs N] [--seed S] [--device auto] [--resume]
[--batch-size B [--lr-scaling sqrt]] [--lr LR]
[--precision bf16] [--compile MODE] [--nondeterministic] [--audio-matmul auto] [--val-every N]`` trains one recipe
(the same command under ``torchrun --nproc_per_node=K -m beatlite.train fit ...`` trains on K processes: every
batch split over them, gradients averaged by ``DistributedDataParallel``, process 0 writing)
on any BEAT-format folder and writes everything under ``--out`` (never into the repository): the
float16 checkpoint ``<out>/<RECIPE>.pt``, the resumable one ``<out>/train/<RECIPE>.pt`` (``RECIPE-paper`` for
``--preset paper``: the model at the paper's size, the recipe's switches on top) and, unless the data
are the shipped ``data_samples/``, an FGD extractor trained on that data (``<out>/fgd_dirvec.pt``, once;
again when the train windows' fingerprint or ``--extractor-epochs`` changed)
for the per-epoch validation FGD (``--val-every N``: every N optimiser steps instead).

``retrain-all [--only NAME ...] [--seed S] [--jobs J]`` rebuilds every shipped checkpoint of
:data:`beatlite.train.recipes.RECIPES` (CaMN and its ablations, the baselines, HA2G and its
ablations) from the ``data_samples/`` (``$BEATLITE_DATA``) train split with its recipe, its shipped seed
(:func:`beatlite.train.seeds.recorded_shipped_seed`; ``--seed`` overrides) and
``BEATLITE_THREADS`` threads, writing the full training checkpoint to ``build/train/<name>.pt``,
a float16 inference copy to ``checkpoints/<name>.pt`` and the training times to
``build/train/times.json``. Without ``--only`` it then retrains the FGD extractors
(``python -m beatlite.metrics.extractor train --space dirvec``, ``--space pose`` and ``--space rot6d``).

``results [--out STEM] [--only NAME ...]`` evaluates every shipped checkpoint on the
test split (:func:`beatlite.train.evaluation.evaluate_models`) and writes
``build/results_models.md`` and ``.json``.

``seeds [--seeds S ...] [--only NAME ...] [--jobs J] [--force] [--ship]`` trains the recipes with every
seed (``build/seeds/<seed>/``; existing ones, the shipped checkpoint for its own seed included, are
kept when their stored settings and model config match today's recipe, see
:func:`beatlite.train.seeds.recipe_mismatch`), writes the mean ± sd table over the seeds to
``build/results_seeds.md`` and ``.json`` and, with ``--ship``, copies each row's median-FGD seed to
``checkpoints/`` (:mod:`beatlite.train.seeds`). With ``--only``, an existing ``--out`` table keeps its other
rows (``make seeds ONLY=NAME`` records a new model's rows in the shipped table).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

from beatlite import paths
from beatlite.io.atomic import atomic_write, exclusive_lock
from beatlite.models import model_class
from beatlite.train.config import AUDIO_MATMUL, COMPILE_BACKENDS, COMPILE_MODES
from beatlite.train.evaluation import RECORD_COLUMNS, evaluate_models, write_results
from beatlite.train.recipes import (
    RECIPES,
    SEED,
    recipe_train_config,
    retrain,
    retrain_many,
    run_name,
    training_data,
)
from beatlite.train.seeds import (
    evaluate_seeds,
    recorded_seed_results,
    recorded_shipped_seed,
    ship_median_seeds,
    train_seeds,
    write_seed_results,
)


def _record_times(seconds: dict[str, float]) -> None:
    """Merge ``seconds`` into ``build/train/times.json`` (name -> training seconds)."""
    import json

    path = paths.build_dir() / "train" / "times.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    times = json.loads(path.read_text()) if path.is_file() else {}
    times.update({k: round(v, 1) for k, v in seconds.items()})
    with atomic_write(path, "w") as fh:
        json.dump(times, fh, indent=2, sort_keys=True)


def main(argv: Sequence[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    command = {"fit": _fit_command, "results": _results_command, "seeds": _seeds_command}
    return command.get(args.command, _retrain_all_command)(args)


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m beatlite.train", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    f = sub.add_parser("fit", help="train one recipe on a BEAT-format folder, writing under --out")
    f.add_argument("recipe", choices=sorted(RECIPES))
    f.add_argument("--data", required=True, help="BEAT-format folder ({speaker_id}/{stem}.bvh, .wav, ...)")
    f.add_argument("--out", required=True, help="output folder (created; the repository is never written)")
    f.add_argument("--epochs", type=int, help="default: the recipe's (>= 1 for a recipe that trains)")
    f.add_argument("--seed", type=int, default=SEED)
    f.add_argument("--device", default="auto", help="cpu, cuda or auto (CUDA when available)")
    f.add_argument("--resume", action="store_true", help="continue <out>/train/<recipe>.pt")
    f.add_argument("--checkpoint-every", type=int, help="also checkpoint every N steps inside an epoch")
    f.add_argument(
        "--val-every",
        type=int,
        help="validate (losses, FGD, best weights) every N optimiser steps instead of every epoch",
    )
    f.add_argument(
        "--batch-size",
        type=int,
        help="windows per step (default: the recipe's, its gpu_batch_size and gpu_lr on CUDA); learning rates scale with it (--lr-scaling)",
    )
    f.add_argument(
        "--lr",
        type=float,
        help="generator learning rate at the run's batch, as given (--lr-scaling then unused; default: the recipe's, scaled to the batch)",
    )
    f.add_argument(
        "--preset",
        default="tiny",
        help="the model's size: tiny (the recipes', default) or paper; checkpoints of paper are named RECIPE-paper.pt",
    )
    f.add_argument(
        "--lr-scaling",
        choices=("linear", "sqrt"),
        default="linear",
        help="how the learning rates follow --batch-size: linearly (default) or by its square root (recipes.scaled_lr)",
    )
    f.add_argument(
        "--data-on-device",
        choices=("auto", "always", "never"),
        default="auto",
        help="hold the store's streams on the device, batches gathered there (auto: CUDA when they fit in half its free memory)",
    )
    f.add_argument(
        "--precision",
        choices=("fp32", "bf16"),
        default="fp32",
        help="bf16: bfloat16 autocast (TrainConfig.amp; weights and optimiser stay float32)",
    )
    f.add_argument(
        "--compile",
        choices=COMPILE_MODES + COMPILE_BACKENDS,
        help="torch.compile the forward pass and losses (reduce-overhead: CUDA graphs); default eager",
    )
    f.add_argument(
        "--nondeterministic",
        action="store_true",
        help="let CUDA use its faster nondeterministic kernels (TrainConfig.deterministic=False)",
    )
    f.add_argument(
        "--audio-matmul",
        choices=AUDIO_MATMUL,
        default="auto",
        help="raw-audio convolutions as one matrix product of the waveform's frames (auto: on CUDA; TrainConfig.audio_matmul)",
    )
    f.add_argument(
        "--extractor-epochs",
        type=int,
        default=100,
        help="epochs of the FGD extractor trained for new data (once; again for other data or epochs)",
    )
    p = sub.add_parser("retrain-all", help="retrain every shipped checkpoint on data_samples/")
    p.add_argument("--seed", type=int, help="default: each recipe's shipped seed in the recorded seed table")
    p.add_argument("--epochs", type=int, help="override every recipe's epochs (for quick checks)")
    p.add_argument("--only", nargs="*", choices=sorted(RECIPES), help="retrain only these")
    p.add_argument("--jobs", type=int, default=1, help="training processes at once (1 thread each)")
    p.add_argument("--skip-extractor", action="store_true", help="do not retrain the FGD extractors")
    r = sub.add_parser("results", help="evaluate the shipped checkpoints -> build/results_models.md/.json")
    r.add_argument("--out", help="output stem (default build/results_models)")
    r.add_argument("--only", nargs="*", help="checkpoint names (default: every shipped one)")
    s = sub.add_parser("seeds", help="train other seeds -> build/results_seeds.md/.json (mean ± sd)")
    s.add_argument("--seeds", nargs="+", type=int, default=[SEED, 2022, 2023])
    s.add_argument("--only", nargs="*", choices=sorted(RECIPES), help="these checkpoints only")
    s.add_argument("--jobs", type=int, default=1, help="training processes at once (1 thread each)")
    s.add_argument("--out", help="output stem (default build/results_seeds)")
    s.add_argument(
        "--evaluate-only", action="store_true", help="train nothing; rows lacking a seed get fewer values"
    )
    s.add_argument(
        "--force", action="store_true", help="retrain checkpoints that exist and match their recipe"
    )
    s.add_argument(
        "--ship",
        action="store_true",
        help="copy each row's median-FGD seed to checkpoints/ (ship_median_seeds)",
    )
    return parser


def _results_command(args: argparse.Namespace) -> int:
    folder = paths.checkpoints_dir()
    missing = [name for name in args.only or () if not (folder / f"{name}.pt").is_file()]
    if missing:  # before loading the test set; evaluate_models would stop on the first with a traceback
        there = sorted(p.stem for p in folder.glob("*.pt") if not p.stem.startswith("fgd_"))
        return _refused(
            f"results: no checkpoint {', '.join(missing)} in {folder} (there: {', '.join(there)})"
        )
    results = evaluate_models(args.only or None, progress=True)
    md, js = write_results(results, args.out)
    print(results.to_markdown())
    print(f"wrote {md} and {js} in {results.info['seconds']:.1f} s")
    return 0


def _seeds_command(args: argparse.Namespace) -> int:
    if not args.evaluate_only:
        train_seeds(args.only or None, args.seeds, jobs=args.jobs, force=args.force)
    missing = "skip" if args.evaluate_only else "error"
    table = evaluate_seeds(
        args.only or None, args.seeds, missing=missing, progress=True, columns=RECORD_COLUMNS
    )
    if args.ship:
        for name, seed in ship_median_seeds(table, args.only or None).items():
            print(f"shipped {name}: seed {seed}", flush=True)
    if args.only and args.out and Path(f"{args.out}.json").is_file():  # record these rows, keep the others
        table = recorded_seed_results(f"{args.out}.json").merged(table)
    md, js = write_seed_results(table, args.out)
    print(table.to_markdown())
    print(f"wrote {md} and {js}")
    return 0


def _retrain_all_command(args: argparse.Namespace) -> int:
    def report(name: str, seed: int, seconds: float) -> None:
        print(f"{name}: {seconds:.1f} s", flush=True)
        _record_times({name: seconds})

    names = args.only or list(RECIPES)
    runs = [(name, recorded_shipped_seed(name) if args.seed is None else args.seed, None) for name in names]
    retrain_many(runs, jobs=args.jobs, epochs=args.epochs, on_done=report)
    if not args.skip_extractor and not args.only:
        for space in ("dirvec", "pose", "rot6d"):
            cmd = [sys.executable, "-m", "beatlite.metrics.extractor", "train", "--space", space]
            subprocess.run(cmd, check=True)
    return 0


def _fit_command(args: argparse.Namespace) -> int:
    """``fit``: one recipe on ``--data``, every file under ``--out``.

    The data are prepared before any process group exists: the window store (built once, then only
    changed takes) and, for data other than ``data_samples/``, the FGD extractor (trained once, again for other
    data or ``--extractor-epochs``). Under
    ``torchrun`` each process does it under a file lock (:func:`beatlite.io.atomic.exclusive_lock`):
    the first builds, the others wait (no time limit, no collective) and find it done.

    One run of a recipe trains into one ``--out`` at a time: process 0 holds ``<out>/train/.<RECIPE>.lock``
    until it ends, and a second run refuses at once (exit 2) instead of overwriting the first's checkpoints
    (or resuming from them) while it trains.
    """

    from beatlite.train.distributed import process_group
    from beatlite.train.training import check_batch_split, check_compilable  # (imports torch)

    options = {
        "seed": args.seed,
        "epochs": args.epochs,
        "resume": args.resume,
        "device": args.device,
        "checkpoint_every": args.checkpoint_every,
        "batch_size": args.batch_size,
        "data_on_device": args.data_on_device,
        "amp": args.precision == "bf16",
        "compile": args.compile,
        "val_every": args.val_every,
        "deterministic": not args.nondeterministic,
        "lr_scaling": args.lr_scaling,
        "audio_matmul": args.audio_matmul,
        "lr": args.lr,
        "preset": args.preset,
    }
    try:  # before anything is prepared or written: the flags' values, the device, the compiler
        config = recipe_train_config(args.recipe, **options)
        check_compilable(model_class(RECIPES[args.recipe].model), args.compile)
        if config.epochs > 0:  # (an untrained baseline takes no step)
            check_batch_split(config, int(os.environ.get("WORLD_SIZE", "1")))  # (torchrun's process count)
    except ValueError as error:
        return _refused(error)
    data_dir, out = Path(args.data).expanduser().resolve(), Path(args.out).expanduser().resolve()
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        return _refused(f"cannot write --out {out}: {error}")
    os.environ.setdefault(
        "BEATLITE_BUILD", str(out / "build")
    )  # the index, the store and caches under --out too
    rank = int(os.environ.get("RANK", "0"))
    stem = run_name(args.recipe, args.preset)
    lock = out / "train" / f".{stem}.lock"
    with contextlib.ExitStack() as held:
        if rank == 0:  # one run of a recipe per --out at a time (under torchrun, process 0 holds it for all)
            try:
                held.enter_context(exclusive_lock(lock, wait=False))
            except BlockingIOError:
                return _refused(
                    f"another fit is training {stem} into {out} (it holds {lock}); "
                    "wait for it to end, or give another --out"
                )
            except OSError as error:  # a read-only --out, a full disk
                return _refused(f"cannot write --out {out}: {error}")
        # under torchrun: the process group the training initialises is destroyed when this block ends (also by
        # an exception), not left to an exit handler that handlers registered later run before
        with process_group():
            return _fit_locked(args, options, data_dir, out, rank)


def _fit_locked(
    args: argparse.Namespace, options: dict[str, object], data_dir: Path, out: Path, rank: int
) -> int:
    """``fit`` once its flags are checked and (on process 0) the run's lock is held: prepare, train, export."""
    from beatlite.train.training import ResumeError

    try:
        data = training_data(data_dir, progress=rank == 0)
    except (ValueError, OSError) as error:  # no val take, a file that cannot be read (FormatError) or written
        return _refused(error)
    extractor = None
    if data_dir != (paths.repo_root() / "data_samples").resolve():
        extractor = out / "fgd_dirvec.pt"
        with exclusive_lock(out / ".fgd_dirvec.lock"):
            stale = _stale_extractor(extractor, data.train.fingerprint, args.extractor_epochs)
            if stale is not None:
                if extractor.is_file():
                    print(f"{extractor} is stale ({stale}): training it again", flush=True)
                _train_extractor(data_dir, extractor, args.extractor_epochs)
    try:
        seconds = retrain(args.recipe, out_dir=out, data=data, extractor=extractor, **options)
    except (ResumeError, FloatingPointError) as error:  # --resume of other data, model or plan; diverged
        return _refused(error)
    if rank == 0:
        stem = run_name(args.recipe, args.preset)
        print(f"{stem}: {seconds:.1f} s of training; wrote {out / (stem + '.pt')}", flush=True)
    return 0


def _refused(error: Exception | str) -> int:
    """Print why ``fit`` refuses to run as one ``error:`` line on stderr; the exit status 2."""
    print(f"error: {error}", file=sys.stderr)
    return 2


def _stale_extractor(path: Path, fingerprint: str, epochs: int) -> str | None:
    """Why the FGD extractor at ``path`` is not the one ``fit`` would train on train windows of data
    ``fingerprint`` for ``epochs`` epochs (none yet, other data, other epochs); None when it is."""
    if not path.is_file():
        return "none yet"
    from beatlite.metrics.extractor import load_extractor

    found = load_extractor("dirvec", path)
    trained_on, trained_for = found.meta.get("data_fingerprint"), found.model.config.epochs
    if trained_on != fingerprint:
        return f"trained on data {trained_on}, the train windows are {fingerprint}"
    if trained_for != epochs:
        return f"trained for {trained_for} epochs, --extractor-epochs is {epochs}"
    return None


def _train_extractor(data_dir: object, path: object, epochs: int) -> None:
    """Train the dirvec FGD extractor of ``data_dir`` into ``path`` (its command, in a child process, on
    the window store the parent built: ``BEATLITE_BUILD`` is inherited)."""
    print(
        f"training the FGD extractor on {data_dir} -> {path} ({epochs} epochs on the train windows)",
        flush=True,
    )
    cmd = [
        sys.executable,
        "-m",
        "beatlite.metrics.extractor",
        "train",
        "--space",
        "dirvec",
        "--epochs",
        str(epochs),
    ]
    subprocess.run([*cmd, "--data", str(data_dir), "--out", str(path)], check=True)


if __name__ == "__main__":
    raise SystemExit(main())
