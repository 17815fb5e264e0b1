"""The layer rules of the package (docs/architecture.md), read from every import statement of
``ballenv``, ``agents`` and ``train.py``: module-level, inside functions and under ``TYPE_CHECKING``
alike, so a hidden import counts as much as a visible one."""

import ast
import pathlib
import subprocess
import sys
import textwrap

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
PACKAGES = ("ballenv", "agents")

# the simulator's layers, lowest first: a module imports only from its own layer or those below
PHYSICS_LAYERS = (
    "base", "model", "scene", "effects", "ground", "walls", "step", "build", "trajectory",
    "simulation", "presets", "__init__",
)  # fmt: skip
# the 3-D ball's layers, lowest first, in the same way
SHELL_LAYERS = (
    "scene", "skin", "solve", "touch", "rest", "step", "simulation", "steering", "presets", "balls",
    "__init__",
)  # fmt: skip
# the package's layers, lowest first (a top-level module or sub-package of ballenv, or agents)
PACKAGE_LAYERS = (
    ("ballenv.extras", "ballenv.files", "ballenv.draw", "ballenv.video", "ballenv.draw3d", "ballenv.rules"),
    ("ballenv.physics",),
    ("ballenv.shell",),
    ("ballenv.balls", "ballenv.controllers", "ballenv.cluster", "ballenv.envs", "ballenv.shell_files"),
    ("ballenv.viewer", "ballenv.viewer3d", "ballenv.scenes", "ballenv.clips", "ballenv.demo", "ballenv"),
    ("agents",),
    ("train",),
)
NUMERICS_ONLY = ("gymnasium", "torch", "pygame", "matplotlib", "stable_baselines3", "PIL")
# what agents may import of ballenv: the env's public modules, never the simulator's internals
AGENTS_MAY_IMPORT = (
    "ballenv", "ballenv.envs", "ballenv.envs.inflated_ball", "ballenv.envs.ball3d.env",
    "ballenv.envs.ball3d.body", "ballenv.envs.ball3d.config", "ballenv.envs.config",
    "ballenv.envs.observation", "ballenv.envs.task", "ballenv.controllers", "ballenv.cluster",
    "ballenv.extras", "ballenv.files", "ballenv.physics",
)  # fmt: skip


def module_name(path):
    """``ballenv/physics/step/newton.py`` -> ``ballenv.physics.step.newton`` (a package: its name)."""
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def source_files():
    files = [p for package in PACKAGES for p in sorted((ROOT / package).rglob("*.py"))]
    return files + [ROOT / "train.py"]


MODULES = {module_name(p): p for p in source_files()}


def imports_of(path):
    """Every module ``path`` imports (absolute names, each as written or as the module it names)."""
    name = module_name(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module
            for alias in node.names:  # `from package import module` imports the module
                full = f"{target}.{alias.name}"
                out.add(full if full in MODULES else target)
    return out


def internal_graph():
    graph = {}
    for module, path in MODULES.items():
        graph[module] = {m for m in imports_of(path) if m in MODULES and m != module}
    return graph


def cycles(graph):
    """The strongly connected components of more than one module (Tarjan's algorithm)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def physics_layer(module):
    """Rank of a ``ballenv.physics`` module in ``PHYSICS_LAYERS``."""
    rest = module.split(".")[2:] or ["__init__"]
    return PHYSICS_LAYERS.index(rest[0])


def shell_layer(module):
    """Rank of a ``ballenv.shell`` module in ``SHELL_LAYERS``."""
    rest = module.split(".")[2:] or ["__init__"]
    return SHELL_LAYERS.index(rest[0])


def package_layer(module):
    """Rank of a module in ``PACKAGE_LAYERS`` (by its longest listed prefix)."""
    best = None
    for rank, names in enumerate(PACKAGE_LAYERS):
        for name in names:
            if (module == name or module.startswith(name + ".")) and (best is None or len(name) > best[1]):
                best = (rank, len(name))
    assert best is not None, f"{module} is in no layer of PACKAGE_LAYERS"
    return best[0]


def climbs(graph):
    """Imports from a lower layer to a higher one: (importer, imported)."""
    out = []
    for a, targets in sorted(graph.items()):
        for b in sorted(targets):
            if a.startswith("ballenv.physics") and b.startswith("ballenv.physics"):
                if physics_layer(b) > physics_layer(a):
                    out.append((a, b))
            elif a.startswith("ballenv.shell") and b.startswith("ballenv.shell"):
                if shell_layer(b) > shell_layer(a):
                    out.append((a, b))
            elif package_layer(b) > package_layer(a):
                out.append((a, b))
    return out


def test_the_walk_sees_every_module_and_the_imports_hidden_in_functions():
    assert len(MODULES) > 70
    graph = internal_graph()
    assert "ballenv.physics.step.newton" in graph["ballenv.physics.step.stepper"]
    assert "ballenv.shell.skin.damping" in graph["ballenv.shell.step.implicit"]
    # the env imports its renderer inside render() (pygame and Pillow load only when drawing)
    assert "ballenv.envs.render" in graph["ballenv.envs.inflated_ball"]


def test_no_import_circle():
    assert cycles(internal_graph()) == []


def test_no_import_climbs_to_a_higher_layer():
    assert climbs(internal_graph()) == []


def test_a_circle_and_a_climb_are_found():
    graph = internal_graph()
    graph["ballenv.physics.base.jit"] = graph["ballenv.physics.base.jit"] | {"ballenv.physics.step.stepper"}
    assert any("ballenv.physics.base.jit" in c and "ballenv.physics.step.stepper" in c for c in cycles(graph))
    assert ("ballenv.physics.base.jit", "ballenv.physics.step.stepper") in climbs(graph)


@pytest.mark.parametrize("module", sorted(m for m in MODULES if m.startswith("ballenv.physics")))
def test_the_simulator_imports_no_gymnasium_torch_pygame_matplotlib(module):
    roots = {name.split(".")[0] for name in imports_of(MODULES[module])}
    assert not roots & set(NUMERICS_ONLY)


@pytest.mark.parametrize("module", sorted(m for m in MODULES if m.startswith("agents")))
def test_agents_import_no_simulator_internals(module):
    ballenv = {m for m in imports_of(MODULES[module]) if m.split(".")[0] == "ballenv"}
    assert ballenv <= set(AGENTS_MAY_IMPORT), sorted(ballenv - set(AGENTS_MAY_IMPORT))


@pytest.mark.parametrize("module", sorted(m for m in MODULES if m.startswith("agents")))
def test_agents_read_no_private_state_of_other_objects(module):
    found = []
    for node in ast.walk(ast.parse(MODULES[module].read_text())):
        if isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__"):
            owner = node.value
            if isinstance(owner, ast.Name) and owner.id in ("self", "cls"):
                continue
            if isinstance(owner, ast.Call) and getattr(owner.func, "id", None) == "super":
                continue
            found.append(f"{node.lineno}: {ast.unparse(node)}")
    assert found == []


SCRIPT = textwrap.dedent(
    """
    import sys

    import gymnasium as gym

    import ballenv  # noqa: F401

    env = gym.make("InflatedBall-v3")
    env.reset(seed=0)
    env.step(env.action_space.sample())
    loaded = sorted(m for m in sys.modules if m.split(".")[0] in ("pygame", "PIL", "matplotlib", "torch"))
    assert "ballenv.envs.render" not in sys.modules and not loaded, loaded
    print("ok")
    """
)


def test_making_and_stepping_an_env_imports_no_renderer():
    out = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip() == "ok"
