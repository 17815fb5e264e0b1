"""The documentation site (mkdocs.yml) builds with ``--strict``, as ``make docs`` does: a warning (a
broken link, a results table that moved, a docstring mkdocstrings cannot read) fails the suite.
The home page and the environment's page fit a 1366-pixel-wide window in headless Chromium: no
code block or table is cut off (scrolls sideways)."""

import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
WIDTH = 1366  # px: the narrowest common laptop screen
CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--hide-scrollbars"]
# written into a copy of a page: the elements wider than their box, listed in an attribute of <body>
OVERFLOW_SCRIPT = """<script>
addEventListener("load", () => {
  const cut = [...document.querySelectorAll(".md-content pre > code, .md-content .md-typeset__scrollwrap")]
    .filter((e) => e.scrollWidth > e.clientWidth + 1)
    .map((e) => e.textContent.trim().split("\\n")[0].slice(0, 80));
  document.body.setAttribute("data-cut-off", JSON.stringify(cut));
});
</script>"""


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    site = tmp_path_factory.mktemp("docs") / "site"
    build = [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)]
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}  # Material's notice about MkDocs 2
    result = subprocess.run(build, cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "WARNING" not in result.stderr, result.stderr
    return site


def test_the_site_builds_without_warnings(site):
    env_page = (site / "envs" / "inflated_ball" / "index.html").read_text()
    assert "Version History" in env_page and "InflatedBallPaddle-v3" in env_page  # from the docstring
    for page in ("training", "simulator", "notes/benchmarks"):  # each table link became its table
        assert 'title="table' not in (site / page / "index.html").read_text()
    home = (site / "index.html").read_text()
    assert "Two commands" in home and "Headline results" in home  # the README


def test_the_nav_is_by_reader(site):
    home = (site / "index.html").read_text()
    label = r'<label class="md-nav__link"[^>]*>\s*<span class="md-ellipsis">\s*([^<]+?)\s*</span>'
    sections = re.findall(label, home)
    assert [s for s in sections if s in {"Guide", "Reference", "Results", "Notes"}] == [
        "Guide",
        "Reference",
        "Results",
        "Notes",
    ], sections


def chromium():
    """The chromium binary; missing, the test fails under CI (.ci/run installs it) and skips elsewhere."""
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        message = "chromium not found: install it (Debian: apt-get install chromium; .ci/run does)"
        if os.environ.get("CI"):
            pytest.fail(message)
        pytest.skip(message)
    return exe


def run_chromium(*args):
    with tempfile.TemporaryDirectory() as profile:
        return subprocess.run(
            [chromium(), *CHROMIUM_FLAGS, f"--user-data-dir={profile}", f"--window-size={WIDTH},900", *args],
            capture_output=True,
            text=True,
            timeout=60,
        )


@pytest.mark.parametrize("page", ["index.html", "envs/inflated_ball/index.html"])
def test_a_front_page_is_not_cut_off_at_1366_px(site, page, tmp_path):
    original = site / page
    probe = original.with_name("probe.html")  # beside the page: its relative links still work
    probe.write_text(original.read_text().replace("</body>", OVERFLOW_SCRIPT + "</body>"))
    dom = run_chromium("--virtual-time-budget=3000", "--dump-dom", probe.as_uri())
    found = re.search(r'data-cut-off="([^"]*)"', dom.stdout)
    assert found, f"{page}: the probe did not run: {dom.stderr[-500:]}"
    assert found.group(1) == "[]", f"{page}: cut off at {WIDTH} px: {found.group(1)}"
    shot = tmp_path / "page.png"  # the picture, for a look when the check fails
    run_chromium(f"--screenshot={shot}", original.as_uri())
    assert shot.is_file() and shot.stat().st_size > 10_000
