# The two commands of the README:  make train  (the main job)  and  make test  (the test suite).
# Both create .venv and install the package with what they need on first use, from the pinned set
# (constraints.txt): make train the core and the train extra, make test (and every other target)
# all extras.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
# every extra (make test and the other targets); the core and [train] (what make train needs)
STAMP := $(VENV)/.installed
TRAIN_STAMP := $(VENV)/.installed-train
export OPENBLAS_NUM_THREADS := 1

.PHONY: venv compile train demo scenes test test-slow docs bench soak lint format clean clean-cache

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip

$(STAMP): pyproject.toml constraints.txt | $(PY)
	$(PY) -m pip install --quiet -c constraints.txt -e '.[dev,docs,peers,plot,ray,render,train]'
	touch $(STAMP) $(TRAIN_STAMP)

$(TRAIN_STAMP): pyproject.toml constraints.txt | $(PY)
	$(PY) -m pip install --quiet -c constraints.txt -e '.[train]'
	touch $(TRAIN_STAMP)

venv: $(STAMP)

# numba's cache filled for the env and the common scenes ahead of a first run, a process per core
# (ballenv/compile.py)
compile: $(STAMP)
	$(PY) -m ballenv.compile

# PPO started from a clone of the privileged lookahead's demonstrations (60 episodes on training
# seeds), 2,048 bounces of PPO, then the scoreboard on 30 held-out episodes (seeds 10,000 on), the
# learning curve and a clip in runs/ppo_pressure_seed0 (train.py --help; agents/train.py). Measured
# (python benchmarks/make_train.py): 287 s on 2 cores shared at load 3.5, with a warm numba cache;
# the first run after an install also compiles the simulator (10 min in all at load 2.7-5.5)
train: $(TRAIN_STAMP)
	$(PY) train.py --algo ppo --action-mode pressure --warm-start clone --demo-episodes 60 \
		--total-timesteps 2048 --eval-freq 1024 --final-episodes 30 --vec-env subproc --log-dir runs

demo: $(STAMP)
	$(PY) -m ballenv.demo --out out

scenes: $(STAMP)
	$(PY) -m ballenv.scenes all --out docs/figures --no-trajectories

# The replay viewer's browser test (tests/test_viewer.py) needs chromium on the PATH (Debian:
# apt-get install chromium; .ci/run installs it); without it that test skips (fails under CI).
# make test installs nothing outside .venv. pytest-xdist runs the test files on every core, each
# file in one worker (its module fixtures built once). A worker that dies is not replaced: with
# --dist loadfile, pytest-xdist 3.8 can wait forever for a replaced worker's tests; without the
# replacement the run ends at once and names the test the worker died in.
test: $(STAMP)
	$(PY) -m pytest -q -n auto --dist loadfile --max-worker-restart=0

test-slow: $(STAMP)
	$(PY) -m pytest -q -m slow

docs: $(STAMP)  # the documentation site (mkdocs.yml) into site/; a warning fails the build
	NO_MKDOCS_2_WARNING=1 $(PY) -m mkdocs build --strict --site-dir site

bench: $(STAMP)
	$(PY) benchmarks/step_cost.py
	$(PY) benchmarks/linear_solve.py
	$(PY) benchmarks/contact_cost.py
	$(PY) benchmarks/collision_cost.py
	$(PY) benchmarks/work_precision.py
	$(PY) benchmarks/env_throughput.py
	$(PY) benchmarks/cold_start.py

soak: $(STAMP)  # the stability soak (about 15 minutes), not part of test or bench
	$(PY) benchmarks/soak.py
	$(PY) benchmarks/soak.py --episodes 0 --rtol 0.01 --out benchmarks/results/soak_rtol.md

lint: $(STAMP)
	$(PY) -m ruff check .
	$(PY) -m ruff format --check .
	$(PY) -m mypy  # the files and strictness: [tool.mypy] in pyproject.toml

format: $(STAMP)
	$(PY) -m ruff format .
	$(PY) -m ruff check --fix .

clean: clean-cache
	rm -rf $(VENV) out runs site .pytest_cache .ruff_cache .mypy_cache

clean-cache:  # numba's compiled kernels (every source version's) and Python's bytecode
	rm -rf "$${XDG_CACHE_HOME:-$$HOME/.cache}/ballenv/numba"
	find . -name __pycache__ -type d -not -path "./$(VENV)/*" -prune -exec rm -rf {} +
