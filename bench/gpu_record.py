"""Fold a GPU run of ``bench/gpu_session.sh`` into the record and the README's GPU table.

A session lent a GPU runs a stage there (``bash bench/gpu_session.sh next``, the device tool's files coming back
in a folder holding ``next.json`` and ``next.md``), then, here:

``python bench/gpu_record.py add next FOLDER [--commit REV] [--not-measured TEXT] [--record RECORD]``
    (stages ``full``, ``tune``, ``next``, ``later`` and ``cudnn``, whose rows ``gpu_session.sh`` merges into ``STAGE.json``)
    appends the run to the record (default ``bench/records/bench_train_h200.json``; a run of that name
    replaced): its measured rows, the GEMM peaks, the GPU and torch named by the log's machine line, the date,
    the commit (default: this checkout's), and the rows that failed or were not measured, each with its note
    (``--not-measured``: a row a time limit stopped, which the JSON cannot name); the log is kept beside the record
    as ``<record>_<name>.log`` (read-only). A record that does not exist yet is started (e.g.
    ``bench_train_h100.json`` for another card). Paths in the record are relative to the repository.
``python bench/gpu_record.py table [--record ...] [--readme README.md]``
    rewrites the README block between ``<!-- gpu-table: RECORD -->`` and ``<!-- /gpu-table -->`` from the record:
    one line per measured row, in the record's order (``tests/test_readme_records.py`` checks every cell against
    the record, independently of this script).

The sentences around the table that compare numbers are written by hand and asserted against the record in
``tests/test_readme_records.py``: add an assertion there for every new one.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import re
import sys
from pathlib import Path

from beatlite.io.atomic import atomic_write, write_json
from beatlite.paths import code_revision, repo_root

RECORD = repo_root() / "bench" / "records" / "bench_train_h200.json"
EPOCH_WINDOWS = 80_000  # about BEAT-4english's train windows: the "epoch (est.)" column
NAMES = {"camn": "CaMN", "ha2g": "HA2G"}
SWITCHES = (
    ("frame_matmul", "audio matmul"),
    ("cudnn_benchmark", "cudnn.benchmark"),
)  # (row key, cell suffix)
HEADER = (
    "| run | model, preset | precision | batch | compile | deterministic | step windows/s | ms/step "
    "| fit windows/s (loader / resident) | GPU peak MiB | epoch (est.) |"
)


def repo_path(path: Path) -> str:
    """``path`` relative to the repository (as the record's ``logs`` and the README's table marker name it)."""
    return Path(os.path.relpath(Path(path).resolve(), repo_root())).as_posix()


def machine(log: str) -> dict[str, str]:
    """``{"host", "torch", "device"}`` from a stage log's machine line (``"{host}  torch {version}  {GPU}"``, its
    first line unless a warning came before it)."""
    pattern = re.compile(r"(\S+)  torch (\S+)  (.+)")
    for line in log.splitlines():
        if found := pattern.fullmatch(line.strip()):
            return dict(zip(("host", "torch", "device"), found.groups(), strict=True))
    first = log.splitlines()[0] if log.strip() else ""
    raise ValueError(f"the log has no line 'HOST  torch VERSION  GPU' (its first: {first!r})")


def run_of(name: str, folder: Path, commit: str, not_measured: str = "") -> tuple[dict, str]:
    """The record entry of stage ``name`` whose files are in ``folder``, and its log; ``not_measured`` adds what
    the stage's JSON cannot say (a row its time limit stopped before it was written)."""
    stage = json.loads((folder / f"{name}.json").read_text())
    log = (folder / f"{name}.md").read_text()
    peaks = stage["peaks"] if isinstance(stage["peaks"], list) else [stage["peaks"]]
    rows = [r for r in stage["rows"] if r.get("step_wps")]
    missing = [
        f"{NAMES.get(r['model'], r['model'])} {r['preset']} {r['precision']} b{r['batch']} {compile_cell(r)}: "
        f"{r['note']}"
        for r in stage["rows"] if not r.get("step_wps")
    ]  # fmt: skip
    run = {
        "name": name, "commit": commit, "command": f"bash bench/gpu_session.sh {name}", **machine(log),
        "date": datetime.date.today().isoformat(), "peaks": peaks, "rows": rows,
        "not measured": "; ".join(missing + ([not_measured] if not_measured else [])),
    }  # fmt: skip
    return run, log


