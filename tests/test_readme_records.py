"""The README's and docs/teaching.md's measured numbers (GPU table, CPU timings, notebook run times) against the records they
come from (``bench/records/``)."""

from __future__ import annotations

import json
import math
import re
import statistics
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
RECORDS = ROOT / "bench" / "records"
RECORD = RECORDS / "bench_train_h200.json"
EPOCH_WINDOWS = 80_000  # about BEAT-4english's train windows (README)
KEY = ("model", "preset", "precision", "batch", "compile", "deterministic")
SWITCHES = {"frame_matmul": " + audio matmul", "cudnn_benchmark": " + cudnn.benchmark"}  # (the compile cell)


def _readme() -> str:
    return (ROOT / "README.md").read_text()


def _guide() -> str:
    return (ROOT / "docs" / "teaching.md").read_text()


def _record(name: str) -> dict:
    return json.loads((RECORDS / name).read_text())


def _table_rows() -> list[list[str]]:
    table = _readme().split("<!-- gpu-table: bench/records/bench_train_h200.json -->")[1]
    lines = table.split("<!-- /gpu-table -->")[0].strip().splitlines()[2:]
    return [[cell.strip() for cell in line.strip("|").split("|")] for line in lines]


def _runs() -> dict[str, dict]:
    return {r["name"]: r for r in _record(RECORD.name)["runs"]}


def _row(
    run: str, model: str, preset: str, precision: str, batch: int, compile: str, det: bool, *on: str
) -> dict:  # noqa: A002
    """The record's row of ``run`` with these settings (``on``: the :data:`SWITCHES` that were on)."""
    found = [
        r
        for r in _runs()[run]["rows"]
        if tuple(r[k] for k in KEY) == (model, preset, precision, batch, compile, det)
        and {k for k in SWITCHES if r.get(k)} == set(on)
    ]
    assert len(found) == 1, (run, model, preset, precision, batch, compile, det, on)
    return found[0]


def _n(value: float) -> str:
    return f"{value:,.0f}"


def _minutes(seconds: float) -> str:
    """``1559.6`` -> ``"26 min 0 s"``."""
    minutes, rest = divmod(round(seconds), 60)
    return f"{minutes} min {rest} s"


def test_the_readme_gpu_table_is_every_measured_row_of_the_record_rounded():
    seen = set()
    for run, name, precision, batch, compile, det, wps, ms, fit, mib, epoch in _table_rows():  # noqa: A001
        model, preset = name.lower().split()
        on = [k for k, suffix in SWITCHES.items() if suffix in compile]  # (bench/gpu_record.py's cell)
        for k in on:
            compile = compile.replace(SWITCHES[k], "")  # noqa: A001
        r = _row(run, model, preset, precision, int(batch), compile, det == "on", *on)
        assert (wps, ms, mib) == (_n(r["step_wps"]), _n(r["step_ms"]), _n(r["peak_mib"])), name
        resident = "-" if r["fit_resident_wps"] is None else _n(r["fit_resident_wps"])
        expected = "-" if r["fit_wps"] is None else f"{_n(r['fit_wps'])} / {resident}"
        assert fit == expected, name
        assert epoch == f"{EPOCH_WINDOWS / r['step_wps']:.0f} s", name
        seen.add((run, *(r[k] for k in KEY), *(bool(r.get(k)) for k in SWITCHES)))
    measured = {
        (n, *(r[k] for k in KEY), *(bool(r.get(k)) for k in SWITCHES))
        for n, run in _runs().items()
        for r in run["rows"]
        if r["step_wps"]
    }
    assert seen == measured and len(measured) == 28


def _profiles(log: str) -> dict[str, str]:
    """Each bench row's result line (``"camn paper cuda bf16 b256 eager det=False"``) -> the profile table
    printed before it."""
    out, table = {}, ""
    for line in log.splitlines():
        match = re.match(r"  (\w+ \w+ cuda \w+ b\d+ [\w-]+ det=\w+(?: matmul)?): [\d,]+ windows/s", line)
        if match:
            out[match.group(1)], table = table, ""
        else:
            table += line + "\n"
    return out


def _gpu_ms(table: str, kernel: str | None = None) -> float:
    """A profile's total GPU time (or ``kernel``'s self GPU time) in ms."""
    if kernel is None:
        return float(re.search(r"Self CUDA time total: ([\d.]+)ms", table).group(1))
    line = next(line for line in table.splitlines() if kernel in line)
    return float(re.search(r"\s([\d.]+)ms\s+[\d.]+%", line).group(1))  # the first ms followed by a percentage


