"""Wall time, CPU time and peak memory of the commands the docs quote on ``data_samples/``, in the docs' order.

Each command runs from the repository's root in a fresh measuring process (:func:`bench_fit_command.measure`), with
``BEATLITE_BUILD`` in a temporary folder (nothing is written into the repository; the first step builds the
window store there that the later ones read) and one torch thread unless ``BEATLITE_THREADS`` says otherwise:

- ``store``: the first window store of ``data_samples/`` (``training_data()``, as a notebook's first
  ``build_windows`` in ``build/lab/`` does; docs/teaching.md);
- ``fit``, ``export``, ``score``: docs/teaching.md's route, ``fit camn_tiny --epochs 1``, then
  ``score OUT --export CHECKPOINT`` and ``score OUT``;
- ``export_shipped``, ``score_bootstrap``: README "Score your model": the shipped CaMN's outputs, then the first
  command with ``--bootstrap 200 --json --md``;
- ``extractor_rot6d``: docs/architecture.md's ``python -m beatlite.metrics.extractor train --space rot6d``.

Usage: ``python bench/time_commands.py [--json FILE] [--only NAME ...]``; about 3 minutes on 2 cores.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("BEATLITE_THREADS", "1")

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_fit_command import measure  # noqa: E402
from bench_scale import run_step  # noqa: E402

from beatlite.io.atomic import write_json  # noqa: E402
from beatlite.paths import n_threads, record_about  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
#: name -> the command's arguments after ``python`` (``{work}``: the temporary folder).
COMMANDS = {
    "store": ["-c", "from beatlite.train.recipes import training_data; training_data()"],
    "fit": ["-m", "beatlite.train", "fit", "camn_tiny", "--data", "data_samples", "--epochs", "1", "--out",
            "{work}/runs/beat"],
    "export": ["-m", "beatlite.score", "{work}/runs/camn_out", "--export", "{work}/runs/beat/camn_tiny.pt"],
    "score": ["-m", "beatlite.score", "{work}/runs/camn_out"],
    "export_shipped": ["-m", "beatlite.score", "{work}/camn_out", "--export", "camn_tiny", "--data", "data_samples"],
    "score_bootstrap": ["-m", "beatlite.score", "{work}/camn_out", "--data", "data_samples", "--bootstrap", "200",
                        "--json", "{work}/scores.json", "--md", "{work}/scores.md"],
    "extractor_rot6d": ["-m", "beatlite.metrics.extractor", "train", "--space", "rot6d", "--out",
                        "{work}/fgd_rot6d.pt"],
}  # fmt: skip


def step(name: str, work: Path) -> dict:
    """Measure command ``name`` once (call in a fresh process: the peak RSS is then the command's own)."""
    command = [sys.executable, *(a.replace("{work}", str(work)) for a in COMMANDS[name])]
    env = {**os.environ, "BEATLITE_BUILD": str(work / "build")}
    got, lines = measure(command, cwd=REPO, env=env)
    return {**got, "output_tail": [line.replace(str(work), "<work>") for _, line in lines[-3:]]}


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--json", type=Path, default=None, help="write the record here")
    p.add_argument("--only", nargs="+", choices=list(COMMANDS), default=list(COMMANDS), help="these commands")
    p.add_argument("--step", nargs=2, metavar=("NAME", "WORK"), help=argparse.SUPPRESS)
    args = p.parse_args()
    if args.step:
        print(json.dumps(step(args.step[0], Path(args.step[1]))))
        return 0
    about = {
        **record_about(threads=n_threads()),
        "commands": {k: " ".join(["python", *v]) for k, v in COMMANDS.items()},
    }
    work = Path(tempfile.mkdtemp(prefix="time_commands_"))
    rows = {}
    try:
        for name in args.only:
            rows[name] = r = run_step(["--step", name, str(work)], __file__)
            print(
                f"{name}: {r['wall_s']:.1f} s wall, {r['cpu_s']:.1f} s CPU, {r['peak_rss_gib']:.2f} GiB",
                flush=True,
            )
            if args.json is not None:  # after every command: a run stopped later keeps what it measured
                write_json(args.json, {**about, "rows": rows})
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
