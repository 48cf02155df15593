"""The exported notebook pages work offline: formulas typeset, animation player drawn, no request made.

The pages are written by ``scripts/run_notebooks.py`` (:func:`export_html`). The browser test opens one in
headless Chromium (Debian package ``chromium``, installed by ``scripts/system_deps.sh``), driven through its
DevTools protocol over a pipe (``--remote-debugging-pipe``: no extra Python package), with the network
emulated offline and every request the page makes recorded.
"""

from __future__ import annotations

import base64
import importlib.util
import json
import os
import re
import select
import shutil
import subprocess
import sys
import time
from pathlib import Path

import nbformat
import pytest
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook, new_output

REPO = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((REPO / "notebooks").glob("[0-9][0-9]_*.ipynb"))
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",  # needed as root and in most containers; the browser opens only our own file
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-extensions",
    "--host-resolver-rules=MAP * ~NOTFOUND",  # no name resolves: nothing can leave even if tried
    "--window-size=1200,900",
    "--remote-debugging-pipe",
]


def _runner():
    spec = importlib.util.spec_from_file_location("run_notebooks", REPO / "scripts" / "run_notebooks.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _chromium() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        if path := shutil.which(name):
            return path
    pytest.skip("Chromium not installed: run `sudo scripts/system_deps.sh` (Debian package chromium)")


class Browser:
    """Headless Chromium driven through the DevTools protocol on fds 3 (commands) and 4 (replies)."""

    def __init__(self, profile: Path) -> None:
        cmd_r, self._cmd_w = os.pipe()
        self._out_r, out_w = os.pipe()
        # A Python trampoline puts the pipe ends on fds 3 and 4, where Chromium expects them.
        script = "import os, sys; os.dup2(int(sys.argv[1]), 3); os.dup2(int(sys.argv[2]), 4); os.execv(sys.argv[3], sys.argv[3:])"
        args = [_chromium(), *CHROMIUM_FLAGS, f"--user-data-dir={profile}", "about:blank"]
        self.proc = subprocess.Popen(
            [sys.executable, "-c", script, str(cmd_r), str(out_w), *args],
            pass_fds=(cmd_r, out_w),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        os.close(cmd_r)
        os.close(out_w)
        self._buffer, self._next_id, self.events = b"", 0, []
        target = self.send("Target.createTarget", url="about:blank")["targetId"]
        self.session = self.send("Target.attachToTarget", targetId=target, flatten=True)["sessionId"]

    def _read(self, timeout: float = 60.0) -> dict:
        while b"\0" not in self._buffer:
            if not select.select([self._out_r], [], [], timeout)[0]:
                raise TimeoutError(f"Chromium sent nothing for {timeout} s")
            chunk = os.read(self._out_r, 1 << 20)
            if not chunk:
                raise RuntimeError("Chromium closed the DevTools pipe")
            self._buffer += chunk
        message, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(message)

    def send(self, method: str, session: str | None = None, **params) -> dict:
        self._next_id += 1
        message = {"id": self._next_id, "method": method, "params": params}
        if session:
            message["sessionId"] = session
        os.write(self._cmd_w, json.dumps(message).encode() + b"\0")
        while True:
            reply = self._read()
            if reply.get("id") == self._next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply["result"]
            self.events.append(reply)

    def page(self, method: str, **params) -> dict:
        return self.send(method, self.session, **params)

    def wait_for(self, event: str, timeout: float = 30.0) -> None:
        deadline = time.monotonic() + timeout
        while not any(e.get("method") == event for e in self.events):
            if time.monotonic() > deadline:
                raise TimeoutError(f"no {event} within {timeout} s")
            self.events.append(self._read())

    def evaluate(self, expression: str):
        reply = self.page("Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in reply:
            raise RuntimeError(reply["exceptionDetails"])
        return reply["result"].get("value")

    def requested_urls(self) -> list[str]:
        return [
            e["params"]["request"]["url"]
            for e in self.events
            if e.get("method") == "Network.requestWillBeSent"
        ]

    def close(self) -> None:
        try:
            self.send("Browser.close")
        except (RuntimeError, OSError):
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        os.close(self._cmd_w)
        os.close(self._out_r)


def open_offline(browser: Browser, page: Path) -> None:
    """Load ``page`` with the network emulated offline and requests recorded; wait for its scripts."""
    browser.page("Network.enable")
    try:  # on top of --host-resolver-rules; the command may leave the protocol one day
        browser.page(
            "Network.emulateNetworkConditions",
            offline=True,
            latency=0,
            downloadThroughput=-1,
            uploadThroughput=-1,
        )
    except RuntimeError:
        pass
    browser.page("Page.enable")
    browser.page("Page.navigate", url=page.resolve().as_uri())
    browser.wait_for("Page.loadEventFired")
    # the player's inline script sets its first frame after loading: wait (at most 20 s) until every image is decoded
    browser.evaluate(
        "Promise.race([new Promise(r => setTimeout(r, 20000)), (async () => { while ([...document.images].some("
        "i => !(i.complete && i.naturalWidth > 0))) await new Promise(r => setTimeout(r, 50)); })()])"
    )


# Measured in the browser: every <math> laid out with a size, fractions stacked (numerator above the
# denominator), no "$" left in the rendered Markdown, and the player's icons and first frame drawn.
PAGE_REPORT = """(() => {
  const maths = [...document.querySelectorAll('math')];
  const sized = maths.filter(m => { const r = m.getBoundingClientRect(); return r.width > 0 && r.height > 0; });
  const fracs = [...document.querySelectorAll('mfrac')].map(f => {
    const [num, den] = [...f.children].map(c => c.getBoundingClientRect());
    return num.bottom <= den.top + 1;
  });
  const text = [...document.querySelectorAll('.jp-MarkdownOutput')].map(d => {
    const c = d.cloneNode(true); c.querySelectorAll('code, pre, math').forEach(e => e.remove());
    return c.textContent; }).join(' ');
  const icons = [...document.querySelectorAll('.anim-buttons i.fa')].map(i => ({
    width: i.getBoundingClientRect().width, image: getComputedStyle(i).backgroundImage.slice(0, 20)}));
  const frame = document.querySelector('.animation img');
  return {maths: maths.length, sized: sized.length, fracs, dollars: (text.match(/\\$/g) || []).length,
          icons, frame: frame ? frame.naturalWidth : -1};
})()"""


def _animation_html() -> str:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation

    fig, ax = plt.subplots(figsize=(2, 1.5), dpi=50)
    (line,) = ax.plot([0, 1], [0, 1])
    anim = FuncAnimation(fig, lambda i: line.set_ydata([0, i]), frames=3)
    html = anim.to_jshtml(fps=5)
    plt.close(fig)
    return html


@pytest.fixture(scope="module")
def small_page(tmp_path_factory) -> Path:
    """A notebook with inline and display formulas and a matplotlib player, exported as a page."""
    html = _animation_html()
    assert "font-awesome" in html  # matplotlib's player links the icon font from the web
    cell = new_code_cell("anim", outputs=[new_output("display_data", data={"text/html": html})])
    nb = new_notebook(
        cells=[
            new_markdown_cell(
                "# Page\nInline $\\mathrm{FD} = \\lVert \\mu_1 - \\mu_2 \\rVert^2$, a shell `$HOME`, and\n\n"
                "$$\\mathrm{PCK} = \\frac{1}{TJ} \\sum_{t=1}^{T} \\sum_{j=1}^{J} "
                "\\mathbf{1}\\!\\left[\\lVert p_t^j - \\hat p_t^j \\rVert_2 < \\delta\\right].$$"
            ),
            cell,
        ]
    )
    path = tmp_path_factory.mktemp("page") / "page.html"
    path.write_text(_runner().export_html(nb), encoding="utf-8")
    return path


def test_formulas_are_taken_out_before_markdown_parses_them():
    html = _runner().markdown_to_html(
        "Loss $a\n+ b$, `$HOME` and `x$y`, \\$5.\n\n$p\n\nq$ and $$\\frac{1}{2}$$"
    )
    assert "<li>" not in html and "<mi>b</mi>" in html  # "+ b" starting a line stays inside the formula
    assert "<code>$HOME</code>" in html and "<code>x$y</code>" in html and "$5" in html
    assert "$p" in html and "q$" in html  # a formula never spans a blank line
    assert html.count("<math") == 2 and html.count('display="block"') == 1 and "<mfrac>" in html
    for broken in ("$x^$", "$\\notacommand x$"):
        with pytest.raises(ValueError, match="cannot convert the formula"):
            _runner().markdown_to_html(broken)


#: Notebook 04's Wasserstein formula: its `\big)^2` was drawn small and low beside a 1.2 em "(" in Chromium.
BIG_PARENS = "$$W_2^2 = \\mathbb{E}\\,\\big(m_1 - m_2 + (s_1 - s_2) z\\big)^2 = \\Big[a\\Big]_i$$"


def test_a_big_delimiter_before_a_script_is_sized_like_its_pair():
    html = _runner().markdown_to_html(BIG_PARENS)
    sized = re.findall(r"<mo minsize=\"([0-9.]+em)\" maxsize=\"\1\">(.)</mo>", html)
    assert sized == [("1.2em", "("), ("1.2em", ")"), ("1.623em", "["), ("1.623em", "]")]
    # the closing ones are script bases: wrapped in an <mrow>, never the <mo> straight under <msup>/<msub>
    assert not re.search(r"<(msup|msub|msubsup)><mo ", html)
    assert html.count("<msup><mrow><mo minsize") == 1 and html.count("<msub><mrow><mo minsize") == 1


def test_big_parentheses_render_as_a_matching_pair_in_chromium(tmp_path):
    _chromium()
    page = tmp_path / "big.html"
    page.write_text(f"<!DOCTYPE html><html><body style='font-size:24px'>{_runner().markdown_to_html(BIG_PARENS)}"
                    "</body></html>", encoding="utf-8")  # fmt: skip
    browser = Browser(tmp_path / "profile")
    try:
        open_offline(browser, page)
        boxes = browser.evaluate(
            "[...document.querySelectorAll('mo[minsize]')].map(m => { const r = m.getBoundingClientRect(); "
            "return [m.textContent, r.top, r.bottom]; })"
        )
    finally:
        browser.close()
    assert [b[0] for b in boxes] == ["(", ")", "[", "]"]
    for (_, top_open, bottom_open), (_, top_close, bottom_close) in (boxes[:2], boxes[2:]):
        # one height and one baseline: within a pixel (the ")" was about 40 % smaller and lower before)
        assert abs(top_open - top_close) <= 1 and abs(bottom_open - bottom_close) <= 1, boxes


def test_page_has_no_remote_reference(small_page):
    html = small_page.read_text(encoding="utf-8")
    assert not re.search(r"<(script|link|img|iframe)[^>]+(src|href)=[\"']?(https?:)?//", html)
    assert "font-awesome" not in html and "MathJax" not in html
    assert html.count("<math") == 2 and "\\frac" not in html


def test_page_names_no_folder_of_the_machine_that_ran_it(monkeypatch):
    """Outputs that print paths (the data folder, a saved table, a score caption, a traceback) show them relative
    to the repository and the home folder as ``~`` (before: ``/home/alice/beatlite/data_samples`` on a published
    course page, naming the user); a folder that only starts like the repository's is left as it is."""
    runner = _runner()
    monkeypatch.setattr(runner, "REPO", Path("/srv/course/beatlite"))
    monkeypatch.setenv("HOME", "/home/alice")
    repo, home = "/srv/course/beatlite", "/home/alice"
    lines = (
        f"data={repo}/data_samples\nPosixPath('{repo}/build/tables/x.md')\n{home}/beat in {repo}.\n{repo}2/y"
    )
    outputs = [
        new_output("stream", name="stdout", text=lines),
        new_output("execute_result", data={"text/plain": lines}),
        new_output("display_data", data={"text/html": f"<p>split of <code>{repo}/data_samples</code></p>"}),
        new_output(
            "error", ename="FileNotFoundError", evalue=f"{home}/beat", traceback=[f"{repo}/beatlite/x.py"]
        ),
    ]
    html = runner.export_html(new_notebook(cells=[new_code_cell("print(data)", outputs=outputs)]))
    assert html.count("data=data_samples") == 2 and html.count("PosixPath('build/tables/x.md')") == 2
    assert html.count("~/beat in .") == 2 and html.count(f"{repo}2/y") == 2 and "beatlite/x.py" in html
    assert "split of <code>data_samples</code>" in html and f"{repo}/" not in html and "alice" not in html


def test_base64_data_is_left_as_it_is_where_its_letters_spell_the_home_folder(monkeypatch):
    """An animation player's frames are base64, whose letters and slashes can spell ``/root/`` (a short home
    folder) by chance: rewriting them would break the frame. Paths outside the data are still rewritten."""
    runner = _runner()
    monkeypatch.setenv("HOME", "/root")
    frame = 'data:image/png;base64,iVBO/root/Rw0K\\\nGgo/root=="'
    text = f'frames[0] = "{frame}; see /root/beat'
    assert runner.local_paths(text) == f'frames[0] = "{frame}; see ~/beat'


def test_page_renders_offline_in_chromium(small_page, tmp_path):
    _chromium()
    browser = Browser(tmp_path / "profile")
    try:
        open_offline(browser, small_page)
        report = browser.evaluate(PAGE_REPORT)
        urls = browser.requested_urls()
    finally:
        browser.close()
    left = [u for u in urls if not u.startswith(("file:", "data:", "about:", "blob:"))]
    assert left == [], f"the page requested {left}"
    assert report["maths"] == 2 and report["sized"] == 2, report
    assert report["fracs"] == [True], "the fraction is not typeset (numerator not above denominator)"
    assert report["dollars"] == 0, "raw $ left in the rendered Markdown"
    assert len(report["icons"]) == 9, report["icons"]
    assert all(i["width"] > 0 and i["image"].startswith('url("data:') for i in report["icons"]), report
    assert report["frame"] > 0, "the player did not draw its first frame"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_every_formula_of_the_notebooks_becomes_mathml(path):
    nb = nbformat.read(path, as_version=4)
    nb.cells = [c for c in nb.cells if c.cell_type == "markdown"]
    html = _runner().export_html(nb)
    markdown = re.sub(r"<(code|pre|math)\b.*?</\1>", "", html, flags=re.S)
    markdown = re.sub(r"<style.*?</style>", "", markdown, flags=re.S)
    assert "$" not in re.sub(r"<[^>]+>", "", markdown), f"{path.name}: a formula was left as TeX"
    sources = "\n".join(c.source for c in nb.cells)
    if "$" in re.sub(r"`[^`]*`", "", sources):
        assert "<math" in html


def screenshot(page: Path, png: Path, selector: str = "math[display=block]", profile: Path | None = None):
    """Save a PNG of ``page`` rendered offline, scrolled to the first ``selector`` (for a person to look at)."""
    browser = Browser(profile or png.with_suffix(".profile"))
    try:
        open_offline(browser, page)
        top = browser.evaluate(
            f"(() => {{ const e = document.querySelector({json.dumps(selector)}); "
            "return e ? e.getBoundingClientRect().top + window.scrollY - 150 : 0; })()"
        )
        clip = {"x": 0, "y": max(top, 0), "width": 1200, "height": 900, "scale": 1}
        data = browser.page("Page.captureScreenshot", format="png", clip=clip, captureBeyondViewport=True)
        png.write_bytes(base64.b64decode(data["data"]))
        return browser.requested_urls()
    finally:
        browser.close()


@pytest.mark.slow
def test_a_notebook_whose_kernel_dies_is_reported_and_the_next_one_runs(tmp_path, monkeypatch):
    """``make run`` used to stop at a dead kernel (only CellExecutionError was caught): no results.md."""
    for name in ("BEATLITE_BUILD", "BEATLITE_INTERACTIVE"):  # main() sets them: restored after the test
        monkeypatch.setenv(name, os.environ.get(name, ""))

    folder = tmp_path / "nbs"
    folder.mkdir()
    for name, source in (("01_dies", "import os\nos._exit(3)"), ("02_fine", "print(6 * 7)")):
        nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(source)])
        nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
        nbformat.write(nb, folder / f"{name}.ipynb")
    runner = _runner()
    code = runner.main(
        ["--out", str(tmp_path / "out"), str(folder / "01_dies.ipynb"), str(folder / "02_fine.ipynb")]
    )
    results = (tmp_path / "out" / "results.md").read_text()
    assert code == 1
    assert "| [01_dies](notebooks/01_dies.html) | FAILED" in results
    assert "| [02_fine](notebooks/02_fine.html) | ok |" in results and "1/2 ok" in results


def test_a_failure_is_reported_in_plain_text(tmp_path, monkeypatch):
    """The failed row of results.md names the exception without the traceback's terminal colour codes."""
    for name in ("BEATLITE_BUILD", "BEATLITE_INTERACTIVE"):  # main() sets them: restored after the test
        monkeypatch.setenv(name, os.environ.get(name, ""))
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("1 / 0")])
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nbformat.write(nb, tmp_path / "01_fails.ipynb")
    assert _runner().main(["--out", str(tmp_path / "out"), str(tmp_path / "01_fails.ipynb")]) == 1
    results = (tmp_path / "out" / "results.md").read_text()
    assert "| FAILED: ZeroDivisionError: division by zero |" in results, results


def test_results_md_names_no_folder_of_the_machine(tmp_path, monkeypatch):
    """A failure's message that names a file of the repository is written to build/results.md relative to it
    (before: the absolute path, e.g. ``/home/alice/beatlite/...``)."""
    for name in ("BEATLITE_BUILD", "BEATLITE_INTERACTIVE"):  # main() sets them: restored after the test
        monkeypatch.setenv(name, os.environ.get(name, ""))
    runner = _runner()
    missing = runner.REPO / "build" / "no_such_table.md"
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(f"open({str(missing)!r})")])
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nbformat.write(nb, tmp_path / "01_fails.ipynb")
    assert runner.main(["--out", str(tmp_path / "out"), str(tmp_path / "01_fails.ipynb")]) == 1
    results = (tmp_path / "out" / "results.md").read_text()
    assert "'build/no_such_table.md'" in results and str(runner.REPO) not in results, results