def test_the_readme_gpu_sentences_match_the_records_and_the_logs():
    text = " ".join(_readme().split())
    ms = lambda r: _n(r["step_ms"])  # noqa: E731
    wps = lambda r: _n(r["step_wps"])  # noqa: E731
    camn = ("camn", "paper", "bf16", 256)
    on, off, compiled = (
        _row("full", *camn, "eager", True),
        _row("full", *camn, "eager", False),
        _row("full", *camn, "reduce-overhead", True),
    )
    off_later = _row("tune", *camn, "eager", False)
    ha2g = ("ha2g", "paper", "bf16", 256)
    h_on, h_off, h_off_later = (
        _row("full", *ha2g, "eager", True),
        _row("full", *ha2g, "eager", False),
        _row("tune", *ha2g, "eager", False),
    )
    wide = ("camn", "paper", "bf16", 1024)
    wide_on, wide_off, wide_compiled = (
        _row("full", *wide, "eager", True),
        _row("tune", *wide, "eager", False),
        _row("tune", *wide, "reduce-overhead", False),
    )
    fp32, fp32_256 = (
        _row("full", "camn", "paper", "fp32", 64, "eager", True),
        _row("full", "camn", "paper", "fp32", 256, "eager", True),
    )
    bf16_64 = _row("full", "camn", "paper", "bf16", 64, "eager", True)
    tiny = _row("full", "camn", "tiny", "fp32", 64, "eager", True)
    best_ha2g = _row("tune", "ha2g", "paper", "bf16", 512, "eager", False)
    ha2g_fp32 = _row("full", "ha2g", "paper", "fp32", 64, "eager", True)
    issue = _record("issue28_h200_9fb39d3.json")
    before = {(r["model"], r["preset"], r["precision"], r["batch"]): r for r in issue["step"]["rows"]}
    before_fit = {(r["model"], r["preset"], r["device"], r["batch"]): r["wps"] for r in issue["fit"]["rows"]}
    b64, b1024 = before["camn", "paper", "fp32", 64], before["camn", "paper", "bf16", 1024]
    for sentence in (
        f"steps in {ms(fp32)} ms instead of {b64['ms']} in fp32 at batch 64 ({wps(fp32)} against {_n(b64['wps'])} windows/s)",
        f"in {ms(wide_on)} instead of {b1024['ms']} ms in bf16 at 1024",
        f"CaMN tiny at {_n(tiny['fit_wps'])} windows/s (loader) and {_n(tiny['fit_resident_wps'])} (resident) "
        f"against {before_fit['camn', 'tiny', 'cuda', 64]}",
        f"CaMN {ms(on)} → {ms(off)} ms, HA2G {ms(h_on)} → {ms(h_off)} ms; {ms(off_later)} and {ms(h_off_later)} ms "
        "in the `tune` run",
        f"(CaMN, bf16 at 256: {ms(on)} → {ms(compiled)} ms; at 1024 with determinism off, in the `tune` run: "
        f"{ms(wide_off)} → {ms(wide_compiled)} ms, the best CaMN rate of those runs, {wps(wide_compiled)} windows/s;",
        f"at batch 64 and 256 ({ms(bf16_64)} against {ms(fp32)} ms, {ms(on)} against {ms(fp32_256)})",
        f"casts add {on['ops_per_step'] - fp32['ops_per_step']} operators",
        f"CaMN's paper preset was at {wps(wide_compiled)} windows/s of the 10,000 asked, HA2G's at {wps(best_ha2g)} of 3,000",
        f"({wps(ha2g_fp32)} against {before['ha2g', 'paper', 'fp32', 64]['wps']} windows/s, fp32, batch 64)",
        f"gains {h_on['step_ms'] / h_off['step_ms']:.2f} times in bf16 at 256",
    ):
        assert sentence in text, sentence
    early = [r for n in ("full", "tune") for r in _runs()[n]["rows"]]
    assert wide_compiled["step_wps"] == max(
        r["step_wps"] for r in early if r["model"] == "camn" and r["preset"] == "paper" and r["step_wps"]
    )
    assert best_ha2g["step_wps"] == max(
        r["step_wps"] for r in early if r["model"] == "ha2g" and r["preset"] == "paper" and r["step_wps"]
    )
    assert wide_on["step_ms"] < b1024["ms"] < 1.01 * wide_on["step_ms"]  # "no change where the GPU is busy"
    assert (
        h_on["step_ms"] / h_off["step_ms"]
        < before["ha2g", "paper", "fp32", 64]["wps"] / ha2g_fp32["step_wps"]
    )
    # the profile figures (the logs' torch.profiler tables)
    full = _profiles((RECORDS / "bench_train_h200_full.log").read_text())
    tune = _profiles((RECORDS / "bench_train_h200_tune.log").read_text())
    step = tune["camn paper cuda bf16 b1024 reduce-overhead det=False"]
    wgrad = _gpu_ms(step, "wgrad2d_grouped_direct_kernel")
    assert f"{wgrad:.0f} of its {_gpu_ms(step):.0f} ms of GPU time" in text
    fp32_profile = full["camn paper cuda fp32 b64 eager det=True"]
    tf32_kernel = "wgrad_implicit_gemm_indexed_wo_smem_tf32"
    tf32_calls = int(next(x for x in fp32_profile.splitlines() if tf32_kernel in x).split()[-1])
    calls = int(next(x for x in step.splitlines() if "wgrad2d_grouped" in x).split()[-1])
    assert calls == tf32_calls == 2  # "the two first convolutions", one call each
    per_call = _gpu_ms(fp32_profile, tf32_kernel) / tf32_calls
    assert f"TF32 implicit-GEMM kernel does it, {per_call:.1f} ms per call at batch 64" in text
    h = tune["ha2g paper cuda bf16 b256 eager det=False"]
    assert f"({_gpu_ms(h):.0f} of its {ms(h_off_later)} ms at 256 in bf16)" in text
    h64 = full["ha2g paper cuda fp32 b64 eager det=True"]
    host = float(re.search(r"Self CPU time total: ([\d.]+)ms", h64).group(1))
    fills = int(next(x for x in h64.splitlines() if "aten::fill_" in x).split()[-1])
    assert f"{host:.0f} ms of CPU time against {_gpu_ms(h64):.0f} ms of GPU time, {fills:,} of its" in text
    for profile in (
        full["camn paper cuda bf16 b64 eager det=True"],
        full["camn paper cuda bf16 b256 eager det=True"],
    ):
        host = float(re.search(r"Self CPU time total: ([\d.]+)ms", profile).group(1))
        assert host > _gpu_ms(profile)  # "its profiles show more host than GPU time"


def _self_cuda_ms(table: str, operator: str) -> float:
    """A profile's "Self CUDA" time of ``operator`` (the table's 7th column) in ms."""
    line = next(line for line in table.splitlines() if line.strip().startswith(operator))
    value = re.split(r"\s{2,}", line.strip())[6]
    return float(value[:-2]) / (1000 if value.endswith("us") else 1)


