"""The instructor's answer sheet: every exercise of ``notebooks/`` with its solution, from the ``solution`` cells.

Writes ``build/instructor/NN_name.md`` per notebook and ``build/instructor/answers.md`` (all of them), without
running anything. For each exercise (a Markdown cell starting ``**Exercise``, then its cells up to the next one):

- the exercise text as the student reads it;
- the checks it runs (``bl.exercise.check``, ``choice``, ``predict``) and, for each "why?" question (``choice``)
  and prediction (``predict``), the answer the solution cell sets (the student's variable, e.g. ``why_bit = "b"``);
- the written answers of the solution cells (comment lines starting ``# Answer``, with their continuation lines)
  and Markdown cells tagged ``solution``: the answer to each open "why?" question;
- the solution code.

``make run`` calls it after the notebooks (``scripts/run_notebooks.py``); ``--key QUESTION ANSWER`` prints the
course's key of a multiple-choice answer (:func:`beatlite.exercise.course_key`) to paste into a notebook cell.
``tests/test_exercises.py`` uses :func:`exercises` to run every check with its solution and with a wrong answer.
"""

from __future__ import annotations

import argparse
import ast
import json
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
CALLS = ("check", "choice", "predict")


def _tags(cell: dict) -> list[str]:
    return cell.get("metadata", {}).get("tags", [])


def _source(cell: dict) -> str:
    src = cell["source"]
    return "".join(src) if isinstance(src, list) else src


def _python(src: str) -> str:
    """A cell's source without IPython magics and shell lines (``%...``, ``!...``)."""
    return "\n".join(line for line in src.splitlines() if not line.lstrip().startswith(("%", "!")))


def exercise_calls(src: str) -> list[tuple[str, str, ast.expr | None]]:
    """``(kind, name, answer argument)`` of every ``bl.exercise.check/choice/predict("name", ...)`` in ``src``.

    The answer argument is the second positional argument (the student's function, choice or prediction).
    """
    out = []
    for node in ast.walk(ast.parse(_python(src))):
        if not isinstance(node, ast.Call) or not isinstance(node.func, ast.Attribute):
            continue
        func = ast.unparse(node.func)
        if node.func.attr in CALLS and func.endswith(f"exercise.{node.func.attr}") and node.args:
            first = node.args[0]
            if isinstance(first, ast.Constant) and isinstance(first.value, str):
                out.append((node.func.attr, first.value, node.args[1] if len(node.args) > 1 else None))
    return out


def student_names(src: str) -> list[str]:
    """What the student writes in a stub cell: functions whose body raises ``NotImplementedError`` and names
    set to ``None`` that a ``choice``/``predict`` call takes as its answer."""
    tree = ast.parse(_python(src))
    names = []
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and any(
            isinstance(n, ast.Raise) and "NotImplementedError" in ast.unparse(n) for n in ast.walk(node)
        ):
            names.append(node.name)
    answers = {
        ast.unparse(arg) for kind, _, arg in exercise_calls(src) if kind != "check" and arg is not None
    }
    for node in tree.body:
        if (
            isinstance(node, ast.Assign)
            and len(node.targets) == 1
            and isinstance(node.targets[0], ast.Name)
            and node.targets[0].id in answers
            and isinstance(node.value, ast.Constant)
            and node.value.value is None
        ):
            names.append(node.targets[0].id)
    return names


@dataclass
class Exercise:
    """One exercise of a notebook: its text, the cells the student sees and the solution cells."""

    notebook: str  # file stem, e.g. "05_camn"
    title: str  # "Exercise 1: convolution lengths."
    text: str
    stubs: list[tuple[int, str]] = field(default_factory=list)  # (cell index, source) with exercise calls
    solutions: list[tuple[int, str]] = field(default_factory=list)  # (cell index, source), code
    answers_md: list[str] = field(default_factory=list)  # Markdown cells tagged solution

    @property
    def calls(self) -> list[tuple[str, str, ast.expr | None]]:
        return [c for _, src in self.stubs for c in exercise_calls(src)]

    @property
    def names(self) -> list[str]:
        return [n for _, src in self.stubs for n in student_names(src)]


