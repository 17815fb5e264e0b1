"""Every headline number of the README and the Guide agrees with its source.

A fact is a number written in a page (found by a pattern with one group per number) and the place
it comes from: the environment itself (``gym.make``), or a results file of ``benchmarks/results/``
(a table cell, or a pattern in the file's text). A number changed on one side only fails here,
naming both. The Guide's other pages show their measured tables from the results files when the
site builds (``docs/hooks.py``), and the environment's page reads its spaces from the code.
"""

import re
import sys
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
NUMBER = re.compile(r"\d[\d,]*(?:\.\d+)?")


def numbers(text):
    """The numbers written in ``text``, in order (``14,072`` is 14072)."""
    return [float(n.replace(",", "")) for n in NUMBER.findall(text)]


def cells(line):
    return [c.strip() for c in line.strip().strip("|").split("|")]


def results_cell(hooks, name, row, column, table=1, heading=None):
    """The cell of ``benchmarks/results/NAME`` in ``column`` (its header) of the first row whose
    first cells start with ``row`` (a tuple), in table ``table`` (from 1) under ``heading``."""
    where = f"benchmarks/results/{name}"
    lines = hooks.nth_table(hooks.section((ROOT / where).read_text(), heading, where), table, where)
    header = cells(lines[0])
    for line in lines[2:]:
        found = cells(line)
        if all(cell.startswith(key) for cell, key in zip(found, row, strict=False)):
            return found[header.index(column)]
    raise AssertionError(f"{where}: no row {row} in table {table} under {heading!r}")


def results_text(name, pattern):
    """The groups of the first match of ``pattern`` in ``benchmarks/results/NAME``."""
    found = re.search(pattern, (ROOT / "benchmarks" / "results" / name).read_text())
    assert found, f"benchmarks/results/{name}: {pattern!r} not found"
    return list(found.groups())


@cache
def env_facts():
    import gymnasium as gym

    import ballenv  # noqa: F401  (registers the ids)
    from ballenv.envs.inflated_ball import ball_env

    env = gym.make("InflatedBall-v3")
    config = ball_env(env).config
    facts = {
        "observation size": str(env.observation_space.shape[0]),
        "nodes": str(config.n_nodes),
        "control frequency": f"{config.control_frequency:g}",
        "episode steps": str(env.spec.max_episode_steps),
        "episode seconds": f"{env.spec.max_episode_steps / config.control_frequency:g}",
    }
    env.close()
    return facts


def make_test_time(hooks):
    """The quickest and the slowest empty-cache runs of one commit, then its quickest and slowest
    runs on a filled cache."""
    heading = "Commit f51154b: an empty cache, the filled cache, and the compile lock's waits"
    column = "pytest (2 workers; 1585 passed)"
    rows = ("empty cache, in the evening", "empty cache", "the filled cache, CI", "the filled cache, at once")
    return [results_cell(hooks, "make_test.md", (row,), column, heading=heading) for row in rows]


def cold_env(hooks):
    return results_cell(hooks, "cold_start.md", ("1 (one process)",), "wall (s)", table=1)


def agents(hooks, mode, row):
    return results_cell(hooks, "agents_v3.md", (row,), "apex error IQM [95 % CI]", heading=mode)


MAKE_TEST = (
    r"`make test`'s pytest takes (\d+ min \d+ s)\s+to (\d+ min \d+ s) in a fresh clone[^(]*"
    r"\((\d+ min \d+ s) to (\d+ min \d+ s) with every kernel"
)

