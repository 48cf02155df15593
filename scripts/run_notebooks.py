"""The main job: execute every notebook in ``notebooks/`` in order and write ``build/``.

Writes, for each ``notebooks/NN_name.ipynb``:

- ``build/notebooks/NN_name.ipynb`` (executed, with outputs) and ``.html``: a page that works offline
  (formulas rendered to MathML at export time, no script, font or style sheet from the web; see
  :func:`export_html`);
- the tables the notebook saved with :func:`beatlite.report.save_table` (``build/tables/``);
- ``build/student/NN_name.ipynb``: the student copy, without the cells tagged ``solution``;
- ``build/instructor/``: the answer sheet of the exercises, from the ``solution`` cells
  (``scripts/instructor_sheet.py``);
- ``build/results.md``: per-notebook status and wall time, then every table (paths as :func:`local_paths` writes
  them: no folder of this machine).

Exit status is non-zero when any notebook fails (the others still run). The notebooks run with
``BEATLITE_INTERACTIVE=off`` (text progress bars, static 3D images: see :func:`beatlite.notebook.interactive`)
and each cell's stream output is merged into one block with carriage returns applied.
"""

from __future__ import annotations

import argparse
import copy
import os
import re
import resource
import sys
import time
from pathlib import Path
from urllib.parse import quote

REPO = Path(__file__).resolve().parents[1]

# The exported page extends nbconvert's "lab" template without its web scripts: require.js and the widget
# manager (no widget state is stored), MathJax (formulas are MathML already) and mermaid (no diagrams).
_OFFLINE_TEMPLATE = """{%- extends 'index.html.j2' -%}
{%- block html_head_js_requirejs -%}{%- endblock html_head_js_requirejs -%}
{%- block jupyter_widgets -%}{%- endblock jupyter_widgets -%}
{%- block html_head_js_mathjax -%}{%- endblock html_head_js_mathjax -%}
{%- block html_head_js_mermaidjs -%}{%- endblock html_head_js_mermaidjs -%}
{%- block extra_css -%}<style type="text/css">{{ resources.offline_css }}</style>{%- endblock extra_css -%}
"""

# matplotlib's animation player (``to_jshtml``) links Font Awesome 4 from a CDN for its nine button icons;
# the page drops that link and draws the icons as inline SVG (16 x 16 paths) instead.
_ICONS = {
    "play": "M4 2l10 6-10 6z",
    "pause": "M3 2h4v12H3zM9 2h4v12H9z",
    "step-forward": "M2 2l9 6-9 6zM11 2h3v12h-3z",
    "step-backward": "M14 2L5 8l9 6zM2 2h3v12H2z",
    "fast-forward": "M1 2l6 6-6 6zM7 2l6 6-6 6zM13 2h2v12h-2z",
    "fast-backward": "M15 2L9 8l6 6zM9 2L3 8l6 6zM1 2h2v12H1z",
    "minus": "M2 7h12v2H2z",
    "plus": "M7 2h2v5h5v2H9v5H7V9H2V7h5z",
}
_FONT_AWESOME_LINK = re.compile(r"<link[^>]*font-awesome[^>]*>", re.IGNORECASE)


def _offline_css() -> str:
    """Style sheet of the offline page: MathML fonts and the animation player's icons."""
    rules = [
        'math { font-family: "Latin Modern Math", "STIX Two Math", "Cambria Math", "DejaVu Math TeX Gyre", math; font-size: 1.1em; }',
        'math[display="block"] { margin: 0.5em 0; }',
        ".anim-buttons .fa { display: inline-block; width: 1em; height: 1em; vertical-align: -0.125em; "
        "background: no-repeat center / contain; }",
        ".anim-buttons .fa-flip-horizontal { transform: scaleX(-1); }",
    ]
    for name, path in _ICONS.items():
        svg = f"<svg xmlns='http://www.w3.org/2000/svg' viewBox='0 0 16 16' fill='#333'><path d='{path}'/></svg>"
        rules.append(
            f'.anim-buttons .fa-{name} {{ background-image: url("data:image/svg+xml,{quote(svg)}"); }}'
        )
    return "\n".join(rules)


