"""One call at the top of every notebook: versions, mode, seeds, threads, figure style.

Used by the setup cell at the top of every notebook (the first code cell of notebooks/00_setup_and_tour.ipynb).
"""

from __future__ import annotations

import os
import platform
import random
import warnings

import numpy as np

from beatlite import __version__, paths


def require(version: str) -> None:
    """Raise ``RuntimeError`` when the installed beatlite is older than ``version`` (e.g. ``"0.1"``)."""

    def parse(v: str) -> tuple[int, ...]:
        return tuple(int(p) for p in v.split(".") if p.isdigit())

    if parse(__version__) < parse(version):
        raise RuntimeError(
            f"these notebooks need beatlite >= {version}, installed is {__version__}: run `make run` or "
            "`pip install -e .` in the repository"
        )


def _inline_figures() -> None:
    """Inside a Jupyter kernel, show matplotlib figures inline even when ``MPLBACKEND=Agg`` is set."""
    try:
        from IPython import get_ipython
    except ImportError:  # plain Python: nothing to do
        return
    shell = get_ipython()
    if shell is not None and getattr(shell, "kernel", None) is not None:
        shell.run_line_magic("matplotlib", "inline")


def setup(seed: int = 0, *, verbose: bool = True) -> dict[str, str]:
    """Prepare a notebook: seed numpy/random (and torch if it is imported), set torch threads.

    Inside Jupyter it also switches matplotlib to inline figures, so executed
    notebooks keep their figures even when the environment says ``MPLBACKEND=Agg``.

    Parameters
    ----------
    seed : int
        Seed for ``random``, ``numpy`` and, when already imported, ``torch``.
    verbose : bool
        Print a one-line summary.

    Returns
    -------
    dict
        ``version``, ``mode``, ``data``, ``threads``, ``python``.
    """
    import sys

    random.seed(seed)
    np.random.seed(seed)  # noqa: NPY002 - legacy global seed for student code that uses np.random.*
    if "torch" in sys.modules:
        torch = sys.modules["torch"]
        torch.manual_seed(seed)
        torch.set_num_threads(paths.n_threads())
    os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")
    # tqdm.auto falls back to a text bar without ipywidgets (not a dependency); its warning is noise
    warnings.filterwarnings("ignore", message="IProgress not found")
    _inline_figures()
    info = {
        "version": __version__,
        "mode": paths.mode(),
        "data": str(paths.data_dir()),
        "threads": str(paths.n_threads()),
        "python": platform.python_version(),
    }
    if verbose:
        print(
            f"beatlite {info['version']} | mode={info['mode']} | threads={info['threads']} | "
            f"data={info['data']} | python {info['python']}"
        )
    return info
