"""The docs stay true to the code: every backticked ``name(params)`` of docs/architecture.md, README.md and
docs/reference_code.md that resolves to one beatlite function or class names only parameters its
``inspect.signature`` has."""

from __future__ import annotations

import argparse
import importlib
import inspect
import keyword
import pkgutil
import re
import runpy
import sys
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


# --- Command lines: every documented command runs a program that has those subcommands, options and choices ---

DOCS = ("README.md", "docs/architecture.md", "docs/teaching.md", "docs/reference_code.md")
FENCE = re.compile(r"^ *```(\w*)\n(.*?)^ *```", re.S | re.M)
TRAIN_COMMANDS = (
    "fit",
    "retrain-all",
    "results",
    "seeds",
)  # `fit --resume` is short for python -m beatlite.train
STOP = {"|", "||", "&&", ";", ">", "2>&1"}
HYPOTHETICAL = {"mymodel_tiny"}  # the text's own example of a recipe not added to RECIPES


def documented_commands(text: str) -> list[str]:
    """The lines of a Markdown text's shell blocks (comments cut) and its backticked spans (one line each)."""
    found = [
        line.split(" #")[0].strip()
        for lang, body in FENCE.findall(text)
        if lang in ("bash", "sh", "")
        for line in body.splitlines()
    ]
    found += [" ".join(span.split()) for span in SPAN.findall(FENCE.sub("", text))]
    return [c for c in found if c and not c.startswith("#")]


def split_command(command: str) -> tuple[str | None, list[str], bool]:
    """``(program, arguments, complete)``: a ``beatlite.*`` module run with ``-m``, a script of ``scripts/`` or
    ``bench/`` (a ``.py`` or ``.sh``), ``make``, or ``beatlite.train`` for a span starting with one of its
    subcommands; ``complete`` when the text is a whole command line (a program first), not a mention of options.
    Synopsis brackets are dropped: ``[--seed S]`` is ``--seed S``."""
    tokens = [t for t in (t.strip("[]") for t in command.split()) if t]
    cut = next((i for i, t in enumerate(tokens) if t in STOP or t.startswith("#")), len(tokens))
    tokens = tokens[:cut]
    complete = bool(tokens) and bool(
        re.match(r"\S*(python|torchrun|bash|sudo|make)|\S+\.(py|sh)$", tokens[0])
    )
    for i, t in enumerate(tokens):
        if t == "-m" and i + 1 < len(tokens) and tokens[i + 1].startswith("beatlite."):
            return tokens[i + 1], tokens[i + 2 :], complete
        if t.endswith((".py", ".sh")):
            name = t.rsplit("/", 1)[-1]
            folders = [f for f in ("scripts", "bench") if (REPO / f / name).is_file()]
            if len(folders) == 1 and (t == name or t.endswith(f"{folders[0]}/{name}")):
                return f"{folders[0]}/{name}", tokens[i + 1 :], complete
        if t == "make":
            return "make", tokens[:i] + tokens[i + 1 :], complete
    if len(tokens) > 1 and tokens[0] in TRAIN_COMMANDS:
        return "beatlite.train", tokens, False
    return None, tokens, False


class _Parsed(Exception):
    def __init__(self, parser: argparse.ArgumentParser):
        self.parser = parser


def program_parser(program: str) -> argparse.ArgumentParser | None:
    """The ``argparse`` parser of a ``beatlite.*`` module or a script's ``main()``, taken at its first parse (so
    nothing runs)."""

    def capture(self, args=None, namespace=None):
        raise _Parsed(self)

    parse, argv = argparse.ArgumentParser.parse_known_args, sys.argv
    argparse.ArgumentParser.parse_known_args, sys.argv = capture, [program]  # (argv[0]: a script's prog)
    try:
        if program.endswith(".py"):
            main = runpy.run_path(str(REPO / program))["main"]  # (not as __main__: only definitions run)
        else:
            module = importlib.import_module(program)
            if hasattr(module, "__path__"):  # a package: python -m runs its __main__
                module = importlib.import_module(f"{program}.__main__")
            main = module.main
        main()
    except _Parsed as parsed:
        return parsed.parser
    finally:
        argparse.ArgumentParser.parse_known_args, sys.argv = parse, argv
    return None


def _placeholder(value: str) -> bool:
    """``NAME``, ``DIR``, ``<corpus>``, ``/path/to/beat``, ``...``: the reader's value, not a literal."""
    return value in ("...", "…") or any(c.isupper() or c in "<>/" for c in value)