def test_the_readme_targets_met_paragraph_is_the_later_runs_records_and_logs():
    """The "Targets met" paragraph: the audio matmul's and compilation's gains, the rates against issue 28's
    targets, the GPU peaks, the epoch estimates and the profile figures, from the ``next`` and ``later`` runs."""
    text = " ".join(_readme().split())
    ms, wps, mib = (lambda r, k=k: _n(r[k]) for k in ("step_ms", "step_wps", "peak_mib"))
    camn = ("next", "camn", "paper", "bf16", 1024)
    eager, eager_mm = _row(*camn, "eager", False), _row(*camn, "eager", False, "frame_matmul")
    comp, comp_mm = (
        _row(*camn, "reduce-overhead", False),
        _row(*camn, "reduce-overhead", False, "frame_matmul"),
    )
    h_eager, h_comp = (
        _row("next", "ha2g", "paper", "bf16", 512, c, False) for c in ("eager", "reduce-overhead")
    )
    h_wide = _row("later", "ha2g", "paper", "bf16", 1024, "reduce-overhead", False)
    assert comp_mm["step_wps"] >= 10_000 and h_wide["step_wps"] >= 3_000  # issue 28's targets
    runs = [r for run in _runs().values() for r in run["rows"]]
    for model, best in (("camn", comp_mm), ("ha2g", h_wide)):  # the best rates of the record
        assert best["step_wps"] == max(
            r["step_wps"] for r in runs if (r["model"], r["preset"]) == (model, "paper") and r["step_wps"]
        )
    camn_log = _profiles((RECORDS / "bench_train_h200_next.log").read_text())
    step = camn_log["camn paper cuda bf16 b1024 reduce-overhead det=False matmul"]
    assert (
        "wgrad2d" not in step
        and "wgrad2d" in camn_log["camn paper cuda bf16 b1024 reduce-overhead det=False"]
    )
    lstm = _self_cuda_ms(step, "aten::_cudnn_rnn_backward")
    h_step = _profiles((RECORDS / "bench_train_h200_later.log").read_text())[
        "ha2g paper cuda bf16 b1024 reduce-overhead det=False"
    ]
    gru = _self_cuda_ms(h_step, "aten::_cudnn_rnn_backward")
    assert gru > _gpu_ms(h_step) / 2  # "over half"
    h_on, h_off = (_row("later", "ha2g", "paper", "bf16", 256, "eager", d) for d in (True, False))
    tiny = _row("full", "camn", "tiny", "fp32", 64, "eager", True)
    source = (ROOT / "bench" / "bench_train.py").read_text()  # `full` ran bench_train's default fit steps
    fit_steps = int(re.search(r"args.fit_steps = 2 if args.quick else (\d+)", source).group(1))
    session = (ROOT / "bench" / "gpu_session.sh").read_text()
    assert "bench 35 camn ha2g --presets tiny --devices cuda --precisions fp32 --batch-sizes 64\n" in session
    assert (
        fit_steps * 64 <= 658
    )  # (no --fit-steps on that line: 10 full batches of data_samples' 658 windows)
    full_on, full_off = (_row("full", "ha2g", "paper", "bf16", 256, "eager", d) for d in (True, False))
    assert h_on["step_ms"] <= h_off["step_ms"]  # "no cost of deterministic mode was measured"
    assert _gpu_ms(h_step) > h_wide["step_ms"]  # "the profiled step, which ran slower than the timed ones"
    for sentence in (
        f"from {ms(eager)} to {ms(eager_mm)} ms eager and from {ms(comp)} to {ms(comp_mm)} ms compiled: "
        f"**{wps(comp_mm)} windows/s** against the 10,000 asked, at a GPU peak of {mib(comp_mm)} MiB",
        f"its LSTM's backward takes {lstm:.0f} of its {_gpu_ms(step):.0f} ms of GPU time",
        f"its step at 512 went from {ms(h_eager)} ms eager to {ms(h_comp)}, and at batch 1024 it runs at "
        f"**{wps(h_wide)} windows/s** against the 3,000 asked ({ms(h_wide)} ms, GPU peak {mib(h_wide)} MiB)",
        f"({gru:.0f} of {_gpu_ms(h_step):.0f} ms in the profiled step, which ran slower than the timed ones)",
        f"takes about {EPOCH_WINDOWS / comp_mm['step_wps']:.0f} s for CaMN's paper preset and "
        f"{EPOCH_WINDOWS / h_wide['step_wps']:.0f} s for HA2G's (all of BEAT: about "
        f"{4.75 * EPOCH_WINDOWS / comp_mm['step_wps']:.0f} s and {4.75 * EPOCH_WINDOWS / h_wide['step_wps'] / 60:.0f} min)",
        f"`fit` ran CaMN tiny at {_n(tiny['fit_resident_wps'])} windows/s on `data_samples/` with its streams on the "
        f"GPU, which would make a BEAT-4english epoch about {EPOCH_WINDOWS / tiny['fit_resident_wps']:.0f} s "
        f"and one of all of BEAT about {4.75 * EPOCH_WINDOWS / tiny['fit_resident_wps'] / 60:.0f} min (estimates from a "
        f"run of {fit_steps} steps)",
        f"HA2G's step at 256 in bf16 took {ms(h_on)} ms with determinism on and {ms(h_off)} with it off "
        f"(in `full`: {ms(full_on)} and {ms(full_off)})",
    ):
        assert sentence in text, sentence
    architecture = " ".join((ROOT / "docs" / "architecture.md").read_text().split())
    assert f"paper-preset step at 1024: {ms(comp)} → {ms(comp_mm)} ms, `gpu_session.sh next`" in architecture


def test_the_train_config_docstring_quotes_the_record():
    from beatlite.train import TrainConfig

    doc = " ".join(TrainConfig.__doc__.split())
    ms = lambda *key: _n(_row(*key)["step_ms"])  # noqa: E731
    camn, ha2g, wide = (
        ("camn", "paper", "bf16", 256),
        ("ha2g", "paper", "bf16", 256),
        ("camn", "paper", "bf16", 1024),
    )
    for sentence in (
        f"from {ms('full', *camn, 'eager', True)} to {ms('full', *camn, 'eager', False)} ms per step and HA2G's "
        f"from {ms('full', *ha2g, 'eager', True)} to {ms('full', *ha2g, 'eager', False)}",
        f"from {ms('full', *camn, 'eager', True)} to {ms('full', *camn, 'reduce-overhead', True)} ms per step at "
        f"batch 256 and, with ``deterministic=False``, from {ms('tune', *wide, 'eager', False)} to "
        f"{ms('tune', *wide, 'reduce-overhead', False)} ms at 1024",
        f"from {ms('next', *wide, 'reduce-overhead', False)} to "
        f"{_n(_row('next', *wide, 'reduce-overhead', False, 'frame_matmul')['step_ms'])} ms",
        f"HA2G's paper-preset step, bf16 at batch 512, from {ms('next', 'ha2g', 'paper', 'bf16', 512, 'eager', False)} "
        f"to {ms('next', 'ha2g', 'paper', 'bf16', 512, 'reduce-overhead', False)} ms",
    ):
        assert sentence in doc, sentence
    repeat = _record("repeat_fit_h200.json")["rows"]
    assert all(
        (r["tensors_differing"] == 0) == r["deterministic"] for r in repeat
    )  # "and with False they did not"
    assert (
        "two CUDA trainings of camn_tiny and of ha2g_tiny with one seed gave the same weights to the bit"
        in doc
    )


