"""``make site``: the course site and the slides build from executed notebooks and work offline from ``file://``.

The site is built from two small notebooks (one already executed in ``build/notebooks/``, one that the builder
must execute), never from the course's own notebooks, which are only checked for their slide metadata and Colab
cell. The browser tests reuse ``test_pages``' headless Chromium (network emulated offline, names unresolvable,
every request recorded).
"""

from __future__ import annotations

import base64
import html
import importlib.util
import re
import shutil
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook, new_output
from test_pages import Browser, _chromium, open_offline

REPO = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((REPO / "notebooks").glob("[0-9][0-9]_*.ipynb"))


def _png() -> bytes:
    """A 2 x 2 RGB PNG (the "figure" of the fixture)."""
    import struct
    import zlib

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    rows = b"".join(b"\x00" + bytes([200, 30, 30, 30, 30, 200]) for _ in range(2))
    header = struct.pack(">IIBBBBB", 2, 2, 8, 2, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(rows))
        + chunk(b"IEND", b"")
    )


PNG = _png()


def _site():
    spec = importlib.util.spec_from_file_location("build_site", REPO / "scripts" / "build_site.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules.setdefault("build_site", module)
    spec.loader.exec_module(module)
    return module


def _lecture(number: str, title: str, goal: str, minutes: int) -> nbformat.NotebookNode:
    """A small lecture: header, Colab cell, setup, two sections with a formula, check and solution cells."""
    site = _site()
    nb = new_notebook(
        cells=[
            new_markdown_cell(
                f"# {number} · {title}\n\n**Goals**\n- {goal}\n- A second goal.\n\n"
                f"**Estimated time:** lecture ~{minutes} min; running it takes ~1 s on 2 CPU cores."
            ),
            new_code_cell("x = 21"),
            new_markdown_cell(f"## 1. Squares of {title}\n\n$$\\frac{{a}}{{b}} = x^2$$"),
            new_code_cell("print(x * 2)"),
            new_code_cell("assert x == 21", metadata={"tags": ["check"]}),
            new_markdown_cell("### 1.1 A detail\n\nInline $\\lVert v \\rVert$ here."),
            new_markdown_cell("## 2. Exercise\n\nWrite `double`."),
            new_code_cell("def double(v):\n    return 'SECRET-ANSWER'", metadata={"tags": ["solution"]}),
        ]
    )
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    site.add_colab_cell(nb)
    site.tag_slides(nb)
    return nb


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """Notebooks 01 (executed copy in build/notebooks/, without slide metadata) and 02 (not executed yet)."""
    root = tmp_path_factory.mktemp("course")
    notebooks, build = root / "notebooks", root / "build"
    notebooks.mkdir()
    (build / "notebooks").mkdir(parents=True)
    (build / "figures").mkdir()
    (build / "figures" / "01_alpha_fig.png").write_bytes(PNG)
    first = _lecture("01", "Alpha", "Learn what $x^2$ is.", 10)
    second = _lecture("02", "Beta", "Read a take.", 25)
    nbformat.write(first, notebooks / "01_alpha.ipynb")
    nbformat.write(second, notebooks / "02_beta.ipynb")

    executed = nbformat.from_dict(first)  # as make run leaves it, but written before the slides were tagged
    for n, cell in enumerate(executed.cells):
        cell.metadata.pop("slideshow", None)
        if cell.cell_type == "code":
            cell.execution_count = n
        if cell.source == "print(x * 2)":
            cell.outputs = [
                new_output("stream", name="stdout", text="PRINTED-42\n"),
                new_output("display_data", data={"image/png": base64.b64encode(PNG).decode()}),
            ]
    nbformat.write(executed, build / "notebooks" / "01_alpha.ipynb")

    paths = [notebooks / "01_alpha.ipynb", notebooks / "02_beta.ipynb"]
    summary = _site().build_site(root / "site", build, paths, guide=REPO / "docs" / "teaching.md")
    return root / "site", summary, paths, build


def test_a_failed_run_is_not_reused_and_fails_the_build(tmp_path, monkeypatch, capsys):
    """An executed copy left by a failed ``make run`` (an error output) is run again, not put on the site as it is;
    a notebook that fails now is on the site with its error, and the build exits 1 naming it."""
    monkeypatch.setenv("BEATLITE_BUILD", str(tmp_path / "unused"))  # main() sets these two: restored after
    monkeypatch.setenv("BEATLITE_INTERACTIVE", "off")
    notebooks, build = tmp_path / "notebooks", tmp_path / "build"
    notebooks.mkdir()
    (build / "notebooks").mkdir(parents=True)
    good, bad = _lecture("01", "Alpha", "g", 10), _lecture("02", "Beta", "g", 10)
    next(c for c in bad.cells if c.source == "print(x * 2)").source = "print(x * 2)\n1 / 0"
    nbformat.write(good, notebooks / "01_alpha.ipynb")
    nbformat.write(bad, notebooks / "02_beta.ipynb")
    stale = nbformat.from_dict(good)  # what a make run that failed in this cell left behind
    for cell in stale.cells:
        if cell.cell_type == "code":
            cell.execution_count = 1
        if cell.source == "print(x * 2)":
            cell.outputs = [
                new_output("error", ename="OSError", evalue="flaky", traceback=["OSError: flaky"])
            ]
    nbformat.write(stale, build / "notebooks" / "01_alpha.ipynb")
    assert _site().run_failure(stale) == "cell 4 raised OSError"

    paths = [str(notebooks / "01_alpha.ipynb"), str(notebooks / "02_beta.ipynb")]
    status = _site().main(["--build", str(build), "--out", str(tmp_path / "site"), *paths])
    out = capsys.readouterr()
    assert status == 1, out.out + out.err
    assert "1 notebooks failed: 02_beta" in out.err
    assert "02_beta.ipynb FAILED (cell 4 raised ZeroDivisionError)" in out.out
    assert '["01_alpha", "02_beta"]' in out.out  # both executed now: the failed copy of 01 was not reused
    assert "OSError" not in (tmp_path / "site" / "lectures" / "01_alpha.html").read_text()
    assert "ZeroDivisionError" in (tmp_path / "site" / "lectures" / "02_beta.html").read_text()


def test_a_site_written_into_the_build_folder_keeps_the_other_files(tmp_path):
    """``--out build`` (the site beside make run's outputs) replaces only the site's own files: the executed
    notebooks, caches and a student's work in ``lab/`` stay; a page left by an earlier build goes."""
    notebooks, build = tmp_path / "notebooks", tmp_path / "build"
    notebooks.mkdir()
    (build / "notebooks").mkdir(parents=True)
    (build / "lab").mkdir()
    (build / "lab" / "01_alpha.ipynb").write_text("my work")
    (build / "results.md").write_text("# beatlite results")
    (build / "lectures").mkdir()
    (build / "lectures" / "00_renamed.html").write_text("stale")
    nb = _lecture("01", "Alpha", "g", 10)
    nbformat.write(nb, notebooks / "01_alpha.ipynb")
    for n, cell in enumerate(nb.cells):  # executed: reused, nothing runs
        if cell.cell_type == "code":
            cell.execution_count = n
    nbformat.write(nb, build / "notebooks" / "01_alpha.ipynb")

    summary = _site().build_site(
        build, build, [notebooks / "01_alpha.ipynb"], guide=REPO / "docs" / "teaching.md"
    )
    assert summary["executed"] == [] and (build / "index.html").is_file()
    assert (build / "lab" / "01_alpha.ipynb").read_text() == "my work"
    assert (build / "results.md").is_file() and (build / "notebooks" / "01_alpha.ipynb").is_file()
    assert not (build / "lectures" / "00_renamed.html").exists()
    assert (build / "lectures" / "01_alpha.html").is_file()


def _links(page: Path) -> list[tuple[str, str]]:
    """``(tag, url)`` of every link, image, style sheet and script of a page."""
    text = page.read_text(encoding="utf-8")
    return re.findall(r"<(a|img|link|script|source)\b[^>]*?\s(?:href|src)=[\"']([^\"']*)[\"']", text)


def test_site_reuses_executed_notebooks_and_runs_the_others(built):
    site, summary, _, build = built
    assert summary == {
        "lectures": ["01_alpha", "02_beta"],
        "executed": ["02_beta"],
        "failed": [],
        "colab": False,
    }
    assert "PRINTED-42" in (site / "lectures" / "01_alpha.html").read_text()  # the stored output, not a rerun
    assert (build / "notebooks" / "02_beta.ipynb").is_file()
    ran = nbformat.read(build / "notebooks" / "02_beta.ipynb", as_version=4)
    assert [o.get("text") for c in ran.cells if c.source == "print(x * 2)" for o in c.outputs] == ["42\n"]
    for name in ("index.html", "guide.html", "figures.html", "figures/01_alpha_fig.png"):
        assert (site / name).is_file(), name
    student = nbformat.read(site / "student" / "01_alpha.ipynb", as_version=4)
    assert (
        "SECRET-ANSWER" not in str(student)
        and len(student.cells) == len(_lecture("01", "A", "g", 1).cells) - 1
    )


def test_every_link_of_the_site_resolves_to_a_file(built):
    site = built[0]
    pages = sorted(site.rglob("*.html"))
    assert len(pages) == 3 + 2 + 2  # index, guide, figures; two lecture pages; two slide decks
    checked = 0
    for page in pages:
        for tag, url in _links(page):
            if url.startswith(("#", "data:")) or (tag == "a" and url.startswith("https://")):
                continue  # a web link is followed only when clicked; nothing else may name the web
            assert not re.match(r"^[a-z]+:", url), f"{page.name}: <{tag}> {url} leaves the site"
            target = (page.parent / html.unescape(url).split("#")[0]).resolve()
            assert target.is_file(), f"{page.relative_to(site)}: {url} is missing"
            assert site in target.parents, f"{page.relative_to(site)}: {url} points outside the site"
            checked += 1
    assert checked >= 2 * 5 + 3  # each index row: page, slides, student copy; the slides' reveal.js files


def test_index_is_the_course_map(built):
    index = (built[0] / "index.html").read_text()
    rows = re.findall(
        r"<tr><td><a href='lectures/([^']+)\.html'>([^<]+)</a></td><td>(.*?)</td><td>([^<]*)</td>", index
    )
    assert [(r[0], r[1], r[3]) for r in rows] == [
        ("01_alpha", "01 · Alpha", "10 min"),
        ("02_beta", "02 · Beta", "25 min"),
    ]
    assert "Learn what" in rows[0][2] and "<math" in rows[0][2]  # the goal line, its formula as MathML
    assert "colab.research.google.com" not in index and "make site COLAB_REPO=owner/name" in index
    assert "The executed lecture pages show the exercises' solutions" in index  # a warning before publishing


def test_colab_links_name_the_repository(built, tmp_path):
    site = _site()
    _, _, paths, build = built
    summary = site.build_site(tmp_path / "site", build, paths, repo="someone/beatlite", branch="course")
    assert summary["executed"] == [] and summary["colab"]  # both executed copies are current now
    index = (tmp_path / "site" / "index.html").read_text()
    assert re.findall(r'href="(https://colab[^"]+)"', index) == [
        "https://colab.research.google.com/github/someone/beatlite/blob/course/notebooks/01_alpha.ipynb",
        "https://colab.research.google.com/github/someone/beatlite/blob/course/notebooks/02_beta.ipynb",
    ]
    assert "--set-repo someone/beatlite" not in index  # the placeholder is not another repository


def test_the_repository_comes_from_the_setting_or_a_github_origin(tmp_path):
    site = _site()
    assert site.github_repo("a-b/c.d") == "a-b/c.d"
    with pytest.raises(ValueError, match="owner/name"):
        site.github_repo("https://github.com/a/b")
    subprocess.run(["git", "init", "-q", str(tmp_path)], check=True)
    assert site.github_repo(None, cwd=tmp_path) is None  # no origin
    for url, repo in (
        ("https://github.com/owner/course.git", "owner/course"),
        ("git@github.com:owner/course.git", "owner/course"),
        ("https://gitlab.com/owner/course.git", None),
    ):
        subprocess.run(["git", "-C", str(tmp_path), "remote", "remove", "origin"], capture_output=True)
        subprocess.run(["git", "-C", str(tmp_path), "remote", "add", "origin", url], check=True)
        assert site.github_repo(None, cwd=tmp_path) == repo, url


def test_set_repo_writes_the_colab_cells(tmp_path):
    site = _site()
    path = tmp_path / "01_x.ipynb"
    nbformat.write(_lecture("01", "X", "g", 1), path)
    assert site.notebook_repo(nbformat.read(path, as_version=4)) is None
    assert site.set_repo([path], "me/course") == 1 and site.set_repo([path], "me/course") == 0
    assert site.notebook_repo(nbformat.read(path, as_version=4)) == "me/course"


def test_slides_follow_the_source_slide_metadata(built):
    slides = (built[0] / "slides" / "01_alpha.html").read_text()
    # title, section 1 (+ subslide 1.1), section 2: the executed copy had no metadata, the source's is used
    assert slides.count("<section") == 3 + 4  # 3 slides (columns), holding 1, 2 and 1 (sub)slides
    assert "PRINTED-42" in slides and "SECRET-ANSWER" not in slides and "assert x == 21" not in slides
    assert "google.colab" not in slides  # the Colab cell is skipped
    assert not re.search(r"<(script|link|img)[^>]+(src|href)=[\"']?(https?:)?//", slides)
    assert "<math" in slides and "\\frac" not in slides


def test_tag_slides_rules():
    site = _site()
    nb = _lecture("01", "A", "g", 1)
    kinds = [c.metadata["slideshow"]["slide_type"] for c in nb.cells]
    # header, colab, setup, section, print, check, subsection, section, solution
    assert kinds == ["slide", "skip", "skip", "slide", "-", "skip", "subslide", "slide", "skip"]
    nb.cells[4].metadata["slideshow"]["slide_type"] = "fragment"
    assert site.tag_slides(nb) == 0 and nb.cells[4].metadata["slideshow"]["slide_type"] == "fragment"
    # text after a shown code cell goes below it; after a skipped one it continues the slide
    more = new_notebook(
        cells=[
            new_markdown_cell("# T"),
            new_code_cell("import x"),
            new_markdown_cell("after the skipped setup"),
            new_code_cell("f()"),
            new_markdown_cell("after a shown cell"),
            new_markdown_cell("text after text"),
        ]
    )
    site.tag_slides(more)
    assert [c.metadata["slideshow"]["slide_type"] for c in more.cells] == [
        "slide",
        "skip",
        "-",
        "-",
        "subslide",
        "-",
    ]


def test_split_headings_starts_a_slide_at_every_section_heading():
    """A heading in the middle of a Markdown cell would sit mid-slide under the previous section (and the right
    arrow would skip its section): the cell is split there, ``## `` a slide, ``### `` a subslide."""
    site = _site()
    nb = new_notebook(
        cells=[
            new_markdown_cell("# T\n\n**Goals**\n- g", metadata={"slideshow": {"slide_type": "slide"}}),
            new_markdown_cell(
                "End of 1.\n\n## 2. Two\n\nIntro.\n\n### 2.1 Sub\n\nBody.",
                metadata={"slideshow": {"slide_type": "subslide"}},
            ),
            new_code_cell("x = 1"),
            new_markdown_cell("## Summary\n\n- a\n\n## Exercises\n\nDo them."),
            new_markdown_cell("Shell:\n\n```\n## not a heading\n```\nafter"),
            new_markdown_cell(
                "Answer.\n\n## Hidden", metadata={"tags": ["solution"], "slideshow": {"slide_type": "skip"}}
            ),
        ]
    )
    assert site.split_headings(nb) == 4
    got = [
        (c.source, c.metadata.get("slideshow", {}).get("slide_type"), c.metadata.get("tags"))
        for c in nb.cells
    ]
    assert got == [
        ("# T\n\n**Goals**\n- g", "slide", None),
        ("End of 1.", "subslide", None),
        ("## 2. Two\n\nIntro.", "slide", None),
        ("### 2.1 Sub\n\nBody.", "subslide", None),
        ("x = 1", None, None),
        ("## Summary\n\n- a", None, None),
        ("## Exercises\n\nDo them.", "slide", None),
        ("Shell:\n\n```\n## not a heading\n```\nafter", None, None),
        ("Answer.", "skip", ["solution"]),
        ("## Hidden", "skip", ["solution"]),
    ]
    assert site.split_headings(nb) == 0  # once split, nothing more to do


def _png_of(width: int, height: int) -> str:
    """A white ``width`` x ``height`` RGB PNG, base64 (a figure of that size in pixels)."""
    import struct
    import zlib

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    rows = b"".join(b"\x00" + b"\xff" * (3 * width) for _ in range(height))
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    png = (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(rows))
        + chunk(b"IEND", b"")
    )
    return base64.b64encode(png).decode()


