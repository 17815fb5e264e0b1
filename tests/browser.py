"""Headless Chromium for the replay pages' tests (Debian's chromium on the PATH)."""

import os
import shutil
import subprocess
import tempfile

import numpy as np
import pytest

CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


def chromium():
    """The chromium binary; missing, the test fails under CI (.ci/run installs it) and skips
    elsewhere."""
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        message = "chromium not found: install it (Debian: apt-get install chromium; .ci/run does)"
        if os.environ.get("CI"):
            pytest.fail(message)
        pytest.skip(message)
    return exe


def run_chromium(*args):
    """Run headless chromium with ``args`` in a fresh profile; the completed process."""
    with tempfile.TemporaryDirectory() as profile:
        return subprocess.run(
            [chromium(), *CHROMIUM_FLAGS, f"--user-data-dir={profile}", *args],
            capture_output=True,
            text=True,
            timeout=60,
        )


def screenshot_pixels(shot):
    """The (H, W, 3) integer RGB pixels of the PNG ``shot``."""
    from PIL import Image

    return np.asarray(Image.open(shot).convert("RGB")).astype(int)
