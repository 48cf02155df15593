"""The frame rate, sample rate and window numbers have one home, ``beatlite.constants``: no default of a
parameter (or dataclass field) and no module-level name outside it retypes them (AST of beatlite/)."""

from __future__ import annotations

import ast
from pathlib import Path

from beatlite import constants

PACKAGE = Path(__file__).resolve().parents[1] / "beatlite"

#: Parameter names whose literal default must be the constant of that value.
GUARDED = {
    "fps": {constants.FPS: "FPS"},
    "sr": {constants.SR: "SR"},
    "audio_sr": {constants.SR: "SR"},
    "length": {constants.WINDOW_LENGTH: "WINDOW_LENGTH"},
    "n_frames": {constants.WINDOW_LENGTH: "WINDOW_LENGTH"},
    "stride": {constants.WINDOW_STRIDE: "WINDOW_STRIDE"},
}
#: Module-level names may not be bound to these literals (``WINDOW = 34``).
RETYPED = {constants.FPS: "FPS", constants.SR: "SR", constants.WINDOW_LENGTH: "WINDOW_LENGTH"}


def _literal(node: ast.AST | None) -> float | None:
    if isinstance(node, ast.Constant) and type(node.value) in (int, float):
        return node.value
    return None


def _defaults(tree: ast.Module):
    """(parameter or field name, default node) of every function and class body in ``tree``."""
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda):
            args = node.args
            positional = args.posonlyargs + args.args
            yield from (
                (a.arg, d) for a, d in zip(positional[len(positional) - len(args.defaults) :], args.defaults)
            )
            yield from ((a.arg, d) for a, d in zip(args.kwonlyargs, args.kw_defaults) if d is not None)
        elif isinstance(node, ast.ClassDef):
            for item in node.body:
                if (
                    isinstance(item, ast.AnnAssign)
                    and isinstance(item.target, ast.Name)
                    and item.value is not None
                ):
                    yield item.target.id, item.value


def retyped_constants(root: Path = PACKAGE) -> list[str]:
    """``path:line: name=value (use CONSTANT)`` for every retyped default or module-level constant."""
    found = []
    for path in sorted(root.rglob("*.py")):
        if path.name == "constants.py":
            continue
        tree = ast.parse(path.read_text())
        where = path.relative_to(root.parent)
        for name, default in _defaults(tree):
            value = _literal(default)
            if name in GUARDED and value in GUARDED[name]:
                found.append(f"{where}:{default.lineno}: {name}={value!r} (use {GUARDED[name][value]})")
        for node in tree.body:
            targets = (
                node.targets
                if isinstance(node, ast.Assign)
                else [node.target]
                if isinstance(node, ast.AnnAssign)
                else []
            )
            value = _literal(getattr(node, "value", None))
            if targets and value in RETYPED and not isinstance(value, bool):
                names = ", ".join(ast.unparse(t) for t in targets)
                found.append(f"{where}:{node.lineno}: {names} = {value!r} (use {RETYPED[value]})")
    return found


def test_no_default_retypes_fps_sr_or_the_window(tmp_path):
    bad = tmp_path / "beatlite"
    bad.mkdir()
    (bad / "mod.py").write_text(
        "WINDOW = 34\n"
        "def f(x, fps=15, *, sr: int = 16000, length=34, stride=10, scale=15): ...\n"
        "class C:\n    n_frames: int = 34\n    fps: float = 30\n"
    )
    assert [line.split(": ", 1)[1] for line in retyped_constants(bad)] == [
        "fps=15 (use FPS)",
        "sr=16000 (use SR)",
        "length=34 (use WINDOW_LENGTH)",
        "stride=10 (use WINDOW_STRIDE)",
        "n_frames=34 (use WINDOW_LENGTH)",
        "WINDOW = 34 (use WINDOW_LENGTH)",
    ]
    found = retyped_constants()
    assert not found, "import these from beatlite.constants:\n" + "\n".join(found)
