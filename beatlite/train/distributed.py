"""Multi-process training with torch's own engine: ``torchrun`` starts the processes, and
:class:`torch.nn.parallel.DistributedDataParallel` (DDP) averages the gradients.

Described in docs/architecture.md ("Scale"). :func:`beatlite.train.fit` calls :func:`distributed_rank`
and, with two or more processes, :func:`wrap_for_ddp`; nothing else changes for a model.

A :class:`~beatlite.models.base.GestureModel` takes two optimiser steps per batch when it has a
discriminator, and some models compute losses with modules that their ``forward`` does not call
(HA2G's contrastive audio heads). DDP needs one forward through the wrapper before each backward, so
the model is wrapped twice, over disjoint parameters:

- the generator view (every child module but the discriminator): its forward is ``model(batch)``;
  the generator losses are computed after it, outside the wrapper, and their backward is reduced by
  it (every generator parameter gets a gradient in every step, a contract of ``GestureModel``);
- the discriminator view: its forward is ``model.discriminator_losses(batch, out)``.

Both use ``find_unused_parameters=False`` (nothing is searched; a parameter without a gradient
stops training with DDP's own error). The processes split each global batch into micro-batches
(``TrainConfig.micro_batches``); every process reads only its own (the window index is the
sampler), and DDP's average of the per-process gradients is scaled so that an optimiser step sees
the mean over the micro-batches, as one process taking them one after the other would.
"""

from __future__ import annotations

import atexit
import contextlib
import os
from collections.abc import Iterator
from typing import Any

import torch
from torch import nn


def distributed_rank() -> tuple[int, int]:
    """``(rank, world size)`` of this process: ``(0, 1)`` unless started by ``torchrun`` with 2+ processes.

    Under ``torchrun`` (``WORLD_SIZE`` >= 2) the default process group is initialised here, with the
    ``nccl`` backend for CUDA tensors when CUDA is available (each process on GPU ``LOCAL_RANK``) and
    ``gloo`` for CPU tensors. A process that exits with the group alive can abort in gloo's worker
    threads during interpreter shutdown (SIGABRT, "terminate called without an active exception"), as
    it once did in this project's CI: the program's top level owns the group in a :func:`process_group`
    block (the ``fit`` command does), which destroys it when the block ends, also by an exception, whatever
    exit handlers run later. A group initialised outside such a block (a script calling
    :func:`beatlite.train.fit` or :func:`beatlite.train.recipes.retrain` itself) is destroyed at interpreter
    exit (``atexit``), while Python is still whole.

    Examples
    --------
    A process not started by ``torchrun`` is the only one:

    >>> distributed_rank()
    (0, 1)
    """
    import torch.distributed as dist

    if int(os.environ.get("WORLD_SIZE", "1")) < 2 or not dist.is_available():
        return 0, 1
    if not dist.is_initialized():
        if torch.cuda.is_available():
            torch.cuda.set_device(local_device(torch.device("cuda")))
        # gloo for CPU tensors, nccl for CUDA ones (training on the CPU of a GPU machine works too)
        dist.init_process_group(backend="cpu:gloo,cuda:nccl" if torch.cuda.is_available() else "gloo")
        atexit.register(_destroy_process_group)
    return dist.get_rank(), dist.get_world_size()


def _destroy_process_group() -> None:
    import torch.distributed as dist

    if dist.is_available() and dist.is_initialized():
        dist.destroy_process_group()


@contextlib.contextmanager
def process_group() -> Iterator[None]:
    """A block that owns the default process group :func:`distributed_rank` initialises inside it: the group is
    destroyed when the block ends (normally or by an exception), before the process goes on or exits.

    Nothing is initialised on entry (the ``fit`` command prepares its data before any group exists), and a group
    that existed before the block is left alone (its owner destroys it). Without ``torchrun`` a no-op. Put it
    around all of a process's training (a script's whole work): under ``torchrun`` a process cannot initialise a
    group again after destroying one (the second connects to the first's stale addresses in torchrun's store).

    Examples
    --------
    >>> with process_group():  # one process: no group, nothing to destroy
    ...     distributed_rank()
    (0, 1)
    """
    import torch.distributed as dist

    existed = dist.is_available() and dist.is_initialized()
    try:
        yield
    finally:
        if not existed:
            _destroy_process_group()


def local_device(device: torch.device) -> torch.device:
    """``device``, made ``cuda:LOCAL_RANK`` for an un-numbered CUDA device under ``torchrun``.

    Examples
    --------
    ``torchrun`` sets ``LOCAL_RANK`` (here by hand, on any machine: no GPU is touched):

    >>> from unittest import mock
    >>> with mock.patch.dict(os.environ, {"LOCAL_RANK": "1"}):
    ...     local_device(torch.device("cuda")), local_device(torch.device("cuda", 0)), local_device(torch.device("cpu"))
    (device(type='cuda', index=1), device(type='cuda', index=0), device(type='cpu'))
    """
    if device.type == "cuda" and device.index is None and "LOCAL_RANK" in os.environ:
        return torch.device("cuda", int(os.environ["LOCAL_RANK"]))
    return device


