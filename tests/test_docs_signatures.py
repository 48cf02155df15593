"""The docs stay true to the code: every backticked ``name(params)`` of docs/architecture.md, README.md and
docs/reference_code.md that resolves to one beatlite function or class names only parameters its
``inspect.signature`` has."""

from __future__ import annotations

import importlib
import inspect
import keyword
import pkgutil
import re
from pathlib import Path

import pytest

import beatlite

REPO = Path(__file__).resolve().parents[1]
DOC = REPO / "docs" / "architecture.md"
FENCED = re.compile(r"^ *```.*?^ *```", re.S | re.M)  # shell commands and printed output, not calls
SPAN = re.compile(r"`([^`]+)`")
CALL = re.compile(r"(?<![\w.])([A-Za-z_][\w.]*)\(")
SECTION = re.compile(r"^#+ .*?`(beatlite(?:\.\w+)*)`", re.M)


def _split_top_level(text: str) -> list[str]:
    """``text`` split at the commas outside brackets and quotes."""
    parts, depth, quote, start = [], 0, "", 0
    for i, ch in enumerate(text):
        if quote:
            quote = "" if ch == quote else quote
        elif ch in "\"'":
            quote = ch
        elif ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
        elif ch == "," and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    parts.append(text[start:])
    return [p.strip() for p in parts]


def _closing(text: str, open_at: int) -> int | None:
    depth = 0
    for i in range(open_at, len(text)):
        depth += {"(": 1, ")": -1}.get(text[i], 0)
        if depth == 0:
            return i
    return None


def documented_calls(text: str) -> list[tuple[str, str, list[str], bool]]:
    """``(section package, dotted name, parameter names, is a call example)`` of every ``name(...)`` in a
    backticked span (a call example passes literals positionally: only its ``name=`` keywords are names)."""
    sections = [(m.start(), m.group(1)) for m in SECTION.finditer(text)]
    found = []
    for span in SPAN.finditer(text):
        code = " ".join(span.group(1).split())
        package = next((p for start, p in reversed(sections) if start < span.start()), "beatlite")
        for call in CALL.finditer(code):
            end = _closing(code, call.end() - 1)
            if end is None:
                continue
            items = [i for i in _split_top_level(code[call.end() : end]) if i]
            example = any(re.match(r"""^(["'\d-]|None\b|True\b|False\b)""", i) for i in items)
            names = []
            for item in items:
                m = re.match(r"^\*{0,2}([A-Za-z_]\w*)\s*(=)?", item)
                if not m or keyword.iskeyword(m.group(1)) or m.group(1) in ("None", "True", "False"):
                    continue
                if re.match(r"[.(\[]", item[m.end(1) :]):  # an expression passed (test.train_speakers)
                    continue
                if example and not m.group(2):
                    continue
                names.append(m.group(1))
            found.append((package, call.group(1), names, example))
    return found


def _index() -> dict[str, object]:
    """Qualified name -> public function or class of every importable beatlite module (and their methods)."""
    index = {}
    for info in pkgutil.walk_packages(beatlite.__path__, "beatlite."):
        if info.name.endswith("__main__"):
            continue
        try:
            module = importlib.import_module(info.name)
            for name in getattr(module, "__all__", ()):  # lazy packages fill their namespace on first access:
                getattr(module, name)  # fill it now, so the index does not depend on what ran before
        except Exception:  # an optional dependency missing here: its names stay unresolved
            continue
        for attr, obj in vars(module).items():
            if attr.startswith("_") or not (inspect.isfunction(obj) or inspect.isclass(obj)):
                continue
            if not getattr(obj, "__module__", "").startswith("beatlite"):
                continue
            index[f"{info.name}.{attr}"] = obj
            if inspect.isclass(obj):
                for meth, fn in vars(obj).items():
                    fn = fn.__func__ if isinstance(fn, classmethod | staticmethod) else fn
                    if not meth.startswith("_") and inspect.isfunction(fn):
                        index[f"{info.name}.{attr}.{meth}"] = fn
    return index


def resolve(name: str, package: str, index: dict[str, object]) -> object | None:
    """The one object ``name`` means in a section on ``package`` (suffix match, the section's package first;
    a name written from ``beatlite.`` on is that one); None when nothing or several different objects match."""
    if name.startswith("beatlite."):
        if name in index:
            return index[name]
        name = name.removeprefix("beatlite.")
    matches = {q: o for q, o in index.items() if q == f"beatlite.{name}" or q.endswith(f".{name}")}
    for scope in (package, "beatlite"):
        objects = {id(o): o for q, o in matches.items() if q.startswith(scope + ".")}
        if len(objects) == 1:
            return next(iter(objects.values()))
        if objects:
            return None
    return None


