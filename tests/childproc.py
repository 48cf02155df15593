"""Run a child process in a test; on failure the assertion shows the child's exit code, stdout and stderr."""

from __future__ import annotations

import subprocess
from collections.abc import Sequence
from typing import Any


def run_ok(cmd: Sequence[str], **kwargs: Any) -> subprocess.CompletedProcess[str]:
    """``subprocess.run(cmd, capture_output=True, text=True, **kwargs)`` that asserts exit code 0.

    ``check=True`` alone raises ``CalledProcessError`` before anything prints what the child said;
    here the failure message carries the command, the exit code, and the end of stdout and stderr.
    """
    done = subprocess.run(list(cmd), capture_output=True, text=True, **kwargs)
    assert done.returncode == 0, (
        f"{' '.join(map(str, cmd))} exited with {done.returncode}\n"
        f"--- stdout (end) ---\n{done.stdout[-4000:]}\n--- stderr (end) ---\n{done.stderr[-8000:]}"
    )
    return done