def _tall_lecture() -> nbformat.NotebookNode:
    """Slides as the course's tallest: a section with a long text, a long cell that prints a lot, shows a long
    table and a figure (together several frames high), then a short section that fits."""
    words = "The quick brown fox jumps over the lazy dog while the speaker gestures on every stressed word. "
    table = "| take | FGD | BC |\n|---|---|---|\n" + "".join(
        f"| take_{i} | {i}.5 | 0.{i} |\n" for i in range(60)
    )
    code = "\n".join(f"value_{i} = {i}  # one line of a long cell" for i in range(40))
    cells = [
        new_markdown_cell(
            "# 01 · Tall\n\n**Goals**\n- Fit every slide.", metadata={"slideshow": {"slide_type": "slide"}}
        ),
        new_markdown_cell(
            "## 1. A long section\n\n"
            + "\n\n".join(words * 4 for _ in range(8))
            + "\n\n- "
            + "\n- ".join(words for _ in range(12)),
            metadata={"slideshow": {"slide_type": "slide"}},
        ),
        new_code_cell(code, metadata={"slideshow": {"slide_type": "-"}}, execution_count=1),
        new_markdown_cell("## 2. Short\n\nIt fits.", metadata={"slideshow": {"slide_type": "slide"}}),
        new_code_cell(
            "print('SHORT-OUTPUT')", metadata={"slideshow": {"slide_type": "-"}}, execution_count=2
        ),
    ]
    cells[2].outputs = [
        new_output("stream", name="stdout", text="".join(f"printed line {i}\n" for i in range(50))),
        new_output("display_data", data={"text/markdown": table, "text/plain": "<Markdown>"}),
        new_output("display_data", data={"image/png": _png_of(1000, 900), "text/plain": "<Figure>"}),
    ]
    cells[4].outputs = [new_output("stream", name="stdout", text="SHORT-OUTPUT\n")]
    nb = new_notebook(cells=cells)
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    return nb


