#!/usr/bin/env bash
# Issue 28's GPU measurements as one prepared run (for a session lent a GPU; tested on the CPU first).
#
# Here, once:  scripts/gpu_wheels.sh            (librosa & co. as wheels into .whl/, ignored by git)
# There:       bash bench/gpu_session.sh STAGE  (the device tool's `run`, carry [".whl"], $OUT set)
#   STAGE eager    bench_train: CaMN and HA2G, tiny and paper presets, fp32 and bf16, batch 64 and 256, eager,
#                  with the torch.profiler table of each row's step (about 5 min on an H100/H200)
#   STAGE compile  the paper presets in bf16 at batch 256, compiled (reduce-overhead: CUDA graphs) and eager
#                  in the same run (compilation included, about 5 min)
#   STAGE cpu      a 1-minute rehearsal of both on this machine's CPU (tiny presets, 2 steps)
# Results: $OUT/<stage>.md (the table and the log) and $OUT/<stage>.json (bench_train's rows).
set -u -o pipefail
stage=${1:?stage: eager, compile or cpu}
case "$stage" in eager | compile | cpu) ;; *) echo "unknown stage $stage (eager, compile or cpu)" >&2; exit 2 ;; esac
out=${OUT:-build/gpu_session}
mkdir -p "$out"
if [ -d .whl ] && ! python3 -c "import librosa" 2>/dev/null; then
    python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site \
        .whl/*.whl || exit 1
    export PYTHONPATH=/tmp/site
fi
export PYTHONPATH="$PWD${PYTHONPATH:+:$PYTHONPATH}" MPLBACKEND=Agg PYTHONUNBUFFERED=1
export BEATLITE_THREADS=${BEATLITE_THREADS:-$(( $(nproc) > 8 ? 8 : $(nproc) ))}
python3 - <<'PY' 2>&1 | tee "$out/$stage.md"
import platform, torch
gpu = torch.cuda.get_device_name(0) if torch.cuda.is_available() else "no CUDA"
print(f"{platform.node()}  torch {torch.__version__}  {gpu}")
from beatlite.metrics.beats import warm_up  # librosa's numba code compiled once before the store's workers
warm_up()
PY
bench() { timeout "$1" python3 bench/bench_train.py "${@:2}" --json "$out/$stage.json" 2>&1 | tee -a "$out/$stage.md"; }
case "$stage" in
    eager) bench 330 --models camn ha2g --presets tiny paper --devices cuda --batch-sizes 64 256 --profile 15 ;;
    compile) bench 330 --models camn ha2g --presets paper --devices cuda --precisions bf16 --batch-sizes 256 \
        --compile eager reduce-overhead ;;
    cpu) bench 300 --quick --devices cpu --steps 2 --fit-steps 1 --compile eager aot_eager --profile 5 ;;
esac
