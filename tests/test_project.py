"""Project-level checks: packaging in step, fast lazy import, notebooks stripped, declared imports."""

from __future__ import annotations

import ast
import json
import os
import re
import subprocess
import sys
import tomllib
from importlib.metadata import packages_distributions
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((REPO / "notebooks").glob("*.ipynb"))


def _norm(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _split_req(req: str) -> tuple[str, str]:
    m = re.match(r"^\s*([A-Za-z0-9_.\-]+)\s*(.*?)\s*(#.*)?$", req)
    assert m, f"cannot parse requirement {req!r}"
    return _norm(m.group(1)), m.group(2).replace(" ", "")


def _pyproject_requirements() -> dict[str, str]:
    data = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    reqs = list(data["dependencies"])
    for extra in data.get("optional-dependencies", {}).values():
        reqs += extra
    return dict(_split_req(r) for r in reqs)


def _environment_requirements() -> dict[str, str]:
    """Parse the dependency list of environment.yml (a flat YAML list; no YAML library needed)."""
    reqs: dict[str, str] = {}
    conda_to_pip = {"pysoundfile": "soundfile"}
    in_deps = False
    for raw in (REPO / "environment.yml").read_text().splitlines():
        line = raw.split("#", 1)[0].rstrip()
        if not line.strip():
            continue
        if re.match(r"^dependencies:\s*$", line):
            in_deps = True
            continue
        if in_deps and not line.startswith(" "):
            in_deps = False
        m = re.match(r"^\s*-\s+(.+)$", line)
        if not (in_deps and m):
            continue
        item = m.group(1).strip()
        if item in ("pip", "pip:") or item.startswith(("python=", "--")):
            continue
        name, spec = _split_req(item.replace("=", "==", 1) if re.match(r"^[\w.\-]+=[^=]", item) else item)
        reqs[_norm(conda_to_pip.get(name, name))] = spec
    return reqs


def test_environment_yml_matches_pyproject():
    pip_reqs = _pyproject_requirements()
    conda_reqs = _environment_requirements()
    assert pip_reqs == conda_reqs, (
        f"only in pyproject: {sorted(set(pip_reqs) - set(conda_reqs))}, "
        f"only in environment.yml: {sorted(set(conda_reqs) - set(pip_reqs))}, "
        f"different pins: {[k for k in pip_reqs if k in conda_reqs and pip_reqs[k] != conda_reqs[k]]}"
    )
    assert pip_reqs["torch"] == ">=2.11,<2.14"  # the tested range (README, "PyTorch on your own machine")


#: Modules that make ``import beatlite`` slow (seconds each); the I/O and skeleton layers need none of them.
HEAVY_MODULES = ("torch", "scipy", "librosa", "numba", "matplotlib", "sklearn", "soundfile", "pyvista")


def test_import_is_lazy():
    """What keeps the import fast, asserted without a clock (its time is in bench/bench_import.py)."""
    code = (
        "import sys, json; import beatlite, beatlite.io, beatlite.skeleton; "
        f"print(json.dumps([m for m in {HEAVY_MODULES!r} if m in sys.modules]))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO)
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout.strip().splitlines()[-1]) == [], "import beatlite loads heavy modules"


def test_compiled_kernels_are_cached_in_this_session_s_own_folder():
    """``conftest.py`` points inductor's cache at a new folder under ``build/`` for this session (unless the caller
    chose one) and torch reads it there: nothing compiled by an earlier, perhaps killed, run or another checkout
    is loaded, and the machine-wide cache in /tmp is not touched."""
    pytest.importorskip("torch")
    import conftest
    from torch._inductor.runtime.cache_dir_utils import cache_dir

    chosen = Path(os.environ["TORCHINDUCTOR_CACHE_DIR"])
    assert Path(cache_dir()) == chosen
    if hasattr(conftest, "INDUCTOR_CACHE"):  # (not when the caller set TORCHINDUCTOR_CACHE_DIR)
        assert chosen == conftest.INDUCTOR_CACHE and chosen.parent == REPO / "build"
        assert chosen.name.startswith("torchinductor_") and chosen.is_dir()


def test_ci_runs_the_readme_test_command():
    readme = (REPO / "README.md").read_text()
    ci = (REPO / ".ci" / "run").read_text()
    assert "make test" in readme and "make run" in readme
    assert re.search(r"^make test\s*$", ci, re.M), ".ci/run must call `make test`, the README's command"


def test_make_seeds_retrains_existing_checkpoints_only_when_forced():
    """``make seeds`` reuses a current checkpoint in build/seeds/; the Makefile had no way to pass ``--force``,
    so after a code change that left the recipe as it was, the table was recorded from the old weights."""
    import shutil
    import subprocess

    if shutil.which("make") is None:
        pytest.skip("no make")

    def seeds_line(*assignments: str) -> str:
        done = subprocess.run(["make", "-n", "seeds", "ONLY=camn_tiny", *assignments], cwd=REPO, capture_output=True,
                              text=True, check=False)  # fmt: skip
        assert done.returncode == 0, done.stderr
        return next(line for line in done.stdout.splitlines() if "beatlite.train seeds" in line)

    assert seeds_line("FORCE=1").split()[-3:] == ["--only", "camn_tiny", "--force"]
    assert "--force" not in seeds_line().split()


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_is_stripped(path):
    nb = json.loads(path.read_text())
    dirty = [
        i
        for i, c in enumerate(nb["cells"])
        if c["cell_type"] == "code" and (c.get("outputs") or c.get("execution_count") is not None)
    ]
    assert not dirty, f"{path.name}: cells {dirty} carry outputs; strip them before committing"


def _checks_in_teaching_cells(path: Path) -> list[str]:
    """``assert`` statements and ``np.testing.assert_*`` calls in code cells not tagged ``check`` or ``solution``."""
    nb = json.loads(path.read_text())
    found = []
    for i, cell in enumerate(nb["cells"]):
        tags = cell.get("metadata", {}).get("tags", [])
        if cell["cell_type"] != "code" or {"check", "solution"} & set(tags):
            continue
        src = "".join(cell["source"])
        src = "\n".join(line for line in src.splitlines() if not line.lstrip().startswith(("%", "!")))
        for node in ast.walk(ast.parse(src)):
            is_call = isinstance(node, ast.Call) and ".testing.assert_" in ast.unparse(node.func)
            if isinstance(node, ast.Assert) or is_call:
                found.append(f"cell {i} line {node.lineno}")
    return found


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_checks_sit_in_check_cells(path):
    """Teaching cells hold no assertion: each sits in a cell tagged ``check`` after the cell it checks.

    A lecture can hide the ``check`` cells; nbval and ``make run`` still execute them (docs/teaching.md).
    """
    found = _checks_in_teaching_cells(path)
    assert not found, f"{path.name}: move these assertions to a cell tagged `check`: {found}"


def _code_cell_trees(path: Path) -> list[tuple[int, ast.Module]]:
    """``(cell index, parsed source)`` of each code cell of a notebook, its ``%`` and ``!`` lines left out."""

    def python(source: list[str]) -> str:
        return "\n".join(ln for ln in "".join(source).splitlines() if not ln.lstrip().startswith(("%", "!")))

    cells = json.loads(path.read_text())["cells"]
    return [(i, ast.parse(python(c["source"]))) for i, c in enumerate(cells) if c["cell_type"] == "code"]


def _figure_saves_not_via_save_figure(path: Path) -> list[str]:
    """Figure saves other than ``bl.viz.save_figure(fig, ...)``: ``savefig``, ``out=`` to a plot function, aliases."""
    found = []
    for i, tree in _code_cell_trees(path):
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call):
                continue
            func = ast.unparse(node.func)
            if func.endswith(("savefig", "save_figure")) and func != "bl.viz.save_figure":
                found.append(f"cell {i}: {func}(...)")
            for k in node.keywords:  # a plot function's own out= argument
                if k.arg == "out" and (
                    "figures_dir" in ast.unparse(k.value) or "FIGURES" in ast.unparse(k.value)
                ):
                    found.append(f"cell {i}: {func}(out=...)")
    return found


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_figures_are_saved_one_way(path):
    """Every notebook figure is written by ``bl.viz.save_figure(fig, bl.report.figures_dir() / "NN_name")``.

    ``make run`` collects them in ``build/figures/`` as ``NN_name.png`` and ``NN_name.svg`` (docs/teaching.md).
    """
    found = _figure_saves_not_via_save_figure(path)
    assert not found, f"{path.name}: save figures with bl.viz.save_figure: {found}"


