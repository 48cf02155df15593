#!/usr/bin/env bash
# Issue 28's GPU measurements as one prepared run (for a session lent a GPU; tested on the CPU first).
#
# Here, once:  scripts/gpu_wheels.sh            (librosa & co. as wheels into .whl/, ignored by git)
# There:       bash bench/gpu_session.sh STAGE  (the device tool's `run`, carry [".whl"], $OUT set)
#   STAGE eager    bench_train, eager: the paper presets of CaMN and HA2G in fp32 and bf16 at batch 64 and 256,
#                  with the torch.profiler table of each row's step, and the tiny presets at batch 64
#                  (one run per model, at most 200 s each)
#   STAGE compile  the paper presets in bf16 at batch 256, compiled (reduce-overhead: CUDA graphs) and eager
#                  in the same run (compilation included; at most 240 s per model)
#   STAGE full     both in one call of about 7 minutes, most telling rows first: per model the paper preset
#                  eager (fp32/bf16 x batch 64/256, profiled; CaMN bf16 also at 1024), bf16 batch 256 with
#                  determinism off, compiled with reduce-overhead; then the tiny presets at 64
#   STAGE tune     after full (about 7 minutes): bf16 with TrainConfig.deterministic off; CaMN paper at 256 (fit
#                  included) and 1024, eager and reduce-overhead, then with the LSTM traced into the graph
#                  (--trace-rnn); HA2G paper at 256 and 512
#   STAGE next     the leads tune left (about 8 minutes), bf16 with determinism off: CaMN paper at 1024, eager and
#                  compiled, its first audio block as convolutions and as one matrix product of the waveform's
#                  frames (--frame-matmul off on: cuDNN's slow bf16 weight gradient of the raw-audio convolutions);
#                  HA2G paper at 512, eager and compiled (reduce-overhead; its training pass compiles since the
#                  style loss gathers its permutation: a new lead, not one tune left), both profiled
#   STAGE later    after next (about 4 minutes, measured as two calls): HA2G paper bf16 at 256 eager with determinism on and off (on no
#                  longer fills every new tensor on CUDA, set_deterministic: against full's 323 and 260 ms/step),
#                  then HA2G paper bf16 at 1024 compiled (reduce-overhead), determinism off
#   STAGE cudnn    after later (at most 5 minutes, its limits; never run yet): CaMN paper bf16 at 1024 compiled with the audio matmul, with
#                  cudnn.benchmark, then with the LSTM traced into the graph (a longer limit)
#   STAGE fit      the fit command itself at the fast settings (347 and 375 s in its two runs, 2026-11-27):
#                  bench/bench_fit_command.py on a 4-hour BEAT-rate corpus made there, fresh and again on one
#                  --out, CaMN at the paper's size, bf16, batch 1024, compiled, determinism off (the extractor 2 epochs),
#                  3 epochs each: the first compiles, the next two time an epoch (bench_fit_command's epoch_s)
#   STAGE repeat   bench/repeat_fit.py: camn_tiny and ha2g_tiny trained twice each (2 epochs, seed 2022) on CUDA with
#                  TrainConfig.deterministic on and off: are the two runs' weights equal to the bit? (about 3 minutes)
#   STAGE cpu      a 1-minute rehearsal of both on this machine's CPU (tiny presets, 2 steps)
# Back here: python bench/gpu_record.py add STAGE FOLDER (full, tune, next, later, cudnn: into
#             bench/records/bench_train_h200.json), then
#             python bench/gpu_record.py table (the README's GPU table from the record)
# Results: $OUT/<stage>.md (the log and tables) and bench_train's rows, written after every row, so a run
# stopped by its time limit keeps the rows it measured: $OUT/<stage>.json for full, tune, next, later and cudnn (all
# of the stage's calls merged), $OUT/<stage>-<model>.json for the others.
set -u -o pipefail
stage=${1:?stage: eager, compile, full, tune, next, later, cudnn, fit, repeat or cpu}
case "$stage" in eager | compile | full | tune | next | later | cudnn | fit | repeat | cpu) ;; *) echo "unknown stage $stage (eager, compile, full, tune, next, later, cudnn, fit, repeat or cpu)" >&2; exit 2 ;; esac
out=${OUT:-build/gpu_session}
mkdir -p "$out"
if [ -d .whl ] && ! python3 -c "import librosa" 2>/dev/null; then
    python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site \
        .whl/*.whl || exit 1
    export PYTHONPATH=/tmp/site
fi
export PYTHONPATH="$PWD${PYTHONPATH:+:$PYTHONPATH}" MPLBACKEND=Agg PYTHONUNBUFFERED=1
export BEATLITE_THREADS=${BEATLITE_THREADS:-$(( $(nproc) > 8 ? 8 : $(nproc) ))}
# (as -c, not a script on stdin: the store's spawned workers re-run __main__, and "<stdin>" is no file)
setup=$(cat <<'PY'
import platform, torch
gpu = torch.cuda.get_device_name(0) if torch.cuda.is_available() else "no CUDA"
print(f"{platform.node()}  torch {torch.__version__}  {gpu}")
from beatlite.metrics.beats import warm_up  # librosa's numba code compiled once before the store's workers
warm_up()
import time
from beatlite.data.index import index_folder
from beatlite.data.store import build_store
from beatlite.paths import data_dir, n_threads
start = time.perf_counter()  # data_samples' store, built once here (outside the rows' time limits)
store = build_store(index_folder(data_dir()), workers=n_threads())
print(f"store: {len(store.windows('train'))} train windows, {time.perf_counter() - start:.1f} s")
PY
)
python3 -c "$setup" 2>&1 | tee "$out/$stage.md"
n=0
parts=$(mktemp -d)
bench() {  # bench SECONDS MODEL ARGS...  (full, tune, next, later, cudnn: every call's rows merged into $out/$stage.json)
    n=$((n + 1))
    local json="$out/$stage-$2.json"
    case "$stage" in full | tune | next | later | cudnn) json="$parts/$(printf %02d $n).json" ;; esac
    timeout "$1" python3 bench/bench_train.py --models "$2" "${@:3}" --json "$json" 2>&1 | tee -a "$out/$stage.md"
    case "$stage" in full | tune | next | later | cudnn) python3 -c 'import json, sys
docs = [json.load(open(p)) for p in sys.argv[2:]]
json.dump({"peaks": [d["peaks"] for d in docs], "rows": [r for d in docs for r in d["rows"]]}, open(sys.argv[1], "w"), indent=1)' \
        "$out/$stage.json.tmp" "$parts"/*.json && mv "$out/$stage.json.tmp" "$out/$stage.json" ;; esac  # (whole or not at all)
    return 0
}
if [ "$stage" = fit ]; then
    # (FIT_HOURS and FIT_ARGS: a rehearsal's smaller corpus and CPU flags; FIT_MORE: flags added, e.g.
    # "--epochs 4 --val-every 1000": validation only at the end, so epochs 2-3 time training alone)
    fast="--epochs 3 --device cuda --preset paper --batch-size 1024 --lr 2e-3 --precision bf16 --compile reduce-overhead --nondeterministic"
    timeout 540 python3 bench/bench_fit_command.py --hours "${FIT_HOURS:-4}" --workers "$(nproc)" --extractor-epochs 2 \
        --fit-args="${FIT_ARGS:-$fast} ${FIT_MORE:-}" --json "$out/fit.json" 2>&1 | tee -a "$out/$stage.md"
    exit 0
fi
if [ "$stage" = repeat ]; then
    timeout 400 python3 bench/repeat_fit.py --device cuda --epochs 2 --json "$out/repeat.json" 2>&1 | tee -a "$out/$stage.md"
    exit 0
fi
paper=(--presets paper --devices cuda --precisions bf16 --deterministic off --fit-steps 0 --profile 12)
if [ "$stage" = next ]; then
    bench 200 camn "${paper[@]}" --batch-sizes 1024 --compile eager reduce-overhead --frame-matmul off on
    bench 240 ha2g "${paper[@]}" --batch-sizes 512 --compile eager reduce-overhead
    exit 0
fi
if [ "$stage" = later ]; then
    bench 80 ha2g --presets paper --devices cuda --precisions bf16 --deterministic on off --fit-steps 0 --profile 12 --batch-sizes 256
    bench 165 ha2g "${paper[@]}" --batch-sizes 1024 --compile reduce-overhead
    exit 0
fi
if [ "$stage" = cudnn ]; then
    bench 90 camn "${paper[@]}" --batch-sizes 1024 --compile reduce-overhead --frame-matmul on --cudnn-benchmark
    bench 200 camn "${paper[@]}" --batch-sizes 1024 --compile reduce-overhead --frame-matmul on --trace-rnn
    exit 0
fi
if [ "$stage" = tune ]; then
    paper=(--presets paper --devices cuda --precisions bf16 --deterministic off --profile 12)  # (fit steps too)
    bench 35 camn "${paper[@]}" --batch-sizes 256
    bench 90 camn "${paper[@]}" --batch-sizes 1024 --fit-steps 0 --compile eager reduce-overhead
    bench 70 ha2g "${paper[@]}" --batch-sizes 256 512 --fit-steps 3
    bench 180 camn "${paper[@]}" --batch-sizes 1024 --fit-steps 0 --compile reduce-overhead --trace-rnn
    exit 0
fi
if [ "$stage" = full ]; then
    nvidia-smi 2>&1 | tee -a "$out/$stage.md"
    for model in camn ha2g; do
        bench 90 "$model" --presets paper --devices cuda --batch-sizes 64 256 --profile 12
        [ "$model" = camn ] && bench 25 camn --presets paper --devices cuda --precisions bf16 --batch-sizes 1024 \
            --fit-steps 0 --profile 12
        bench 30 "$model" --presets paper --devices cuda --precisions bf16 --batch-sizes 256 --deterministic off \
            --fit-steps 0
        bench 100 "$model" --presets paper --devices cuda --precisions bf16 --batch-sizes 256 \
            --compile reduce-overhead --profile 12
    done
    bench 35 camn ha2g --presets tiny --devices cuda --precisions fp32 --batch-sizes 64
    exit 0
fi
for model in camn ha2g; do
    case "$stage" in
        eager)
            bench 150 "$model" --presets paper --devices cuda --batch-sizes 64 256 --profile 15
            bench 50 "$model" --presets tiny --devices cuda --batch-sizes 64 ;;
        compile) bench 240 "$model" --presets paper --devices cuda --precisions bf16 --batch-sizes 256 \
            --compile eager reduce-overhead ;;
        cpu) bench 150 "$model" --quick --devices cpu --steps 2 --fit-steps 1 --compile eager aot_eager --profile 5 ;;
    esac
done