def exercises(path: Path) -> list[Exercise]:
    """The exercises of one notebook, in order (see the module docstring for what makes one)."""
    nb = json.loads(Path(path).read_text(encoding="utf-8"))
    found: list[Exercise] = []
    current: Exercise | None = None
    for i, cell in enumerate(nb["cells"]):
        src, tags = _source(cell), _tags(cell)
        if cell["cell_type"] == "markdown":
            m = re.search(r"^\*\*(Exercise [^*]*)\*\*", src, re.M)
            if m:
                current = Exercise(Path(path).stem, m[1].strip(), src[m.start() :].strip())
                found.append(current)
            elif re.match(r"\s*#+ ", src):
                current = None  # a new section ends the exercises
            elif current is not None and "solution" in tags:
                current.answers_md.append(src.strip())
            continue
        if current is None or cell["cell_type"] != "code" or "check" in tags:
            continue
        if "solution" in tags:
            current.solutions.append((i, src))
        elif exercise_calls(src):
            current.stubs.append((i, src))
    return found


def written_answers(src: str) -> list[str]:
    """The ``# Answer ...`` comments of a solution cell, each with its following comment lines."""
    out, block = [], None
    for line in src.splitlines():
        stripped = line.strip()
        if stripped.startswith("# Answer"):
            block = [stripped[1:].strip()]
            out.append(block)
        elif block is not None and stripped.startswith("#"):
            block.append(stripped[1:].strip())
        else:
            block = None
    return [" ".join(b) for b in out]


def _set_values(src: str, names: list[str]) -> dict[str, str]:
    """``name -> source of the value`` of the top-level assignments of ``names`` in a solution cell."""
    out = {}
    for node in ast.parse(_python(src)).body:
        if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
            if node.targets[0].id in names:
                out[node.targets[0].id] = ast.unparse(node.value)
    return out


def sheet(path: Path) -> str:
    """The answer sheet of one notebook (Markdown)."""
    lines = [f"# Answers: {Path(path).stem}", ""]
    for ex in exercises(path):
        lines += [f"## {ex.title}", "", "> " + ex.text.replace("\n", "\n> "), ""]
        solution = "\n\n".join(src for _, src in ex.solutions)
        checks = [f'`{kind}("{name}")`' for kind, name, _ in ex.calls]
        lines += [f"Checks: {', '.join(checks)}.", ""]
        values = _set_values(solution, ex.names)
        for kind, name, arg in ex.calls:
            if kind == "check":
                continue
            var = ast.unparse(arg) if arg is not None else "?"
            what = "right choice" if kind == "choice" else "predicted value"
            lines.append(
                f'- {kind} "{name}": {what} `{var} = {values.get(var, "(not set by the solution)")}`'
            )
        answers = [a for _, src in ex.solutions for a in written_answers(src)] + ex.answers_md
        lines += [f"- {a}" for a in answers]
        if not ex.solutions:
            lines.append("- **no solution cell**")
        lines += ["", "```python", solution.strip(), "```", ""]
    return "\n".join(lines)


def write_sheets(out: Path, notebooks: list[Path] | None = None) -> list[Path]:
    """Write ``out/NN_name.md`` for each notebook with exercises and ``out/answers.md`` with all of them."""
    paths = notebooks or sorted((REPO / "notebooks").glob("[0-9][0-9]_*.ipynb"))
    out.mkdir(parents=True, exist_ok=True)
    written, parts = [], []
    for path in paths:
        if not exercises(path):
            continue
        text = sheet(path)
        (out / f"{Path(path).stem}.md").write_text(text, encoding="utf-8")
        written.append(out / f"{Path(path).stem}.md")
        parts.append(text)
    header = "# beatlite: the instructor's answer sheet\n\nGenerated from the `solution` cells of `notebooks/` by `scripts/instructor_sheet.py`; keep it away from students.\n"
    (out / "answers.md").write_text("\n".join([header, *parts]), encoding="utf-8")
    return [out / "answers.md", *written]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--out", type=Path, default=REPO / "build" / "instructor", help="output folder")
    parser.add_argument(
        "--key", nargs=2, metavar=("QUESTION", "ANSWER"), help="print the course's key and exit"
    )
    parser.add_argument("notebooks", nargs="*", type=Path, help="notebooks (default: all, in order)")
    args = parser.parse_args(argv)
    if args.key:
        sys.path.insert(0, str(REPO))
        from beatlite.exercise import course_key

        print(course_key(*args.key))
        return 0
    written = write_sheets(args.out, args.notebooks or None)
    print(f"[instructor] wrote {written[0]} and {len(written) - 1} notebook sheets")
    return 0


if __name__ == "__main__":
    sys.exit(main())