#: pyplot functions that make a figure (or one when none is open): a figure of its own, not a beatlite function's.
_PYPLOT_FIGURE_MAKERS = {"figure", "subplots", "subplot", "subplot_mosaic", "axes", "plot", "imshow", "bar", "barh",
                         "hist", "scatter", "errorbar", "semilogx", "semilogy", "loglog", "fill_between"}  # fmt: skip


def _figures_outside_the_style(path: Path) -> list[str]:
    """``plt.subplots(...)``, ``plt.figure(...)``, ``plt.plot(...)``, ... calls not inside ``with bl.viz.figure_style():``."""
    found = []

    def visit(node: ast.AST, styled: bool, i: int) -> None:
        if isinstance(node, ast.With) and any(
            isinstance(item.context_expr, ast.Call)
            and ast.unparse(item.context_expr.func).endswith("figure_style")
            for item in node.items
        ):
            styled = True
        if isinstance(node, ast.Call) and not styled:
            func = ast.unparse(node.func)
            if func.startswith("plt.") and func[4:] in _PYPLOT_FIGURE_MAKERS:
                found.append(f"cell {i} line {node.lineno}: {func}(...)")
        for child in ast.iter_child_nodes(node):
            visit(child, styled, i)

    for i, tree in _code_cell_trees(path):
        visit(tree, False, i)
    return found


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_figures_are_drawn_in_the_course_style(path):
    """A figure a notebook draws itself is made inside ``with bl.viz.figure_style():`` (beatlite's figure functions
    apply it themselves): slide-size fonts, the style's grid and colour cycle, like every other figure of the course.

    Notebooks 00, 01, 03, 05, 06, 07, 08 and 10 drew 14 figures with a bare ``plt.subplots``/``plt.figure`` (matplotlib's
    defaults: 9-pt titles, boxed axes, the default colour cycle).
    """
    found = _figures_outside_the_style(path)
    assert not found, f"{path.name}: draw these figures inside `with bl.viz.figure_style():`: {found}"


