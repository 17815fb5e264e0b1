"""Shared settings of the env tests: pygame draws without a display."""

import os

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