def _slides_of(nb) -> list[list]:
    """The cells of each slide (a ``slide`` or ``subslide`` cell starts one; skipped cells left out)."""
    slides: list[list] = []
    for cell in nb.cells:
        kind = cell.metadata.get("slideshow", {}).get("slide_type", "-")
        if kind in ("slide", "subslide") or not slides:
            slides.append([])
        if kind not in ("skip", "notes"):
            slides[-1].append(cell)
    return slides


def test_fit_slides_breaks_a_slide_taller_than_the_frame_below_it():
    """A slide taller than the frame scrolled (119 of the 237 slides of the course decks did): its text, code,
    printed lines, tables and figures are shared out over slides below it, each within the frame, all in order."""
    site = _site()
    nb = _tall_lecture()
    heights = [sum(map(site.cell_height, s)) for s in _slides_of(nb)]
    assert (
        heights[1] > 3 * site.SLIDE_HEIGHT and heights[0] < site.SLIDE_HEIGHT
    )  # section 1 is several frames
    original = nbformat.from_dict(nb)

    added = site.fit_slides(nb)
    slides = _slides_of(nb)
    assert added == len(slides) - 3 > 3
    assert [site.cell_height(c) for c in slides[0]] == [
        site.cell_height(original.cells[0])
    ]  # it fitted: as it was
    assert [c.source for c in slides[-1]] == [original.cells[3].source, original.cells[4].source]
    for cells in slides:
        assert sum(map(site.cell_height, cells)) <= site._SLIDE_BUDGET < site.SLIDE_HEIGHT, [
            c.source[:40] for c in cells
        ]
    kinds = [site._kind(c) for c in nb.cells]
    assert kinds.count("slide") == 3  # what continues a section is below it (a subslide), not a new section
    # nothing lost or repeated: the Markdown, the code, the printed lines, the table rows and the figure
    middle = [c for s in slides[1:-1] for c in s]
    text = "\n\n".join(c.source for c in middle if c.cell_type == "markdown")
    assert text.split() == original.cells[1].source.split()
    shown = [
        c
        for c in middle
        if c.cell_type == "code" and not c.metadata.get("transient", {}).get("remove_source")
    ]
    assert "\n".join(c.source for c in shown) == original.cells[2].source
    outputs = [o for c in middle if c.cell_type == "code" for o in c.outputs]
    printed = "".join(o.text for o in outputs if o.output_type == "stream")
    assert printed == original.cells[2].outputs[0].text
    tables = [o.data["text/markdown"] for o in outputs if "text/markdown" in o.get("data", {})]
    rows = [r for t in tables for r in t.splitlines()[2:]]
    assert len(tables) > 1 and all(t.startswith("| take | FGD | BC |\n|---|---|---|\n") for t in tables)
    assert rows == original.cells[2].outputs[1].data["text/markdown"].splitlines()[2:]
    assert [o for o in outputs if "image/png" in o.get("data", {})] == [original.cells[2].outputs[2]]
    ids = [c.id for c in nb.cells]
    assert (
        len(set(ids)) == len(ids) and ids[2] == f"{original.cells[1].id}-part1"
    )  # nbformat's unique cell ids
    assert site.fit_slides(nb) == 0  # once fitted, nothing more to do


