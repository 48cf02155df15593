"""One call at the top of every notebook: versions, mode, seeds, threads, figure style.

Also where beatlite decides between widgets and plain output: :func:`interactive` is True in a live
Jupyter kernel unless ``BEATLITE_INTERACTIVE=off`` (set by ``make run`` and ``make test``, whose saved
pages cannot hold live widgets); :func:`progress` gives a widget bar there and a text bar elsewhere, and
:func:`beatlite.viz.render.show_skeleton` an interactive 3D view.

Used by the setup cell at the top of every notebook (the first code cell of notebooks/00_setup_and_tour.ipynb).
"""

from __future__ import annotations

import os
import platform
import random
import warnings
from typing import Any

import numpy as np

from beatlite import __version__, paths

ENV_INTERACTIVE = "BEATLITE_INTERACTIVE"


def defined_again(old: Any, new: Any) -> bool:
    """Whether ``new`` is ``old`` defined again: the same module and qualified name, as when a notebook cell that
    defines a class or function runs twice (the registries accept that and refuse a real clash).

    >>> def f(): pass
    >>> g = f
    >>> def f(): pass
    >>> g is f, defined_again(g, f), defined_again(g, print)
    (False, True, False)
    """
    key = [(getattr(x, "__module__", None), getattr(x, "__qualname__", None)) for x in (old, new)]
    return key[0][1] is not None and key[0] == key[1]


def require(version: str) -> None:
    """Raise ``RuntimeError`` when the installed beatlite is older than ``version`` (e.g. ``"0.1"``).

    Versions compare by their numeric dot-separated parts, trailing zeros ignored (``"0.1"`` is ``"0.1.0"``).

    Examples
    --------
    The installed version itself and every older one pass; a newer one is refused, naming both:

    >>> from beatlite import __version__
    >>> require(__version__), require(__version__ + ".0"), require("0.0.1")
    (None, None, None)
    >>> require("99.0")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    RuntimeError: these notebooks need beatlite >= 99.0, installed is ...
    """

    def parse(v: str) -> tuple[int, ...]:
        parts = [int(p) for p in v.split(".") if p.isdigit()]
        while parts and parts[-1] == 0:  # 0.1.0 == 0.1: the shorter tuple would compare as older
            parts.pop()
        return tuple(parts)

    if parse(__version__) < parse(version):
        raise RuntimeError(
            f"these notebooks need beatlite >= {version}, installed is {__version__}: run `make run` or "
            "`pip install -e .` in the repository"
        )


_require_version = require  # setup()'s argument of the same name shadows the function


def interactive() -> bool:
    """True in a live Jupyter kernel that may show widgets.

    That is: IPython's ZMQ shell (JupyterLab, Notebook, VS Code) and ``$BEATLITE_INTERACTIVE``
    not ``off`` (also ``0``, ``false``, ``no``). ``scripts/run_notebooks.py`` (``make run``) and
    ``make test`` set it to ``off``: a notebook executed in batch saves a widget's stale first state,
    and its exported page would need the widget scripts from the web. Read at call time.

    Examples
    --------
    >>> interactive()  # a plain Python process is not a Jupyter kernel
    False
    """
    if os.environ.get(ENV_INTERACTIVE, "").strip().lower() in ("off", "0", "false", "no"):
        return False
    import sys

    ipython = sys.modules.get("IPython")
    shell = ipython.get_ipython() if ipython is not None else None
    return shell is not None and type(shell).__name__ == "ZMQInteractiveShell"


def progress(iterable: Any = None, **kwargs: Any) -> Any:
    """A tqdm progress bar: a widget in a live kernel with ipywidgets, a text bar elsewhere.

    ``tqdm.auto`` when :func:`interactive` (it falls back to text without ipywidgets), else
    ``tqdm.std``. The text bar redraws one line with carriage returns, which
    ``scripts/run_notebooks.py`` collapses to its final state in the saved notebook.

    Parameters
    ----------
    iterable : iterable, optional
        What to iterate over.
    **kwargs
        Passed to ``tqdm`` (``desc``, ``total``, ``unit``, ``disable``, ...).

    Examples
    --------
    >>> sum(progress(range(4), desc="demo", disable=True))
    6
    """
    if interactive():
        from tqdm.auto import tqdm
    else:
        from tqdm.std import tqdm
    return tqdm(iterable, **kwargs)


def _inline_figures() -> None:
    """Inside a Jupyter kernel, show matplotlib figures inline even when ``MPLBACKEND=Agg`` is set."""
    try:
        from IPython import get_ipython
    except ImportError:  # plain Python: nothing to do
        return
    shell = get_ipython()
    if shell is not None and getattr(shell, "kernel", None) is not None:
        shell.run_line_magic("matplotlib", "inline")


def setup(seed: int = 0, *, require: str | None = None, verbose: bool = True) -> dict[str, str]:
    """Prepare a notebook: seed numpy/random (and torch if it is imported), set torch threads.

    The one call of every notebook's first cell, after its imports (so that ``torch``, when the
    notebook imports it, is seeded and gets ``BEATLITE_THREADS`` threads). Inside Jupyter it also
    switches matplotlib to inline figures (no ``%matplotlib inline`` needed), so executed notebooks
    keep their figures even when the environment says ``MPLBACKEND=Agg``.

    Parameters
    ----------
    seed : int
        Seed for ``random``, ``numpy`` and, when already imported, ``torch``.
    require : str, optional
        The oldest beatlite the notebook runs with (e.g. ``"0.1"``): :func:`require` raises
        ``RuntimeError`` before anything else when the installed one is older.
    verbose : bool
        Print a one-line summary.

    Returns
    -------
    dict
        ``version``, ``mode``, ``data``, ``threads``, ``python``.

    Examples
    --------
    >>> info = setup(seed=0, require="0.1", verbose=False)
    >>> sorted(info)
    ['data', 'mode', 'python', 'threads', 'version']
    >>> setup(require="99.0")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    RuntimeError: these notebooks need beatlite >= 99.0, installed is ...
    """
    import sys

    if require is not None:
        _require_version(require)

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
