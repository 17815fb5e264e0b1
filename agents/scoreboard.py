"""The scoreboard of a training run: the trained agent and the baselines scored on the same
held-out episodes in this run, beside reference rows read from results files (never retyped).

References, each labelled with the file it comes from:

* the privileged lookahead (and the other policies of the pump's results page), from
  ``benchmarks/results/pump_response.md`` (``python benchmarks/pump_response.py``; pressure mode);
* the long studies' trained agents, from every ``{algo}_{mode}.json`` that ``agents.study`` wrote
  under the run's log folder (``python -m agents.study ... --out runs/study``).

A reference was measured on its own episodes and budget: it says where the run stands, it is not
part of the run's comparison, which :func:`verdict` makes between the trained agent and the tuned
heuristic on the same episodes, by their 95 % intervals of the mean apex error.
"""

from __future__ import annotations

import json
import pathlib
import re
from collections.abc import Sequence
from dataclasses import dataclass

from .evaluate import Score

ROOT = pathlib.Path(__file__).resolve().parent.parent  # a source checkout holds benchmarks/ here
PUMP_RESULTS = ROOT / "benchmarks" / "results" / "pump_response.md"
SKIPPED = ("heuristic", "random")  # measured again in the run itself


@dataclass(frozen=True)
class Reference:
    """A row of a results file: its policy, where it was read, runs x episodes, and its apex error
    (mean; IQM with its 95 % interval), apexes within 5 % (a fraction) and mean return."""

    policy: str
    source: str
    runs: int
    episodes: int  # per run
    mean: float
    iqm: float
    iqm_ci: tuple[float, float]
    success: float
    episode_return: float


def pump_references(path: pathlib.Path = PUMP_RESULTS) -> list[Reference]:
    """The rows of the held-out table of the pump's results page (``| policy | runs x episodes |
    apex error IQM [95 % CI] | apex error mean | apexes within 5 % | return |``), but the policies
    the run scores itself (``SKIPPED``); none if the file is not there."""
    if not path.exists():
        return []
    row = re.compile(
        r"^\| (?P<policy>[^|]+?) \| (?P<runs>\d+) x (?P<episodes>\d+) \| (?P<iqm>[\d.]+) "
        r"\[(?P<low>[\d.]+), (?P<high>[\d.]+)\] \| (?P<mean>[\d.]+) \| (?P<success>[\d.]+) % "
        r"\| (?P<ret>[\d.]+) \|$"
    )
    out = []
    for line in path.read_text().splitlines():
        m = row.match(line.strip())
        if m is None or m["policy"] in SKIPPED:
            continue
        out.append(
            Reference(
                m["policy"],
                _shown(path),
                int(m["runs"]),
                int(m["episodes"]),
                float(m["mean"]),
                float(m["iqm"]),
                (float(m["low"]), float(m["high"])),
                float(m["success"]) / 100,
                float(m["ret"]),
            )  # fmt: skip
        )
    return out


def study_references(log_dir: pathlib.Path, algo: str, mode: str) -> list[Reference]:
    """The trained agents' rows of every study table ``{algo}_{mode}.json`` under ``log_dir``
    (``agents.study``'s output), the baselines left out."""
    out = []
    for path in sorted(pathlib.Path(log_dir).glob(f"**/{algo}_{mode}.json")):
        try:
            rows = json.loads(path.read_text())
            for r in rows:
                if r["policy"] in SKIPPED:
                    continue
                out.append(
                    Reference(
                        f"{r['policy']}, study {path.parent.name}",
                        _shown(path),
                        int(r["runs"]),
                        int(r["episodes"]) // int(r["runs"]),
                        float(r["mean"]),
                        float(r["iqm"]),
                        (float(r["ci"][0]), float(r["ci"][1])),
                        float(r["success"]),
                        float(r["return"]),
                    )  # fmt: skip
                )
        except (OSError, ValueError, KeyError, TypeError, IndexError):
            continue  # not a study table
    return out


def references(mode: str, algo: str, log_dir: pathlib.Path) -> list[Reference]:
    """The reference rows of a run in action mode ``mode`` (see the module doc)."""
    pump = pump_references() if mode == "pressure" else []
    return pump + study_references(log_dir, algo, mode)


def _shown(path: pathlib.Path) -> str:
    """``path`` relative to the checkout (or the working folder) when inside it."""
    for base in (ROOT, pathlib.Path.cwd()):
        try:
            return str(path.resolve().relative_to(base.resolve()))
        except ValueError:
            continue
    return str(path)


def interval(s: Score) -> tuple[float, float]:
    """The 95 % interval of ``s``'s mean apex error."""
    return s.apex_error - s.apex_error_ci95, s.apex_error + s.apex_error_ci95


def verdict(trained: Score, heuristic: Score) -> str:
    """One line: whether the trained agent beats the tuned heuristic on their held-out episodes, by
    whether the 95 % intervals of their mean apex errors are apart."""
    (a_low, a_high), (b_low, b_high) = interval(trained), interval(heuristic)
    numbers = (
        f"mean apex error {trained.apex_error:.3f} [{a_low:.3f}, {a_high:.3f}] against the tuned "
        f"heuristic's {heuristic.apex_error:.3f} [{b_low:.3f}, {b_high:.3f}] on the same "
        f"{trained.episodes} held-out episodes"
    )
    if a_high < b_low:
        return f"The trained agent wins: {numbers}, the 95 % intervals apart."
    if b_high < a_low:
        return f"The tuned heuristic wins: {numbers}, the 95 % intervals apart."
    return f"No winner: {numbers}, the 95 % intervals overlap."


def board(scores: Sequence[Score], refs: Sequence[Reference], seed: int) -> str:
    """The scoreboard in Markdown: the run's ``scores`` (episodes from seed ``seed``, 95 % interval
    of the mean from Student's t), then ``refs``, labelled as references."""
    lines = [
        "| policy | source | runs x episodes | apex error mean [95 % CI] | apex error IQM [95 % CI] "
        "| apexes within 5 % | return |",
        "|---|---|---:|---:|---:|---:|---:|",
    ]
    for s in scores:
        low, high = interval(s)
        lines.append(
            f"| {s.policy} | this run, held-out seeds {seed}-{seed + s.episodes - 1} | 1 x {s.episodes} | "
            f"{s.apex_error:.3f} [{low:.3f}, {high:.3f}] | | {100 * s.success_rate:.1f} % | "
            f"{s.episode_return:.0f} |"
        )
    for r in refs:
        lines.append(
            f"| reference: {r.policy} | {r.source} | {r.runs} x {r.episodes} | {r.mean:.3f} | "
            f"{r.iqm:.3f} [{r.iqm_ci[0]:.3f}, {r.iqm_ci[1]:.3f}] | {100 * r.success:.1f} % | "
            f"{r.episode_return:.0f} |"
        )
    return "\n".join(lines)