@pytest.mark.parametrize("cell_id", ["a1b2c3d4", "theory-part-2"])
def test_the_parts_of_a_split_cell_get_unique_ids_whatever_its_id(cell_id):
    """A split cell's parts are numbered after its id; an id that itself holds '-part' (a name given by hand) left
    every part with the same id (before: three cells 'theory-part-2'; nbformat then put random ids in the
    slides' HTML and warned 'Non-unique cell id')."""
    site = _site()
    words = "The quick brown fox jumps over the lazy dog while the speaker gestures on every stressed word. "
    cell = new_markdown_cell(
        "## 1. Long\n\n" + "\n\n".join(words * 4 for _ in range(10)),
        metadata={"slideshow": {"slide_type": "slide"}},
    )
    cell.id = cell_id
    nb = new_notebook(cells=[cell])
    assert site.fit_slides(nb) == 2
    assert [c.id for c in nb.cells] == [cell_id, f"{cell_id}-part1", f"{cell_id}-part2"]


def test_fit_slides_leaves_fitted_slides_as_they_are_with_an_output_taller_than_a_slide():
    """An animation player (its frame and buttons) taller than the budget goes below its source with the source
    hidden; fitting again split that cell again, into an empty cell (no source shown, no output: a blank slide)
    and the player, whose copy had the same id (notebooks 05 and 08's decks: one slide more at every call)."""
    site = _site()
    player = f"<div class='animation'><img id='frame' src='data:image/png;base64,{_png_of(1000, 900)}'></div>"
    cells = [
        new_markdown_cell("## 1. Motion", metadata={"slideshow": {"slide_type": "slide"}}),
        new_code_cell("HTML(anim.to_html())", metadata={"slideshow": {"slide_type": "-"}}, execution_count=1),
    ]
    cells[1].outputs = [new_output("display_data", data={"text/html": player, "text/plain": "<HTML>"})]
    nb = new_notebook(cells=cells)
    assert site.cell_height(cells[1]) - site.cell_height(new_code_cell(cells[1].source)) > site._SLIDE_BUDGET
    assert site.fit_slides(nb) == 1  # the player on a slide below its source
    fitted = nbformat.from_dict(nb)
    assert site.fit_slides(nb) == 0 and nb == fitted  # once fitted, nothing more to do
    assert [(site._kind(c), bool(c.get("outputs"))) for c in nb.cells] == [
        ("slide", False),
        ("-", False),
        ("subslide", True),
    ]


