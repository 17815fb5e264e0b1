"""The documentation site (mkdocs.yml) builds with ``--strict``, as ``make docs`` does: a warning (a
broken link, a results table that moved, a docstring mkdocstrings cannot read) fails the suite."""

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_the_site_builds_without_warnings(tmp_path):
    site = tmp_path / "site"
    build = [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)]
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}  # Material's notice about MkDocs 2
    result = subprocess.run(build, cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "WARNING" not in result.stderr, result.stderr
    env_page = (site / "envs" / "inflated_ball" / "index.html").read_text()
    assert "Version History" in env_page and "InflatedBallPaddle-v3" in env_page  # from the docstring
    benchmarks = (site / "benchmarks" / "index.html").read_text()
    assert 'title="table' not in benchmarks  # every table link became its table
    assert "Two commands" in (site / "index.html").read_text()  # the README
