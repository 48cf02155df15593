"""``make site``: the course as a static site in ``build/site/``, complete offline (it works from ``file://``).

Writes:

- ``index.html``: the course map, the lectures in order with each notebook's first goal and lecture minutes (its
  header cell), and links to the page, the slides, the student copy and, when a GitHub repository is known,
  "Open in Colab";
- ``lectures/NN_name.html``: the executed notebook as an offline page (``run_notebooks.export_html``: formulas as
  MathML, no web script or font);
- ``slides/NN_name.html``: the same notebook as reveal.js slides. Cells carry Jupyter's slide convention
  (``metadata.slideshow.slide_type``: ``slide``, ``subslide``, ``fragment``, ``skip``, ``notes`` or ``-``), so
  JupyterLab's RISE presents the same notebooks. reveal.js (MIT) comes from the ``sphinx-revealjs`` package (the
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
                   slideNumber: "c/t", width: 1280, height: 800, margin: 0.04, plugins: [RevealNotes]});
</script>
{%- endblock footer_js -%}
"""

# Slides scroll when a cell is taller than the screen; figures fit its height.
_SLIDES_CSS = """
.reveal .slides > section, .reveal .slides > section > section { height: 100%; overflow-y: auto; }
.reveal .jp-OutputArea-output img { max-height: 600px; width: auto; }
.reveal .jp-RenderedHTMLCommon table { font-size: 16px; }
.reveal .jp-InputArea-editor pre, .reveal .jp-OutputArea-output pre { white-space: pre-wrap; font-size: 16px; }
.reveal .slide-number { left: 8px; right: auto; }
"""


def export_slides(nb, url_prefix: str = "../assets/reveal") -> str:
    """The reveal.js slides of an executed notebook, complete offline (formulas as MathML, reveal.js local)."""
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
    body, _ = exporter.from_notebook_node(
        runner.offline_notebook(nb), resources={"offline_css": runner._offline_css() + _SLIDES_CSS}
    )
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