def test_the_frame_conv1d_docstring_quotes_the_profile():
    from beatlite.models.layers import frame_conv1d

    doc = " ".join(frame_conv1d.__doc__.split())
    step = _profiles((RECORDS / "bench_train_h200_tune.log").read_text())[
        "camn paper cuda bf16 b1024 reduce-overhead det=False"
    ]
    wgrad = _gpu_ms(step, "wgrad2d_grouped_direct_kernel")
    assert (
        f"{wgrad:.0f} of the {_gpu_ms(step):.0f} ms of CaMN's compiled paper-preset step at batch 1024" in doc
    )


def test_the_readme_repeat_sentences_are_the_cpu_and_gpu_records():
    record = _record("repeat_fit_cpu.json")
    rows = record["rows"]
    assert {(r["recipe"], r["deterministic"]) for r in rows} == {
        (name, det) for name in ("camn_tiny", "ha2g_tiny") for det in (True, False)
    }
    assert all(r["device"] == "cpu" and r["epochs"] == 1 for r in rows)
    assert all(r["tensors_differing"] == 0 and r["histories_equal"] for r in rows)  # "bit-identical"
    text = " ".join(_readme().split())
    assert (
        "On this CPU camn_tiny and ha2g_tiny trained twice for one epoch gave bit-identical weights and losses, "
        "determinism on and off" in text
    )
    gpu = _record("repeat_fit_h200.json")
    assert gpu["machine"]["cuda"] == "NVIDIA H200"
    rows = {(r["recipe"], r["deterministic"]): r for r in gpu["rows"]}
    assert set(rows) == {(name, det) for name in ("camn_tiny", "ha2g_tiny") for det in (True, False)}
    assert all(r["device"] == "cuda" and r["epochs"] == 2 for r in rows.values())
    for name in ("camn_tiny", "ha2g_tiny"):
        same = rows[name, True]
        assert same["tensors_differing"] == 0 and same["largest_difference"] == 0 and same["histories_equal"]
        assert not rows[name, False]["histories_equal"]
    camn, ha2g = rows["camn_tiny", False], rows["ha2g_tiny", False]
    assert (
        "each trained twice for two epochs gave bit-identical weights and losses with determinism on; with it off "
        f"{camn['tensors_differing']} of CaMN's {camn['tensors']} tensors and {ha2g['tensors_differing']} of "
        f"HA2G's {ha2g['tensors']} differed, and their losses too" in text
    )


def test_the_readme_batch_scaling_sentences_are_the_record():
    record = _record("batch_scaling_camn_tiny.json")
    assert record["recipe"] == "camn_tiny" and record["epochs"] == 40 and record["recipe_batch"] == 32
    rows = record["rows"]
    assert {r["seed"] for r in rows} == {2021, 2022, 2023}

    def fgd(batch: int, rule: str) -> str:  # mean ± sample sd, from the rows (the record's summary agrees)
        values = [r["FGD"] for r in rows if (r["batch"], r["rule"]) == (batch, rule)]
        assert len(values) == 3
        mean, sd = statistics.mean(values), statistics.stdev(values)
        assert record["summary"][f"{batch} {rule}"]["FGD"] == pytest.approx([mean, sd])
        return f"{mean:.2f} ± {sd:.2f}"

    seeds = json.loads((ROOT / "checkpoints" / "results_seeds.json").read_text())["rows"]["CaMN"]["FGD"]
    text = " ".join(_readme().split())
    for sentence in (
        f"batch 32, the recipe's, {fgd(32, 'linear')}; batch 64, {fgd(64, 'linear')} with linear scaling and "
        f"{fgd(64, 'sqrt')} with the square root; batch 128, {fgd(128, 'linear')} and {fgd(128, 'sqrt')}; "
        f"batch 256, {fgd(256, 'linear')} and {fgd(256, 'sqrt')}.",
        f"the shipped recipe here: {fgd(32, 'linear')} against the seed table's "
        f"{seeds['mean']:.2f} ± {seeds['sd']:.2f}",
    ):
        assert sentence in text, sentence
    b32 = {r["seed"]: r["FGD"] for r in rows if (r["batch"], r["rule"]) == (32, "linear")}
    table = dict(
        zip(json.loads((ROOT / "checkpoints" / "results_seeds.json").read_text())["seeds"], seeds["values"])
    )
    sentence = (
        f"FGD {b32[2022]:.3f} for seed 2022 and {b32[2021]:.3f} for 2021 (the batch-32 rows' values), where the "
        f"table has {table[2022]:.3f} and {table[2021]:.3f}."
    )  # the seed table's command retrained seeds 2022 and 2021 to these values (README)
    assert sentence in text, sentence
    from beatlite.train.recipes import training_data  # (the data_samples store the recipes train on)

    train = len(training_data(progress=False).train)
    steps = math.ceil(train / 128)  # (fit keeps a last, shorter batch of 2 windows or more)
    assert f"With its {train} train windows, batch 128 is {steps} steps per epoch" in text
    equal = _record("batch_scaling_camn_tiny_equal_steps.json")
    assert {(r["batch"], r["rule"], r["seed"]) for r in equal["rows"]} == {
        (128, "linear", s) for s in (2021, 2022, 2023)
    }
    values = [r["FGD"] for r in equal["rows"]]
    epochs, recipe_steps = equal["epochs"], math.ceil(train / 32) * record["epochs"]
    assert steps * epochs == recipe_steps  # "840 steps, as batch 32's 40 epochs"
    assert (
        f"(batch 128, linear, {epochs} epochs: {recipe_steps} steps, as batch 32's {record['epochs']} epochs;"
        in text
        and f"FGD is {statistics.mean(values):.2f} ± {statistics.stdev(values):.2f} (its best epoch chosen among "
        f"{epochs} validated ones, not {record['epochs']})"
        in text
    )


