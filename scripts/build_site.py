"""``make site``: the course as a static site in ``build/site/``, complete offline (it works from ``file://``).

Writes:

- ``index.html``: the course map, the lectures in order with each notebook's first goal and lecture minutes (its
  header cell), and links to the page, the slides, the student copy and, when a GitHub repository is known,
  "Open in Colab";
- ``lectures/NN_name.html``: the executed notebook as an offline page (``run_notebooks.export_html``: formulas as
  MathML, no web script or font);
- ``slides/NN_name.html``: the same notebook as reveal.js slides. Cells carry Jupyter's slide convention
  (``metadata.slideshow.slide_type``: ``slide``, ``subslide``, ``fragment``, ``skip``, ``notes`` or ``-``), so
  JupyterLab's RISE presents the same notebooks; a slide taller than the 1280 x 800 frame continues on slides
  below it (:func:`fit_slides`). reveal.js (MIT) comes from the ``sphinx-revealjs`` package (the
  ``site`` extra) and is copied into ``assets/reveal/``;
- ``student/NN_name.ipynb`` (the copies without ``solution`` cells), ``guide.html`` (``docs/teaching.md``) and
  ``figures/`` with ``figures.html``.

Executed notebooks are taken from ``BUILD/notebooks/`` when their cells' sources equal the notebook's and that run
was complete (the slide metadata is then taken from ``notebooks/``, so retagging needs no new run); the others are
executed first as ``make run`` does. The exit status is 1 when a notebook failed (the site is still written). The Colab links need the GitHub repository: ``--colab-repo owner/name`` (``make site
COLAB_REPO=owner/name``), else the ``origin`` remote when it is on GitHub; without one the index says how to
add them. ``--set-repo owner/name`` writes the repository into every notebook's Colab cell (commit it once).
``--tag-slides`` adds the Colab cell where it is missing, splits a Markdown cell at each section heading inside it
(:func:`split_headings`: every ``## `` section starts a slide, every ``### `` one a subslide) and gives each cell
without slide metadata a slide type by the rules of :func:`tag_slides`.
"""

from __future__ import annotations

import argparse
import html
import importlib.util
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from beatlite.viz.check import SLIDE_FIGURE_BOX

REPO = Path(__file__).resolve().parents[1]
SLIDE_TYPES = ("slide", "subslide", "fragment", "skip", "notes", "-")
#: The repository named in the committed notebooks' Colab cell until ``--set-repo`` writes a real one.
PLACEHOLDER_REPO = "OWNER/NAME"
_REPO_LINE = re.compile(r'^REPO = "([^"]*)"', re.M)
_GITHUB = re.compile(
    r"^(?:https://github\.com/|git@github\.com:|ssh://git@github\.com/)([\w.-]+/[\w.-]+?)(?:\.git)?/?$"
)
#: The reveal.js files the slides load (copied from the sphinx-revealjs package).
_REVEAL_FILES = (
    "LICENSE",
    "dist/reveal.css",
    "dist/reveal.js",
    "dist/theme/white.css",
    "dist/theme/fonts/source-sans-pro",
    "plugin/notes/notes.js",
)


#: The first code cell of every notebook (tagged ``colab``, skipped on slides): on Google Colab it fetches the
#: course from GitHub and installs beatlite without its dependencies (Colab has numpy, torch, librosa...: its
#: torch is never replaced); anywhere else it does nothing.
COLAB_CELL = f"""# Google Colab only (nothing happens elsewhere): get the course from GitHub and install beatlite beside
# Colab's own torch. REPO is set by `python scripts/build_site.py --set-repo owner/name`.
REPO = "{PLACEHOLDER_REPO}"
import sys

if "google.colab" in sys.modules:
    import os
    import subprocess

    if REPO == "{PLACEHOLDER_REPO}":
        raise RuntimeError("this copy does not name its GitHub repository: set REPO above to 'owner/name'")
    if not os.path.isdir("/content/beatlite"):
        subprocess.run(["git", "clone", "--depth", "1", f"https://github.com/{{REPO}}", "/content/beatlite"], check=True)
        pip = [sys.executable, "-m", "pip", "install", "--quiet"]
        subprocess.run([*pip, "--no-deps", "-e", "/content/beatlite"], check=True)
        subprocess.run([*pip, "librosa", "soundfile", "imageio", "tqdm"], check=True)
    sys.path.insert(0, "/content/beatlite")
    os.environ.setdefault("BEATLITE_PYVISTA", "off")  # matplotlib 3D views: no OpenGL probe on Colab
    os.chdir("/content/beatlite/notebooks")"""


def add_colab_cell(nb) -> bool:
    """Insert :data:`COLAB_CELL` before the first code cell unless the notebook has a ``colab`` cell."""
    from nbformat.v4 import new_code_cell

    if any("colab" in _tags(c) for c in nb.cells):
        return False
    first = next(i for i, c in enumerate(nb.cells) if c.cell_type == "code")
    cell = new_code_cell(COLAB_CELL, metadata={"tags": ["colab"], "slideshow": {"slide_type": "skip"}})
    nb.cells.insert(first, cell)
    return True