def test_a_player_is_estimated_as_high_as_its_first_frame_and_its_controls():
    """matplotlib's player (``to_jshtml``, as bl.viz's animations write it) embeds each frame as base64 lines that
    end in a backslash: the estimate stopped at the first line end, read no frame, and took every player to be a
    600-px figure high (notebook 05's player, 768 x 416 px: its cell counted 792 px high instead of 608)."""
    import base64
    import io

    from matplotlib.animation import FuncAnimation
    from matplotlib.figure import Figure
    from PIL import Image

    site = _site()
    fig = Figure(figsize=(4, 2), dpi=80)
    (line,) = fig.add_subplot().plot([0, 1], [0, 1])
    page = FuncAnimation(fig, lambda i: (line,), frames=2).to_jshtml()
    first = page.split("base64,", 1)[1].split('"', 1)[0]
    assert "\\\n" in first  # (its base64 lines, continued)
    with Image.open(io.BytesIO(base64.b64decode(first.replace("\\\n", "")))) as image:
        width, height = image.size
    assert width <= site._OUTPUT_WIDTH and height < site._IMAGE_MAX_HEIGHT  # shown at its own size
    output = new_output("display_data", data={"text/html": page, "text/plain": "<Animation>"})
    assert site.output_height(output) == site._PLAYER + height