def _camn_tiny_cpu_fit_rate(record: str) -> float:
    """CaMN tiny's fp32 ``fit`` windows/s (loader route, one thread, batch 16) of a ``bench_train --quick`` record."""
    rows = _record(record)["rows"]
    return next(
        r["fit_wps"] for r in rows if (r["model"], r["precision"]) == ("camn", "fp32") and r["fit_wps"]
    )


def test_counts_and_estimates_of_the_cpu_sentences_follow_their_sources():
    """The seed trainings' count from the recipes, and a CPU epoch of BEAT-4english from 80,000 windows at CaMN tiny's
    rates of the two CPUs' quick records (with AVX-512 rounded to 50 windows/s, without to one)."""
    from beatlite.train.recipes import RECIPES

    readme, guide = _readme(), _guide()
    flat, guide = " ".join(readme.split()), " ".join(guide.split())
    assert (
        f"All {len(RECIPES)} shipped recipes with three seeds each (`make seeds`, {3 * len(RECIPES)} trainings)"
        in flat
    )
    fast = round(_camn_tiny_cpu_fit_rate("bench_train_quick_cpu.json") / 50) * 50
    slow = round(_camn_tiny_cpu_fit_rate("bench_train_quick_cpu_avx2.json"))
    assert _record("bench_train_quick_cpu_avx2.json")["machine"]["cpu_capability"] == "AVX2"
    fast_min, slow_min = round(EPOCH_WINDOWS / fast / 60), round(EPOCH_WINDOWS / slow / 60)
    assert (
        f"CaMN tiny epoch on the CPU runs at about {fast} windows/s on one thread of a CPU with AVX-512 (≈ {fast_min} "
        f"min per epoch for 16 h's 80,000 windows; `bench/records/bench_train_quick_cpu.json`, batch 16) and at "
        f"about {slow} on one without (≈ {slow_min} min; `bench/records/bench_train_quick_cpu_avx2.json`)"
        in flat
    )
    assert (
        f"about {fast_min} min per CaMN tiny epoch on one CPU thread with AVX-512 (80,000 windows at about {fast} "
        f"windows/s), {slow_min} min on one without (about {slow} windows/s;" in guide
    )
    assert "all of BEAT (76 h) about 23 GB and 4.75 times as long per epoch" in guide
    assert "(76 h, about 4.75 times more)" in flat  # the ratio the README derives from the corpus sizes


def _nice(seconds: float) -> int:
    """A run-time estimate: ``seconds`` rounded to 5 s, at least 5."""
    return 5 * max(1, round(seconds / 5))


def test_the_readme_recipe_times_are_the_cpu_record():
    from beatlite.train.recipes import RECIPES

    record = _record("time_recipes_cpu.json")
    assert record["machine"]["cpus"] == 2 and record["command"].startswith(
        "BEATLITE_THREADS=2 "
    )  # "on 2 cores"
    assert record["machine"]["load_average"] < 1.5  # "idle": not another busy process beside it
    rows = {r["recipe"]: r for r in record["rows"]}
    assert all(r["epochs"] == RECIPES[name].epochs and r["seed"] == 2021 for name, r in rows.items())
    camn, ha2g, trimodal = (rows[n] for n in ("camn_tiny", "ha2g_tiny", "trimodal_tiny"))
    text = " ".join(_readme().split())
    minutes = round(max(r["fit_seconds"] for r in rows.values()) / 60)
    assert f"One tiny model trains in about {minutes} minutes on 2 cores" in text
    assert (
        f"recorded {camn['fit_seconds']:.0f} s of `fit` for CaMN ({camn['epochs']} epochs), {ha2g['fit_seconds']:.0f} s "
        f"for HA2G ({ha2g['epochs']} epochs) and {trimodal['fit_seconds']:.0f} s for Trimodal ({trimodal['epochs']} "
        "epochs) on an idle 2-core machine (`bench/records/time_recipes_cpu.json`)" in text
    )


def test_the_guide_run_times_and_the_headers_are_the_notebooks_record():
    """docs/teaching.md's measured table, its totals, each notebook header's estimate (the time rounded to 5 s) and
    the README's sentence, from ``scripts/run_notebooks.py --record`` of one lecture-mode run."""
    import sys

    sys.path.insert(0, str(ROOT / "tests"))
    from test_teaching_guide import NOTEBOOKS, header_times

    record = _record("notebooks_cpu.json")
    rows = record["rows"]
    assert [r["notebook"] for r in rows] == [p.stem for p in NOTEBOOKS] and all(r["ok"] for r in rows)
    assert record["settings"]["BEATLITE_MODE"] == "lecture" and record["settings"]["BEATLITE_THREADS"] == "1"
    total, user = record["total_wall_seconds"], sum(r["kernel_user_seconds"] for r in rows)
    guide = _guide()
    row = next(line for line in guide.splitlines() if line.startswith("| wall time (s) |"))
    cells = [c.strip() for c in row.strip().strip("|").split("|")][1:]
    assert cells == [f"{r['wall_seconds']:.1f}" for r in rows] + [
        f"{total:.0f} ({_minutes(total)}; {user:.0f} s of the kernels' user CPU, "
        f"{record['largest_kernel_gib']:.2f} GiB resident at most in one kernel)"
    ]
    peak = (
        f"{record['largest_kernel_gib']:.2f} GiB resident in one kernel (`bench/records/notebooks_cpu.json`)"
    )
    assert f"One `make run` here used at most {peak}" in guide  # the troubleshooting table
    for path, r in zip(NOTEBOOKS, rows):
        assert header_times(path)["run"] == f"~{_nice(r['wall_seconds'])} s", path.name
    flat = " ".join(guide.split())
    assert (
        f"| **~{total / 60:.1f} min** |" in flat
        and f"the eleven notebooks run in about {total / 60:.1f} minutes" in flat
    )
    assert f"executes the eleven notebooks (~{total / 60:.1f} min)" in flat
    first9 = sum(r["wall_seconds"] for r in rows[:9])
    assert (
        f"`make run` executes the eleven notebooks in about {total / 60:.1f} minutes in lecture mode ({total:.0f} s "
        f"recorded in `bench/records/notebooks_cpu.json`: {first9 / 60:.1f} minutes for 00–08, "
        f"{rows[9]['wall_seconds']:.0f} s for 09 and {rows[10]['wall_seconds']:.0f} s for 10"
        in " ".join(_readme().split())
    )


