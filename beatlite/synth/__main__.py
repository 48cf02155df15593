"""Command line: ``python -m beatlite.synth --out data_samples [--seed 0] [--fps 30] [--full-rate]``."""

from __future__ import annotations

import argparse
import sys
import time
from collections import Counter
from collections.abc import Sequence

from beatlite.synth.corpus import TakeSpec, corpus_specs, generate_corpus
from beatlite.synth.speech import EspeakNotFoundError


def _parser() -> argparse.ArgumentParser:
    """The command line's options."""
    parser = argparse.ArgumentParser(
        prog="python -m beatlite.synth",
        description="Generate beatlite's synthetic BEAT-format corpus (see data_samples/README.md).",
    )
    parser.add_argument("--out", default="data_samples", help="output folder (created if missing)")
    parser.add_argument("--seed", type=int, default=0, help="corpus seed (default 0)")
    parser.add_argument(
        "--fps", type=int, default=30, help="BVH frame rate of the compact corpus (default 30)"
    )
    parser.add_argument(
        "--full-rate",
        action="store_true",
        help="write BEAT's rates instead: plain .bvh at 120 fps (6 decimals) and plain .json",
    )
    parser.add_argument("--workers", type=int, default=None, help="processes (default min(2, CPUs))")
    parser.add_argument("--only", nargs="*", default=None, help="generate only these take names")
    return parser


def _selected_specs(parser: argparse.ArgumentParser, only: Sequence[str] | None) -> list[TakeSpec]:
    """The corpus takes named in ``only`` (all when empty); unknown names are a usage error."""
    specs = corpus_specs()
    if only:
        unknown = sorted(set(only) - {s.name for s in specs})
        if unknown:
            parser.error(f"unknown take names {unknown}; known: {[s.name for s in specs]}")
        specs = [s for s in specs if s.name in only]
    return specs


def main(argv: Sequence[str] | None = None) -> int:
    """Generate the synthetic BEAT-format corpus; returns the exit status."""
    parser = _parser()
    args = parser.parse_args(argv)
    specs = _selected_specs(parser, args.only)
    tic = time.perf_counter()
    try:
        results = generate_corpus(
            args.out, args.seed, fps=args.fps, full_rate=args.full_rate, workers=args.workers, specs=specs
        )
    except (EspeakNotFoundError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    wall = time.perf_counter() - tic
    total = sum(r.duration for r in results)
    splits = Counter(s.split for s in specs)
    print(
        f"wrote {len(results)} takes, {total:.1f} s ({total / 60:.2f} min) of data to {args.out} in {wall:.1f} s"
    )
    print("takes per split: " + ", ".join(f"{k} {v}" for k, v in sorted(splits.items())))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