def missing_parameters(obj: object, names: list[str]) -> list[str]:
    """The ``names`` that ``obj``'s signature lacks (a class's base classes, ``FormatError(ValueError)``, are
    not parameters)."""
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return []
    kinds = {p.kind for p in sig.parameters.values()}
    if inspect.Parameter.VAR_KEYWORD in kinds:
        return []
    bases = {b.__name__ for b in inspect.getmro(obj)} if inspect.isclass(obj) else set()
    return [n for n in names if n not in sig.parameters and n not in bases]


def wrong_calls(text: str, index: dict[str, object]) -> tuple[int, list[str]]:
    """``(calls checked, one line per call naming a parameter its function lacks)`` of a Markdown text, its
    fenced blocks left out."""
    checked, wrong = 0, []
    for package, name, names, _ in documented_calls(FENCED.sub("", text)):
        obj = resolve(name, package, index)
        if obj is None or not names:
            continue
        checked += 1
        if bad := missing_parameters(obj, names):
            where = f"{obj.__module__}.{obj.__qualname__}"
            wrong.append(f"{name}({', '.join(names)}) -> {where}{inspect.signature(obj)}: no {bad}")
    return checked, wrong


def test_documented_calls_are_parsed_as_signatures_or_examples():
    text = (
        '### `beatlite.metrics`\n- `srgr(gen, gt, semantic (T,), *, variant="paper"|"reference",\n  delta=None)`,'
        " `SampledProtocol(model, test.train_speakers, seed)`,"
        ' `register_model("x", "m:C")`, `Recipe("m", "M", epochs=40)`'
    )
    assert documented_calls(text) == [
        ("beatlite.metrics", "srgr", ["gen", "gt", "semantic", "variant", "delta"], False),
        ("beatlite.metrics", "SampledProtocol", ["model", "seed"], False),
        ("beatlite.metrics", "register_model", [], True),
        ("beatlite.metrics", "Recipe", ["epochs"], True),
    ]


@pytest.fixture(scope="module")
def index():
    pytest.importorskip("torch")
    return _index()


@pytest.mark.parametrize(
    "name, at_least", [("docs/architecture.md", 300), ("README.md", 4), ("docs/reference_code.md", 4)]
)
def test_documented_signatures_name_real_parameters(index, name, at_least):
    checked, wrong = wrong_calls((REPO / name).read_text(), index)
    print(f"{name}: {checked} backticked calls resolved to one beatlite function with parameters to check")
    assert checked >= at_least, checked  # the parser finds the document's signatures
    assert not wrong, f"{name} names parameters the code does not have:\n" + "\n".join(wrong)


def test_resolution_is_by_section_then_unique(index):
    srgr = resolve("srgr", "beatlite.metrics", index)
    assert srgr is importlib.import_module("beatlite.metrics.recall").srgr
    assert missing_parameters(srgr, ["gen", "gt"]) == ["gen", "gt"]  # the old text's names
    assert resolve("load_take", "beatlite.io", index) is importlib.import_module("beatlite.io.take").load_take
    assert resolve("no_such_function", "beatlite", index) is None
    # a name written in full is that object (it was skipped as unresolved: README named parameters nobody checked)
    score_folder = importlib.import_module("beatlite.score").score_folder
    assert resolve("beatlite.score.score_folder", "beatlite", index) is score_folder
    assert missing_parameters(score_folder, ["folder", "data"]) == ["folder"]
    assert missing_parameters(resolve("beatlite.io.FormatError", "beatlite", index), ["ValueError"]) == []


def test_the_store_training_example_runs_as_written(data_samples):
    """The statements of "Training on the store (for the trainer)" in docs/architecture.md run as written on
    data_samples/ (the loop body ``...`` replaced by keeping one batch)."""
    pytest.importorskip("torch")
    from beatlite.data.index import index_folder
    from beatlite.data.store import build_store
    from beatlite.data.torch_dataset import window_loader

    text = DOC.read_text()
    start = text.index("Training on the store (for the trainer):")
    spans = [" ".join(s.split()) for s in SPAN.findall(text[start : text.index("\n- ", start)])]
    assert len(spans) == 4 and spans[-1].endswith(": ..."), spans
    names = {"build_store": build_store, "window_loader": window_loader, "index": index_folder(data_samples)}
    names.update(model_keys=("pose", "audio"), epoch_seed=0, cuda=False, seen=[])
    for statement in spans:
        exec(statement.replace(": ...", ": seen.append(batch); break"), names)
    assert len(names["seen"]) == 1 and set(names["seen"][0]) >= {"pose", "audio"}
    assert len(names["val"]) > 0 and names["val"].normalizers.matches(names["train"].normalizers)