def test_the_notebook_times_without_avx512_are_their_record():
    """The guide's second row of notebook times, its ratio to the first and the README's sentence, from
    ``scripts/run_notebooks.py --record`` of one lecture-mode run on a CPU whose torch capability is AVX2."""
    record, first = _record("notebooks_cpu_avx2.json"), _record("notebooks_cpu.json")
    rows = record["rows"]
    assert [r["notebook"] for r in rows] == [r["notebook"] for r in first["rows"]] and all(
        r["ok"] for r in rows
    )
    assert record["machine"]["cpu_capability"] == "AVX2"
    assert record["settings"]["BEATLITE_MODE"] == "lecture" and record["settings"]["BEATLITE_THREADS"] == "1"
    total, user = record["total_wall_seconds"], sum(r["kernel_user_seconds"] for r in rows)
    guide = _guide()
    row = next(
        line for line in guide.splitlines() if line.startswith("| wall time on a CPU without AVX-512 (s) |")
    )
    cells = [c.strip() for c in row.strip().strip("|").split("|")][1:]
    assert cells == [f"{r['wall_seconds']:.1f}" for r in rows] + [
        f"{total:.0f} ({_minutes(total)}; {user:.0f} s of the kernels' user CPU, "
        f"{record['largest_kernel_gib']:.2f} GiB resident at most in one kernel)"
    ]
    ratio = total / first["total_wall_seconds"]
    assert f"{ratio:.1f} times as long in all" in " ".join(guide.split())
    assert (
        f"on a CPU without AVX-512 the same run took {total / 60:.1f} minutes, {total:.0f} s in "
        "`bench/records/notebooks_cpu_avx2.json`" in " ".join(_readme().split())
    )


def test_the_numba_compile_times_are_the_record():
    record = _record("numba_cpu.json")
    cold = [r["warm_up_seconds"] for r in record["cold"]]
    cached = [r["warm_up_seconds"] for r in record["cached"]]
    assert len(cold) == len(cached) == 3 and max(cached) < min(cold)
    flat = " ".join(_guide().split())
    assert (
        f"librosa's numba compilation ({min(cold):.1f}–{max(cold):.1f} s with an empty `NUMBA_CACHE_DIR`"
        in flat
    )
    assert (
        f"`warm_up()` took {min(cold):.1f}–{max(cold):.1f} s with an empty cache here and "
        f"{min(cached):.1f}–{max(cached):.1f} s once compiled, in three fresh processes each" in flat
    )
    assert f"a fresh environment adds librosa's numba compile once, about {round(max(cold))} s" in " ".join(
        _readme().split()
    )


def test_the_readme_cpu_compile_sentence_is_the_record():
    rows = {r["compile"]: r for r in _record("bench_train_cpu_compile.json")["rows"]}
    eager, compiled = rows["eager"], rows["default"]
    assert _record("bench_train_cpu_compile.json")["machine"]["threads"] == 1  # "on one thread"
    assert all(
        (r["model"], r["preset"], r["device"], r["batch"]) == ("camn", "tiny", "cpu", 16)
        for r in (eager, compiled)
    )
    assert compiled["step_wps"] <= eager["step_wps"]  # "compiling does not pay"
    assert (
        f"On the CPU, compiling does not pay: CaMN tiny at batch 16 on one thread stepped at {compiled['step_wps']:.0f} "
        f"windows/s compiled (inductor) against {eager['step_wps']:.0f} eager" in " ".join(_readme().split())
    )


def test_the_full_mode_table_is_the_full_mode_record():
    """docs/teaching.md's "What `full` mode adds" (the headers repeat it: tests/test_teaching_guide.py): the seconds
    per epoch the cells printed, the extra wall time (full minus lecture, rounded to 5 s) and the full run's time."""
    lecture = {r["notebook"]: r for r in _record("notebooks_cpu.json")["rows"]}
    full = _record("notebooks_full_cpu.json")
    assert full["settings"]["BEATLITE_MODE"] == "full" and full["settings"]["BEATLITE_THREADS"] == "1"
    table = {}
    for line in _guide().split("### What `full` mode adds")[1].splitlines():
        if re.match(r"^\| \d\d ", line):
            cells = [c.strip() for c in line.strip("|").split("|")]
            table[cells[0][:2]] = (cells[3], cells[4])
    assert set(table) == {r["notebook"][:2] for r in full["rows"]}
    for r in full["rows"]:
        assert r["ok"] and len(r["printed_epoch_seconds"]) == 1, r["notebook"]
        extra = _nice(r["wall_seconds"] - lecture[r["notebook"]]["wall_seconds"])
        assert table[r["notebook"][:2]] == (
            f"{r['printed_epoch_seconds'][0]} s",
            f"{extra} s ({r['wall_seconds']:.1f} s in all)",
        ), r["notebook"]