def test_the_slides_figure_box_is_the_one_save_figure_measures_text_in(monkeypatch):
    """check.SLIDE_FIGURE_BOX, the box save_figure measures a figure's text in as a slide shows it, is the slides'
    own: the CSS max-height of a figure and the output width fit_slides estimates with follow it (before: 1089 and
    600 written again in build_site.py, so a change to one side left the check measuring another slide)."""
    from beatlite.viz import check

    monkeypatch.setattr(check, "SLIDE_FIGURE_BOX", (900, 500))
    site = _site()  # (executed afresh: its constants from the box above)
    assert (site._OUTPUT_WIDTH, site._IMAGE_MAX_HEIGHT) == (900, 500)
    assert ".reveal .jp-OutputArea-output img { max-height: 500px; width: auto; }" in site._SLIDES_CSS
    assert site._shown_image_height((1800, 900)) == 450  # 900 px wide: half its size


def test_slides_fit_the_frame_in_chromium(tmp_path):
    """Measured in the browser at the deck's size: no slide of a deck with tall sections scrolls, and reveal.js
    counts the slides fit_slides made."""
    _chromium()
    site = _site()
    slides = tmp_path / "slides"
    slides.mkdir()
    reveal = site.reveal_dir()
    for rel in site._REVEAL_FILES:
        src, dst = reveal / rel, tmp_path / "assets" / "reveal" / rel
        dst.parent.mkdir(parents=True, exist_ok=True)
        (shutil.copytree if src.is_dir() else shutil.copy2)(src, dst)
    nb = _tall_lecture()
    (slides / "tall.html").write_text(site.export_slides(nb), encoding="utf-8")
    browser = Browser(tmp_path / "profile")
    try:
        browser.page(
            "Emulation.setDeviceMetricsOverride",
            width=1280,  # the deck's frame: reveal.js shows it at scale 1
            height=800,
            deviceScaleFactor=1,
            mobile=False,
        )
        open_offline(browser, slides / "tall.html")
        browser.evaluate("new Promise(r => Reveal.isReady() ? r() : Reveal.on('ready', r))")
        sizes = browser.evaluate(SLIDE_SIZES)
    finally:
        browser.close()
    tall = [s for s in sizes if s["scroll"] > s["client"]]
    assert not tall, f"slides taller than the 1280 x 800 frame: {tall}"
    assert {s["client"] for s in sizes} == {800}
    site.fit_slides(nb)
    assert len(sizes) == len(_slides_of(nb))