def _load(name: str):
    """``scripts/<name>.py`` as a module (the scripts folder is not a package)."""
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, Path(__file__).with_name(f"{name}.py"))
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def reveal_dir() -> Path:
    """The reveal.js distribution inside the installed ``sphinx-revealjs`` package (found without importing it)."""
    spec = importlib.util.find_spec("sphinx_revealjs")
    folder = Path(next(iter(spec.submodule_search_locations))) / "_static" / "revealjs" if spec else None
    if folder is None or not (folder / "dist" / "reveal.js").is_file():
        raise FileNotFoundError(
            "reveal.js not found: install the site extra (pip install -e '.[site]'; `make site` does it)"
        )
    return folder


def github_repo(setting: str | None = None, cwd: Path = REPO) -> str | None:
    """``owner/name`` of the course on GitHub: ``setting`` if given, else the ``origin`` remote when it is on
    GitHub, else None. Raises ``ValueError`` for a setting that is not ``owner/name``."""
    if setting:
        if not re.fullmatch(r"[\w.-]+/[\w.-]+", setting):
            raise ValueError(f"COLAB_REPO must be owner/name on GitHub, got {setting!r}")
        return setting
    try:
        url = subprocess.run(
            ["git", "remote", "get-url", "origin"], cwd=cwd, capture_output=True, text=True, check=True
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None
    m = _GITHUB.match(url)
    return m[1] if m else None


def colab_url(repo: str, notebook: str, branch: str = "main") -> str:
    """The "Open in Colab" address of ``notebooks/<notebook>`` on GitHub."""
    return f"https://colab.research.google.com/github/{repo}/blob/{branch}/notebooks/{notebook}"


_HEADING = re.compile(r"^(#{2,3}) ")
_FENCE = re.compile(r"^ {0,3}(```|~~~)")


def split_headings(nb) -> int:
    """Split every Markdown cell at each ``## `` / ``### `` heading that is not its first line; return how many
    cells were added.

    A slide starts at a cell, so a section heading in the middle of a cell would land in the middle of the
    previous section's slide, and reveal.js's right arrow would skip that section (it would sit below the
    previous one). The new cell starting at a ``## `` heading is a ``slide``, at a ``### `` heading a
    ``subslide`` (a skipped cell's parts stay skipped); it keeps the cell's tags. Headings inside fenced code
    stay where they are.
    """
    from nbformat.v4 import new_markdown_cell

    added, cells = 0, []
    for cell in nb.cells:
        if cell.cell_type != "markdown":
            cells.append(cell)
            continue
        parts, fenced = [[]], False
        for line in cell.source.splitlines(keepends=True):
            if _FENCE.match(line):
                fenced = not fenced
            if not fenced and _HEADING.match(line) and "".join(parts[-1]).strip():
                parts.append([])
            parts[-1].append(line)
        cells.append(cell)
        if len(parts) == 1:
            continue
        texts = ["".join(p).strip("\n") for p in parts]
        cell.source = texts[0]
        for text in texts[1:]:
            kind = cell.metadata.get("slideshow", {}).get("slide_type")
            if kind not in ("skip", "notes"):
                kind = "slide" if text.startswith("## ") else "subslide"
            metadata = {"slideshow": {"slide_type": kind}}
            if "tags" in cell.metadata:
                metadata["tags"] = list(cell.metadata["tags"])
            cells.append(new_markdown_cell(text, metadata=metadata))
            added += 1
    nb.cells = cells
    return added


def tag_slides(nb) -> int:
    """Give every cell without ``metadata.slideshow`` a slide type; return how many were tagged.

    The header cell is the title slide, a ``## `` section starts a slide and a ``### `` one a subslide, as does
    any other Markdown cell that follows a shown code cell (one idea per screen: text, code, output); the Colab
    and import cells (setup), ``check`` cells (the lecture hides them) and ``solution`` cells (answers stay off
    the screen) are skipped; every other cell continues its slide (``-``).
    """
    code = [i for i, c in enumerate(nb.cells) if c.cell_type == "code" and "colab" not in _tags(c)]
    tagged = 0
    for i, cell in enumerate(nb.cells):
        if "slide_type" in cell.metadata.get("slideshow", {}):
            continue
        text = "".join(cell.source).lstrip()
        if i == 0:
            kind = "slide"
        elif {"colab", "check", "solution"} & set(_tags(cell)) or (code and i == code[0]):
            kind = "skip"
        elif cell.cell_type == "markdown" and text.startswith("## "):
            kind = "slide"
        elif cell.cell_type == "markdown" and text.startswith("### "):
            kind = "subslide"
        elif cell.cell_type == "markdown" and _shown_code_before(nb.cells, i):
            kind = "subslide"  # the next idea after a shown cell's output: below, not on the same screen
        else:
            kind = "-"
        cell.metadata["slideshow"] = {"slide_type": kind}
        tagged += 1
    return tagged


def _shown_code_before(cells, i: int) -> bool:
    """Whether the nearest cell before ``i`` that is shown on the slides is a code cell."""
    for cell in reversed(cells[:i]):
        if cell.metadata.get("slideshow", {}).get("slide_type") != "skip":
            return cell.cell_type == "code"
    return False


def _tags(cell) -> list[str]:
    return cell.get("metadata", {}).get("tags", [])


def set_repo(paths: list[Path], repo: str) -> int:
    """Write ``REPO = "owner/name"`` into the Colab cell of each notebook; return how many changed."""
    import nbformat

    github_repo(repo)  # validates
    changed = 0
    for path in paths:
        nb = nbformat.read(path, as_version=4)
        for cell in nb.cells:
            if "colab" in _tags(cell) and _REPO_LINE.search(cell.source):
                new = _REPO_LINE.sub(f'REPO = "{repo}"', cell.source, count=1)
                if new != cell.source:
                    cell.source, changed = new, changed + 1
                    nbformat.write(nb, path)
    return changed


def notebook_repo(nb) -> str | None:
    """The repository written in the notebook's Colab cell (None while it is the placeholder)."""
    for cell in nb.cells:
        if "colab" in _tags(cell) and (m := _REPO_LINE.search(cell.source)):
            return None if m[1] == PLACEHOLDER_REPO else m[1]
    return None


def header(nb) -> dict:
    """Title, first goal and lecture minutes from the notebook's header cell (its first Markdown cell)."""
    text = next((c.source for c in nb.cells if c.cell_type == "markdown"), "")
    title = re.search(r"^#\s+(.+)$", text, re.M)
    goal = re.search(r"\*\*Goals?\*\*\s*\n\s*[-*]\s+(.+?)(?=\n\s*[-*]\s|\n\s*\n|$)", text, re.S)
    minutes = re.search(r"lecture ~(\d+) min", text)
    return {
        "title": title[1].strip() if title else "",
        "goal": " ".join(goal[1].split()) if goal else "",
        "minutes": int(minutes[1]) if minutes else None,
    }


def run_failure(nb) -> str | None:
    """Why an executed notebook is not a complete run (``None`` if it is): its first code cell that raised (unless
    tagged ``raises-exception``) or that never ran (the kernel died or a cell timed out before it)."""
    for i, cell in enumerate(nb.cells):
        if cell.cell_type != "code" or not cell.source.strip():
            continue
        errors = [o for o in cell.get("outputs", []) if o.get("output_type") == "error"]
        if errors and "raises-exception" not in _tags(cell):
            return f"cell {i} raised {errors[0].get('ename', 'an error')}"
        if cell.get("execution_count") is None:
            return f"cell {i} did not run"
    return None


def executed_notebook(source: Path, build: Path, timeout: int = 900):
    """The executed copy of ``source``: ``build/notebooks/<name>`` if its cells have the same sources and that run
    was complete (:func:`run_failure`; slide metadata taken from ``source``), else executed now as ``make run``
    does. Returns ``(nb, reused)``."""
    import nbformat

    nb = nbformat.read(source, as_version=4)
    done = build / "notebooks" / source.name
    if done.is_file():
        old = nbformat.read(done, as_version=4)
        same = [(c.cell_type, c.source) for c in old.cells] == [(c.cell_type, c.source) for c in nb.cells]
        if same and run_failure(old) is None:
            for new, cell in zip(nb.cells, old.cells):
                cell.metadata = new.metadata
            return old, True
    ok, seconds, message = _load("run_notebooks").execute(source.resolve(), build / "notebooks", timeout)
    print(
        f"[site] executed {source.name}: {'ok' if ok else 'FAILED ' + message} in {seconds:.1f} s", flush=True
    )
    return nbformat.read(done, as_version=4), False


# The slide template extends nbconvert's reveal template without its web scripts (jQuery, require.js, mermaid,
# MathJax, the widget manager) and loads reveal.js from the site's own copy.
_SLIDES_TEMPLATE = """{%- extends 'index.html.j2' -%}
{%- block html_head_js -%}{%- endblock html_head_js -%}
{%- block jupyter_widgets -%}{%- endblock jupyter_widgets -%}
{%- block html_head_js_mathjax -%}{%- endblock html_head_js_mathjax -%}
{%- block html_head_css -%}<style type="text/css">{{ resources.offline_css }}</style>{%- endblock html_head_css -%}
{%- block footer_js -%}
<script src="{{ resources.reveal.url_prefix }}/dist/reveal.js"></script>
<script src="{{ resources.reveal.url_prefix }}/plugin/notes/notes.js"></script>
<script>
Reveal.initialize({controls: true, progress: true, hash: true, center: false, transition: "none",
                   slideNumber: "c/t", width: SLIDE_WIDTH, height: SLIDE_HEIGHT, margin: 0.04, plugins: [RevealNotes]});
</script>
{%- endblock footer_js -%}
"""

#: The slides' frame, CSS pixels (reveal.js scales it to the screen): what a slide shows without scrolling.
SLIDE_WIDTH, SLIDE_HEIGHT = 1280, 800
_SLIDES_TEMPLATE = _SLIDES_TEMPLATE.replace("SLIDE_WIDTH", f"{SLIDE_WIDTH}").replace(
    "SLIDE_HEIGHT", f"{SLIDE_HEIGHT}"
)

# A figure on a slide: at most an output's width (the frame less the prompt column, measured in Chromium) and
# _IMAGE_MAX_HEIGHT high, the box check_figure measures the text of a saved figure in (one home: SLIDE_FIGURE_BOX).
_OUTPUT_WIDTH, _IMAGE_MAX_HEIGHT = SLIDE_FIGURE_BOX

# A slide is at most the frame's height (fit_slides splits taller ones; should an estimate fall short, the slide
# scrolls rather than cut its end); figures at most _IMAGE_MAX_HEIGHT; code in Markdown as large as code cells.
_SLIDES_CSS = """
.reveal .slides > section, .reveal .slides > section > section { height: 100%; overflow-y: auto; }
.reveal .jp-OutputArea-output img { max-height: IMAGE_MAX_HEIGHTpx; width: auto; }
.reveal .jp-RenderedHTMLCommon table { font-size: 16px; }
.reveal .jp-InputArea-editor pre, .reveal .jp-OutputArea-output pre { white-space: pre-wrap; font-size: 16px; }
.reveal .jp-RenderedMarkdown pre { font-size: 16px; line-height: 1.3; }
.reveal .slide-number { left: 8px; right: auto; }
""".replace("IMAGE_MAX_HEIGHT", f"{_IMAGE_MAX_HEIGHT}")

# fit_slides: heights of rendered cells on a slide, CSS pixels, measured in Chromium on the 1280 x 800 frame with
# the styles above (paragraphs 20 px text on 26 px lines, list items 32 px lines, code and printed text 16 px
# monospace on 23 px lines, tables 16 px), and the characters per line of each, a little under what fits.
# What the cells of one slide may fill: the frame less a margin for the estimate's error.
_SLIDE_BUDGET = SLIDE_HEIGHT - 60
_CELL = 12  # a cell's own padding
_TEXT_LINE, _TEXT_CHARS, _PARAGRAPH = 27, 85, 20
_ITEM_LINE, _ITEM_CHARS, _LIST = 32, 72, 24
_TABLE_ROW, _TABLE_LINE, _TABLE_CHARS, _TABLE = 28, 19, 100, 20
_HEADINGS = {1: (60, 50, 40), 2: (39, 40, 55), 3: (32, 36, 65), 4: (27, 30, 80)}  # line, margins, characters
_MATH = 70  # a display formula with its margins
_CODE_LINE, _CODE_CHARS, _CODE = 23, 95, 23  # code cells and fenced code
_PRINTED_CHARS, _OUTPUT, _FIGURE, _PLAYER, _AUDIO = 85, 16, 56, 180, 80
_LIST_ITEM = re.compile(r"^\s*(?:[-*+]|\d+\.)\s+")


def _lines(text: str, chars: int) -> int:
    """Screen lines of ``text`` wrapped at word boundaries ``chars`` characters wide (at least 1)."""
    import textwrap

    return max(1, len(textwrap.wrap(text, chars, break_long_words=False)))


def _plain(text: str) -> str:
    """Markdown as it reads: a formula about a third as wide as its TeX, links as their text, no ** or `."""
    text = re.sub(r"\$([^$]+)\$", lambda m: "x" * max(1, len(m[1]) // 3), text)
    return re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text).replace("**", "").replace("`", "")


def _markdown_blocks(source: str) -> list[tuple[str, list[str]]]:
    """The blocks of a Markdown text, in order: ``("heading", [line])``, ``("fence", lines)`` (with its fence
    lines), ``("math", lines)``, ``("table", lines)``, ``("list", lines)`` or ``("text", lines)``."""
    blocks: list[tuple[str, list[str]]] = []
    lines, fenced = [], False
    for line in [*source.splitlines(), ""]:
        fence = _FENCE.match(line)
        if fenced or fence:
            lines.append(line)
            if fence and (fenced or len(lines) == 1):
                fenced = not fenced
                if not fenced:
                    blocks.append(("fence", lines))
                    lines = []
            elif fence:  # a fence opening after text
                blocks.append(("text", lines[:-1]))
                lines, fenced = [line], True
            continue
        if lines and _LIST_ITEM.match(line) and not _LIST_ITEM.match(lines[0]):  # a list right below a line
            blocks.append(("table" if lines[0].strip().startswith("|") else "text", lines))
            lines = []
        if line.strip() and not re.match(r"#{1,6} ", line):
            lines.append(line)
            continue
        if lines:
            first = lines[0].strip()
            kind = "table" if first.startswith("|") else "math" if first.startswith("$$") else "list"
            blocks.append((kind if kind != "list" or _LIST_ITEM.match(lines[0]) else "text", lines))
            lines = []
        if line.strip():
            blocks.append(("heading", [line]))
    return blocks


def markdown_height(source: str) -> float:
    """Estimated height, CSS pixels, of a Markdown cell's text on a slide."""
    height = 0.0
    for kind, lines in _markdown_blocks(source):
        if kind == "heading":
            level = min(len(lines[0].split()[0]), 4)
            line, margins, chars = _HEADINGS[level]
            height += line * _lines(lines[0], chars) + margins
        elif kind == "fence":
            height += _CODE_LINE * sum(_lines(x, _CODE_CHARS) for x in lines[1:-1]) + _CODE + _PARAGRAPH
        elif kind == "math":
            height += _MATH * max(1, sum(x.count("$$") for x in lines) // 2) + _TEXT_LINE * sum(
                x.count("\\\\") for x in lines
            )
        elif kind == "table":
            rows = [x for x in lines if not re.fullmatch(r"\s*\|[\s:|-]+\|\s*", x)]
            height += _TABLE + sum(
                _TABLE_ROW + _TABLE_LINE * (_lines(_plain("      ".join(r.split("|"))), _TABLE_CHARS) - 1)
                for r in rows
            )
        elif kind == "list":
            items: list[str] = []
            for x in lines:
                if _LIST_ITEM.match(x):
                    items.append(_LIST_ITEM.sub("", x))
                else:
                    items[-1] += " " + x.strip()
            height += _LIST + _ITEM_LINE * sum(_lines(_plain(x), _ITEM_CHARS) for x in items)
        else:
            height += _PARAGRAPH + _TEXT_LINE * _lines(
                _plain(" ".join(x.strip() for x in lines)), _TEXT_CHARS
            )
    return height


def _image_size(data: str) -> tuple[int, int] | None:
    """(width, height) in pixels of a base64 PNG or JPEG, None if unreadable."""
    import base64
    import io

    from PIL import Image

    try:
        with Image.open(io.BytesIO(base64.b64decode(data))) as image:
            return image.size
    except (OSError, ValueError):
        return None


def _shown_image_height(size: tuple[int, int] | None, limit: float = _IMAGE_MAX_HEIGHT) -> float:
    """Height of an image as the slide shows it: at most the output's width and ``limit`` high."""
    if size is None:
        return limit
    width, height = size
    return min(height * min(1.0, _OUTPUT_WIDTH / max(width, 1)), limit)


def output_height(output) -> float:
    """Estimated height, CSS pixels, of one output of a code cell on a slide."""
    kind = output.get("output_type")
    if kind == "stream":
        text = output.get("text", "")
    elif kind == "error":
        text = "\n".join(output.get("traceback", []))
    else:
        data = output.get("data", {})
        if "image/png" in data or "image/jpeg" in data:
            return _FIGURE + _shown_image_height(_image_size(data.get("image/png") or data["image/jpeg"]))
        if "text/html" in data:
            page = "".join(data["text/html"])
            if "<audio" in page and "<img" not in page:
                return _AUDIO
            # an animation player (matplotlib's to_jshtml: base64 lines continued by a backslash): its first frame,
            # then its buttons and slider
            frame = re.search(r"data:image/(?:png|jpeg);base64,([A-Za-z0-9+/=\\\s]+)", page)
            if frame:
                return _PLAYER + _shown_image_height(_image_size(re.sub(r"[\\\s]", "", frame[1])))
            return _OUTPUT + markdown_height(re.sub(r"<[^>]+>", " ", page))
        if "text/markdown" in data:
            return _OUTPUT + markdown_height("".join(data["text/markdown"]))
        text = "".join(data.get("text/plain", ""))
    text = re.sub(r"\x1b\[[0-9;]*m", "", "".join(text))
    return _OUTPUT + _CODE_LINE * sum(_lines(x, _PRINTED_CHARS) for x in text.rstrip("\n").split("\n"))


def cell_height(cell) -> float:
    """Estimated height, CSS pixels, of a cell on a slide (0 for a cell the slides leave out)."""
    if cell.metadata.get("slideshow", {}).get("slide_type") in ("skip", "notes"):
        return 0.0
    if cell.cell_type == "markdown":
        return _CELL + markdown_height(cell.source)
    if cell.cell_type != "code":
        return _CELL + _CODE_LINE * len(cell.source.splitlines())
    shown = not cell.metadata.get("transient", {}).get("remove_source", False)
    code = _CODE + _CODE_LINE * sum(_lines(x, _CODE_CHARS) for x in cell.source.splitlines()) if shown else 0
    return _CELL + code + sum(output_height(o) for o in cell.get("outputs", []))


def _kind(cell) -> str:
    return cell.metadata.get("slideshow", {}).get("slide_type", "-")


def _continuation(cell, **changes):
    """A copy of ``cell`` on a new subslide below (a skipped cell stays skipped), with ``changes`` applied."""
    import copy

    new = copy.deepcopy(cell)
    new.metadata["slideshow"] = {"slide_type": "subslide"}
    for key, value in changes.items():
        new[key] = value
    return new


def split_markdown(text: str, budget: float) -> list[str]:
    """``text`` in parts each at most ``budget`` high (:func:`markdown_height`) where it can: between blocks
    (paragraphs, lists, tables, formulas, fenced code), a long list between items and a long table between rows,
    its header row above each part. Any other block taller than ``budget`` stays whole."""
    pieces: list[str] = []
    for kind, lines in _markdown_blocks(text):
        if kind not in ("table", "list") or markdown_height("\n".join(lines)) <= budget:
            pieces.append("\n".join(lines))
            continue
        head, rows = (lines[:2], lines[2:]) if kind == "table" else ([], [])
        for line in lines if kind == "list" else []:  # an item with its continuation lines
            if _LIST_ITEM.match(line) or not rows:
                rows.append(line)
            else:
                rows[-1] += "\n" + line
        part: list[str] = []
        for row in rows:
            if part and markdown_height("\n".join([*head, *part, row])) > budget:
                pieces.append("\n".join([*head, *part]))
                part = []
            part.append(row)
        pieces.append("\n".join([*head, *part]))
    parts, chunk = [], []
    for piece in pieces:
        if chunk and markdown_height("\n\n".join([*chunk, piece])) > budget:
            parts.append("\n\n".join(chunk))
            chunk = []
        chunk.append(piece)
    return ["\n\n".join(chunk)] if not parts else [*parts, "\n\n".join(chunk)]


def _split_output(output, budget: float) -> list:
    """An output taller than ``budget`` as several: printed text between lines, a Markdown output (a table shown
    with ``display(Markdown(...))``) by :func:`split_markdown`; any other output as it is."""
    import copy

    from nbformat import from_dict

    data = output.get("data", {})
    if output_height(output) <= budget or (
        "text/markdown" not in data and output.get("output_type") != "stream"
    ):
        return [output]
    parts = []
    if output.get("output_type") == "stream":
        lines: list[str] = []
        for line in "".join(output.get("text", "")).splitlines(keepends=True):
            if lines and output_height({"output_type": "stream", "text": "".join([*lines, line])}) > budget:
                parts.append(from_dict({**copy.deepcopy(output), "text": "".join(lines)}))
                lines = []
            lines.append(line)
        return [*parts, from_dict({**copy.deepcopy(output), "text": "".join(lines)})]
    for text in split_markdown("".join(data["text/markdown"]), budget - _OUTPUT):
        part = copy.deepcopy(output)
        part["data"] = {"text/markdown": text}
        parts.append(part)
    return parts


def _split_cell(cell, budget: float) -> list:
    """``cell`` as cells each at most ``budget`` high where it can: a Markdown cell at its blocks, a code cell's
    source at its lines and its outputs one cell below (source hidden), itself split between outputs (a cell whose
    source is hidden only between outputs: no empty part). A single block, code line or output taller than
    ``budget`` stays whole."""
    if cell_height(cell) <= budget or cell.cell_type not in ("markdown", "code"):
        return [cell]
    parts: list = []
    if cell.cell_type == "markdown":
        texts = split_markdown(cell.source, budget - _CELL)
        first = _continuation(cell, source=texts[0])
        first.metadata["slideshow"] = dict(cell.metadata.get("slideshow", {"slide_type": "-"}))
        return [first, *(_continuation(cell, source=text) for text in texts[1:])]
    shown = not cell.metadata.get("transient", {}).get("remove_source", False)  # (hidden: moved outputs)
    lines, chunk = cell.source.splitlines() if shown else [], []
    for line in lines:
        if (
            chunk
            and _CELL + _CODE + _CODE_LINE * sum(_lines(x, _CODE_CHARS) for x in [*chunk, line]) > budget
        ):
            parts.append(_continuation(cell, source="\n".join(chunk), outputs=[]))
            chunk = []
        chunk.append(line)
    if shown:
        parts.append(_continuation(cell, source="\n".join(chunk), outputs=[]))
    groups: list[list] = []
    for output in (part for o in cell.get("outputs", []) for part in _split_output(o, budget - _CELL)):
        if not groups or _CELL + sum(output_height(o) for o in [*groups[-1], output]) > budget:
            groups.append([])
        groups[-1].append(output)
    if len(parts) == 1 and groups and cell_height(_continuation(cell, outputs=groups[0])) <= budget:
        parts[0]["outputs"] = groups.pop(0)  # the source with its first outputs; the others below
    for group in groups:
        parts.append(_continuation(cell, outputs=group))
        parts[-1].metadata["transient"] = {"remove_source": True}
    parts[0].metadata["slideshow"] = dict(cell.metadata.get("slideshow", {"slide_type": "-"}))
    return parts


def fit_slides(nb, budget: float = _SLIDE_BUDGET) -> int:
    """Break every slide taller than the frame into slides below it (subslides); return how many were added.

    A slide is the cells from one ``slide`` or ``subslide`` cell to the next; its height is estimated from the
    sources and outputs (:func:`cell_height`, the styles of the slides at :data:`SLIDE_WIDTH` x
    :data:`SLIDE_HEIGHT`). A cell that would end below ``budget`` starts a subslide (it continues the idea
    below, where the down arrow goes); a cell taller than ``budget`` on its own is split first
    (:func:`_split_cell`): Markdown between paragraphs, lists, tables or formulas, code between lines, a code
    cell's outputs onto the slide below its source. Changes ``nb`` in place (the slides' copy: the notebooks
    keep their tags, so RISE shows them as before).
    """
    before = sum(_kind(c) in ("slide", "subslide") for c in nb.cells)
    ids = {c["id"] for c in nb.cells if "id" in c}
    cells = []
    for cell in nb.cells:
        parts = _split_cell(cell, budget)
        n = 0  # the parts of a split cell: its id and their number (unique, as nbformat asks)
        for part in parts[1:]:
            if "id" in part:
                n += 1
                while f"{cell['id']}-part{n}" in ids:
                    n += 1
                part["id"] = f"{cell['id']}-part{n}"
                ids.add(part["id"])
        cells += parts
    filled = 0.0
    for cell in cells:
        height = cell_height(cell)
        if _kind(cell) in ("slide", "subslide"):
            filled = 0.0
        elif height and filled and filled + height > budget:
            cell.metadata["slideshow"] = {"slide_type": "subslide"}
            filled = 0.0
        filled += height
    nb.cells = cells
    return sum(_kind(c) in ("slide", "subslide") for c in nb.cells) - before


def export_slides(nb, url_prefix: str = "../assets/reveal") -> str:
    """The reveal.js slides of an executed notebook, complete offline (formulas as MathML, reveal.js local); a slide
    taller than the frame continues on slides below it (:func:`fit_slides`)."""
    from jinja2 import DictLoader, pass_context
    from nbconvert import SlidesExporter

    runner = _load("run_notebooks")

    class OfflineSlidesExporter(SlidesExporter):
        @pass_context
        def markdown2html(self, context, source):
            return runner.markdown_to_html(
                source,
                attachments=context.get("cell", {}).get("attachments", {}),
                anchor_link_text=self.anchor_link_text,
                path=context.get("resources", {}).get("metadata", {}).get("path", ""),
            )

    exporter = OfflineSlidesExporter(
        extra_loaders=[DictLoader({"beatlite_slides.html.j2": _SLIDES_TEMPLATE})],
        template_file="beatlite_slides.html.j2",
        reveal_url_prefix=url_prefix,
        reveal_theme="white",  # the copied theme; "simple" (the default) imports web fonts
    )
    nb = runner.offline_notebook(nb)
    fit_slides(nb)
    body, _ = exporter.from_notebook_node(nb, resources={"offline_css": runner._offline_css() + _SLIDES_CSS})
    return body


_STYLE = """
body { font-family: "DejaVu Sans", "Helvetica Neue", Arial, sans-serif; max-width: 72em; margin: 2em auto;
       padding: 0 1em; line-height: 1.45; color: #222; }
table { border-collapse: collapse; } th, td { border-bottom: 1px solid #ccc; padding: 0.35em 0.6em;
       text-align: left; vertical-align: top; }
code { background: #f3f3f3; padding: 0 0.2em; } pre { background: #f6f6f6; padding: 0.6em; overflow-x: auto; }
nav a { margin-right: 1.2em; } .note { color: #555; font-size: 0.92em; }
.figures figure { display: inline-block; margin: 0.5em; max-width: 46%; vertical-align: top; }
.figures img { max-width: 100%; border: 1px solid #ddd; }
math { font-family: "Latin Modern Math", "STIX Two Math", "DejaVu Math TeX Gyre", math; }
"""


def _page(title: str, body: str, css: str = "assets/site.css") -> str:
    return (
        f'<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n<title>{html.escape(title)}</title>\n'
        f'<link rel="stylesheet" href="{css}">\n</head>\n<body>\n{body}\n</body>\n</html>\n'
    )


def _nav(prefix: str = "") -> str:
    return (
        f'<nav><a href="{prefix}index.html">Course map</a><a href="{prefix}guide.html">Instructor\'s guide</a>'
        f'<a href="{prefix}figures.html">Figures</a></nav>'
    )


def _fix_links(page: str, repo: str | None, branch: str, folder: str) -> str:
    """Links of a rendered repository Markdown file: notebooks to their pages, other repository files to GitHub
    (or plain text without a repository); anchors and web links stay."""

    def fix(m: re.Match) -> str:
        href, text = m[1], m[2]
        if re.match(r"^([a-z]+:|#)", href):
            return m[0]
        path = os.path.normpath(os.path.join(folder, href.split("#")[0]))
        if path.startswith("notebooks/") and path.endswith(".ipynb"):
            return f'<a href="lectures/{Path(path).stem}.html">{text}</a>'
        if repo:
            return f'<a href="https://github.com/{repo}/blob/{branch}/{path}">{text}</a>'
        return text

    return re.sub(r'<a href="([^"]*)"[^>]*>(.*?)</a>', fix, page, flags=re.S)


def build_site(
    out: Path,
    build: Path,
    notebooks: list[Path],
    repo: str | None = None,
    branch: str = "main",
    guide: Path = REPO / "docs" / "teaching.md",
    timeout: int = 900,
) -> dict:
    """Write the site into ``out`` from the notebooks (executed ones from ``build/notebooks/`` when current).

    The site's own entries in ``out`` (``index.html``, ``guide.html``, ``figures.html`` and the folders
    ``lectures``, ``slides``, ``student``, ``figures``, ``assets``) are replaced; anything else there is kept.

    Returns a summary: ``{"lectures": [names], "executed": [names run now], "failed": [names whose run failed:
    their pages show the error], "colab": bool}``.
    """

    runner = _load("run_notebooks")
    subfolders = ("lectures", "slides", "student", "figures", "assets")
    for name in (*subfolders, "index.html", "guide.html", "figures.html"):  # only what a build writes: `out`
        old = out / name  # may be build/ itself, whose notebooks, caches and lab/ work stay
        if old.is_dir() and not old.is_symlink():
            shutil.rmtree(old)
        elif old.exists() or old.is_symlink():
            old.unlink()
    for sub in subfolders:
        (out / sub).mkdir(parents=True, exist_ok=True)
    reveal = reveal_dir()
    for rel in _REVEAL_FILES:
        src, dst = reveal / rel, out / "assets" / "reveal" / rel
        dst.parent.mkdir(parents=True, exist_ok=True)
        (shutil.copytree if src.is_dir() else shutil.copy2)(src, dst)
    (out / "assets" / "site.css").write_text(_STYLE, encoding="utf-8")

    rows, executed, failed, stale_cells = [], [], [], []
    for source in notebooks:
        nb, reused = executed_notebook(source, build, timeout)
        if not reused:
            executed.append(source.stem)
        if why := run_failure(nb):
            failed.append(source.stem)
            print(f"[site] {source.name} FAILED ({why}): its page and slides show the error", flush=True)
        if repo and notebook_repo(nb) not in (None, repo):
            stale_cells.append(source.name)
        (out / "lectures" / f"{source.stem}.html").write_text(runner.export_html(nb), encoding="utf-8")
        (out / "slides" / f"{source.stem}.html").write_text(export_slides(nb), encoding="utf-8")
        runner.write_student_copy(source, out / "student")
        rows.append((source, header(nb)))

    for figure in sorted((build / "figures").glob("*")) if (build / "figures").is_dir() else []:
        if figure.suffix.lower() in (".png", ".svg", ".gif"):
            shutil.copy2(figure, out / "figures" / figure.name)
    shown = sorted(p for p in (out / "figures").iterdir() if p.suffix.lower() in (".png", ".gif"))
    gallery = "".join(
        f'<figure><a href="figures/{p.name}"><img src="figures/{p.name}" alt="{p.stem}"></a>'
        f"<figcaption><code>{p.name}</code></figcaption></figure>"
        for p in shown
    )
    (out / "figures.html").write_text(
        _page(
            "beatlite figures",
            f"{_nav()}<h1>Figures</h1><p class='note'>Saved by the notebooks into <code>build/figures/</code> "
            f"({len(shown)} images; SVG versions beside them).</p><div class='figures'>{gallery}</div>",
        ),
        encoding="utf-8",
    )

    guide_html = _fix_links(runner.markdown_to_html(guide.read_text(encoding="utf-8")), repo, branch, "docs")
    (out / "guide.html").write_text(_page("Teaching with beatlite", _nav() + guide_html), encoding="utf-8")

    lines = []
    for source, head in rows:
        name = source.stem
        colab = f'<a href="{colab_url(repo, source.name, branch)}">Open in Colab</a>' if repo else ""
        minutes = f"{head['minutes']} min" if head["minutes"] is not None else ""
        goal = re.sub(r"^<p>(.*)</p>\s*$", r"\1", runner.markdown_to_html(head["goal"]), flags=re.S)
        lines.append(
            f"<tr><td><a href='lectures/{name}.html'>{html.escape(head['title'] or name)}</a></td>"
            f"<td>{goal}</td><td>{minutes}</td>"
            f"<td><a href='slides/{name}.html'>slides</a></td>"
            f"<td><a href='student/{source.name}' download>student copy</a></td><td>{colab}</td></tr>"
        )
    if repo:
        colab_note = f"<p class='note'>Colab links open the notebooks of <code>{repo}</code> ({branch}).</p>"
        if stale_cells:
            colab_note += (
                f"<p class='note'>The Colab cell of {', '.join(stale_cells)} names another repository: run "
                f"<code>python scripts/build_site.py --set-repo {repo}</code> and commit.</p>"
            )
    else:
        colab_note = (
            "<p class='note'>No GitHub repository is known, so there are no Colab links: build with "
            "<code>make site COLAB_REPO=owner/name</code> (or from a clone whose <code>origin</code> is on "
            "GitHub).</p>"
        )
    body = (
        f"{_nav()}<h1>beatlite: co-speech gesture synthesis, a course</h1>"
        "<p>Lectures in order: the executed notebook, its slides (arrow keys; <kbd>s</kbd> opens the speaker "
        "view, <kbd>Esc</kbd> the overview), the student copy without solutions.</p>"
        "<p class='note'>The executed lecture pages show the exercises' solutions (the slides and the student "
        "copies do not): publish them once the exercises are due.</p>"
        "<table><thead><tr><th>lecture</th><th>goal</th><th>time</th><th>slides</th><th>download</th>"
        f"<th>Colab</th></tr></thead><tbody>{''.join(lines)}</tbody></table>{colab_note}"
    )
    (out / "index.html").write_text(_page("beatlite course", body), encoding="utf-8")
    return {
        "lectures": [s.stem for s, _ in rows],
        "executed": executed,
        "failed": failed,
        "colab": bool(repo),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "--build", type=Path, default=REPO / "build", help="make run's output folder (build/)"
    )
    parser.add_argument("--out", type=Path, default=None, help="site folder (default BUILD/site)")
    parser.add_argument(
        "--colab-repo", default=os.environ.get("COLAB_REPO") or None, help="owner/name on GitHub"
    )
    parser.add_argument("--branch", default="main", help="branch the Colab links open (default main)")
    parser.add_argument("--timeout", type=int, default=900, help="per-cell timeout when a notebook runs")
    parser.add_argument("--set-repo", metavar="OWNER/NAME", help="write the repository into the Colab cells")
    parser.add_argument(
        "--tag-slides",
        action="store_true",
        help="add the Colab cell, split cells at headings, give untagged cells a slide type",
    )
    parser.add_argument("notebooks", nargs="*", type=Path, help="notebooks (default: all, in order)")
    args = parser.parse_args(argv)
    paths = args.notebooks or sorted((REPO / "notebooks").glob("[0-9][0-9]_*.ipynb"))

    if args.set_repo or args.tag_slides:
        import nbformat

        if args.set_repo:
            print(f"[site] REPO set in {set_repo(paths, args.set_repo)} notebooks")
        if args.tag_slides:
            for path in paths:
                nb = nbformat.read(path, as_version=4)
                if (count := add_colab_cell(nb) + split_headings(nb) + tag_slides(nb)) > 0:
                    nbformat.write(nb, path)
                print(f"[site] {path.name}: {count} cells tagged")
        return 0

    build = args.build.resolve()
    os.environ["BEATLITE_BUILD"] = str(build)
    os.environ["BEATLITE_INTERACTIVE"] = "off"
    out = (args.out or build / "site").resolve()
    summary = build_site(out, build, paths, repo=github_repo(args.colab_repo), branch=args.branch)
    print(
        f"[site] wrote {out / 'index.html'}: {len(summary['lectures'])} lectures "
        f"({len(summary['executed'])} executed now), Colab links {'on' if summary['colab'] else 'off'}"
    )
    print(json.dumps(summary["executed"]))
    if summary["failed"]:
        print(
            f"[site] {len(summary['failed'])} notebooks failed: {', '.join(summary['failed'])}",
            file=sys.stderr,
        )
    return 1 if summary["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