def _not_chosen(action: argparse.Action, values: list[str], where: str) -> list[str]:
    allowed = {str(c) for c in action.choices or ()}
    return [
        f"{where}: {piece!r} is not one of its choices"
        for value in values
        for piece in value.split("|")  # (a synopsis' alternatives, dirvec|pose|rot6d)
        if allowed and piece and not _placeholder(piece) and piece not in allowed | HYPOTHETICAL
    ]


def command_problems(parser: argparse.ArgumentParser, args: list[str], complete: bool = True) -> list[str]:
    """What ``parser`` would refuse in ``args``: an unknown subcommand or option, a choice it lacks and, in a
    ``complete`` command line, an option without the values it takes."""
    problems, i = [], 0
    sub = next((a for a in parser._actions if isinstance(a, argparse._SubParsersAction)), None)
    positionals = [a for a in parser._actions if not a.option_strings and a is not sub]
    while i < len(args):
        token, i = args[i], i + 1
        if token.startswith("--"):
            flag, _, inline = token.partition("=")
            action = parser._option_string_actions.get(flag)
            if action is None:
                problems.append(f"{parser.prog}: no option {flag}")
                continue
            nargs = action.nargs
            low, high = {None: (1, 1), "?": (0, 1), "*": (0, 99), "+": (1, 99)}.get(nargs, (nargs, nargs))
            values = [inline] if inline else []
            while len(values) < high and i < len(args) and not args[i].startswith("-"):
                values, i = [*values, args[i]], i + 1
            if complete and len(values) < low:
                problems.append(f"{parser.prog} {flag}: takes {low} value(s), the text gives {values}")
            problems += _not_chosen(action, values, f"{parser.prog} {flag}")
        elif sub is not None:
            if token in sub.choices:
                return problems + command_problems(sub.choices[token], args[i:], complete)
            return problems + ([] if _placeholder(token) else [f"{parser.prog}: no command {token!r}"])
        elif positionals:
            problems += _not_chosen(positionals.pop(0), [token], f"{parser.prog} {token}")
    return problems


def make_problems(args: list[str]) -> list[str]:
    """Targets the Makefile lacks and ``VAR=value`` settings that neither it nor beatlite reads."""
    makefile = (REPO / "Makefile").read_text()
    targets = set(re.findall(r"^([\w-]+):", makefile, re.M))
    variables = set(re.findall(r"^(?:export )?(\w+)\s*[:?]?=", makefile, re.M))
    variables |= set(re.findall(r"\$\((\w+)\)", makefile))
    sources = "".join(p.read_text() for p in (REPO / "beatlite").rglob("*.py"))
    variables |= set(re.findall(r"[\"'](BEATLITE_\w+)[\"']", sources))
    problems = []
    for token in args:
        name, equals, _ = token.partition("=")
        if equals and re.fullmatch(r"[A-Z_]+", name) and name not in variables:
            problems.append(f"make: {name} is no variable of the Makefile or beatlite")
        elif not equals and re.fullmatch(r"[a-z][\w-]*", token) and token not in targets:
            problems.append(f"make: no target {token!r}")
    return problems


def stage_problems(script: str, args: list[str]) -> list[str]:
    """A ``bench/gpu_session.sh STAGE`` whose stage its ``case`` does not accept."""
    stages = re.search(r'case "\$stage" in ([\w |]+)\)', (REPO / script).read_text()).group(1)
    known = {s.strip() for s in stages.split("|")}
    return [f"{script}: no stage {args[0]!r}" for _ in [0] if args and args[0] not in known]


def test_the_command_checker_finds_unknown_options_missing_values_and_choices():
    parser = argparse.ArgumentParser(prog="p")
    sub = parser.add_subparsers()
    fit = sub.add_parser("fit", prog="p fit")
    fit.add_argument("recipe", choices=["camn_tiny", "ha2g_tiny"])
    fit.add_argument("--keep")
    fit.add_argument("--space", choices=["dirvec", "pose"])
    fit.add_argument("--resume", action="store_true")
    fit.add_argument("--hours", nargs="+")
    assert split_command("python -m beatlite.train fit camn_tiny [--seed S]  # comment") == (
        "beatlite.train",
        ["fit", "camn_tiny", "--seed", "S"],
        True,
    )
    assert split_command("fit --keep") == ("beatlite.train", ["fit", "--keep"], False)
    assert (
        command_problems(parser, ["fit", "camn_tiny", "--keep", "DIR", "--hours", "1", "4", "--resume"]) == []
    )
    assert command_problems(parser, "fit NAME --space dirvec|pose --keep=x".split()) == []
    assert command_problems(parser, ["fit", "camn_tiny", "--keep"]) == [
        "p fit --keep: takes 1 value(s), the text gives []"
    ]
    assert command_problems(parser, ["fit", "--keep"], complete=False) == []  # a mention of the option
    assert command_problems(parser, "fit camn_small --space rot6d --seed 1".split()) == [
        "p fit camn_small: 'camn_small' is not one of its choices",
        "p fit --space: 'rot6d' is not one of its choices",
        "p fit: no option --seed",
    ]
    assert command_problems(parser, ["train"]) == ["p: no command 'train'"]
    assert make_problems(["JOBS=2", "seeds", "ONLY=x", "BEATLITE_DATA=/d", "run"]) == []
    assert make_problems(["tests", "THREADS=2"]) == [
        "make: no target 'tests'",
        "make: THREADS is no variable of the Makefile or beatlite",
    ]


