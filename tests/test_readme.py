"""Every code block of the README, of the docs' quick start and of the regulation balls' guide is run
or checked.

Python blocks run, in order, in one namespace per file (a later block may use an earlier one's
names), in a temporary folder. Each command of a shell block is checked without running it:
``make X`` is a target of the Makefile (``make -n``); ``python train.py``, ``python -m
agents.evaluate`` / ``study`` / ``tune`` / ``imitation`` and ``python benchmarks/ball3d_strike.py``
parse with those modules' own argument parsers; ``pip install`` installs this checkout (``-e
.[EXTRAS]``, extras that exist) with a constraints file that exists, and takes packages from no
index but PyPI and PyTorch's CPU-only one. A block of another language, or a command no check
knows, fails: a new block needs a check here, or an entry in ``EXEMPT`` with the reason. The
Guide's pages of commands only (``SHELL_DOCUMENTS``) are checked the same way.
"""

import re
import shlex
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = ("README.md", "docs/quickstart.md", "docs/balls.md")  # Python blocks that run, and commands
SHELL_DOCUMENTS = ("docs/training.md", "benchmarks/results/agents_v3.md")  # commands only
TORCH_CPU_INDEX = "https://download.pytorch.org/whl/cpu"  # PyTorch's index of its CPU-only builds
PYTHON = {"python", "py"}
SHELL = {"bash", "sh", "shell"}
EXEMPT = {  # command -> why it is not checked
    "tensorboard --logdir runs": "TensorBoard's own command line (a server that runs until stopped); "
    "runs/ is train.py's default --log-dir, which test_train_defaults_to_runs checks",
}
FENCE = re.compile(r"^```(\S*)[^\n]*\n(.*?)^```[ \t]*$", re.MULTILINE | re.DOTALL)


def code_blocks(name):
    """(language, line of the opening fence, code) of each fenced block of ``name``."""
    text = (ROOT / name).read_text()
    return [(m.group(1), text.count("\n", 0, m.start()) + 1, m.group(2)) for m in FENCE.finditer(text)]


def shell_blocks():
    return [
        pytest.param(name, line, code, id=f"{name}:{line}")
        for name in DOCUMENTS + SHELL_DOCUMENTS
        for language, line, code in code_blocks(name)
        if language in SHELL
    ]


def commands(code):
    """The commands of a shell block as argument lists (comments dropped, ``\\`` joins lines)."""
    joined = code.replace("\\\n", " ")
    return [argv for line in joined.splitlines() if (argv := shlex.split(line, comments=True))]


def check_make(args):
    # -n: print the commands without running them; -B: as in a fresh clone (every step out of date)
    dry = subprocess.run(["make", "-n", "-B", *args], cwd=ROOT, capture_output=True, text=True)
    assert dry.returncode == 0, f"make {shlex.join(args)}: {dry.stderr.strip()}"


def check_train(args):
    from agents.train import parse_args

    parse_args(args)


def check_evaluate(args):
    from agents.evaluate import build_parser

    build_parser().parse_args(args)


def check_evaluate3d(args):
    from agents.evaluate3d import build_parser

    build_parser().parse_args(args)


def check_imitation(args):
    from agents.imitation import parse_args

    parse_args(args)


def check_study_or_tune(module):
    def check(args):
        from agents.train import parse_args

        _, rest = module.build_parser().parse_known_args(args)
        parse_args(rest)  # what the module passes on to agents.train

    return check


def check_benchmark(name):
    def check(args):
        from tests.benchmark_modules import load_benchmark

        load_benchmark(name).build_parser().parse_args(args)

    return check


def pyproject_extras():
    """The names of the optional dependencies (extras) in pyproject.toml."""
    text = (ROOT / "pyproject.toml").read_text()
    table = text.split("[project.optional-dependencies]", 1)[1].split("\n[", 1)[0]
    return set(re.findall(r"^([\w-]+)\s*=", table, re.MULTILINE))


def check_pip_install(args):
    options, values = args[::2], args[1::2]
    known = len(options) == len(values) and set(options) <= {"-c", "-e", "--extra-index-url"}
    only = "-c FILE, -e .[EXTRAS] and --extra-index-url URL"
    assert known, f"pip install {shlex.join(args)}: the check knows only {only}"
    assert "-e" in options, f"pip install {shlex.join(args)}: installs no checkout (ballenv is not on PyPI)"
    for option, value in zip(options, values, strict=True):
        if option == "-c":
            assert (ROOT / value).is_file(), f"pip install -c {value}: no such file"
        elif option == "--extra-index-url":
            assert value == TORCH_CPU_INDEX, f"pip install --extra-index-url {value}: only {TORCH_CPU_INDEX}"
        else:
            named = re.fullmatch(r"\.(?:\[([\w,-]+)\])?", value)
            assert named, f"pip install -e {value}: not this checkout (.[extras])"
            missing = set((named.group(1) or "").split(",")) - pyproject_extras() - {""}
            assert not missing, f"pip install -e {value}: no extra {sorted(missing)} in pyproject.toml"


