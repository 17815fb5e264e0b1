"""The benchmark scripts (``benchmarks/NAME.py``), imported by name for the tests that run them."""

import importlib.util
import pathlib
import sys
from types import ModuleType

BENCHMARKS = pathlib.Path(__file__).resolve().parents[1] / "benchmarks"


def load_benchmark(name: str) -> ModuleType:
    """``benchmarks/{name}.py`` as the module ``name``, loaded once and kept in ``sys.modules``
    (where dataclasses look their module up); ``benchmarks/`` goes on ``sys.path`` first, as when the
    script runs, so that it imports its sibling scripts by name."""
    if str(BENCHMARKS) not in sys.path:
        sys.path.insert(0, str(BENCHMARKS))
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, BENCHMARKS / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]
