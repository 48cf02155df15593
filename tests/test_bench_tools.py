"""bench/repeat_fit.py's comparison and bench/batch_scaling.py's summary (the scripts themselves train: run, not here)."""

from __future__ import annotations

import importlib.util
import statistics
import sys
from pathlib import Path

import pytest

torch = pytest.importorskip("torch")

ROOT = Path(__file__).resolve().parents[1]


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, ROOT / "bench" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def test_repeat_fit_compares_every_tensor_bit_for_bit():
    compare = _load("repeat_fit").compare
    a = {"state": {"w": torch.tensor([1.0, 2.0]), "n": torch.tensor(3)}, "history": [{"train": {"rec": 0.5}}]}
    assert compare(a, a) == {
        "tensors": 2,
        "tensors_differing": 0,
        "largest_difference": 0.0,
        "histories_equal": True,
    }
    b = {
        "state": {"w": torch.tensor([1.0, 2.0 + 2**-22]), "n": torch.tensor(3)},
        "history": [{"train": {"rec": 0.6}}],
    }
    got = compare(a, b)
    assert (
        got["tensors_differing"] == 1 and got["largest_difference"] == 2**-22 and not got["histories_equal"]
    )


def test_batch_scaling_summarises_each_batch_and_rule_over_the_seeds():
    summary = _load("batch_scaling").summary
    rows = [{"batch": b, "rule": r, "seed": s, **{m: float(v) for m in ("FGD", "SRGR")}}
            for b, r, vals in ((32, "linear", (3, 4, 5)), (64, "sqrt", (6, 8, 10))) for s, v in zip((1, 2, 3), vals)]  # fmt: skip
    got = summary(rows)
    assert list(got) == ["32 linear", "64 sqrt"]
    assert got["32 linear"]["FGD"] == [4.0, 1.0] and got["64 sqrt"]["SRGR"] == [
        8.0,
        statistics.stdev([6, 8, 10]),
    ]
    assert summary(rows[:1]) == {"32 linear": {"FGD": [3.0, None], "SRGR": [3.0, None]}}  # one seed: no sd


def test_batch_scaling_records_its_thread_count_host_and_torch(monkeypatch):
    """The record's command said ``BEATLITE_THREADS=1`` whatever the run's thread count (a training repeats to
    the bit only for one thread count), and nothing named the machine or torch."""
    import argparse
    import platform

    batch_scaling = _load("batch_scaling")
    monkeypatch.setenv("BEATLITE_THREADS", "2")
    about = {
        **batch_scaling.record_about(),
        "revision": "abc1234",
    }  # (as main() describes the run when it starts)
    args = argparse.Namespace(recipe="camn_tiny", batches=[32], rules=["linear"], seeds=[2021], epochs=1,
                              about=about)  # fmt: skip
    record = batch_scaling._record(args, batch_scaling.RECIPES["camn_tiny"], [])
    assert record["command"].startswith("BEATLITE_THREADS=2 python bench/batch_scaling.py --recipe camn_tiny")
    assert (record["machine"]["host"], record["machine"]["torch"], record["revision"]) == (
        platform.node(),
        torch.__version__,
        "abc1234",
    )


def test_repeat_fit_and_time_recipes_records_state_the_threads_they_train_with(monkeypatch, tmp_path):
    """Their records' ``machine["threads"]`` is ``BEATLITE_THREADS``, the threads the fits run with (before: the
    recording process's torch default, one per core whatever ``BEATLITE_THREADS`` said, as neither process had set
    it when it described the machine). The trainings are stubbed: what is checked is the record."""
    import json

    before = torch.get_num_threads()
    want = 1 if before != 1 else 2  # a count the process does not have already
    monkeypatch.setenv("BEATLITE_THREADS", str(want))
    repeat_fit, time_recipes = _load("repeat_fit"), _load("time_recipes")
    monkeypatch.setattr(repeat_fit, "fit_once", lambda *a: {"state": {"w": torch.zeros(1)}, "history": []})
    for name, stub in (("warm_up", lambda: None), ("training_data", lambda progress: None),
                       ("retrain", lambda name, **kw: 1.0)):  # fmt: skip
        monkeypatch.setattr(time_recipes, name, stub)
    argv = ["repeat_fit.py", "--recipes", "camn_tiny", "--device", "cpu", "--deterministic", "on"]
    monkeypatch.setattr(sys, "argv", [*argv, "--json", str(tmp_path / "repeat.json")])
    try:
        repeat_fit.main()
        time_recipes.main(["--recipes", "camn_tiny", "--json", str(tmp_path / "times.json")])
    finally:
        torch.set_num_threads(before)
    for record in ("repeat.json", "times.json"):
        assert json.loads((tmp_path / record).read_text())["machine"]["threads"] == want, record