# In the browser: each slide shown in turn, its height and the height of what it holds (CSS pixels).
SLIDE_SIZES = """(async () => { const out = [];
  for (const s of Reveal.getSlides()) { const i = Reveal.getIndices(s); Reveal.slide(i.h, i.v);
    await new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)));
    out.push({h: i.h, v: i.v || 0, client: s.clientHeight, scroll: s.scrollHeight, text: s.innerText.slice(0, 60)}); }
  return out; })()"""


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_every_section_heading_starts_a_slide(path):
    """Each ``## `` section of a notebook is a slide of its own (the right arrow reaches it) and each ``### ``
    subsection a subslide: a heading is always the first line of its Markdown cell (``--tag-slides`` splits)."""
    nb = nbformat.read(path, as_version=4)
    kinds = {"## ": "slide", "### ": "subslide"}
    wrong = []
    for i, cell in enumerate(nb.cells):
        if cell.cell_type != "markdown":
            continue
        fenced = False
        for n, line in enumerate(cell.source.lstrip("\n").splitlines()):
            fenced ^= bool(re.match(r" {0,3}(```|~~~)", line))
            level = next((k for k in kinds if line.startswith(k)), None)
            if level and not fenced and n > 0:
                wrong.append(f"cell {i}: {line[:50]!r} in the middle of the cell")
            elif level and n == 0 and cell.metadata.get("slideshow", {}).get("slide_type") != kinds[level]:
                wrong.append(f"cell {i}: {line[:50]!r} is not a {kinds[level]}")
    assert not wrong, f"run `python scripts/build_site.py --tag-slides`: {wrong}"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_slide_metadata_is_valid(path):
    """Every cell has a slide type RISE and nbconvert know; a title slide; setup, checks and answers skipped."""
    nb = nbformat.read(path, as_version=4)
    kinds = [c.metadata.get("slideshow", {}).get("slide_type") for c in nb.cells]
    assert set(kinds) <= set(_site().SLIDE_TYPES), f"unknown or missing slide types: {set(kinds)}"
    assert kinds[0] == "slide" and nb.cells[0].source.startswith("# "), "no title slide"
    assert kinds.count("slide") >= 3
    for cell, kind in zip(nb.cells, kinds):
        if {"colab", "check", "solution"} & set(cell.metadata.get("tags", [])):
            assert kind == "skip", cell.source[:60]


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_starts_with_the_colab_cell(path):
    nb = nbformat.read(path, as_version=4)
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert "colab" in code[0].metadata.get("tags", []), "the first code cell must be the Colab cell"
    assert [c for c in code if "colab" in c.metadata.get("tags", [])] == [code[0]]
    expected = _site().COLAB_CELL
    assert re.sub(r'^REPO = ".*"$', 'REPO = "OWNER/NAME"', code[0].source, flags=re.M) == expected


def _run_colab_cell(
    monkeypatch, on_colab: bool, repo: str = "me/course"
) -> tuple[list[list[str]], list[str]]:
    calls, dirs = [], []
    monkeypatch.setattr(subprocess, "run", lambda cmd, **kw: calls.append([str(a) for a in cmd]))
    monkeypatch.setattr("os.chdir", dirs.append)
    monkeypatch.setattr("os.path.isdir", lambda p: False)
    monkeypatch.setattr(sys, "path", list(sys.path))
    monkeypatch.delenv("BEATLITE_PYVISTA", raising=False)
    if on_colab:
        monkeypatch.setitem(sys.modules, "google.colab", type(sys)("google.colab"))
    else:
        monkeypatch.delitem(sys.modules, "google.colab", raising=False)
    source = _site().COLAB_CELL.replace('REPO = "OWNER/NAME"', f'REPO = "{repo}"')
    exec(compile(source, "colab-cell", "exec"), {})
    return calls, dirs


