"""What ``make train`` does in one run: its wall time (s) and the machine's load while it ran, and
its scoreboard (the trained agent against the tuned heuristic on held-out episodes, with the
reference rows). Runs the Makefile's ``train`` command as written there (its ``$(PY)`` is this
Python), into a new run folder under ``--log-dir``, sampling the 1-minute load average every 10 s.

    python benchmarks/make_train.py   # writes benchmarks/results/make_train.md (about 6-10 min)

The machine is shared: a load above the core count means other processes took part of the cores,
and the wall time is longer than on a quiet machine; the page gives both.
"""

import argparse
import datetime
import os
import pathlib
import shlex
import subprocess
import sys
import threading
import time

from ballenv.files import write_text

ROOT = pathlib.Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"


def train_command(makefile: pathlib.Path = ROOT / "Makefile") -> list[str]:
    """The ``train`` target's command of ``makefile`` (continuation lines joined), ``$(PY)`` this
    Python."""
    lines = makefile.read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("train:"))
    command = ""
    for line in lines[start + 1 :]:
        if not line.startswith("\t"):
            break
        command += line.strip().removesuffix("\\") + " "
        if not line.rstrip().endswith("\\"):
            break
    return shlex.split(command.replace("$(PY)", shlex.quote(sys.executable)))


def with_log_dir(command: list[str], log_dir: pathlib.Path) -> list[str]:
    """``command`` with its ``--log-dir`` set to ``log_dir``."""
    out = list(command)
    if "--log-dir" in out:
        out[out.index("--log-dir") + 1] = str(log_dir)
    else:
        out += ["--log-dir", str(log_dir)]
    return out


def run(command: list[str]) -> tuple[float, list[float], str]:
    """Run ``command`` in the checkout: (wall time in s, the 1-minute load averages sampled every
    10 s while it ran, its standard output)."""
    samples: list[float] = []
    done = threading.Event()

    def sample() -> None:
        while not done.wait(10.0 if samples else 0.0):
            samples.append(os.getloadavg()[0])

    sampler = threading.Thread(target=sample, daemon=True)
    start = time.perf_counter()
    sampler.start()
    finished = subprocess.run(command, cwd=ROOT, stdout=subprocess.PIPE, text=True, check=True)
    wall = time.perf_counter() - start
    done.set()
    sampler.join()
    return wall, samples, finished.stdout


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--log-dir", type=pathlib.Path, default=ROOT / "runs" / "make_train")
    p.add_argument("--out", type=pathlib.Path, default=RESULTS / "make_train.md")
    args = p.parse_args(argv)
    made = train_command()
    command = with_log_dir(made, args.log_dir)
    before = set(args.log_dir.glob("*")) if args.log_dir.exists() else set()
    wall, loads, _ = run(command)
    (folder,) = set(args.log_dir.glob("*")) - before
    scores = (folder / "scores.md").read_text().strip()
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True)
    shown = shlex.join(["python", *made[1:]])
    page = (
        "# make train: the cloned agent against the tuned heuristic\n\n"
        f"`python benchmarks/make_train.py` ran `make train`'s command, `{shown}`, on "
        f"{os.cpu_count()} cores ({datetime.date.today()}, commit {commit.stdout.strip() or '?'}, a warm "
        f"numba cache): **{wall:.0f} s** wall from start to the last file written. The machine's 1-minute "
        f"load average while it ran: {min(loads):.1f}-{max(loads):.1f} (mean {sum(loads) / len(loads):.1f}; "
        f"above {os.cpu_count()}, other processes shared the cores).\n\n"
        f"Its `scores.md` (`{folder.name}`):\n\n{scores}\n"
    )
    write_text(args.out, page)
    print(page)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