def add(record_path: Path, run: dict, log: str) -> Path:
    """Put ``run`` into the record at ``record_path`` (a run of the same name replaced) and its log beside it."""
    record = json.loads(record_path.read_text()) if record_path.is_file() else {"runs": [], "logs": {}}
    if not isinstance(record, dict) or not isinstance(record.get("runs"), list):
        raise ValueError(f"{record_path} is no bench_train GPU record (no 'runs' list)")
    log_path = record_path.with_name(f"{record_path.stem}_{run['name']}.log")
    record["runs"] = [r for r in record["runs"] if r["name"] != run["name"]] + [run]
    record.setdefault("logs", {})[run["name"]] = repo_path(log_path)
    with atomic_write(log_path) as f:  # (replaces a read-only log of an earlier add)
        f.write(log)
    log_path.chmod(0o444)
    write_json(record_path, record)
    return log_path


def _n(value: float) -> str:
    return f"{value:,.0f}"


def _cell(value: float | None) -> str:
    return "-" if value is None else _n(value)


def compile_cell(row: dict) -> str:
    """The row's compile setting, naming the audio matmul and cudnn.benchmark when they were on."""
    return row["compile"] + "".join(f" + {label}" for key, label in SWITCHES if row.get(key))


def table_row(run: str, row: dict) -> str:
    """One README table line of a measured row."""
    fit = (
        "-" if row.get("fit_wps") is None else f"{_n(row['fit_wps'])} / {_cell(row.get('fit_resident_wps'))}"
    )
    cells = [
        run, f"{NAMES.get(row['model'], row['model'])} {row['preset']}", row["precision"], str(row["batch"]),
        compile_cell(row), "on" if row["deterministic"] else "off", _n(row["step_wps"]), _n(row["step_ms"]), fit,
        _n(row["peak_mib"]), f"{EPOCH_WINDOWS / row['step_wps']:.0f} s",
    ]  # fmt: skip
    return "| " + " | ".join(cells) + " |"


def table(record: dict) -> str:
    """The README's GPU table of ``record``: header, rule and one line per measured row."""
    lines = [HEADER, "|" + "---|" * HEADER.count(" | ") + "---|"]
    lines += [
        table_row(run["name"], row) for run in record["runs"] for row in run["rows"] if row.get("step_wps")
    ]
    return "\n".join(lines)


def update_readme(readme: Path, record_path: Path) -> None:
    """Rewrite ``readme``'s block for ``record_path`` (``ValueError`` when it has none)."""
    text = readme.read_text()
    start = f"<!-- gpu-table: {repo_path(record_path)} -->"
    if start not in text or "<!-- /gpu-table -->" not in text.split(start, 1)[1]:
        raise ValueError(f"{readme} has no block '{start}' ... '<!-- /gpu-table -->'")
    before, rest = text.split(start, 1)
    after = rest.split("<!-- /gpu-table -->", 1)[1]
    block = table(json.loads(record_path.read_text()))
    with atomic_write(readme) as f:
        f.write(f"{before}{start}\n{block}\n<!-- /gpu-table -->{after}")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="command", required=True)
    a = sub.add_parser("add", help="fold a stage's files into the record")
    a.add_argument("name", help="the stage (its NAME.json and NAME.md in FOLDER)")
    a.add_argument("folder", type=Path)
    a.add_argument("--commit", default=None, help="the commit the GPU ran (default: this checkout's)")
    a.add_argument("--not-measured", default="", help="rows the stage's time limits stopped, and why")
    t = sub.add_parser("table", help="rewrite the README's GPU table from the record")
    t.add_argument("--readme", type=Path, default=repo_root() / "README.md")
    for q in (a, t):
        q.add_argument("--record", type=Path, default=RECORD)
    args = p.parse_args(argv)
    try:
        if args.command == "add":
            run, log = run_of(args.name, args.folder, args.commit or code_revision(), args.not_measured)
            print(
                f"{args.record}: run {args.name!r}, {len(run['rows'])} measured rows -> {add(args.record, run, log)}"
            )
        else:
            update_readme(args.readme, args.record)
            print(f"{args.readme}: the table of {args.record} rewritten")
    except (OSError, ValueError, KeyError, TypeError, json.JSONDecodeError) as error:
        print(f"gpu_record: {error}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
