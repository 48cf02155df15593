"""Multi-process training with torch's own engine: ``torchrun`` with the gloo backend on the CPU."""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

import pytest
from childproc import run_ok

torch = pytest.importorskip("torch")

SCRIPT = Path(__file__).with_name("ddp_fit.py")


def _env(tmp_path: Path) -> dict[str, str]:
    """The children's environment: this checkout first on the path, one thread, and a temp folder of their own
    inside ``tmp_path`` (torchrun leaves a ``torchelastic_*`` log folder in the temp folder of every run)."""
    root = str(Path(__file__).resolve().parents[1])
    env = {
        k: v for k, v in os.environ.items() if k not in ("WORLD_SIZE", "RANK", "LOCAL_RANK", "MASTER_ADDR")
    }
    env["PYTHONPATH"] = root + os.pathsep + env.get("PYTHONPATH", "")
    env["BEATLITE_THREADS"] = "1"
    temp = tmp_path / "tmp"
    temp.mkdir(exist_ok=True)
    env["TMPDIR"] = str(temp)
    return env


def _torchrun() -> str:
    torchrun = shutil.which("torchrun", path=str(Path(sys.executable).parent)) or shutil.which("torchrun")
    if torchrun is None:
        pytest.skip("torchrun is not installed")
    return torchrun


def _one_and_two_processes(tmp_path: Path, micro: int, windows: int) -> tuple[dict, dict]:
    """What tests/ddp_fit.py saves for 1 process and for ``torchrun`` with 2 (``micro`` micro-batches)."""
    torchrun = _torchrun()
    one, two = tmp_path / "one.pt", tmp_path / "two.pt"
    args = [str(micro), str(windows)]
    run_ok([sys.executable, str(SCRIPT), str(one), *args], env=_env(tmp_path), timeout=900)
    cmd = [torchrun, "--standalone", "--nproc_per_node=2", str(SCRIPT), str(two), *args]
    run_ok(cmd, env=_env(tmp_path), timeout=900)
    return torch.load(one, weights_only=True), torch.load(two, weights_only=True)


@pytest.mark.slow
def test_two_processes_take_the_same_steps_as_one_with_two_micro_batches(tmp_path):
    """DistributedDataParallel over 2 processes (a global batch of 16 split over them, one micro-batch
    each) ends an adversarial epoch with the same weights as 1 process splitting each batch of 16 into
    2 micro-batches: the same sums in the same order, so equal to within float rounding."""
    a, b = _one_and_two_processes(tmp_path, micro=2, windows=64)
    assert a["params"].keys() == b["params"].keys()
    worst = max(float((a["params"][k] - b["params"][k]).abs().max()) for k in a["params"])
    moved = max(float((a["params"][k] - a["start"][k]).abs().max()) for k in a["params"])
    # Adam turns even last-bit gradient differences into lr-sized steps for the biases before a
    # BatchNorm (their true gradient is 0): this bound holds because the sums are the same
    assert worst < 1e-4 and moved > 1e-3, (worst, moved)
    print(f"largest weight change {moved:.3g}, largest difference 1 vs 2 processes {worst:.3g}")
    la, lb = a["history"][0]["train"], b["history"][0]["train"]
    assert la.keys() == lb.keys() and all(abs(la[k] - lb[k]) <= 1e-4 * (1 + abs(la[k])) for k in la)


@pytest.mark.slow
def test_two_processes_on_resident_windows_take_the_loaders_steps(tmp_path):
    """Under torchrun, every process gathering its micro-batches from streams held on its device
    (data_on_device="always") ends the epoch with the weights of the loader route, to the bit."""
    torchrun = _torchrun()
    runs = {}
    for mode in ("never", "always"):
        out = tmp_path / f"{mode}.pt"
        run_ok([torchrun, "--standalone", "--nproc_per_node=2", str(SCRIPT), str(out), "2", "48", mode],
               env=_env(tmp_path), timeout=900)  # fmt: skip
        runs[mode] = torch.load(out, weights_only=True)
    a, b = runs["never"], runs["always"]
    assert a["history"] == b["history"]
    assert all(torch.equal(a["params"][k], b["params"][k]) for k in a["params"])


@pytest.mark.slow
def test_two_micro_batches_per_process_give_the_mean_gradient(tmp_path):
    """With 4 micro-batches per global batch, each of the 2 processes takes 2 (forwards under DDP's
    ``no_sync`` but the last, one backward over their sum): the generator gradient of the step is the
    mean over the 4 micro-batches, as 1 process taking them in turn computes it (float32 sums in
    another order: relative differences of rounding size)."""
    a, b = _one_and_two_processes(tmp_path, micro=4, windows=16)  # one optimiser step
    assert a["grads"].keys() == b["grads"].keys() and len(a["grads"]) > 100
    ga = torch.cat([a["grads"][k].flatten() for k in sorted(a["grads"])])
    gb = torch.cat([b["grads"][k].flatten() for k in sorted(a["grads"])])
    # relative to the whole gradient: biases before a BatchNorm have a true gradient of 0, and their
    # computed ones are rounding noise on their own scale
    error = float((ga - gb).norm() / ga.norm())
    assert 0 < float(ga.norm()) and error < 1e-5, error
    la, lb = a["history"][0]["train"], b["history"][0]["train"]
    assert all(abs(la[k] - lb[k]) <= 1e-5 * (1 + abs(la[k])) for k in la)