def test_the_cpu_index_is_where_torch_meets_its_constraint():
    # the CPU-only builds are torch==X+cpu, which the constraint torch==X admits (PEP 440: a local
    # version label is ignored by a specifier without one)
    from packaging.specifiers import SpecifierSet

    pins = dict(
        line.split("==", 1) for line in (ROOT / "constraints.txt").read_text().splitlines() if "==" in line
    )
    assert "torch" in pins, "constraints.txt pins no torch"
    assert f"{pins['torch']}+cpu" in SpecifierSet(f"=={pins['torch']}")


def checker(argv):
    """The check of one command (its argument list), and the arguments it checks."""
    import agents.study
    import agents.tune

    prefixes = {
        ("make",): check_make,
        ("python", "train.py"): check_train,
        ("python", "-m", "agents.evaluate"): check_evaluate,
        ("python", "-m", "agents.evaluate3d"): check_evaluate3d,
        ("python", "-m", "agents.study"): check_study_or_tune(agents.study),
        ("python", "-m", "agents.tune"): check_study_or_tune(agents.tune),
        ("python", "-m", "agents.imitation"): check_imitation,
        ("pip", "install"): check_pip_install,
        ("python", "benchmarks/ball3d_strike.py"): check_benchmark("ball3d_strike"),
    }
    for prefix, check in prefixes.items():
        if tuple(argv[: len(prefix)]) == prefix:
            return check, argv[len(prefix) :]
    return None, argv


@pytest.mark.parametrize("name", DOCUMENTS + SHELL_DOCUMENTS)
def test_every_block_is_python_or_shell(name):
    blocks = code_blocks(name)
    assert blocks, f"{name}: no code block found"
    other = [f"{name}:{line} ({lang or 'none'})" for lang, line, _ in blocks if lang not in PYTHON | SHELL]
    assert not other, f"blocks that no test runs or checks: {other}"


@pytest.mark.parametrize("name", DOCUMENTS)
def test_python_blocks_run(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "__main__"}
    blocks = [(line, code) for language, line, code in code_blocks(name) if language in PYTHON]
    assert blocks, f"{name}: no python block"
    for line, code in blocks:
        # padded so that a traceback names the line of the file
        exec(compile("\n" * line + code, str(ROOT / name), "exec"), namespace)


@pytest.mark.parametrize(("name", "line", "code"), shell_blocks())
def test_shell_commands_parse(name, line, code):
    argvs = commands(code)
    assert argvs, f"{name}:{line}: an empty shell block"
    for argv in argvs:
        command = shlex.join(argv)
        if command in EXEMPT:
            continue
        check, args = checker(argv)
        assert check is not None, f"{name}:{line}: no check knows {command!r} (add one, or an EXEMPT reason)"
        try:
            check(args)
        except SystemExit as exit_:  # argparse's error exit
            pytest.fail(f"{name}:{line}: {command!r} is rejected by its parser (exit {exit_.code})")


def test_train_defaults_to_runs():
    from agents.train import parse_args

    assert parse_args([]).log_dir == "runs"


def test_an_unknown_command_has_no_check():
    assert checker(["python", "-m", "agents.nothing"])[0] is None
    assert checker(["curl", "example"])[0] is None


def test_a_wrong_command_line_fails_its_check():
    check, args = checker(shlex.split("python train.py --algo dqn"))
    with pytest.raises(SystemExit):
        check(args)
    check, args = checker(["make", "no-such-target"])
    with pytest.raises(AssertionError, match="No rule to make target"):
        check(args)
    check, args = checker(shlex.split("pip install -e '.[no-such-extra]'"))
    with pytest.raises(AssertionError, match="no extra"):
        check(args)
    check, args = checker(shlex.split("pip install ballenv"))
    with pytest.raises(AssertionError, match="knows only"):
        check(args)
    check, args = checker(shlex.split("pip install -c constraints.txt 'ballenv[train]'"))
    with pytest.raises(AssertionError, match="knows only"):
        check(args)
    check, args = checker(shlex.split("pip install -c constraints.txt"))
    with pytest.raises(AssertionError, match="installs no checkout"):
        check(args)
    check, args = checker(shlex.split("pip install -e . --extra-index-url https://example.org/simple"))
    with pytest.raises(AssertionError, match="only https://download.pytorch.org/whl/cpu"):
        check(args)
