"""Command line: ``python -m beatlite.train retrain-all [--epochs N] [--only NAME ...]``.

``retrain-all`` rebuilds every shipped checkpoint of models engineer A from the
``data_samples/`` train split (windows of 34 frames, stride 10; validation on the val
split), each with ``BEATLITE_THREADS`` threads, writing the full training checkpoint to
``build/train/<name>.pt`` and a float16 inference copy to ``checkpoints/<name>.pt``.
It then calls HA2G's trainer (``beatlite.models.ha2g.retrain``, when present) and the
FGD extractor's (``python -m beatlite.metrics.extractor train``).
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


def retrain(name: str, *, epochs: int, batch_size: int, seed: int) -> None:
    """Train checkpoint ``name`` of :data:`CHECKPOINTS` on ``data_samples/`` and export it."""
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
    config = TrainConfig(epochs=epochs, batch_size=batch_size, seed=seed, checkpoint=full)
    fit(model, train, config, val, meta=meta)
    export_checkpoint(full, checkpoints_dir() / f"{name}.pt")


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m beatlite.train", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("retrain-all", help="retrain every shipped checkpoint on data_samples/")
    p.add_argument("--epochs", type=int, default=30)
    p.add_argument("--batch-size", type=int, default=32)
    p.add_argument("--seed", type=int, default=2021)
    p.add_argument("--only", nargs="*", choices=sorted(CHECKPOINTS), help="retrain only these")
    p.add_argument(
        "--skip-others", action="store_true", help="do not call HA2G's and the extractor's trainers"
    )
    args = parser.parse_args(argv)
    if args.command == "retrain-all":
        for name in args.only or list(CHECKPOINTS):
            print(f"== {name}", flush=True)
            retrain(name, epochs=args.epochs, batch_size=args.batch_size, seed=args.seed)
        if not args.skip_others and not args.only:
            import importlib

            try:
                ha2g = importlib.import_module("beatlite.models.ha2g")
            except ImportError:
                print("beatlite.models.ha2g not found: HA2G checkpoints not retrained", file=sys.stderr)
            else:
                if hasattr(ha2g, "retrain"):
                    ha2g.retrain()
            subprocess.run([sys.executable, "-m", "beatlite.metrics.extractor", "train"], check=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
