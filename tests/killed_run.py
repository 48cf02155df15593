"""A training run killed mid-epoch, for the resume tests (imported by tests/test_train.py and tests/ddp_resume.py)."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def step_killed_after(steps: int) -> Iterator[None]:
    """Inside the block, ``fit``'s optimiser step raises ``KeyboardInterrupt`` instead of taking step ``steps + 1``
    (counted over every run in the block), as a process killed there would stop; restored on leaving it."""
    from beatlite.train import training

    real_step, calls = training._Run.step, {"n": 0}

    def dying_step(self, *args):  # noqa: ANN001, ANN002, ANN202
        if calls["n"] == steps:
            raise KeyboardInterrupt("killed")
        calls["n"] += 1
        return real_step(self, *args)

    training._Run.step = dying_step
    try:
        yield
    finally:
        training._Run.step = real_step
