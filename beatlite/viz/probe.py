"""Can pyvista/VTK render off-screen here? Asked once per process, in a subprocess.

VTK with no usable OpenGL library does not raise: it kills the process
(segmentation fault or abort). So :func:`probe_offscreen` renders a tiny scene
in a *child* Python process, once per candidate render-window class, with a
timeout, and the first class that gives a non-blank image wins. The answer is
cached for the lifetime of the process (``functools.lru_cache``).

Candidates, in order (``VTK_DEFAULT_OPENGL_WINDOW`` is read by VTK when a
render window is created):

1. ``$VTK_DEFAULT_OPENGL_WINDOW`` when the user has set it;
2. on Linux with ``$DISPLAY`` set: VTK's default (X11 / GLX);
3. ``vtkEGLRenderWindow``: headless EGL; with Mesa (Debian ``libegl1 libgl1-mesa-dri``) it renders
   on the CPU (llvmpipe) and uses a GPU when one is present. Chosen first because Mesa keeps
   supporting it (OSMesa was removed from Mesa 25.1);
4. ``vtkOSOpenGLRenderWindow``: OSMesa (Debian ``libosmesa6``);
5. elsewhere (macOS, Windows): VTK's default.

An X virtual frame buffer also works (``xvfb-run -a jupyter lab`` sets
``$DISPLAY``, then candidate 2 is used). Set ``BEATLITE_PYVISTA=off`` to skip
pyvista entirely (matplotlib everywhere), e.g. on a machine where the probe
itself is too slow. Install the libraries with ``scripts/system_deps.sh``.

Taught in notebooks/00_setup_and_tour.ipynb, section 1 (can this machine draw 3D skeletons with pyvista?) and notebooks/08_visualisation_3d.ipynb, section 4.
"""

from __future__ import annotations

import functools
import json
import os
import subprocess
import sys
import warnings
from dataclasses import dataclass

ENV_SWITCH = "BEATLITE_PYVISTA"
ENV_WINDOW = "VTK_DEFAULT_OPENGL_WINDOW"
FIX_HINT = (
    "To enable pyvista rendering install an off-screen OpenGL: on Debian/Ubuntu run "
    "`sudo scripts/system_deps.sh` (or `sudo apt-get install libegl1 libgl1-mesa-dri libosmesa6`), "
    "or start Jupyter under `xvfb-run -a`. Set BEATLITE_PYVISTA=off to silence this."
)

_PROBE_SCRIPT = r"""
import json, sys
import numpy as np
import pyvista as pv
p = pv.Plotter(off_screen=True, window_size=(64, 48))
p.add_mesh(pv.Sphere(), color="red")
img = p.screenshot(return_img=True)
cls = p.ren_win.GetClassName()
p.close()
print(json.dumps({"window": cls, "shape": list(img.shape), "std": float(np.std(img))}))
"""


@dataclass(frozen=True)
class RenderProbe:
    """The answer of the off-screen rendering probe.

    Attributes
    ----------
    ok : bool
        True when pyvista rendered a non-blank image in a child process.
    window_class : str or None
        The ``VTK_DEFAULT_OPENGL_WINDOW`` value that worked (``None``: VTK's default,
        or nothing worked).
    reason : str
        Why it failed (empty when ``ok``), or which render window was used.
    tried : tuple of str
        One line per candidate tried, with its outcome.
    """

    ok: bool
    window_class: str | None
    reason: str
    tried: tuple[str, ...] = ()


def candidate_windows() -> list[str | None]:
    """Render-window classes to try, in order (``None`` = VTK's platform default); see the module docstring.

    Examples
    --------
    On Linux without ``$DISPLAY``, a class the user set comes first and is not tried twice:

    >>> from unittest import mock
    >>> with mock.patch.object(sys, "platform", "linux"), mock.patch.dict(
    ...     os.environ, {ENV_WINDOW: "vtkOSOpenGLRenderWindow", "DISPLAY": ""}
    ... ):
    ...     candidate_windows()
    ['vtkOSOpenGLRenderWindow', 'vtkEGLRenderWindow']
    """
    out: list[str | None] = []
    user = os.environ.get(ENV_WINDOW, "").strip()
    if user:
        out.append(user)
    if sys.platform.startswith("linux"):
        if os.environ.get("DISPLAY"):
            out.append(None)
        out += ["vtkEGLRenderWindow", "vtkOSOpenGLRenderWindow"]
    else:
        out.append(None)
    seen: list[str | None] = []
    for c in out:
        if c not in seen:
            seen.append(c)
    return seen


def probe_command() -> list[str]:
    """The child command that renders the probe scene (tests replace it to simulate a crash)."""
    return [sys.executable, "-c", _PROBE_SCRIPT]


