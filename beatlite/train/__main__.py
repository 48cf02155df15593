"""Command line: ``python -m beatlite.train {retrain-all,results}``.

``retrain-all [--only NAME ...] [--epochs N]`` rebuilds every shipped checkpoint of
:data:`CHECKPOINTS` from the ``data_samples/`` (``$BEATLITE_DATA``) train split (windows
of 34 frames, stride 10; validation on the val split) with the settings of
:data:`TRAINING` and ``BEATLITE_THREADS`` threads, writing the full training checkpoint
to ``build/train/<name>.pt``, a float16 inference copy to ``checkpoints/<name>.pt`` and the
training times to ``build/train/times.json``. Without ``--only`` it then calls HA2G's
trainer (:func:`beatlite.models.ha2g.retrain`) and the FGD extractor's
(``python -m beatlite.metrics.extractor train --space dirvec`` and ``--space pose``).

``results [--out STEM] [--only NAME ...]`` evaluates every shipped checkpoint on the
test split (:func:`beatlite.train.evaluation.evaluate_models`) and writes
``build/results_models.md`` and ``.json``.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from collections.abc import Sequence
from typing import Any

ABLATIONS: dict[str, dict[str, Any]] = {
    "camn_tiny": {},
    "camn_tiny_no_audio": {"use_audio": False},
    "camn_tiny_no_text": {"use_text": False},
    "camn_tiny_no_face": {"use_face": False},
    "camn_tiny_no_emotion": {"use_emotion": False},
    "camn_tiny_no_speaker": {"use_speaker": False},
    "camn_tiny_no_cascade": {"cascade": False},
    "camn_tiny_no_semantic": {"semantic_weighting": False},
}
"""Shipped CaMN checkpoints: name -> config overrides of the ``tiny`` preset."""

CHECKPOINTS: dict[str, tuple[str, dict[str, Any]]] = {
    **{name: ("camn", kw) for name, kw in ABLATIONS.items()},
    "s2g_tiny": ("s2g", {}),
    "trimodal_tiny": ("trimodal", {}),
    "mean_pose": ("mean_pose", {}),
    "random_clip": ("random_clip", {}),
}
"""Shipped checkpoint name -> (model name, overrides)."""

TRAINING: dict[str, Any] = {"epochs": 15, "batch_size": 32, "lr": 1e-3, "seed": 2021}
"""Harness settings of every shipped tiny checkpoint (:class:`beatlite.train.TrainConfig` fields).

15 epochs at lr 1e-3 (16x the reference's batch-scaled 6.25e-5) over the ~660 train windows of
``data_samples/``; the adversarial term starts at each tiny preset's ``no_adv_epochs`` (10).
"""


def retrain(
    name: str,
    *,
    epochs: int = TRAINING["epochs"],
    batch_size: int = TRAINING["batch_size"],
    lr: float = TRAINING["lr"],
    seed: int = TRAINING["seed"],
    progress: bool = True,
) -> float:
    """Train checkpoint ``name`` of :data:`CHECKPOINTS` on ``data_samples/`` and export it.

    Returns
    -------
    float
        Seconds spent in :func:`beatlite.train.fit` (window building excluded).
    """
    import time

    import torch

    from beatlite.data.index import index_folder
    from beatlite.data.vocab import build_vocab, take_sentences, word_vectors
    from beatlite.data.windows import build_windows
    from beatlite.models import build_model
    from beatlite.paths import build_dir, checkpoints_dir, data_dir
    from beatlite.train.checkpoint import export_checkpoint
    from beatlite.train.config import TrainConfig
    from beatlite.train.training import fit

    model_name, overrides = CHECKPOINTS[name]
    index = index_folder(data_dir())
    vocab = build_vocab(index)
    train = build_windows(index, split="train", vocab=vocab)
    stats = (train.pose_norm, train.dir_norm)
    val = build_windows(index, split="val", vocab=vocab, stats=stats)
    kw = dict(overrides)
    if model_name in ("camn", "trimodal"):
        kw["vocab_size"] = len(vocab)
    torch.manual_seed(seed)
    model = build_model(model_name, preset="tiny", **kw)
    if hasattr(model, "set_word_vectors") and kw.get("use_text", True):
        model.set_word_vectors(
            word_vectors(vocab, take_sentences(index), dim=model.config.word_dim, seed=seed)
        )
    meta = {
        "pose_mean": train.pose_norm.mean,
        "pose_std": train.pose_norm.std,
        "dirvec_mean": train.dir_norm.mean,
        "vocab": list(vocab.itos),
        "data": str(data_dir()),
    }
    full = build_dir() / "train" / f"{name}.pt"
    config = TrainConfig(
        epochs=epochs, batch_size=batch_size, lr=lr, seed=seed, checkpoint=full, progress=progress
    )
    start = time.perf_counter()
    fit(model, train, config, val, meta=meta)
    seconds = time.perf_counter() - start
    export_checkpoint(full, checkpoints_dir() / f"{name}.pt")
    return seconds


def _record_times(seconds: dict[str, float]) -> None:
    """Merge ``seconds`` into ``build/train/times.json`` (name -> training seconds)."""
    import json

    from beatlite.io.atomic import atomic_write
    from beatlite.paths import build_dir

    path = build_dir() / "train" / "times.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    times = json.loads(path.read_text()) if path.is_file() else {}
    times.update({k: round(v, 1) for k, v in seconds.items()})
    with atomic_write(path, "w") as fh:
        json.dump(times, fh, indent=2, sort_keys=True)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m beatlite.train", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("retrain-all", help="retrain every shipped checkpoint on data_samples/")
    p.add_argument("--epochs", type=int, default=TRAINING["epochs"])
    p.add_argument("--batch-size", type=int, default=TRAINING["batch_size"])
    p.add_argument("--lr", type=float, default=TRAINING["lr"])
    p.add_argument("--seed", type=int, default=TRAINING["seed"])
    p.add_argument("--only", nargs="*", choices=sorted(CHECKPOINTS), help="retrain only these")
    p.add_argument(
        "--skip-others", action="store_true", help="do not call HA2G's and the extractor's trainers"
    )
    r = sub.add_parser("results", help="evaluate the shipped checkpoints -> build/results_models.md/.json")
    r.add_argument("--out", help="output stem (default build/results_models)")
    r.add_argument("--only", nargs="*", help="checkpoint names (default: every shipped one)")
    args = parser.parse_args(argv)
    if args.command == "results":
        from beatlite.train.evaluation import evaluate_models, write_results

        results = evaluate_models(args.only or None, progress=True)
        md, js = write_results(results, args.out)
        print(results.to_markdown())
        print(f"wrote {md} and {js} in {results.info['seconds']:.1f} s")
        return 0
    for name in args.only or list(CHECKPOINTS):
        print(f"== {name}", flush=True)
        seconds = retrain(name, epochs=args.epochs, batch_size=args.batch_size, lr=args.lr, seed=args.seed)
        print(f"{name}: {seconds:.1f} s", flush=True)
        _record_times({name: seconds})
    if not args.skip_others and not args.only:
        import importlib

        try:
            ha2g = importlib.import_module("beatlite.models.ha2g")
        except ImportError:
            print("beatlite.models.ha2g not found: HA2G checkpoints not retrained", file=sys.stderr)
        else:
            if hasattr(ha2g, "retrain"):
                _record_times(ha2g.retrain())
        for space in ("dirvec", "pose"):
            subprocess.run(
                [sys.executable, "-m", "beatlite.metrics.extractor", "train", "--space", space], check=True
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