def test_documented_commands_have_those_programs_commands_options_and_choices():
    """Every command line of README.md and docs/*.md (shell blocks and backticked spans) names a program that
    exists with the subcommands, options, option values and choices it is given; make targets and variables too."""
    pytest.importorskip("torch")
    parsers, wrong, checked = {}, [], 0
    for doc in DOCS:
        for command in documented_commands((REPO / doc).read_text()):
            program, args, complete = split_command(command)
            if program is None:
                continue
            checked += 1
            if program == "make":
                problems = make_problems(args)
            elif program.endswith(".sh"):
                problems = stage_problems(program, args) if program == "bench/gpu_session.sh" else []
            else:
                if program not in parsers:
                    parsers[program] = program_parser(program)
                if parsers[program] is None:  # (scripts/lab_copies.py reads sys.argv itself)
                    continue
                problems = command_problems(parsers[program], args, complete)
            wrong += [f"{doc}: `{command}`: {p}" for p in problems]
    print(f"{checked} command lines checked, {len(parsers)} programs' parsers")
    assert checked > 100 and len(parsers) >= 12, (checked, sorted(parsers))
    assert not wrong, "documented commands the programs refuse:\n" + "\n".join(wrong)


# --- Counts and lists the docs state about the registries ---

NUMBER_WORDS = {"ten": 10, "eleven": 11, "twelve": 12, "thirteen": 13}


def recipe_listing(text: str) -> list[tuple[str, int]]:
    """``(system, recipes)`` of architecture's list of the shipped recipes, ``CaMN + 7 ablations`` = 8."""
    listing = re.search(r"for every shipped checkpoint \(([^:]*):", text).group(1)
    items = [" ".join(item.split()) for item in listing.split(",")]
    return [
        (re.sub(r" \+ \d+ ablations", "", i), 1 + int(m.group(1)) if (m := re.search(r"\+ (\d+)", i)) else 1)
        for i in items
    ]


def test_the_documented_counts_and_lists_are_the_registries():
    """The recipe, model and notebook counts of README.md and docs/architecture.md are those of the code."""
    pytest.importorskip("torch")
    from beatlite.models import MODELS
    from beatlite.train.recipes import RECIPES

    readme, architecture = (REPO / "README.md").read_text(), DOC.read_text()
    readme_flat = " ".join(readme.split())
    assert int(re.search(r"All (\d+) shipped recipes", readme_flat).group(1)) == len(RECIPES)
    seeds = next(a for a in program_parser("beatlite.train")._actions if a.dest == "command").choices["seeds"]
    n_seeds = len(seeds.get_default("seeds"))
    assert int(re.search(r"`make seeds`, (\d+) trainings", readme_flat).group(1)) == n_seeds * len(RECIPES)
    registry = re.search(r"registry `models.MODELS` \(([^)]*)\)", architecture).group(1)
    assert [m.strip() for m in registry.split(",")] == list(MODELS)
    listed = recipe_listing(architecture)
    assert sum(n for _, n in listed) == len(RECIPES), f"{listed}: {len(RECIPES)} recipes"
    labels = {r.label.split("-style")[0].lower() for r in RECIPES.values()}
    assert {system.lower() for system, _ in listed} <= labels, listed
    notebooks = len(list((REPO / "notebooks").glob("[0-9][0-9]_*.ipynb")))
    for name in DOCS:
        for word in re.findall(r"\b(\w+) notebooks\b", (REPO / name).read_text(), re.I):
            assert NUMBER_WORDS.get(word.lower(), notebooks) == notebooks, f"{name}: '{word} notebooks'"