def test_gpu_record_renders_the_readme_table_from_the_shipped_record():
    """bench/gpu_record.py's table of bench/records/bench_train_h200.json is the README's block, to the byte."""
    import json

    gpu_record = _load("gpu_record")
    readme = (ROOT / "README.md").read_text()
    block = readme.split("<!-- gpu-table: bench/records/bench_train_h200.json -->\n")[1]
    block = block.split("\n<!-- /gpu-table -->")[0]
    record = json.loads((ROOT / "bench" / "records" / "bench_train_h200.json").read_text())
    assert gpu_record.table(record) == block


def _stage_row(model: str, compile: str, wps: float | None, **kw):  # noqa: A002
    row = {"model": model, "preset": "paper", "device": "cuda", "precision": "bf16", "batch": 512,
           "compile": compile, "deterministic": False, "step_wps": wps, "step_ms": None if wps is None else 512e3 / wps,
           "fit_wps": None, "fit_resident_wps": None, "peak_mib": 1234.4, "note": "", "frame_matmul": None}  # fmt: skip
    return {**row, **kw}


def test_gpu_record_adds_a_stage_to_a_new_record_and_rewrites_the_readme_block(tmp_path):
    """A stage folder (NAME.json, NAME.md) becomes a run of a new record: measured rows kept, the failed one
    named with its note, machine and torch from the log's first line, the log beside the record read-only; adding
    it again replaces it; the README block is rewritten with the rows' rounded cells (epoch = 80,000 / rate)."""
    import json

    gpu_record = _load("gpu_record")
    stage = tmp_path / "out"
    stage.mkdir()
    rows = [
        _stage_row("camn", "reduce-overhead", 10240.0, frame_matmul=True),
        _stage_row("ha2g", "eager", 1600.0, fit_wps=500.0),  # (a fit whose resident half failed)
        _stage_row("ha2g", "reduce-overhead", None, note="failed: BackendCompilerFailed: x"),
        _stage_row("camn", "reduce-overhead", 5120.0, cudnn_benchmark=True),
    ]
    (stage / "next.json").write_text(json.dumps({"peaks": [{"cuda torch.bfloat16": 7e14}], "rows": rows}))
    (stage / "next.md").write_text(
        "UserWarning: printed first\ngpu-host  torch 2.11.0+cu130  NVIDIA H100 80GB HBM3\nstore: 658 windows\n"
    )
    record = tmp_path / "records" / "bench_train_h100.json"
    record.parent.mkdir()
    argv = ["add", "next", str(stage), "--commit", "abc1234", "--record", str(record)]
    for _ in range(2):
        assert gpu_record.main([*argv, "--not-measured", "CaMN paper bf16 b1024 eager: its time limit"]) == 0
    data = json.loads(record.read_text())
    (run,) = data["runs"]
    assert (run["name"], run["commit"], run["device"], run["torch"]) == (
        "next", "abc1234", "NVIDIA H100 80GB HBM3", "2.11.0+cu130"
    )  # fmt: skip
    assert [r["model"] for r in run["rows"]] == ["camn", "ha2g", "camn"]
    assert run["not measured"] == (
        "HA2G paper bf16 b512 reduce-overhead: failed: BackendCompilerFailed: x; "
        "CaMN paper bf16 b1024 eager: its time limit"
    )
    log = ROOT / data["logs"]["next"]  # (paths in the record are relative to the repository)
    assert log.read_text() == (stage / "next.md").read_text() and not log.stat().st_mode & 0o222
    readme = tmp_path / "README.md"
    marker = f"<!-- gpu-table: {gpu_record.repo_path(record)} -->"
    readme.write_text(f"before\n{marker}\nold table\n<!-- /gpu-table -->\nafter\n")
    assert gpu_record.main(["table", "--readme", str(readme), "--record", str(record)]) == 0
    lines = readme.read_text().splitlines()
    assert lines[0] == "before" and lines[-1] == "after" and "old table" not in lines
    assert lines[4:7] == [
        "| next | CaMN paper | bf16 | 512 | reduce-overhead + audio matmul | off | 10,240 | 50 | - | 1,234 | 8 s |",
        "| next | HA2G paper | bf16 | 512 | eager | off | 1,600 | 320 | 500 / - | 1,234 | 50 s |",
        "| next | CaMN paper | bf16 | 512 | reduce-overhead + cudnn.benchmark | off | 5,120 | 100 | - | 1,234 | 16 s |",
    ]