def test_colab_cell_does_nothing_outside_colab(monkeypatch):
    calls, dirs = _run_colab_cell(monkeypatch, on_colab=False)
    assert calls == [] and dirs == []


def test_colab_cell_without_a_repository_says_so_before_cloning(monkeypatch):
    calls = []
    monkeypatch.setattr(subprocess, "run", lambda cmd, **kw: calls.append(cmd))
    monkeypatch.setitem(sys.modules, "google.colab", type(sys)("google.colab"))
    with pytest.raises(RuntimeError, match="set REPO above"):
        exec(compile(_site().COLAB_CELL, "colab-cell", "exec"), {})
    assert calls == []  # nothing cloned or installed


def test_colab_cell_installs_beatlite_without_touching_torch(monkeypatch):
    calls, dirs = _run_colab_cell(monkeypatch, on_colab=True)
    assert calls[0][:2] == ["git", "clone"] and "https://github.com/me/course" in calls[0]
    installs = [c for c in calls if c[1:4] == ["-m", "pip", "install"]]
    assert len(installs) == 2 and "--no-deps" in installs[0] and "/content/beatlite" in installs[0]
    assert not [c for c in calls if any("torch" in a for a in c)], "the cell must not install torch"
    assert dirs == ["/content/beatlite/notebooks"] and sys.path[0] == "/content/beatlite"


# In the browser: Reveal ready, which slide is shown, what it shows.
SLIDE_STATE = """(() => ({ready: Reveal.isReady(), total: Reveal.getTotalSlides(), index: Reveal.getIndices(),
  text: Reveal.getCurrentSlide().innerText, counter: (document.querySelector('.slide-number') || {}).innerText,
  maths: [...Reveal.getCurrentSlide().querySelectorAll('math')].filter(m => m.getBoundingClientRect().width > 0).length}))()"""


def _key(browser: Browser, key: str, code: int) -> None:
    for kind in ("keyDown", "keyUp"):
        browser.page("Input.dispatchKeyEvent", type=kind, key=key, code=key, windowsVirtualKeyCode=code)


def test_site_and_slides_open_offline_in_chromium(built, tmp_path):
    _chromium()
    site = built[0]
    urls, states, checks = [], [], {}
    for name in (
        "index.html",
        "lectures/01_alpha.html",
        "guide.html",
        "figures.html",
        "slides/01_alpha.html",
    ):
        browser = Browser(tmp_path / name.replace("/", "_"))
        try:
            open_offline(browser, site / name)
            checks[name] = browser.evaluate(
                "({title: document.title, images: [...document.images].map(i => i.naturalWidth),"
                " bodyText: document.body.innerText.length})"
            )
            if name.startswith("slides/"):
                browser.evaluate("new Promise(r => Reveal.isReady() ? r() : Reveal.on('ready', r))")
                states.append(browser.evaluate(SLIDE_STATE))
                _key(browser, "ArrowRight", 39)
                states.append(browser.evaluate(SLIDE_STATE))
                _key(browser, "ArrowDown", 40)
                states.append(browser.evaluate(SLIDE_STATE))
            urls += browser.requested_urls()
        finally:
            browser.close()
    left = [u for u in urls if not u.startswith(("file:", "data:", "about:", "blob:"))]
    assert left == [], f"requests left the machine: {left}"
    assert any(u.endswith("/assets/reveal/dist/reveal.js") for u in urls)  # the local copy was loaded
    assert checks["index.html"]["title"] == "beatlite course"
    assert all(w > 0 for c in checks.values() for w in c["images"]), checks  # every image decoded
    assert checks["figures.html"]["images"] == [2]
    first, second, third = states
    assert first["ready"] and first["total"] == 4 and first["index"]["h"] == 0
    assert first["text"].strip().lower().startswith("01 · alpha") and first["counter"] == "1 / 4"
    assert (
        second["index"]["h"] == 1
        and "squares of alpha" in second["text"].lower()
        and "PRINTED-42" in second["text"]
    )
    assert second["maths"] == 1 and second["counter"] == "2 / 4"
    assert (third["index"]["h"], third["index"]["v"]) == (1, 1) and "a detail" in third["text"].lower()
