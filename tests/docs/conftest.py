"""The docs' Python files (docs/ is not a package) loaded by path."""

import importlib.util
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[2] / "docs"


def load(name):
    spec = importlib.util.spec_from_file_location(f"docs_{name}", DOCS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="session")
def hooks():
    return load("hooks")


@pytest.fixture(scope="session")
def griffe_rest():
    return load("griffe_rest")