def test_gpu_record_refuses_a_log_without_its_machine_line(tmp_path, capsys):
    gpu_record = _load("gpu_record")
    (tmp_path / "next.json").write_text('{"peaks": [], "rows": []}')
    (tmp_path / "next.md").write_text("Traceback (most recent call last):\n")
    assert gpu_record.main(["add", "next", str(tmp_path), "--record", str(tmp_path / "r.json")]) == 2
    assert capsys.readouterr().err.startswith("gpu_record: the log has no line 'HOST  torch VERSION  GPU'")
    assert not (tmp_path / "r.json").exists()


@pytest.mark.slow
def test_bench_data_without_out_leaves_nothing_in_the_temp_folder(tmp_path):
    """``make bench`` runs bench/bench_data.py without ``--out``: its figures and window cache (60 MB on
    data_samples/) went to a ``bench_data_*`` folder of the system's temp folder that was never deleted."""
    import os
    import subprocess

    temp = tmp_path / "tmp"
    temp.mkdir()
    env = {**os.environ, "TMPDIR": str(temp), "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    done = subprocess.run([sys.executable, str(ROOT / "bench" / "bench_data.py")], capture_output=True, text=True,
                          env=env, cwd=tmp_path, timeout=900)  # fmt: skip
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-6000:]
    assert "TOTAL cache build" in done.stdout  # (it ran to its last part)
    assert [p.name for p in temp.iterdir() if p.name.startswith("bench_data_")] == []


@pytest.mark.slow
def test_bench_fit_command_times_each_phase_of_a_fresh_and_a_repeated_fit(tmp_path):
    """bench/bench_fit_command.py runs the README's ``fit`` command twice on one ``--out``: the fresh run
    prepares the store and trains the FGD extractor, the repeated one only trains; the phases come from the
    command's own lines (the extractor's ``wrote ... in N s``, fit's ``N s of training``); ``--fit-args`` reach
    the command."""
    import json
    import os

    from childproc import run_ok

    corpus = tmp_path / "corpus"  # data_samples/ under another name: fit trains an extractor for it
    for source in (ROOT / "data_samples").rglob("*"):
        if source.is_file():
            (corpus / source.relative_to(ROOT / "data_samples")).parent.mkdir(parents=True, exist_ok=True)
            (corpus / source.relative_to(ROOT / "data_samples")).symlink_to(source)
    record = tmp_path / "fit.json"
    env = {**os.environ, "PYTHONPATH": str(ROOT), "TMPDIR": str(tmp_path)}
    run_ok([sys.executable, str(ROOT / "bench" / "bench_fit_command.py"), "--corpus", str(corpus),
            "--extractor-epochs", "2", "--fit-args=--batch-size 24", "--json", str(record)],
           env=env, cwd=tmp_path, timeout=900)  # fmt: skip
    got = json.loads(record.read_text())
    assert (
        got["fit_command"].endswith("--epochs 1 --device cpu --extractor-epochs 2 --batch-size 24")
        and got["hours"] is None
    )
    fresh, again = got["runs"]["fresh"], got["runs"]["again"]
    assert fresh["extractor_s"] is not None and again["extractor_s"] is None  # kept: not trained again
    for run in (fresh, again):
        assert run["train_s"] > 0 and run["prepare_s"] > 0 and run["peak_rss_kib"] > 0
        assert run["prepare_s"] + (run["extractor_s"] or 0) + run["train_s"] <= run["wall_s"]
        assert not any(
            str(tmp_path) in line for line in run["output_tail"]
        )  # <run> and <corpus>, not this machine's
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith("bench_fit_command_")] == []