# Formulas are taken out of the Markdown before it is parsed, as JupyterLab does, so that Markdown syntax inside
# them (a line starting with "+ ", "_" pairs) cannot break them; code spans and fenced blocks keep their "$".
_CODE = re.compile(r"^ {0,3}(```|~~~).*?^ {0,3}\1[ \t]*$|(`+)(?!`).+?(?<!`)\2(?!`)", re.M | re.S)
_MATH = re.compile(
    r"(?<!\\)\$\$(?P<display>.+?)(?<!\\)\$\$"
    r"|(?P<env>\\begin\{(?P<name>[a-z]+\*?)\}.*?\\end\{(?P=name)\})"
    r"|(?<![\\$])\$(?P<inline>[^$]+?)(?<![\\$])\$",
    re.S,
)
_PLAIN_BARS = re.compile(r"<mo>(&#x0007C;|&#x02016;)</mo>")
# latex2mathml writes `\big)^2` as <msup><mo minsize=.. maxsize=..>)</mo>...: Chromium then draws that ")" small and
# low, unlike its "(" (an operator as a script base is stretched differently); in an <mrow> it matches its pair.
_SIZED_SCRIPT_BASE = re.compile(r"<(msup|msub|msubsup)><mo( [^>]*minsize=[^>]*)>(.*?)</mo>")


def markdown_to_html(source: str, **renderer_options) -> str:
    """Markdown to HTML with every formula written as MathML (browsers render it natively, no script).

    ``$$...$$`` and ``\\begin{env}...\\end{env}`` become display formulas, ``$...$`` inline ones; a
    formula never spans a blank line, and ``$`` inside code stays as it is. Raises ``ValueError`` naming
    a formula that ``latex2mathml`` cannot convert or that uses a command it does not know.
    """
    from latex2mathml.converter import convert
    from nbconvert.filters.markdown_mistune import IPythonRenderer, MarkdownWithMath

    codes: list[str] = []
    maths: list[str] = []

    def keep_code(m: re.Match) -> str:
        codes.append(m[0])
        return f"@@code{len(codes) - 1}@@"

    def take_math(m: re.Match) -> str:
        if re.search(r"\n[ \t]*\n", m[0]):  # a paragraph break: not a formula
            return m[0]
        tex, display = (
            (m["inline"], "inline") if m["inline"] is not None else (m["display"] or m["env"], "block")
        )
        try:
            mathml = convert(tex, display=display)
        except Exception as exc:
            raise ValueError(f"cannot convert the formula {m[0]!r} to MathML: {exc!r}") from exc
        if unknown := re.findall(r">(\\[A-Za-z]+)<", mathml):  # latex2mathml prints commands it does not know
            raise ValueError(f"cannot convert the formula {m[0]!r} to MathML: unknown {', '.join(unknown)}")
        mathml = _SIZED_SCRIPT_BASE.sub(r"<\1><mrow><mo\2>\3</mo></mrow>", mathml)  # \big)^2 like \big(
        # latex2mathml leaves \lvert, \rvert, \lVert, \rVert stretchy; in TeX only \left/\right stretch
        maths.append(_PLAIN_BARS.sub(r'<mo stretchy="false">\1</mo>', mathml))
        return f"@@math{len(maths) - 1}@@"

    text = _MATH.sub(take_math, _CODE.sub(keep_code, source))
    text = re.sub(r"@@code(\d+)@@", lambda m: codes[int(m[1])], text)
    html = MarkdownWithMath(renderer=IPythonRenderer(escape=False, **renderer_options)).render(text)
    return re.sub(r"@@math(\d+)@@", lambda m: maths[int(m[1])], html)


def _offline_exporter():
    """nbconvert's ``HTMLExporter`` with :func:`markdown_to_html` and the offline template."""
    from jinja2 import DictLoader, pass_context
    from nbconvert import HTMLExporter

    class OfflineHTMLExporter(HTMLExporter):
        @pass_context
        def markdown2html(self, context, source):
            return markdown_to_html(
                source,
                attachments=context.get("cell", {}).get("attachments", {}),
                anchor_link_text=self.anchor_link_text,
                path=context.get("resources", {}).get("metadata", {}).get("path", ""),
            )

    return OfflineHTMLExporter(
        extra_loaders=[DictLoader({"beatlite_offline.html.j2": _OFFLINE_TEMPLATE})],
        template_file="beatlite_offline.html.j2",
    )


def export_html(nb) -> str:
    """The HTML page of an executed notebook, complete offline.

    Formulas in Markdown cells and Markdown outputs become MathML at export time (:func:`markdown_to_html`),
    so no MathJax is loaded; the page has no ``<script src>``, web font or remote style sheet: the animation
    player's Font Awesome link is dropped and its icons are inline SVG. Widget state is not embedded (the
    notebooks run with ``BEATLITE_INTERACTIVE=off``, without widgets).
    """
    body, _ = _offline_exporter().from_notebook_node(
        offline_notebook(nb), resources={"offline_css": _offline_css()}
    )
    return body