# (page, pattern: one group per number, the source: a function of the hooks module)
FACTS = {
    "observation size": (
        "README.md",
        r"observes (\d+) numbers in the pressure mode",
        lambda hooks: env_facts()["observation size"],
    ),
    "observation size in the example": (
        "README.md",
        r"observation_space\.shape == \((\d+),\)",
        lambda hooks: env_facts()["observation size"],
    ),
    "node count": ("README.md", r"the ring's (\d+) points", lambda hooks: env_facts()["nodes"]),
    "control frequency": (
        "README.md",
        r"the agent acts (\d+) times a second",
        lambda hooks: env_facts()["control frequency"],
    ),
    "episode length": (
        "README.md",
        r"at most (\d+) steps \((\d+) s\)",
        lambda hooks: [env_facts()["episode steps"], env_facts()["episode seconds"]],
    ),
    "make test's time": ("README.md", MAKE_TEST, make_test_time),
    "make test's time, quick start": ("docs/quickstart.md", MAKE_TEST, make_test_time),
    "cold start": ("README.md", r"empty compile cache .*?\| ([\d.]+) s \|", cold_env),
    "cold start, quick start": ("docs/quickstart.md", r"its first steps took\s+([\d.]+) s", cold_env),
    "cold start of simulate, quick start": (
        "docs/quickstart.md",
        r"first `simulate\(\)` of one ring with `Scene`'s\s+defaults ([\d.]+) s",
        lambda hooks: results_cell(hooks, "cold_start.md", ("1",), "wall (s)", table=2),
    ),
    "pressure mode scores": (
        "README.md",
        r"\| pressure mode: apex error [^|]*\| ([\d.]+) against ([\d.]+) \|",
        lambda hooks: [
            agents(hooks, "Pressure mode", "PPO cloned"),
            agents(hooks, "Pressure mode", "scripted pump"),
        ],
    ),
    "paddle mode scores": (
        "README.md",
        r"\| paddle mode: [^|]*\| ([\d.]+) against ([\d.]+) \|",
        lambda hooks: [
            agents(hooks, "Paddle mode", "PPO cloned"),
            agents(hooks, "Paddle mode", "scripted dribble"),
        ],
    ),
    "make train's scores": (
        "README.md",
        r"\| `make train`: [^|]*\| ([\d.]+) against ([\d.]+) \| [^|]*, (\d+) s on 2 cores [^|]*\|",
        lambda hooks: [
            results_cell(hooks, "make_train.md", ("ppo",), "apex error mean [95 % CI]"),
            results_cell(hooks, "make_train.md", ("heuristic",), "apex error mean [95 % CI]"),
            results_text("make_train.md", r"\*\*(\d+) s\*\* wall")[0],
        ],
    ),
    "soak under error control": (
        "docs/simulator.md",
        r"The soak's ([\d,]+) random hard\s+scenes under the default's `rtol` reach their end in ([\d,]+)"
        r" \(`benchmarks/soak.py --rtol 0.01`;\s+Newton's rescue took (\d+) steps in (\d+) of them\)",
        lambda hooks: [
            results_cell(hooks, "soak_rtol.md", (), "cases", heading="Random scenes"),
            results_cell(hooks, "soak_rtol.md", ("reached t_end",), "runs", table=2, heading="Random scenes"),
            *results_text("soak_rtol.md", r"Newton's rescue \(`[^`]*`\) took (\d+) steps in (\d+) runs"),
        ],
    ),
    "3-D balls' fitted damping": (
        "docs/shell.md",
        r"the basketball\s+carcass's ([\d.]+) 1/s on FIBA's test, synthetic leather's ([\d.]+) 1/s on FIFA's,"
        r"\s+the tennis rubber's\s+([\d.]+) 1/s on the ITF's",
        lambda hooks: [
            results_cell(hooks, "shell_balls.md", (name,), "c (1/s)")
            for name in ("basketball", "football", "tennis_ball")
        ],
    ),
    "3-D balls' damping fitted on 642 vertices": (
        "docs/shell.md",
        r"fitted again on 642 vertices \(([\d.]+), ([\d.]+) and ([\d.]+) 1/s\)",
        lambda hooks: [
            results_cell(
                hooks, "shell_balls.md", (n,), "c on 642 (1/s)", heading="The same drops on 642 vertices"
            )
            for n in ("basketball", "football", "tennis_ball")
        ],
    ),
    "3-D volleyball's predicted drop": (
        "docs/shell.md",
        r"damping unchanged: ([\d.]+) m from 2 m\s+\(restitution ([\d.]+);",
        lambda hooks: [
            results_cell(hooks, "shell_balls.md", ("volleyball",), "rebound (m)"),
            results_cell(hooks, "shell_balls.md", ("volleyball",), "restitution"),
        ],
    ),
    "3-D tennis ball's contact time": (
        "docs/shell.md",
        r"the tennis ball's\s+([\d.]+) ms is",
        lambda hooks: results_cell(hooks, "shell_balls.md", ("tennis_ball",), "contact (ms)"),
    ),
    "env throughput": (
        "README.md",
        r"\| env steps per second, [^|]*\| ([\d,]+) \|",
        lambda hooks: results_cell(hooks, "env_throughput.md", ("fast", "pressure"), "scripted policy"),
    ),
    "3-D ball's speed": (
        "README.md",
        r"\| the 3-D ball [^|]*\| ([\d.]+)x; (-?[\d.]+ %) \|",
        lambda hooks: [
            results_cell(hooks, "shell_drop.md", ("162", "preset fast"), "x real time"),
            results_cell(hooks, "shell_drop.md", ("162", "preset fast"), "first-apex error"),
        ],
    ),
    "against PyElastica": (
        "README.md",
        r"\| a 1-s drop within 1 % [^|]*\| ([\d.]+) ms; ([\d.]+)x \|",
        lambda hooks: results_text(
            "peers.md",
            r"Cheapest ballenv run within 1 %[^\n]*?wall ([\d.]+) ms[^\n]*\n(?:.*\n)*?.*?"
            r"at matched accuracy: ([\d.]+)x in wall time",
        ),
    ),
}