def _whole_and_resumed(tmp_path: Path, *options: str) -> tuple[dict, dict]:
    """tests/ddp_resume.py under torchrun (2 processes), uninterrupted and killed-then-resumed: the
    ``.out`` records (final parameters, history, best) of both runs."""
    torchrun = _torchrun()
    script = Path(__file__).with_name("ddp_resume.py")
    out = {}
    for mode in ("whole", "kill"):
        path = tmp_path / f"{mode}.pt"
        cmd = [torchrun, "--standalone", "--nproc_per_node=2", str(script), str(path), mode, *options]
        run_ok(cmd, env=_env(tmp_path), timeout=900)
        out[mode] = torch.load(str(path) + ".out", weights_only=True)
    return out["whole"], out["kill"]


@pytest.mark.slow
def test_a_two_process_run_killed_mid_epoch_resumes_from_its_last_step(tmp_path):
    """Under torchrun, process 0 checkpoints after every step; a run stopped in epoch 2 resumes there and
    ends with the weights of an uninterrupted run, and logs the same mean losses (the checkpoint keeps
    the loss sums of both processes)."""
    whole, resumed = _whole_and_resumed(tmp_path)
    for name, p in whole["params"].items():
        assert torch.equal(p, resumed["params"][name]), name
    for a, b in zip(whole["history"], resumed["history"], strict=True):
        assert a["train"].keys() == b["train"].keys()
        assert all(abs(a["train"][k] - b["train"][k]) <= 1e-9 * (1 + abs(a["train"][k])) for k in a["train"])


@pytest.mark.slow
def test_two_processes_validating_every_two_steps_resume_mid_epoch_with_the_same_record(tmp_path):
    """Under torchrun with val_every=2, process 0 validates between steps (before a checkpoint of the same
    step) while process 1 goes on: the steps' collectives still meet, validations fall on the global steps
    2, 4 and 6 (3 steps per epoch), and a run stopped in epoch 2 resumes to the validations, best and
    weights of an uninterrupted one."""
    whole, resumed = _whole_and_resumed(tmp_path, "val")
    assert [[v["step"] for v in h["validations"]] for h in whole["history"]] == [[2], [4, 6]]
    assert whole["history"][1]["validations"][0]["val"]["rec"] > 0
    for a, b in zip(whole["history"], resumed["history"], strict=True):
        assert a["validations"] == b["validations"] and a["val"] == b["val"]
    assert whole["best"] == resumed["best"] and whole["best"][1] in (2, 4, 6)
    for name, p in whole["params"].items():
        assert torch.equal(p, resumed["params"][name]), name


@pytest.mark.slow
def test_two_processes_with_dropout_resume_each_with_its_own_generator(tmp_path):
    """Process 0's per-epoch validation draws random numbers that process 1 does not draw, so their
    generators differ by the time of a checkpoint; each process's dropout masks after a resume must be
    those of an uninterrupted run, so the checkpoint keeps every process's generator (not process 0's
    for all)."""
    whole, resumed = _whole_and_resumed(tmp_path, "dropout")
    assert whole["best"] == resumed["best"]
    for name, p in whole["params"].items():
        assert torch.equal(p, resumed["params"][name]), name


EXIT_CHECK = """
import atexit, sys
import torch.distributed as dist
from beatlite.train.distributed import distributed_rank

# registered before distributed_rank's handler, so it runs after it (atexit is last in, first out)
atexit.register(lambda: print(f"group alive at exit: {dist.is_initialized()}", flush=True))
rank, world = distributed_rank()
print(f"rank {rank} of {world}", flush=True)
"""


@pytest.mark.slow
def test_the_process_group_is_destroyed_before_the_interpreter_exits(tmp_path):
    """A process group left alive at exit can abort a process in gloo's threads (it did once in CI):
    the group distributed_rank initialises is gone by the time later exit handlers run."""
    script = tmp_path / "exit_check.py"
    script.write_text(EXIT_CHECK)
    cmd = [_torchrun(), "--standalone", "--nproc_per_node=2", str(script)]
    done = run_ok(cmd, env=_env(tmp_path), timeout=300)
    assert done.stdout.count("group alive at exit: False") == 2, done.stdout + done.stderr
    assert "rank 0 of 2" in done.stdout and "rank 1 of 2" in done.stdout
    # torchrun's log folder (one per run, never removed by torch) went to the children's temp folder in
    # tmp_path, not to the system's: these tests once left hundreds of torchelastic_* folders in /tmp
    assert len(list((tmp_path / "tmp").glob("torchelastic_*"))) == 1