def offline_notebook(nb):
    """A copy of ``nb`` without web references in its outputs: the animation player's Font Awesome link dropped
    (the offline style sheet draws its icons) and no widget state; and without this machine's folders
    (:func:`local_paths`: the page is published on the course site)."""
    nb = copy.deepcopy(nb)
    for cell in nb.cells:
        for output in cell.get("outputs", []):
            html = output.get("data", {}).get("text/html")
            if isinstance(html, str | list):
                text = "".join(html) if isinstance(html, list) else html
                output["data"]["text/html"] = _FONT_AWESOME_LINK.sub("", text)
            for key, value in [("text", output.get("text")), ("evalue", output.get("evalue"))]:
                if isinstance(value, str | list):
                    output[key] = local_paths("".join(value) if isinstance(value, list) else value)
            if isinstance(output.get("traceback"), list):
                output["traceback"] = [local_paths(line) for line in output["traceback"]]
            for mime, value in output.get("data", {}).items():
                if mime.startswith("text/") and isinstance(value, str | list):
                    output["data"][mime] = local_paths("".join(value) if isinstance(value, list) else value)
    nb.metadata.pop("widgets", None)
    return nb


_BASE64 = re.compile(r"data:[\w/+.-]+;base64,(?:[A-Za-z0-9+/=]|\\\r?\n)*")  # (lines may end in "\")


def local_paths(text: str) -> str:
    """``text`` without this machine's folders: the repository root's path left out of the paths below it
    (``/home/alice/beatlite/build/tables/x.md`` -> ``build/tables/x.md``, the root itself ``.``) and the home
    folder written ``~`` (a data folder outside the repository: ``~/beat``), so a published page names no user.
    Base64 data (``data:image/png;base64,...``: the animation player's frames) is left as it is: its letters
    and slashes can spell a short home folder such as ``/root/`` by chance."""
    parts, end = [], 0
    for match in _BASE64.finditer(text):
        parts += [_local_paths(text[end : match.start()]), match.group()]
        end = match.end()
    return "".join([*parts, _local_paths(text[end:])])


def _local_paths(text: str) -> str:
    for root, short in ((REPO, ""), (Path.home(), "~")):
        if str(root) in ("", "/", "."):
            continue
        for form in dict.fromkeys((str(root), os.path.abspath(root))):
            text = re.sub(
                re.escape(form) + r"(/|(?![\w-]|\.\w))",
                lambda m, short=short: (short + "/" if short else "") if m.group(1) else (short or "."),
                text,
            )
    return text


_ANSI = re.compile(r"\x1b\[[0-9;]*m")


def execute(path: Path, out_dir: Path, timeout: int) -> tuple[bool, float, str]:
    """Execute one notebook in its own folder; save the executed copy and its HTML."""
    import nbformat
    from nbclient.exceptions import CellTimeoutError, DeadKernelError
    from nbconvert.preprocessors import CellExecutionError, ExecutePreprocessor

    nb = nbformat.read(path, as_version=4)
    ep = ExecutePreprocessor(
        timeout=timeout, kernel_name="python3", coalesce_streams=True, store_widget_state=False
    )
    start = time.perf_counter()
    ok, message = True, ""
    try:
        ep.preprocess(nb, {"metadata": {"path": str(path.parent)}})
    except (
        CellExecutionError,
        CellTimeoutError,
        DeadKernelError,
    ) as exc:  # a dead kernel fails this notebook only
        ok, message = False, str(exc).strip().splitlines()[-1] if str(exc).strip() else repr(exc)
        message = _ANSI.sub("", message)  # the traceback's colours: results.md is plain Markdown
    seconds = time.perf_counter() - start
    out_dir.mkdir(parents=True, exist_ok=True)
    nbformat.write(nb, out_dir / path.name)
    (out_dir / path.with_suffix(".html").name).write_text(export_html(nb), encoding="utf-8")
    return ok, seconds, message


def write_student_copy(path: Path, out_dir: Path) -> None:
    """Write ``path`` without its ``solution``-tagged cells (the exercise stubs stay)."""
    import nbformat

    nb = nbformat.read(path, as_version=4)
    nb.cells = [c for c in nb.cells if "solution" not in c.get("metadata", {}).get("tags", [])]
    out_dir.mkdir(parents=True, exist_ok=True)
    nbformat.write(nb, out_dir / path.name)