def test_unstyled_figure_cells_are_found(tmp_path):
    """The check of the test above, on a hand-made notebook: bare pyplot figures found, styled ones and
    beatlite's figure functions not."""
    cells = [
        "fig, ax = plt.subplots()\nax.plot([0, 1])",  # bare: found
        "with bl.viz.figure_style():\n    fig = plt.figure()\n    for k in range(2):\n        plt.plot([k])",
        "fig = bl.viz.charts.plot_signals(t, curves, 'speed (cm/s)')\nplt.show()",  # styled by the library
        "%matplotlib inline\nif True:\n    plt.imshow(image)",  # bare, nested: found
        "with open('x') as f, bl.viz.figure_style(**{'font.size': 12}):\n    plt.subplots(1, 2)",
    ]
    nb = {"cells": [{"cell_type": "code", "source": c.splitlines(keepends=True)} for c in cells]}
    path = tmp_path / "nb.ipynb"
    path.write_text(json.dumps(nb))
    assert _figures_outside_the_style(path) == [
        "cell 0 line 1: plt.subplots(...)",
        "cell 3 line 2: plt.imshow(...)",
    ]


_TEMP_MAKERS = ("TemporaryDirectory", "example_corpus", "example_beat2_corpus")


def _temporary_dirs_left(path: Path) -> list[str]:
    """Names bound to a temporary directory outside a ``with`` that no later code cell ``.cleanup()``s."""
    nb = json.loads(path.read_text())
    made, cleaned = {}, set()
    for i, cell in enumerate(nb["cells"]):
        if cell["cell_type"] != "code":
            continue
        src = "\n".join(
            ln for ln in "".join(cell["source"]).splitlines() if not ln.lstrip().startswith(("%", "!"))
        )
        for node in ast.walk(ast.parse(src)):
            if isinstance(node, ast.Assign) and isinstance(node.value, ast.Call):
                if ast.unparse(node.value.func).split(".")[-1] in _TEMP_MAKERS:
                    made.update({ast.unparse(t): i for t in node.targets})
            elif isinstance(node, ast.Call) and ast.unparse(node.func).endswith(".cleanup"):
                cleaned.add(ast.unparse(node.func)[: -len(".cleanup")])
    return [f"cell {i}: {name}" for name, i in made.items() if name not in cleaned]


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_removes_its_temporary_directories(path):
    """A temporary directory a notebook keeps across cells is ``.cleanup()``-ed by the notebook itself.

    nbval stops its kernels with SIGKILL (``shutdown_kernel(now=True)``), so no finaliser runs: each ``make test`` left
    a copy in the system's temporary folder.
    """
    left = _temporary_dirs_left(path)
    assert not left, f"{path.name}: call .cleanup() once these are read, or use `with`: {left}"


def _notebook_imports(path: Path) -> set[str]:
    nb = json.loads(path.read_text())
    names: set[str] = set()
    for cell in nb["cells"]:
        if cell["cell_type"] != "code":
            continue
        src = "".join(cell["source"])
        src = "\n".join(line for line in src.splitlines() if not line.lstrip().startswith(("%", "!")))
        for node in ast.walk(ast.parse(src)):
            if isinstance(node, ast.Import):
                names |= {a.name.split(".")[0] for a in node.names}
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names.add(node.module.split(".")[0])
    return names


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_imports_are_declared(path):
    declared = set(_pyproject_requirements())
    dists = packages_distributions()
    # IPython reaches notebooks through ipykernel, which is declared.
    provided_by = {"IPython": "ipykernel"}
    missing = []
    for mod in sorted(_notebook_imports(path)):
        if mod in sys.stdlib_module_names or mod == "beatlite":
            continue
        owners = {_norm(provided_by.get(mod, d)) for d in dists.get(mod, [mod])}
        if not owners & declared:
            missing.append(f"{mod} (from {sorted(owners)})")
    assert not missing, f"{path.name} imports undeclared packages: {missing}"


def test_no_module_is_shadowed_by_a_function_of_its_name():
    """``beatlite.metrics.srgr`` is the function, and no submodule of that name hides behind it."""
    import importlib
    import pkgutil
    import types

    shadowed = []
    for pkg in ("io", "skeleton", "data", "stats", "metrics", "models", "train", "viz", "synth"):
        package = importlib.import_module(f"beatlite.{pkg}")
        for sub in pkgutil.iter_modules(package.__path__):
            if sub.name in getattr(package, "__all__", ()):
                value = getattr(package, sub.name)
                if not isinstance(value, types.ModuleType):
                    shadowed.append(f"beatlite.{pkg}.{sub.name}")
    assert not shadowed, shadowed
