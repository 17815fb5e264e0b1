"""Optional dependencies: a module of an extra, or an ImportError that says what to install."""

import importlib
import importlib.util
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


def installed(name: str) -> bool:
    """Whether the module ``name`` can be imported (found, not imported)."""
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):
        return False


# what each render mode draws with: the modes whose modules are installed are the ones offered
RENDER_NEEDS = {"human": ("PIL", "pygame"), "rgb_array": ("PIL",)}
PACKAGES = {"PIL": "pillow", "pygame": "pygame-ce"}


def render_modes() -> list[str]:
    """The render modes this installation can draw in (``RENDER_NEEDS``)."""
    return [mode for mode, needs in RENDER_NEEDS.items() if all(installed(n) for n in needs)]


def require_render_mode(mode: str) -> None:
    """An ImportError naming what to install if render mode ``mode`` cannot draw here."""
    for name in RENDER_NEEDS[mode]:
        optional_module(name, f"the {mode} render mode", "render", PACKAGES[name])