def test_the_readme_cpu_route_sentence_and_epoch_rate_are_the_quick_record():
    rows = [r for r in _record("bench_train_quick_cpu.json")["rows"] if r["device"] == "cpu"]
    assert {(r["model"], r["precision"]) for r in rows} == {
        (m, p) for m in ("camn", "ha2g") for p in ("fp32", "bf16")
    }
    ratios = [r["fit_resident_wps"] / r["fit_wps"] for r in rows]
    text = " ".join(_readme().split())
    assert f"resident/loader {min(ratios):.2f} to {max(ratios):.2f} in one run" in text


def test_the_re_recorded_a2g_row_is_the_seed_record():
    record = json.loads((ROOT / "checkpoints" / "results_seeds.json").read_text())
    row = record["rows"]["A2G-style"]
    fgd, srgr = row["FGD"], row["SRGR"]
    text = " ".join(_readme().split())
    assert (
        f"FGD 5.07 ± 0.29 → {fgd['mean']:.2f} ± {fgd['sd']:.2f}, SRGR 0.108 → {srgr['mean']:.3f}, shipped seed 2021 → "
        f"{record['info']['shipped']['A2G-style']}." in text
    )
    reference = " ".join((ROOT / "docs" / "reference_code.md").read_text().split())
    assert f"A2G-style FGD {fgd['mean']:.2f} ± {fgd['sd']:.2f} sd (re-recorded on 2026-11-27" in reference


def test_the_readme_store_scale_table_and_its_sums_are_the_record():
    record = _record("bench_scale_cpu.json")
    rows = record["rows"]
    readme = _readme()
    table = readme.split("`bench/records/bench_scale_cpu.json`):")[1].split("\n\n")[1].splitlines()[2:]
    assert table == [
        f"| {r['hours']:.0f} | {r['store_gb']:.2f} GB | {r['store_s']:.0f} ({r['store_cpu_per_h'] * r['hours']:.0f}) | "
        f"{r['store_rss_main']:.2f} / {r['store_rss_child']:.2f} GiB | {r['epoch_rss_main']:.2f} / "
        f"{r['epoch_rss_child']:.2f} GiB | {r['epoch_wps']:,.0f} |"
        for r in rows
    ]
    text = " ".join(readme.split())
    per_hour = [r["store_gb_per_h"] for r in rows]
    assert (
        round(16 * max(per_hour)) == 5 and round(76 * max(per_hour)) == 23
    )  # "about 5 GB" and "about 23 GB"
    assert all(r["store_rss_main"] + 2 * r["store_rss_child"] < 2 for r in rows)  # "flat at under 2 GiB"
    cpu = [r["store_cpu_per_h"] for r in rows]
    c = rows[-1]["store_cpu_per_h"]
    assert (
        f"building takes {min(cpu):.0f}–{max(cpu):.0f} CPU-seconds per hour of mocap (≈ {16 * c / 2 / 60:.0f} min for "
        f"16 h on 2 free cores, ≈ {76 * c / 2 / 60:.0f} min for 76 h" in text
    )


def test_the_readme_fit_command_sentences_are_the_record():
    """The 4-hour ``fit`` command's time, memory, phases and the estimates from them (README, the guide)."""
    record = _record("fit_command_cpu.json")
    fresh, again = record["runs"]["fresh"], record["runs"]["again"]
    assert record["hours"] == 4 and record["machine"]["cpus"] == 2 and record["machine"]["threads"] == 1
    assert record["machine"]["cpu_capability"] == "AVX2"  # "one without AVX-512"
    windows = next(r for r in _record("bench_scale_cpu.json")["rows"] if round(r["hours"]) == 4)[
        "train_windows"
    ]
    extractor_wps = windows * 100 / fresh["extractor_s"]  # fit's default: 100 extractor epochs
    epoch_wps = windows / fresh["train_s"]
    text = " ".join(_readme().split())
    assert (
        f"`python -m beatlite.train fit camn_tiny --data <corpus> --out <run> --epochs 1 --device cpu`, one torch "
        f"thread, {windows:,} train windows)"
        in text
        and record["fit_command"]
        == "python -m beatlite.train fit camn_tiny --data <corpus> --out <run> --epochs 1 --device cpu"
    )
    assert (
        f"with a fresh `--out` it took {_minutes(fresh['wall_s'])} and peaked at {fresh['peak_rss_gib']:.2f} GiB resident"
        in text
    )
    assert (
        f"preparing the index and the store {fresh['prepare_s']:.0f} s, the FGD extractor's 100 epochs "
        f"{fresh['extractor_s']:,.0f} s ({extractor_wps:,.0f} windows/s) and the CaMN tiny epoch with its validation "
        f"FGD {fresh['train_s']:.0f} s" in text
    )
    assert again["extractor_s"] is None and (
        f"it took {_minutes(again['wall_s'])} and peaked at {again['peak_rss_gib']:.2f} GiB" in text
    )
    assert (
        f"BEAT-4english (about {EPOCH_WINDOWS:,} train windows) about {EPOCH_WINDOWS / epoch_wps / 60:.0f} min per "
        f"CaMN tiny epoch with its validation and {EPOCH_WINDOWS * 100 / extractor_wps / 3600:.1f} h for the extractor"
        in text
    )
    assert (
        f"(76 h, about 4.75 times more) about {4.75 * EPOCH_WINDOWS / epoch_wps / 60:.0f} min per epoch"
        in text
    )
    assert (
        f"the second `fit` spent {again['prepare_s']:.0f} s before training instead of {fresh['prepare_s']:.0f} s"
        in text
    )
    guide = " ".join(_guide().split())
    assert (
        f"took {_minutes(fresh['wall_s'])} on a fresh `--out` on a 2-core CPU without AVX-512 "
        f"({fresh['extractor_s']:,.0f} s of it the FGD extractor, trained once; {_minutes(again['wall_s'])} run again)"
        in guide
    )