def _try_window(window: str | None, timeout: float) -> tuple[bool, str]:
    env = dict(os.environ)
    env.pop(ENV_WINDOW, None)
    if window is not None:
        env[ENV_WINDOW] = window
    name = window or "VTK default"
    try:
        proc = subprocess.run(probe_command(), env=env, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return False, f"{name}: no answer within {timeout:g} s"
    except OSError as exc:
        return False, f"{name}: could not start the probe ({exc})"
    if proc.returncode != 0:
        return False, f"{name}: {_exit_reason(proc)}"
    return _read_answer(proc.stdout, window, name)


def _exit_reason(proc: subprocess.CompletedProcess) -> str:
    """Why the probe child failed: a signal (VTK without OpenGL kills the process) or its last stderr line."""
    if proc.returncode < 0:
        return f"crashed with signal {-proc.returncode} (no usable OpenGL library?)"
    last = (proc.stderr.strip().splitlines() or ["no message"])[-1]
    return f"failed with exit code {proc.returncode}: {last[:200]}"


def _read_answer(stdout: str, window: str | None, name: str) -> tuple[bool, str]:
    """The probe child's JSON line: a non-blank image from the asked render window, or why not."""
    try:
        answer = json.loads(stdout.strip().splitlines()[-1])
    except (ValueError, IndexError):
        return False, f"{name}: the probe printed no result"
    if answer.get("std", 0.0) <= 0.0:
        return False, f"{name}: rendered a blank image"
    actual = answer.get("window")
    if window is not None and actual != window:
        return False, f"{name}: VTK fell back to {actual}"
    return True, f"{name}: ok ({actual})"


@functools.cache
def probe_offscreen(timeout: float = 60.0) -> RenderProbe:
    """Find a render window that works off-screen, trying each candidate in a child process (cached).

    Parameters
    ----------
    timeout : float
        Seconds allowed for each candidate (the first import of VTK can take a few seconds).

    Returns
    -------
    RenderProbe
        ``ok`` and the ``window_class`` to use, or why nothing worked. Call
        ``probe_offscreen.cache_clear()`` to probe again (e.g. after installing libraries).
    """
    import importlib.util

    if importlib.util.find_spec("pyvista") is None:
        return RenderProbe(False, None, "pyvista is not installed (pip install pyvista)")
    tried = []
    for window in candidate_windows():
        ok, line = _try_window(window, timeout)
        tried.append(line)
        if ok:
            return RenderProbe(True, window, line, tuple(tried))
    return RenderProbe(False, None, "; ".join(tried), tuple(tried))


def pyvista_status() -> RenderProbe:
    """The probe answer, honouring ``BEATLITE_PYVISTA=off`` (read at call time).

    Examples
    --------
    Switched off, nothing is probed (no child process):

    >>> from unittest import mock
    >>> with mock.patch.dict(os.environ, {ENV_SWITCH: "off"}):
    ...     status = pyvista_status()
    >>> status.ok, status.reason
    (False, 'BEATLITE_PYVISTA=off turns pyvista off')
    """
    if os.environ.get(ENV_SWITCH, "").strip().lower() in ("off", "0", "false", "no"):
        return RenderProbe(False, None, f"{ENV_SWITCH}={os.environ[ENV_SWITCH]} turns pyvista off")
    return probe_offscreen()


@functools.cache
def _warn_once(reason: str) -> None:
    warnings.warn(
        f"beatlite.viz: pyvista cannot render off-screen here ({reason}); using matplotlib instead. {FIX_HINT}",
        UserWarning,
        stacklevel=4,
    )


def use_pyvista(backend: str = "auto") -> bool:
    """Decide between pyvista and matplotlib, warning once per process when pyvista is unusable.

    Parameters
    ----------
    backend : {"auto", "pyvista", "matplotlib"}
        ``"matplotlib"`` never probes; ``"auto"`` and ``"pyvista"`` probe (once) and
        fall back to matplotlib with one ``UserWarning`` when rendering is impossible.

    Returns
    -------
    bool
        True when pyvista should be used; then ``VTK_DEFAULT_OPENGL_WINDOW`` is set in
        this process to the window class that the probe found working.

    Raises
    ------
    ValueError
        An unknown ``backend``.

    Examples
    --------
    ``"matplotlib"`` decides without probing; with ``BEATLITE_PYVISTA=off`` ``"auto"`` falls back to matplotlib
    (with its one warning, silenced here):

    >>> from unittest import mock
    >>> use_pyvista("matplotlib")
    False
    >>> with mock.patch.dict(os.environ, {ENV_SWITCH: "off"}), warnings.catch_warnings():
    ...     warnings.simplefilter("ignore")
    ...     use_pyvista("auto")
    False
    """
    if backend not in ("auto", "pyvista", "matplotlib"):
        raise ValueError(f"backend must be 'auto', 'pyvista' or 'matplotlib', got {backend!r}")
    if backend == "matplotlib":
        return False
    status = pyvista_status()
    if not status.ok:
        _warn_once(status.reason)
        return False
    if status.window_class is not None:
        os.environ[ENV_WINDOW] = status.window_class  # read by VTK at render-window creation
    return True
