"""The README's GPU table and its sentences against the record they come from (``bench/records/``)."""

from __future__ import annotations

import json
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RECORD = ROOT / "bench" / "records" / "bench_train_h200.json"
EPOCH_WINDOWS = 80_000  # about BEAT-4english's train windows (README)


def _readme_rows() -> list[list[str]]:
    text = (ROOT / "README.md").read_text()
    table = text.split("<!-- gpu-table: bench/records/bench_train_h200.json -->")[1].split(
        "<!-- /gpu-table -->"
    )[0]
    lines = [line for line in table.strip().splitlines()[2:]]
    return [[cell.strip() for cell in line.strip("|").split("|")] for line in lines]


def _record_row(
    run: str, model: str, preset: str, precision: str, batch: str, compile: str, det: str
) -> dict:  # noqa: A002
    runs = {r["name"]: r for r in json.loads(RECORD.read_text())["runs"]}
    found = [
        r for r in runs[run]["rows"]
        if (r["model"], r["preset"], r["precision"], r["batch"], r["compile"], r["deterministic"])
        == (model, preset, precision, int(batch), compile, det == "on")
    ]  # fmt: skip
    assert len(found) == 1, (run, model, preset, precision, batch, compile, det)
    return found[0]


def _n(value: float) -> str:
    return f"{value:,.0f}"


def test_every_row_of_the_readme_gpu_table_is_the_record_rounded():
    rows = _readme_rows()
    assert len(rows) == 15
    for run, name, precision, batch, compile, det, wps, ms, fit, mib, epoch in rows:  # noqa: A001
        model, preset = name.lower().split()
        r = _record_row(run, model, preset, precision, batch, compile, det)
        assert (wps, ms, mib) == (_n(r["step_wps"]), _n(r["step_ms"]), _n(r["peak_mib"])), name
        expected = "-" if r["fit_wps"] is None else f"{_n(r['fit_wps'])} / {_n(r['fit_resident_wps'])}"
        assert fit == expected, name
        assert epoch == f"{EPOCH_WINDOWS / r['step_wps']:.0f} s", name


def test_the_readme_gpu_sentences_match_the_record_and_the_logs():
    text = " ".join((ROOT / "README.md").read_text().split())
    row = lambda *key: _record_row(*key)  # noqa: E731
    camn = ("camn", "paper", "bf16", "256")
    eager_on, eager_off = row("full", *camn, "eager", "on"), row("full", *camn, "eager", "off")
    compiled = row("full", *camn, "reduce-overhead", "on")
    wide_eager, wide = (
        row("tune", "camn", "paper", "bf16", "1024", "eager", "off"),
        row("tune", "camn", "paper", "bf16", "1024", "reduce-overhead", "off"),
    )
    ha2g_on, ha2g_off = (
        row("full", "ha2g", "paper", "bf16", "256", "eager", "on"),
        row("full", "ha2g", "paper", "bf16", "256", "eager", "off"),
    )
    best_ha2g = row("tune", "ha2g", "paper", "bf16", "512", "eager", "off")
    fp32 = row("full", "camn", "paper", "fp32", "64", "eager", "on")
    ms = lambda r: _n(r["step_ms"])  # noqa: E731
    for sentence in (
        f"CaMN paper fp32 at 64: {ms(fp32)} ms",
        f"(bf16 at 256: {ms(eager_on)} → {ms(eager_off)} ms; HA2G {ms(ha2g_on)} → {ms(ha2g_off)} ms;",
        f"(bf16 at 256: {ms(eager_on)} → {ms(compiled)} ms; at 1024 with determinism off: {ms(wide_eager)} → {ms(wide)} ms,",
        f"the best CaMN rate, {_n(wide['step_wps'])} windows/s;",
        f"autocast's casts add {eager_on['ops_per_step'] - fp32['ops_per_step']} operators",
        f"CaMN's paper preset is at {_n(wide['step_wps'])} windows/s of the 10,000 asked, HA2G's at {_n(best_ha2g['step_wps'])} of 3,000",
        f"({_n(row('full', 'ha2g', 'paper', 'fp32', '64', 'eager', 'on')['step_wps'])} against 470 windows/s, fp32, batch 64)",
    ):
        assert sentence in text, sentence
    # the profile figures: the compiled CaMN step at 1024 and HA2G's bf16 step at 256 (tune run's log)
    log = (ROOT / "bench" / "records" / "bench_train_h200_tune.log").read_text()
    tables = log.split("Self CUDA time total: ")
    camn_table = next(t for t in tables if "wgrad2d_grouped_direct_kernel" in t and "CompiledFxGraph" in t)
    wgrad = re.search(r"wgrad2d_grouped_direct_kernel.*?\s(\d+\.\d+)ms\s+\d+\.\d+%", camn_table).group(1)
    total = tables[tables.index(camn_table) + 1].split("ms")[0]
    assert f"{float(wgrad):.0f} of its {float(total):.0f} ms of GPU time" in text
    ha2g_total = [t.split("ms")[0] for t in tables[1:]][3]  # the 4th profile: HA2G bf16 256, determinism off
    assert (
        f"{float(ha2g_total):.0f} of its {ms(row('tune', 'ha2g', 'paper', 'bf16', '256', 'eager', 'off'))} ms"
        in text
    )


def test_the_train_config_docstring_quotes_the_record():
    from beatlite.train import TrainConfig

    doc = " ".join(TrainConfig.__doc__.split())
    ms = lambda *key: _n(_record_row(*key)["step_ms"])  # noqa: E731
    camn, ha2g = ("camn", "paper", "bf16", "256"), ("ha2g", "paper", "bf16", "256")
    wide = ("camn", "paper", "bf16", "1024")
    for sentence in (
        f"from {ms('full', *camn, 'eager', 'on')} to {ms('full', *camn, 'eager', 'off')} ms per step and HA2G's "
        f"from {ms('full', *ha2g, 'eager', 'on')} to {ms('full', *ha2g, 'eager', 'off')}",
        f"from {ms('full', *camn, 'eager', 'on')} to {ms('full', *camn, 'reduce-overhead', 'on')} ms per step at "
        f"batch 256 and, with ``deterministic=False``, from {ms('tune', *wide, 'eager', 'off')} to "
        f"{ms('tune', *wide, 'reduce-overhead', 'off')} ms at 1024",
    ):
        assert sentence in doc, sentence