def _instructor_sheet():
    """``scripts/instructor_sheet.py`` as a module (the scripts folder is not a package)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "instructor_sheet", Path(__file__).with_name("instructor_sheet.py")
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules.setdefault("instructor_sheet", module)  # dataclasses look their module up there
    spec.loader.exec_module(module)
    return sys.modules["instructor_sheet"]


EPOCH_TIME = re.compile(r"([\d.]+) s per (?:\w+\s+)?epoch")


def printed_epoch_seconds(path: Path) -> list[float]:
    """The seconds per epoch an executed notebook printed (``... 3.3 s per epoch ...``: the cells that train
    live in ``full`` mode print what they measured), in cell order."""
    import nbformat

    nb = nbformat.read(path, as_version=4)
    text = "".join(
        o.get("text", "") for c in nb.cells for o in c.get("outputs", []) if o.get("output_type") == "stream"
    )
    return [float(x) for x in EPOCH_TIME.findall(text)]


def write_record(path: Path, timings: list[dict], total: float, about: dict) -> None:
    """The run's timings as JSON (``docs/teaching.md``'s table is checked against the shipped one): each
    notebook's wall seconds, its kernel's user-CPU seconds and the seconds per epoch it printed, the whole run's wall seconds (exports
    included), the largest resident memory of one kernel, the settings, and ``about``: the command, revision and
    machine as :func:`beatlite.paths.record_about` described them before the run (``threads`` None: this process
    trains nothing; the kernels' threads are ``BEATLITE_THREADS``, in the settings)."""
    from beatlite.io.atomic import write_json

    peak = (
        resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
        * (1 if sys.platform == "darwin" else 1024)
        / 2**30
    )
    settings = {k: os.environ.get(k) for k in ("BEATLITE_MODE", "BEATLITE_THREADS", "BEATLITE_DATA")}
    write_json(path, {**about, "settings": settings,
                      "total_wall_seconds": total, "largest_kernel_gib": peak, "rows": timings})  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--out", type=Path, default=REPO / "build", help="output folder (default build/)")
    parser.add_argument("--timeout", type=int, default=900, help="per-cell timeout in seconds")
    parser.add_argument(
        "--record", type=Path, help="also write each notebook's wall and kernel CPU seconds here (JSON)"
    )
    parser.add_argument("notebooks", nargs="*", type=Path, help="notebooks to run (default: all, in order)")
    args = parser.parse_args(argv)

    out = args.out.resolve()
    os.environ["BEATLITE_BUILD"] = str(out)
    os.environ["BEATLITE_INTERACTIVE"] = "off"  # text bars and static 3D images in the saved pages
    paths = args.notebooks or sorted((REPO / "notebooks").glob("[0-9][0-9]_*.ipynb"))
    if not paths:
        print("run_notebooks: no notebooks found in notebooks/", file=sys.stderr)
        return 1
    (out / "tables").mkdir(parents=True, exist_ok=True)
    for stale in (out / "tables").glob("*.md"):
        stale.unlink()

    rows, failed, timings = [], 0, []
    from beatlite.paths import record_about

    about = record_about(threads=None) if args.record else {}
    total = time.perf_counter()
    for path in paths:
        print(f"[run] {path.name} ...", flush=True)
        kernels = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime  # (its kernel is reaped on return)
        ok, seconds, message = execute(path.resolve(), out / "notebooks", args.timeout)
        kernels = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - kernels
        write_student_copy(path, out / "student")
        failed += not ok
        rows.append((path.stem, ok, seconds, message))
        if args.record:  # (reads the executed notebook again)
            timings.append({"notebook": path.stem, "ok": ok, "wall_seconds": seconds, "kernel_user_seconds": kernels,
                            "printed_epoch_seconds": printed_epoch_seconds(out / "notebooks" / path.name)})  # fmt: skip
        print(f"[run] {path.name}: {'ok' if ok else 'FAILED'} in {seconds:.1f} s {message}", flush=True)
    total = time.perf_counter() - total
    _instructor_sheet().write_sheets(out / "instructor", [p.resolve() for p in paths])

    lines = [
        "# beatlite results",
        "",
        f"Data: `{os.environ.get('BEATLITE_DATA', 'data_samples/')}`; mode: "
        f"`{os.environ.get('BEATLITE_MODE', 'lecture')}`; threads: `{os.environ.get('BEATLITE_THREADS', '1')}`.",
        "",
        "| notebook | status | wall time (s) |",
        "|---|---|---:|",
    ]
    lines += [
        f"| [{s}](notebooks/{s}.html) | {'ok' if ok else 'FAILED: ' + m} | {t:.1f} |" for s, ok, t, m in rows
    ]
    lines += [f"| **total** | {len(rows) - failed}/{len(rows)} ok | {total:.1f} |", ""]
    for table in sorted((out / "tables").glob("*.md")):
        lines += [table.read_text(encoding="utf-8").rstrip(), ""]
    text = local_paths("\n".join(lines))  # shared: no folder of this machine
    (out / "results.md").write_text(text, encoding="utf-8")
    if args.record:
        write_record(args.record, timings, total, about)
    print(f"[run] wrote {out / 'results.md'} ({len(rows) - failed}/{len(rows)} notebooks ok, {total:.0f} s)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