def first_numbers(text, count):
    """The first ``count`` numbers of a source's value (a cell may hold an interval after it)."""
    values = numbers(text)
    assert len(values) >= count, f"{text!r}: fewer than {count} numbers"
    return values[:count]


@pytest.mark.parametrize("fact", FACTS)
def test_a_headline_number_agrees_with_its_source(hooks, fact):
    page, pattern, source = FACTS[fact]
    found = [m.groups() for m in re.finditer(pattern, (ROOT / page).read_text())]
    assert found, f"{page}: the {fact} ({pattern!r}) is not written there any more: update FACTS"
    expected = source(hooks)
    expected = [expected] if isinstance(expected, str) else expected
    for groups in found:
        assert len(groups) == len(expected), f"{fact}: {len(groups)} numbers written, {len(expected)} sourced"
        for written, value in zip(groups, expected, strict=True):
            assert numbers(written) == first_numbers(value, len(numbers(written))), (
                f"{page}: the {fact} is written {written!r}, its source says {value!r}"
            )


def headline_table(text):
    """The value cells of the README's table under "Headline results"."""
    lines = text.split("## Headline results", 1)[1].splitlines()
    rows = [cells(line) for line in lines if line.startswith("|")]
    column = rows[0].index("value")
    return [row[column] for row in rows[2:]]


def test_every_number_of_the_headline_table_is_checked():
    text = (ROOT / "README.md").read_text()
    checked = [m.group(0) for _, pattern, _ in FACTS.values() for m in re.finditer(pattern, text)]
    for value in headline_table(text):
        covered = [row for row in checked if f"| {value} |" in row]
        assert covered, f"README.md: the headline value {value!r} has no fact in FACTS (its source)"


def test_a_wrong_number_fails(hooks, tmp_path, monkeypatch):
    # the check itself: a README whose score differs from the results file is caught
    readme = (ROOT / "README.md").read_text()
    written = re.search(FACTS["pressure mode scores"][1], readme).group(1)
    wrong = f"{float(written) + 0.001:.3f}"
    (tmp_path / "README.md").write_text(readme.replace(f"| {written} against", f"| {wrong} against"))
    (tmp_path / "benchmarks").symlink_to(ROOT / "benchmarks")
    monkeypatch.setattr(sys.modules[__name__], "ROOT", tmp_path)
    with pytest.raises(AssertionError, match="the pressure mode scores is written"):
        test_a_headline_number_agrees_with_its_source(hooks, "pressure mode scores")