OWNED_GROUP = """
import atexit, os, sys
import torch.distributed as dist
from beatlite.paths import repo_root
from beatlite.train import __main__ as command

out, how, rank = sys.argv[1], sys.argv[2], int(os.environ["RANK"])
if how == "fails":  # an exception after training, with the group alive
    def export_fails(full, export):
        raise RuntimeError("export failed")
    import beatlite.train.checkpoint as checkpoint
    checkpoint.export_checkpoint = export_fails
try:
    status = command.main(["fit", "mean_pose", "--data", str(repo_root() / "data_samples"), "--out", out])
except RuntimeError as error:
    status = str(error)
print(f"rank {rank}: {status}; alive after fit: {dist.is_initialized()}", flush=True)
# registered after the group was initialised, so atexit runs it before distributed_rank's own handler: the
# group must be gone already, whatever the order of the exit handlers
atexit.register(lambda: print(f"group alive at exit: {dist.is_initialized()}", flush=True))
"""


@pytest.mark.slow
@pytest.mark.parametrize("how", ["ends", "fails"])
def test_the_fit_command_destroys_the_process_group_it_started(tmp_path, how):
    """The fit command owns the process group in a process_group block: destroyed when it ends, also by an
    exception, not left to distributed_rank's atexit handler, which exit handlers registered later run before
    (a process exiting with the group alive aborts in gloo's threads: 4 runs in 10 of a script that did)."""
    script = tmp_path / "owned_group.py"
    script.write_text(OWNED_GROUP)
    cmd = [_torchrun(), "--standalone", "--nproc_per_node=2", str(script), str(tmp_path / "out"), how]
    done = run_ok(cmd, env=_env(tmp_path), timeout=600)
    said = done.stdout + done.stderr
    status = "0" if how == "ends" else "export failed"
    for rank in (0, 1):
        assert f"rank {rank}: {status if rank == 0 else 0}; alive after fit: False" in done.stdout, said
    assert done.stdout.count("group alive at exit: False") == 2, said
    assert (tmp_path / "out" / "mean_pose.pt").is_file() == (how == "ends")


SUM_ORDER = """
import json, sys
from beatlite.train.distributed import distributed_rank, sum_over_processes

rank, world = distributed_rank()
sums = {"rec": 1.0 + rank, "adv": 10.0, "D_real": 0.5}  # the model's insertion order: rec first
with open(f"{sys.argv[1]}/{rank}.json", "w") as f:  # one file per process: stdout lines interleave
    json.dump(list(sum_over_processes(sums, world).items()), f)
"""


@pytest.mark.slow
def test_summed_losses_keep_the_models_order(tmp_path):
    """Under torchrun the progress bar showed ``adv=0``: the reduced sums came back in sorted-key order and
    the bar shows the first key. They are summed over the processes and come back in the model's order."""
    import json

    script = tmp_path / "sum_order.py"
    script.write_text(SUM_ORDER)
    run_ok(
        [_torchrun(), "--standalone", "--nproc_per_node=2", str(script), str(tmp_path)],
        env=_env(tmp_path),
        timeout=300,
    )
    rows = [json.loads((tmp_path / f"{rank}.json").read_text()) for rank in (0, 1)]
    assert rows == [[["rec", 3.0], ["adv", 20.0], ["D_real", 1.0]]] * 2


@pytest.mark.slow
def test_the_fit_command_prepares_new_data_once_under_torchrun(tmp_path):
    """Two processes of ``torchrun -m beatlite.train fit`` on a corpus other than data_samples/: one builds the
    window store and trains the FGD extractor (each under a file lock, before any process group exists), the
    other waits and finds them built (it used to wait in a gloo barrier that timed out after 30 minutes)."""
    from test_train_recipes import symlinked_corpus

    corpus, out = symlinked_corpus(tmp_path / "corpus", 1), tmp_path / "run"
    cmd = [_torchrun(), "--standalone", "--nproc_per_node=2", "-m", "beatlite.train", "fit", "s2g_tiny",
           "--data", str(corpus), "--out", str(out), "--epochs", "1", "--device", "cpu", "--extractor-epochs", "1",
           "--compile", "aot_eager"]  # fmt: skip
    # (--compile: the DDP-wrapped modules through torch.compile too)
    env = {k: v for k, v in _env(tmp_path).items() if k != "BEATLITE_BUILD"}
    done = run_ok(cmd, env=env, timeout=900)
    assert done.stdout.count("training the FGD extractor") == 1, done.stdout
    assert (out / "fgd_dirvec.pt").is_file() and (out / "s2g_tiny.pt").is_file()
    assert len(list((out / "build" / "cache" / "store").iterdir())) == 1  # one store, built once
    from beatlite.train.checkpoint import load_checkpoint

    full = load_checkpoint(out / "train" / "s2g_tiny.pt")
    assert full["train_config"]["compile"] == "aot_eager" and full["epoch"] == 1
