"""The shell is pure numerics: none of its modules imports gymnasium, torch, pygame, matplotlib,
Stable-Baselines3, Pillow or SciPy (a test and benchmark dependency only)."""

import ast
import pathlib

import pytest

SHELL = pathlib.Path(__file__).resolve().parents[2] / "ballenv" / "shell"
FORBIDDEN = {"gymnasium", "torch", "pygame", "matplotlib", "stable_baselines3", "PIL", "scipy"}


def imported_roots(path):
    roots = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            roots.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and not node.level:
            roots.add(node.module.split(".")[0])
    return roots


@pytest.mark.parametrize("path", sorted(SHELL.rglob("*.py")), ids=lambda p: p.relative_to(SHELL).as_posix())
def test_the_shell_imports_only_numerics(path):
    assert not imported_roots(path) & FORBIDDEN
