"""The main job: execute every notebook in ``notebooks/`` in order and write ``build/``.

Writes, for each ``notebooks/NN_name.ipynb``:

- ``build/notebooks/NN_name.ipynb`` (executed, with outputs) and ``.html``;
- the tables the notebook saved with :func:`beatlite.report.save_table` (``build/tables/``);
- ``build/student/NN_name.ipynb``: the student copy, without the cells tagged ``solution``;
- ``build/results.md``: per-notebook status and wall time, then every table.

Exit status is non-zero when any notebook fails (the others still run).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def execute(path: Path, out_dir: Path, timeout: int) -> tuple[bool, float, str]:
    """Execute one notebook in its own folder; save the executed copy and its HTML."""
    import nbformat
    from nbconvert import HTMLExporter
    from nbconvert.preprocessors import CellExecutionError, ExecutePreprocessor

    nb = nbformat.read(path, as_version=4)
    ep = ExecutePreprocessor(timeout=timeout, kernel_name="python3")
    start = time.perf_counter()
    ok, message = True, ""
    try:
        ep.preprocess(nb, {"metadata": {"path": str(path.parent)}})
    except CellExecutionError as exc:
        ok, message = False, str(exc).strip().splitlines()[-1] if str(exc).strip() else repr(exc)
    seconds = time.perf_counter() - start
    out_dir.mkdir(parents=True, exist_ok=True)
    nbformat.write(nb, out_dir / path.name)
    body, _ = HTMLExporter().from_notebook_node(nb)
    (out_dir / path.with_suffix(".html").name).write_text(body, encoding="utf-8")
    return ok, seconds, message


def write_student_copy(path: Path, out_dir: Path) -> None:
    """Write ``path`` without its ``solution``-tagged cells (the exercise stubs stay)."""
    import nbformat

    nb = nbformat.read(path, as_version=4)
    nb.cells = [c for c in nb.cells if "solution" not in c.get("metadata", {}).get("tags", [])]
    out_dir.mkdir(parents=True, exist_ok=True)
    nbformat.write(nb, out_dir / path.name)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--out", type=Path, default=REPO / "build", help="output folder (default build/)")
    parser.add_argument("--timeout", type=int, default=900, help="per-cell timeout in seconds")
    parser.add_argument("notebooks", nargs="*", type=Path, help="notebooks to run (default: all, in order)")
    args = parser.parse_args(argv)

    out = args.out.resolve()
    os.environ["BEATLITE_BUILD"] = str(out)
    paths = args.notebooks or sorted((REPO / "notebooks").glob("[0-9][0-9]_*.ipynb"))
    if not paths:
        print("run_notebooks: no notebooks found in notebooks/", file=sys.stderr)
        return 1
    (out / "tables").mkdir(parents=True, exist_ok=True)
    for stale in (out / "tables").glob("*.md"):
        stale.unlink()

    rows, failed = [], 0
    total = time.perf_counter()
    for path in paths:
        print(f"[run] {path.name} ...", flush=True)
        ok, seconds, message = execute(path.resolve(), out / "notebooks", args.timeout)
        write_student_copy(path, out / "student")
        failed += not ok
        rows.append((path.stem, ok, seconds, message))
        print(f"[run] {path.name}: {'ok' if ok else 'FAILED'} in {seconds:.1f} s {message}", flush=True)
    total = time.perf_counter() - total

    lines = [
        "# beatlite results",
        "",
        f"Data: `{os.environ.get('BEATLITE_DATA', 'data_samples/')}`; mode: "
        f"`{os.environ.get('BEATLITE_MODE', 'lecture')}`; threads: `{os.environ.get('BEATLITE_THREADS', '1')}`.",
        "",
        "| notebook | status | wall time (s) |",
        "|---|---|---:|",
    ]
    lines += [
        f"| [{s}](notebooks/{s}.html) | {'ok' if ok else 'FAILED: ' + m} | {t:.1f} |" for s, ok, t, m in rows
    ]
    lines += [f"| **total** | {len(rows) - failed}/{len(rows)} ok | {total:.1f} |", ""]
    for table in sorted((out / "tables").glob("*.md")):
        lines += [table.read_text(encoding="utf-8").rstrip(), ""]
    (out / "results.md").write_text("\n".join(lines), encoding="utf-8")
    print(f"[run] wrote {out / 'results.md'} ({len(rows) - failed}/{len(rows)} notebooks ok, {total:.0f} s)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
