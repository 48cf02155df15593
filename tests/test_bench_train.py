"""bench/bench_train.py's counting and table (its timings are measured by running it, not here)."""

from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

torch = pytest.importorskip("torch")

ROOT = Path(__file__).resolve().parents[1]


def _bench():
    spec = importlib.util.spec_from_file_location("bench_train", ROOT / "bench" / "bench_train.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_train"] = module  # (its dataclass looks its module up)
    spec.loader.exec_module(module)
    return module


def test_ops_are_counted_below_autograd_one_per_kernel():
    bench = _bench()
    a, b = torch.randn(3, 4, requires_grad=True), torch.randn(4, 2)
    with bench._CountOps() as ops:
        (a @ b).sum()
    assert ops.count == 2  # mm, sum
    with bench._CountOps() as ops:
        torch.add(a, 1.0).detach()
    assert ops.count == 2  # add, detach: a view is an operator too (no kernel, but dispatched)


def test_the_grid_has_a_row_per_compile_setting_and_compiled_rows_leave_the_fit_columns_out():
    bench = _bench()
    args = argparse.Namespace(models=["camn"], devices=["cuda"], quick=False, presets=None,
                              precisions=["bf16"], batch_sizes=[256], compile=["eager", "reduce-overhead"],
                              deterministic=["on", "off"], frame_matmul=["off", "on"])  # fmt: skip
    assert bench._grid(args) == [
        ("camn", preset, "cuda", "bf16", 256, c, d, m)
        for preset in ("tiny", "paper")
        for c in ("eager", "reduce-overhead")
        for d in (True, False)
        for m in (False, True)
    ]
    args.models, args.deterministic = ["ha2g"], ["off"]  # no one-channel audio block: one row, matmul None
    assert bench._grid(args) == [
        ("ha2g", preset, "cuda", "bf16", 256, c, False, None)
        for preset in ("tiny", "paper")
        for c in ("eager", "reduce-overhead")
    ]
    row = bench.Row("camn", "paper", "cuda", "bf16", 256, "reduce-overhead", step_wps=1000.0, step_ms=256.0)
    cells = bench.markdown([row]).splitlines()[2].split(" | ")
    header = bench.markdown([row]).splitlines()[0].split(" | ")
    assert cells[header.index("compile")] == "reduce-overhead"
    assert cells[header.index("audio matmul")] == "-"  # (a model without a one-channel audio block)
    assert (
        cells[header.index("fit windows/s (loader)")] == "-"
        and cells[header.index("step windows/s")] == "1,000"
    )


def test_the_gpu_session_script_refuses_an_unknown_stage_before_doing_anything(tmp_path):
    proc = subprocess.run(["bash", str(ROOT / "bench" / "gpu_session.sh"), "nope"], capture_output=True,
                          text=True, cwd=ROOT, env={"PATH": "/usr/bin:/bin", "OUT": str(tmp_path)})  # fmt: skip
    assert proc.returncode == 2, proc.stderr
    assert "unknown stage nope" in proc.stderr and not any(tmp_path.iterdir())


def test_a_row_that_fails_is_reported_in_the_table_and_the_others_still_run(monkeypatch, capsys, tmp_path):
    bench = _bench()

    def measure_step(name, *args, **kwargs):
        if name == "ha2g":
            raise RuntimeError("index_copy_(): self and source expected to have the same dtype | Float\nmore")
        return bench.Row(name, "tiny", "cpu", "fp32", 16, step_wps=100.0, step_ms=160.0)

    monkeypatch.setattr(bench, "measure_step", measure_step)
    monkeypatch.setattr(bench, "_store_train", lambda quick, folder: [])
    monkeypatch.setattr(sys, "argv", ["bench_train.py", "--models", "ha2g", "camn", "--devices", "cpu",
                                      "--batch-sizes", "16", "--precisions", "fp32", "--fit-steps", "0",
                                      "--json", str(tmp_path / "rows.json")])  # fmt: skip
    bench.main()
    table = capsys.readouterr().out.splitlines()
    ha2g = next(line for line in table if line.startswith("| ha2g"))
    camn = next(line for line in table if line.startswith("| camn"))
    note = "failed: RuntimeError: index_copy_(): self and source expected to have the same dtype / Float"
    assert ha2g.count(note) == 11 and "| 100 | 160 |" in camn  # every measured column says why; camn ran


def test_a_fit_that_fails_keeps_the_step_columns_of_its_row(monkeypatch, capsys):
    bench = _bench()
    monkeypatch.setattr(
        bench,
        "measure_step",
        lambda name, *a, **k: bench.Row(name, "tiny", "cpu", "fp32", 16, step_wps=100.0, step_ms=160.0),
    )
    monkeypatch.setattr(bench, "measure_fit", lambda row, train, steps: 1 / 0)
    monkeypatch.setattr(bench, "_store_train", lambda quick, folder: [])
    monkeypatch.setattr(sys, "argv", ["bench_train.py", "--models", "camn", "--devices", "cpu",
                                      "--batch-sizes", "16", "--precisions", "fp32", "--fit-steps", "1"])  # fmt: skip
    bench.main()
    out = capsys.readouterr().out
    assert (
        "camn tiny cpu fp32 b16 eager det=True: 100 windows/s (fit failed: ZeroDivisionError: division by zero)"
        in out
    )
    row = next(line for line in out.splitlines() if line.startswith("| camn"))
    assert "| 100 | 160 | - |" in row


def test_the_json_record_names_the_revision_and_the_machine(monkeypatch, tmp_path):
    """``--json`` wrote the rows and peaks alone: nothing said which code or machine measured them."""
    import json
    import platform

    from beatlite.paths import code_revision

    bench = _bench()
    monkeypatch.setattr(
        bench,
        "measure_step",
        lambda name, *a, **k: bench.Row(name, "tiny", "cpu", "fp32", 16, step_wps=100.0, step_ms=160.0),
    )
    monkeypatch.setattr(bench, "_store_train", lambda quick, folder: [])
    argv = ["bench_train.py", "--models", "camn", "--devices", "cpu", "--batch-sizes", "16", "--precisions",
            "fp32", "--fit-steps", "0", "--json", str(tmp_path / "rows.json")]  # fmt: skip
    monkeypatch.setattr(sys, "argv", argv)
    bench.main()
    record = json.loads((tmp_path / "rows.json").read_text())
    assert record["revision"] == code_revision() and record["command"] == "python " + " ".join(argv)
    machine = record["machine"]
    assert machine["host"] == platform.node() and machine["torch"] == torch.__version__
    assert machine["threads"] == torch.get_num_threads() and machine["cpu"]
    assert [r["model"] for r in record["rows"]] == ["camn"]
