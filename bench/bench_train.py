"""Training speed per model x preset x device x precision x batch size: windows/s, peak memory, FLOPs.

Run: ``BEATLITE_THREADS=1 .venv/bin/python bench/bench_train.py --quick [--json build/bench_train.json]``
(``--quick``: CaMN and HA2G tiny, batch 16, fp32 and bf16, on a 3-take store; under a minute on one CPU
core). Without ``--quick`` every trainable registered model's ``tiny`` preset (and on CUDA CaMN's and HA2G's
``paper`` preset) runs at batch 16 and 64 on the ``data_samples/`` train split (``--models``, ``--presets``,
``--batch-sizes``, ``--devices``, ``--precisions`` choose; a paper preset on one CPU thread takes minutes per row).
``--json``: the rows and GEMM peaks, rewritten (atomically) after every row, with the command, the code's revision
(``git rev-parse --short HEAD``, ``+changes`` for a modified checkout) and the machine (host, CPU, torch, threads, GPU).

Per row:

- **step windows/s** (and ms/step): the model's own training step, as ``fit`` takes it
  (``beatlite.train.training._Run.step``: forward, losses, discriminator step, backward, Adam, gradient
  clipping; adversarial epoch) on one batch already on the device: no data path.
- **fit windows/s (loader)**: ``fit`` itself on a window store (``store.windows("train", keys=batch_keys)``),
  one epoch of ``--fit-steps`` steps, batches read by the store's DataLoader and copied to the device: the data
  path included. ``fit/step`` is their ratio (the named alternative measured in the same run: what the data
  path costs).
- **fit windows/s (resident)**: the same ``fit`` with ``data_on_device="always"``: the model's streams held on
  the device (:class:`beatlite.data.resident.ResidentWindows`), every batch gathered there; ``resident/loader``
  is its ratio to the loader route in the same run.
- **GFLOP/window**: FLOPs of one training step divided by the batch size, counted with
  ``torch.utils.flop_counter.FlopCounterMode`` (matrix products and convolutions; the fused recurrent kernels
  that it does not know, oneDNN's ``mkldnn_rnn_layer`` and cuDNN's ``_cudnn_rnn``, are counted here as
  ``2 x frames x windows x`` the size of their weight matrices forward and twice that backward; elementwise
  work is not counted).
- **ops/step**: operators of one eager training step dispatched below autograd (counted by a
  ``TorchDispatchMode``): a kernel launch each on a GPU, views aside, and the host's cost per launch bounds
  a step of many small kernels whatever the batch. On the CPU a GRU counts its time steps' cell operators
  (CUDA runs it as one cuDNN kernel), and Adam its loop over parameters (one fused kernel on CUDA).
- **compile**: :attr:`beatlite.train.TrainConfig.compile` of the row (``--compile``; ``eager`` = none; the
  timed steps come after a first, compiling one). FLOPs and operators are the eager step's; the fit
  columns are left out (``-``): a fit of a few steps would time its compilation.
- **deterministic**: :attr:`beatlite.train.TrainConfig.deterministic` of the row (``--deterministic on off``):
  on CUDA, ``off`` lets torch pick nondeterministic kernels and skips filling new tensors.
- **audio matmul**: ``--frame-matmul off on``: CaMN's first audio block (two convolutions of the one-channel
  waveform) as one matrix product of the waveform's frames (:func:`beatlite.models.layers.use_frame_matmul`;
  the same values to float rounding) or as cuDNN/oneDNN convolutions (``off``, the default); ``-`` for models
  without such a block (a row that failed or was not measured says what it asked for).
- ``--trace-rnn``: compiled rows trace the recurrent layers too (``torch._dynamo.config.allow_rnn``: the LSTM
  and GRU unrolled over time into the compiled graph, instead of a graph break around cuDNN's kernel); their
  compile cell says ``+rnn``.
- ``--cudnn-benchmark``: ``torch.backends.cudnn.benchmark = True`` for every row (cuDNN times its algorithms for each
  new shape and keeps the fastest; on the H200 the bf16 weight gradient of CaMN's first audio convolutions took 79 of
  153 ms of a compiled step at batch 1024 with cuDNN's default choice); the device line says ``cudnn.benchmark``.
- **% of peak**: achieved FLOP/s (GFLOP/window x step windows/s) over the rate of a large matrix product
  of the same precision measured in the same run on the same device (``peak`` line; 1024^2 on the CPU, 8192^2
  on CUDA), i.e. of what this device reaches on dense GEMMs, not of its datasheet.
- ``--profile N`` prints, per row, the ``torch.profiler`` table of one step (its N most costly operators).
- **peak MiB**: on CUDA ``torch.cuda.max_memory_allocated`` during the timed steps; on the CPU the peak
  resident set above its level before the steps (``VmHWM`` after resetting it through
  ``/proc/self/clear_refs``).

Devices that are not present print ``unmeasured``. Timings on a shared machine are noisy: compare rows of
one run, on one machine. Issue 28's targets (benchmark, not tests): CaMN paper >= 10,000 windows/s in bf16
and HA2G paper >= 3,000 on one H100/H200; tiny models on one CPU thread no slower than before (CaMN tiny
``fit`` about 150 windows/s on a CPU with AVX-512, ``bench/records/bench_train_quick_cpu.json``; 47 on one
without, ``bench_train_quick_cpu_avx2.json``). Measured on an H200: ``bench/records/bench_train_h200.json`` (README, "Using real BEAT").
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import tempfile
import time
import traceback
from pathlib import Path
from typing import Any

import numpy as np
import torch
import torch._dynamo
from torch.utils._python_dispatch import TorchDispatchMode
from torch.utils.flop_counter import FlopCounterMode

from beatlite.io.atomic import write_json
from beatlite.models import MODELS, build_model, model_class
from beatlite.models.layers import use_frame_matmul
from beatlite.paths import data_dir, n_threads, record_about
from beatlite.train import TrainConfig, fit
from beatlite.train.config import COMPILE_BACKENDS, COMPILE_MODES
from beatlite.train.training import _Run, model_keys, set_deterministic

QUICK_TAKES = ("2_scott_0_9_9", "4_lawrence_0_11_11", "6_carla_0_13_13")
"""The 3 train takes of ``--quick`` (those of the model contract suite)."""
UNMEASURED = "unmeasured"


# ---------------------------------------------------------------------------- FLOPs
def _rnn_flops(weights: list[Any], input_shape: Any) -> int:
    """2 x (rows x cols of every 2-D weight) per frame and window of a fused recurrent kernel (forward)."""
    steps = math.prod(input_shape[:-1])
    return 2 * steps * sum(math.prod(w) for w in weights if w is not None and len(w) == 2)


def _mkldnn_rnn(input, w0, w1, *args: Any, out_shape: Any = None, **kwargs: Any) -> int:  # noqa: A002, ANN001
    return _rnn_flops([w0, w1], input)


def _mkldnn_rnn_backward(input, w0, w1, *args: Any, out_shape: Any = None, **kwargs: Any) -> int:  # noqa: A002, ANN001
    return 2 * _rnn_flops([w0, w1], input)


def _cudnn_rnn(input, weights, *args: Any, out_shape: Any = None, **kwargs: Any) -> int:  # noqa: A002, ANN001
    return _rnn_flops(list(weights), input)


def _cudnn_rnn_backward(input, weights, *args: Any, out_shape: Any = None, **kwargs: Any) -> int:  # noqa: A002, ANN001
    return 2 * _rnn_flops(list(weights), input)


def _flop_counter() -> FlopCounterMode:
    """``FlopCounterMode`` that also counts the fused recurrent kernels (module docstring)."""
    aten = torch.ops.aten
    mapping = {aten.mkldnn_rnn_layer: _mkldnn_rnn, aten.mkldnn_rnn_layer_backward: _mkldnn_rnn_backward}
    if hasattr(aten, "_cudnn_rnn"):
        mapping.update({aten._cudnn_rnn: _cudnn_rnn, aten._cudnn_rnn_backward: _cudnn_rnn_backward})
    return FlopCounterMode(display=False, custom_mapping=mapping)


def gemm_peak(device: torch.device, dtype: torch.dtype) -> float:
    """FLOP/s of the best of 3 timed large square matrix products (1024 on the CPU, 8192 on CUDA)."""
    n = 8192 if device.type == "cuda" else 1024
    a, b = (torch.randn(n, n, device=device, dtype=dtype) for _ in range(2))
    best = math.inf
    for _ in range(4):
        _sync(device)
        start = time.perf_counter()
        a @ b
        _sync(device)
        best = min(best, time.perf_counter() - start)
    return 2 * n**3 / best


def _sync(device: torch.device) -> None:
    if device.type == "cuda":
        torch.cuda.synchronize(device)


# ---------------------------------------------------------------------------- memory
def _status_kib(field: str) -> int:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return int(line.split()[1])
    return 0


class _PeakMemory:
    """Peak memory (MiB) of the block: CUDA's allocator peak, or the CPU resident set's rise."""

    def __init__(self, device: torch.device) -> None:
        self.device, self.mib = device, float("nan")

    def __enter__(self) -> _PeakMemory:
        if self.device.type == "cuda":
            torch.cuda.reset_peak_memory_stats(self.device)
        else:
            try:
                Path("/proc/self/clear_refs").write_text("5")  # VmHWM := VmRSS
            except OSError:
                pass
            self.start = _status_kib("VmRSS")
        return self

    def __exit__(self, *exc: Any) -> None:
        if self.device.type == "cuda":
            self.mib = torch.cuda.max_memory_allocated(self.device) / 2**20
        elif Path("/proc/self/status").is_file():
            self.mib = (_status_kib("VmHWM") - self.start) / 1024


# ---------------------------------------------------------------------------- one row
@dataclasses.dataclass
class Row:
    """One measured (or unmeasured) configuration."""

    model: str
    preset: str
    device: str
    precision: str
    batch: int
    compile: str = "eager"
    deterministic: bool = True
    params: int | None = None
    gflop_per_window: float | None = None
    step_wps: float | None = None
    step_ms: float | None = None
    fit_wps: float | None = None
    fit_resident_wps: float | None = None
    peak_mib: float | None = None
    peak_fraction: float | None = None
    ops_per_step: int | None = None
    note: str = ""
    fit_error: str = ""
    frame_matmul: bool | None = None  # (None: the model has no one-channel audio block)
    cudnn_benchmark: bool = False  # (--cudnn-benchmark: cuDNN timed its algorithms for each shape first)


def _model(
    name: str, preset: str, train: Any, *, prepare: bool = True, frame_matmul: bool | None = None
) -> Any:
    """Model ``name`` at ``preset`` (seed 0) sized for the store's vocabulary, prepared on its windows (and its
    one-channel audio blocks switched to ``frame_matmul`` when given)."""
    fields = {f.name for f in dataclasses.fields(model_class(name).config_class)}
    torch.manual_seed(0)
    model = build_model(
        name, preset=preset, **({"vocab_size": len(train.vocab)} if "vocab_size" in fields else {})
    )
    if prepare:
        model.prepare(train, train.normalizers)
    if frame_matmul is not None:
        use_frame_matmul(model, frame_matmul)
    return model


def _config(device: str, precision: str, batch: int, compile: str = "eager", **kw: Any) -> TrainConfig:  # noqa: A002
    return TrainConfig(
        batch_size=batch, device=device, amp=precision == "bf16", progress=False, no_adv_epochs=0,
        compile=None if compile == "eager" else compile, **kw,
    )  # fmt: skip


class _CountOps(TorchDispatchMode):
    """Counts the operators dispatched below autograd, views (``detach``, ``t``, ``view``) included: a kernel
    launch each on a GPU but the views, which launch none (so the count bounds the launches from above)."""

    def __init__(self) -> None:
        super().__init__()
        self.count = 0

    def __torch_dispatch__(self, func: Any, types: Any, args: tuple = (), kwargs: dict | None = None) -> Any:
        self.count += 1
        return func(*args, **(kwargs or {}))


def measure_step(
    name: str, preset: str, device: str, precision: str, batch: int, train: Any, steps: int, profile: int = 0,
    compile: str = "eager",  # noqa: A002
    deterministic: bool = True,
    frame_matmul: bool | None = False,
) -> Row:  # fmt: skip
    """The step columns of one row: FLOPs, operators, windows/s and peak memory of ``fit``'s training step
    (and, with ``profile`` > 0, the ``torch.profiler`` table of one more step: its ``profile`` most costly
    operators)."""
    set_deterministic(deterministic, device)  # (as fit sets it from its TrainConfig)
    model = _model(name, preset, train, frame_matmul=frame_matmul)
    run = _Run(model, _config(device, precision, batch, compile, epochs=1), "bench", {})
    keys = model_keys(model)
    data = train.batch(np.arange(batch) % len(train), keys=keys)
    tensors = {k: torch.from_numpy(np.ascontiguousarray(v)).to(run.device) for k, v in data.items()}
    tensors = {
        k: v.long() if v.dtype in (torch.int32, torch.int16, torch.int8) else v for k, v in tensors.items()
    }
    step = [(tensors, batch)]
    model.train()
    counted = run  # FLOPs and operators of the eager step (a compiled step's kernels are not dispatched)
    if compile != "eager":
        counted = _Run(
            _model(name, preset, train, frame_matmul=frame_matmul),
            _config(device, precision, batch, epochs=1),
            "bench",
            {},
        )
    with _flop_counter() as counter:
        counted.step(step, 0, {})
    with _CountOps() as ops:
        counted.step(step, 0, {})
    for _ in range(1 if compile == "eager" else 3):  # warm-up: allocator, oneDNN primitives, cuDNN plans;
        run.step(step, 0, {})  # compiled: the compilation, then reduce-overhead's CUDA-graph recording
    _sync(run.device)
    with _PeakMemory(run.device) as memory:
        start = time.perf_counter()
        for _ in range(steps):
            run.step(step, 0, {})
        _sync(run.device)
        seconds = (time.perf_counter() - start) / steps
    if profile:
        _profile(run, step, profile)
    dtype = torch.bfloat16 if precision == "bf16" else torch.float32
    gflop = counter.get_total_flops() / batch / 1e9
    row = Row(
        name, preset, device, precision, batch, compile, deterministic, model.n_parameters(), gflop,
        batch / seconds, 1e3 * seconds, ops_per_step=ops.count,
    )  # fmt: skip
    row.frame_matmul = bool(frame_matmul) if use_frame_matmul(model, bool(frame_matmul)) else None
    row.peak_mib = memory.mib
    row.peak_fraction = gflop * 1e9 * row.step_wps / _peak(run.device, dtype)
    return row


def _profile(run: _Run, step: list, top: int) -> None:
    """Print the operators of one training step by self time (CPU, and CUDA when on the GPU)."""
    from torch.profiler import ProfilerActivity, profile

    activities = [ProfilerActivity.CPU] + ([ProfilerActivity.CUDA] if run.device.type == "cuda" else [])
    with profile(activities=activities) as prof:
        run.step(step, 0, {})
        _sync(run.device)
    key = "self_cuda_time_total" if run.device.type == "cuda" else "self_cpu_time_total"
    print(prof.key_averages().table(sort_by=key, row_limit=top))


_PEAKS: dict[tuple[str, torch.dtype], float] = {}


def _peak(device: torch.device, dtype: torch.dtype) -> float:
    key = (str(device), dtype)
    if key not in _PEAKS:
        _PEAKS[key] = gemm_peak(device, dtype)
    return _PEAKS[key]


def measure_fit(row: Row, store_train: Any, steps: int) -> None:
    """``fit``'s windows/s on the store view of the model's keys (one epoch of ``steps`` steps), by both routes
    of a store view: batches read by the store's loader (``data_on_device="never"``) and gathered on the
    device from resident streams (``"always"``, :class:`beatlite.data.resident.ResidentWindows`)."""
    for mode, field in (("never", "fit_wps"), ("always", "fit_resident_wps")):
        model = _model(row.model, row.preset, store_train, prepare=False, frame_matmul=bool(row.frame_matmul))
        keys = type(model).batch_keys(model.config)
        view = store_train.store.windows("train", keys=keys, stats=store_train.normalizers)
        n = min(len(view), steps * row.batch)
        config = _config(
            row.device, row.precision, row.batch, row.compile, epochs=1, windows_per_epoch=n,
            data_on_device=mode, deterministic=row.deterministic,
        )  # fmt: skip
        start = time.perf_counter()
        fit(model, view, config)
        setattr(row, field, n / (time.perf_counter() - start))


# ---------------------------------------------------------------------------- table and command line
COLUMNS = (
    ("model", "model"), ("preset", "preset"), ("device", "device"), ("precision", "precision"),
    ("batch", "batch"), ("compile", "compile"), ("deterministic", "deterministic"), ("frame_matmul", "audio matmul"), ("params", "params (M)"), ("gflop_per_window", "GFLOP/window"),
    ("ops_per_step", "ops/step"),
    ("step_wps", "step windows/s"), ("step_ms", "ms/step"), ("fit_wps", "fit windows/s (loader)"),
    ("fit_ratio", "fit/step"), ("fit_resident_wps", "fit windows/s (resident)"), ("resident_ratio", "resident/loader"), ("peak_mib", "peak MiB"), ("peak_fraction", "% of GEMM peak"),
)  # fmt: skip


def _cell(row: Row, field: str) -> str:
    if row.note and field not in (
        "model",
        "preset",
        "device",
        "precision",
        "batch",
        "compile",
        "deterministic",
        "frame_matmul",
    ):
        return row.note
    ratios = {"fit_ratio": (row.fit_wps, row.step_wps), "resident_ratio": (row.fit_resident_wps, row.fit_wps)}
    if field in ratios:
        a, b = ratios[field]
        value = a / b if a and b else None
    else:
        value = getattr(row, field)
    if isinstance(value, bool):
        return "on" if value else "off"
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    if field == "peak_mib":
        value = max(value, 0.0)  # (the CPU's resident set may shrink during the steps)
    if field == "params":
        return f"{value / 1e6:.2f}"
    if field == "peak_fraction":
        return f"{100 * value:.1f}"
    if field in ("gflop_per_window", "fit_ratio", "resident_ratio"):
        return f"{value:.3g}"
    return f"{value:,.0f}" if isinstance(value, float) else str(value)


def markdown(rows: list[Row]) -> str:
    """The rows as a Markdown table."""
    lines = ["| " + " | ".join(h for _, h in COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    lines += ["| " + " | ".join(_cell(r, f) for f, _ in COLUMNS) + " |" for r in rows]
    return "\n".join(lines)


def _store_train(quick: bool, folder: Path) -> Any:
    """The train split of a window store: 3 takes of ``data_samples/`` (quick, in ``folder``) or all its takes
    (the default store folder, built once and kept)."""
    from beatlite.data.index import index_folder
    from beatlite.data.store import build_store

    index = index_folder(data_dir())
    if quick:
        return build_store(index.where(stem=list(QUICK_TAKES)), folder, workers=0).windows("train")
    return build_store(index, workers=n_threads()).windows("train")


def _parse() -> argparse.Namespace:
    trainable = [n for n in MODELS if n not in ("mean_pose", "random_clip")]
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument(
        "--quick", action="store_true", help="CaMN and HA2G tiny, batch 16, 3 takes (< 1 min on a CPU)"
    )
    p.add_argument(
        "--models", nargs="+", default=None, help=f"default: {' '.join(trainable)} (quick: camn ha2g)"
    )
    p.add_argument(
        "--presets", nargs="+", default=None, help="default: tiny, and paper for camn/ha2g on CUDA"
    )
    p.add_argument("--devices", nargs="+", default=["cpu", "cuda"])
    p.add_argument("--precisions", nargs="+", default=["fp32", "bf16"], choices=["fp32", "bf16"])
    p.add_argument("--batch-sizes", nargs="+", type=int, default=None, help="default 16 64 (quick: 16)")
    p.add_argument("--steps", type=int, default=None, help="timed steps per row (default 10, quick 3)")
    p.add_argument(
        "--fit-steps",
        type=int,
        default=None,
        help="steps of the timed fit epoch (default 10, quick 2; 0: no fit)",
    )
    p.add_argument(
        "--compile", nargs="+", default=["eager"], choices=["eager", *COMPILE_MODES, *COMPILE_BACKENDS],
        help="TrainConfig.compile of the rows (eager: none); default eager",
    )  # fmt: skip
    p.add_argument(
        "--deterministic", nargs="+", default=["on"], choices=["on", "off"],
        help="TrainConfig.deterministic of the rows; default on",
    )  # fmt: skip
    p.add_argument(
        "--frame-matmul", nargs="+", default=["off"], choices=["off", "on"],
        help="CaMN's first audio block as a matrix product of frames (on) or as convolutions (off); default off",
    )  # fmt: skip
    p.add_argument(
        "--trace-rnn", action="store_true",
        help="compiled rows trace the LSTM/GRU layers too (torch._dynamo.config.allow_rnn)",
    )  # fmt: skip
    p.add_argument(
        "--cudnn-benchmark", action="store_true", help="torch.backends.cudnn.benchmark = True for every row"
    )
    p.add_argument("--json", type=Path, default=None, help="also write the rows as JSON here")
    p.add_argument(
        "--profile", type=int, default=0, help="print the N most costly operators of one step per row"
    )
    args = p.parse_args()
    args.models = args.models or (["camn", "ha2g"] if args.quick else trainable)
    args.batch_sizes = args.batch_sizes or ([16] if args.quick else [16, 64])
    args.steps = args.steps or (3 if args.quick else 10)
    if args.fit_steps is None:
        args.fit_steps = 2 if args.quick else 10
    return args


def _grid(args: argparse.Namespace) -> list[tuple[str, str, str, str, int, str, bool, bool | None]]:
    """(model, preset, device, precision, batch, compile, deterministic, frame matmul) of every row; by default
    the paper presets on CUDA only; frame matmul ``None`` (one row) for a model without a one-channel audio
    block."""
    grid = []
    for name in args.models:
        matmul = [m == "on" for m in args.frame_matmul]
        if use_frame_matmul(build_model(name, preset="tiny"), False) == 0:
            matmul = [None]
        for device in args.devices:
            paper = name in ("camn", "ha2g") and device == "cuda" and not args.quick
            for preset in args.presets or (["tiny", "paper"] if paper else ["tiny"]):
                for precision in args.precisions:
                    for b in args.batch_sizes:
                        grid += [
                            (name, preset, device, precision, b, c, d == "on", m)
                            for c in args.compile
                            for d in args.deterministic
                            for m in matmul
                        ]
    return grid


def main() -> None:
    args = _parse()
    os.environ.setdefault("CUBLAS_WORKSPACE_CONFIG", ":4096:8")  # (as fit's: before CUDA's first product)
    torch.backends.cudnn.benchmark = args.cudnn_benchmark
    if args.trace_rnn:
        torch._dynamo.config.allow_rnn = True
    torch.set_num_threads(n_threads())
    about = record_about()  # (before the record, maybe a tracked file)
    with tempfile.TemporaryDirectory() as tmp:
        train = _store_train(args.quick, Path(tmp) / "store")
        bench = "  cudnn.benchmark" if args.cudnn_benchmark else ""
        print(
            f"threads={torch.get_num_threads()}  torch {torch.__version__}  {len(train)} train windows{bench}"
        )
        rows = []
        for name, preset, device, precision, batch, comp, det, matmul in _grid(args):
            key = (name, preset, device, precision, batch, comp, det)  # (a row that is not measured)
            if device == "cuda" and not torch.cuda.is_available():
                rows.append(Row(*key, note=UNMEASURED, frame_matmul=matmul))
                continue
            label = f"{comp}+rnn" if args.trace_rnn and comp != "eager" else comp
            try:
                row = measure_step(
                    name, preset, device, precision, batch, train, args.steps, args.profile, compile=comp,
                    deterministic=det, frame_matmul=matmul,
                )  # fmt: skip
            except Exception as error:  # noqa: BLE001 (a row that fails is reported and the others run)
                row = Row(*key, note=_failed(error), frame_matmul=matmul)  # (as asked: not measured)
                _recover(device)
            else:  # (a compiled row's short fit would time its compilation)
                if comp == "eager" and args.fit_steps > 0:
                    try:
                        measure_fit(row, train, args.fit_steps)
                    except Exception as error:  # noqa: BLE001 (the step's columns stay; the fit's say "-")
                        row.fit_error = _failed(error)
                        _recover(device)
            row.compile, row.cudnn_benchmark = label, args.cudnn_benchmark
            rows.append(row)
            fit_error = f" (fit {row.fit_error})" if row.fit_error else ""
            matmul_label = " matmul" if row.frame_matmul else ""
            print(f"  {name} {preset} {device} {precision} b{batch} {comp} det={det}{matmul_label}: "
                  + (row.note or f"{row.step_wps:,.0f} windows/s{fit_error}"), flush=True)  # fmt: skip
            _write_json(
                args.json, rows, about
            )  # after every row: a run stopped by a time limit keeps what it measured
    for (device, dtype), flops in sorted(_PEAKS.items(), key=str):
        print(f"peak: {device} {str(dtype).replace('torch.', '')} matrix product {flops / 1e9:,.1f} GFLOP/s")
    print(markdown(rows))
    _write_json(args.json, rows, about)


def _recover(device: str) -> None:
    """After a failed row: print its traceback, forget what ``torch.compile`` cached, free the GPU's cache."""
    traceback.print_exc()
    torch._dynamo.reset()
    if device == "cuda":
        torch.cuda.empty_cache()


def _failed(error: BaseException) -> str:
    """A failed row's note: ``failed: <type>: <first line of the message, at most 80 characters>``."""
    message = (str(error).strip().splitlines() or [""])[0][:80].replace("|", "/")
    return f"failed: {type(error).__name__}: {message}"


def _write_json(path: Path | None, rows: list[Row], about: dict[str, Any]) -> None:
    """The rows (and the GEMM peaks measured so far) as JSON at ``path`` (nothing without one), after ``about``
    (the command, the code's revision and :func:`beatlite.paths.machine`: :func:`main`)."""
    if path is None:
        return
    peaks = {f"{d} {t}": f for (d, t), f in _PEAKS.items()}
    write_json(path, {**about, "peaks": peaks, "rows": [dataclasses.asdict(r) for r in rows]})


if __name__ == "__main__":
    main()