def test_the_readme_gpu_fit_command_paragraph_is_the_records():
    """The ``fit`` command on the H200 (``gpu_session.sh fit``, twice): times, phases, epochs, peaks, estimates."""
    per_epoch, val_end = _record("fit_command_h200.json"), _record("fit_command_h200_val_end.json")
    for record in (per_epoch, val_end):
        assert record["hours"] == 4 and record["machine"]["cuda"] == "NVIDIA H200"
        assert (
            "--device cuda --preset paper --batch-size 1024 --lr 2e-3 --precision bf16 --compile reduce-overhead --nondeterministic"
            in record["fit_command"]
        )
    assert "--epochs 4 --val-every 1000" in val_end["fit_command"]
    fresh, again = per_epoch["runs"]["fresh"], per_epoch["runs"]["again"]
    alone = [val_end["runs"][r]["epoch_s"] for r in ("fresh", "again")]  # epochs 1, 2 alone; 3 validates
    windows = int(re.search(r"autoencoder on (\d+) windows", " ".join(fresh["output_tail"])).group(1))

    def first_epoch(run: dict) -> float:  # tqdm's s/epoch when the bar reached 1 (its first epoch, compiling)
        return float(
            next(
                m.group(1)
                for line in run["output_tail"]
                if (m := re.search(r" 1/\d+ \[.*?([0-9.]+)s/epoch", line))
            )
        )

    fastest, slowest = min(e for run in alone for e in run[:2]), max(e for run in alone for e in run[:2])
    validating = fresh["epoch_s"] + again["epoch_s"]
    assert min(validating) - slowest > slowest  # "the validation ... is most of an epoch that runs it"
    text = " ".join(_readme().split())
    for sentence in (
        f"a 4-hour BEAT-rate corpus made on that machine, {windows:,} train windows",
        f"with a fresh `--out` it took {_minutes(fresh['wall_s'])}, {fresh['prepare_s']:.0f} s for the index and the "
        f"store, {fresh['extractor_s']:.0f} s for the extractor and {fresh['train_s']:.0f} s of training, of which the "
        f"first epoch, compiling, took {first_epoch(fresh):.0f} s and the next two {fresh['epoch_s'][0]:.1f} and "
        f"{fresh['epoch_s'][1]:.1f} s with their validation",
        f"it took {_minutes(again['wall_s'])}, its first epoch {first_epoch(again):.0f} s and the next two "
        f"{again['epoch_s'][0]:.1f} and {again['epoch_s'][1]:.1f} s",
        f"an epoch with its checkpoint took {alone[0][1]:.2f} and {alone[1][1]:.2f} s (the first after compiling: "
        f"{alone[0][0]:.2f} and {alone[1][0]:.2f} s), {windows / fastest:,.0f} windows/s against the step's "
        f"{_n(_row('next', 'camn', 'paper', 'bf16', 1024, 'reduce-overhead', False, 'frame_matmul')['step_wps'])}",
        f"`fit` at its fast settings trains CaMN's paper preset at about {EPOCH_WINDOWS / windows * fastest:.0f} to "
        f"{EPOCH_WINDOWS / windows * slowest:.0f} s per BEAT-4english epoch, its validations apart",
        f"takes about {EPOCH_WINDOWS / windows * fastest:.0f} to {EPOCH_WINDOWS / windows * slowest:.0f} s of training "
        f"and one of all of BEAT about {4.75 * EPOCH_WINDOWS / windows * fastest:.0f} to "
        f"{4.75 * EPOCH_WINDOWS / windows * slowest:.0f} s",
        f"was {fresh['peak_rss_gib']:.2f} GiB with a fresh `--out` and {again['peak_rss_gib']:.2f} GiB run again, over "
        f"the 2.5 GiB asked ({_record('fit_command_cpu.json')['runs']['fresh']['peak_rss_gib']:.2f} on the CPU, above)",
    ):
        assert sentence in text, sentence
    assert min(fresh["peak_rss_gib"], again["peak_rss_gib"]) > 2.5


def test_the_documented_command_times_are_the_commands_record():
    """README's bootstrap scoring, the guide's data_samples route and store build, architecture's rot6d extractor."""
    record = _record("commands_cpu.json")
    assert (
        record["machine"]["cpu_capability"] == "AVX2" and record["machine"]["cpus"] == 2
    )  # "2-core, without AVX-512"
    rows = record["rows"]
    readme, guide = " ".join(_readme().split()), " ".join(_guide().split())
    boot = rows["score_bootstrap"]
    assert "--bootstrap 200" in record["commands"]["score_bootstrap"]
    assert (
        f"took {boot['wall_s']:.0f} s wall, {boot['cpu_s']:.0f} s CPU and {boot['peak_rss_gib']:.2f} GiB peak RAM"
        in readme
    )
    fit, export, score = (rows[k]["wall_s"] for k in ("fit", "export", "score"))
    assert (
        f"`fit camn_tiny --epochs 1` took {fit:.0f} s wall, the export of its checkpoint {export:.0f} s, the "
        f"scoring {score:.0f} s" in guide
    )
    assert (
        f"builds its window store: {rows['store']['wall_s']:.0f} s on a 2-core CPU without AVX-512" in guide
    )
    architecture = " ".join((ROOT / "docs" / "architecture.md").read_text().split())
    assert (
        f"({rows['extractor_rot6d']['wall_s']:.0f} s for rot6d on data_samples on a 2-core CPU"
        in architecture
    )


def test_the_readme_cpu_bf16_sentence_is_the_avx2_record():
    """Without AVX-512 bfloat16 trains slower than float32 (emulated products): the README's numbers."""
    record = _record("bench_train_quick_cpu_avx2.json")
    assert record["machine"]["cpu_capability"] == "AVX2"
    assert record["peaks"]["cpu torch.bfloat16"] < record["peaks"]["cpu torch.float32"] / 10  # "emulated"
    fit = {(r["model"], r["precision"]): r["fit_wps"] for r in record["rows"] if r["device"] == "cpu"}
    assert all(fit[m, "bf16"] < fit[m, "fp32"] for m in ("camn", "ha2g"))
    assert (
        f"`fit` at {fit['camn', 'bf16']:.0f} against {fit['camn', 'fp32']:.0f} windows/s for CaMN tiny, "
        f"{fit['ha2g', 'bf16']:.0f} against {fit['ha2g', 'fp32']:.0f} for HA2G tiny"
        in " ".join(_readme().split())
    )