class _View(nn.Module):
    """Some child modules of ``owner``, whose forward is ``call``.

    The modules are shared, not copied: DDP over a view synchronises the owner's own tensors. Buffers
    held by the owner itself (HA2G's angle statistics, CaMN's assembly map) are not synchronised:
    ``prepare`` computes them from the same windows in every process.
    """

    def __init__(self, owner: nn.Module, children: dict[str, nn.Module], call: Any) -> None:
        super().__init__()
        for name, child in children.items():
            self.add_module(name, child)
        object.__setattr__(self, "_call", call)  # a bound method of the owner: not a submodule

    def forward(self, *args: Any) -> Any:
        return self._call(*args)


def generator_view(model: Any) -> nn.Module:
    """The model without its discriminator; ``view(batch)`` is ``model(batch)``.

    Raises ``ValueError`` when the model holds parameters outside its child modules (a view could
    not share them) or when the view's trainable parameters are not ``model.generator_parameters()``.

    Examples
    --------
    The S2G-style model's two views share its modules and split its parameters between them:

    >>> from beatlite.models.base import GestureModel
    >>> from beatlite.models.testing import fake_batch
    >>> _ = torch.manual_seed(0)
    >>> model = GestureModel.from_config({"name": "s2g", "preset": "tiny"}).eval()
    >>> generator, discriminator = generator_view(model), discriminator_view(model)
    >>> def count(module):
    ...     return sum(p.numel() for p in module.parameters())
    >>> count(generator) + count(discriminator) == count(model), "discriminator" in dict(generator.named_children())
    (True, False)
    >>> batch = fake_batch(2)
    >>> bool(torch.equal(generator(batch)["pose"], model(batch)["pose"]))
    True
    """
    if list(model.named_parameters(recurse=False)):
        raise ValueError(f"{type(model).__name__}: DDP needs every parameter inside a child module")
    children = {n: c for n, c in model.named_children() if c is not model.discriminator}
    view = _View(model, children, model.forward)
    got = {id(p) for p in view.parameters() if p.requires_grad}
    if got != {id(p) for p in model.generator_parameters()}:
        raise ValueError(f"{type(model).__name__}: the discriminator shares modules with the generator")
    return view


def discriminator_view(model: Any) -> nn.Module:
    """The discriminator alone; ``view(batch, out)`` is ``model.discriminator_losses(batch, out)``.

    Examples
    --------
    >>> from beatlite.models.base import GestureModel
    >>> model = GestureModel.from_config({"name": "s2g", "preset": "tiny"})
    >>> view = discriminator_view(model)
    >>> list(dict(view.named_children())), view.discriminator is model.discriminator
    (['discriminator'], True)
    """
    return _View(model, {"discriminator": model.discriminator}, model.discriminator_losses)


def wrap_for_ddp(model: Any, device: torch.device) -> tuple[nn.Module, nn.Module | None]:
    """DDP wrappers ``(generator, discriminator or None)`` of ``model`` (already on ``device``).

    Building them broadcasts process 0's parameters and buffers, so every process starts equal.
    """
    from torch.nn.parallel import DistributedDataParallel as DDP

    ids = [device.index] if device.type == "cuda" else None
    generator = DDP(generator_view(model), device_ids=ids)
    if model.discriminator is None:
        return generator, None
    return generator, DDP(discriminator_view(model), device_ids=ids)


def sync_on_last(ddp: nn.Module | None, last: bool) -> Any:
    """Context for one micro-batch's forward: gradients are reduced only after the last one's backward.

    Every micro-batch but the last runs under ``ddp.no_sync()``; the caller then takes a single
    backward over the sum of the micro-batch losses, which DDP reduces once.
    """
    if ddp is None or last:
        return contextlib.nullcontext()
    return ddp.no_sync()


def wait_for_all(world: int) -> None:
    """Return when every process has called this (a barrier); nothing with one process."""
    if world < 2:
        return
    import torch.distributed as dist

    dist.barrier()


def rng_states(world: int) -> list[torch.Tensor]:
    """Every process's CPU generator state (``torch.get_rng_state()``), in rank order: a collective, every
    process calls it (one process: its own state alone).

    The processes' generators differ (process 0 alone validates, and a validation may draw random numbers),
    so a resumed run restores each its own (:meth:`beatlite.train.training._Run.resume`).
    """
    state = torch.get_rng_state()
    if world < 2:
        return [state]
    import torch.distributed as dist

    states = [torch.empty_like(state) for _ in range(world)]
    dist.all_gather(states, state)  # (a CPU tensor: gloo's, also in the group of a CUDA machine)
    return states


def sum_over_processes(sums: dict[str, float], world: int) -> dict[str, float]:
    """The loss sums of all processes (every process has the same keys), in the order of ``sums``
    (reduced in sorted-key order; the model's first loss stays first, as the progress bar shows it)."""
    if world < 2:
        return sums
    import torch.distributed as dist

    keys = sorted(sums)
    device = torch.device("cuda", torch.cuda.current_device()) if torch.cuda.is_available() else None
    values = torch.tensor([sums[k] for k in keys], dtype=torch.float64, device=device)
    dist.all_reduce(values, op=dist.ReduceOp.SUM)
    reduced = dict(zip(keys, values.cpu().tolist(), strict=True))
    return {k: reduced[k] for k in sums}
