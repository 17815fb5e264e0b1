"""Optional dependencies: a module of an extra, or an ImportError that says what to install."""

import importlib
from types import ModuleType


def optional_module(name: str, needed_for: str, extra: str, package: str) -> ModuleType:
    """``importlib.import_module(name)``; if it is not installed, an ImportError naming what needs it
    (``needed_for``), the ballenv ``extra`` that brings it and its pip ``package``."""
    try:
        return importlib.import_module(name)
    except ImportError as err:
        raise ImportError(
            f"{needed_for} needs {package}: pip install 'ballenv[{extra}]' (or pip install {package})"
        ) from err
