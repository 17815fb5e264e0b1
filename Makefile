# The two commands of the README:  make demo  (the main job)  and  make test  (the test suite).
# Both create .venv and install the package with what they need on first use.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
export OPENBLAS_NUM_THREADS := 1

.PHONY: venv demo test test-slow bench soak lint format clean

$(STAMP): pyproject.toml constraints.txt
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -c constraints.txt -e '.[dev,plot,render,train]'
	touch $(STAMP)

venv: $(STAMP)

demo: $(STAMP)
	$(PY) -m ballenv.demo --out out

test: $(STAMP)
	$(PY) -m pytest -q

test-slow: $(STAMP)
	$(PY) -m pytest -q -m slow

bench: $(STAMP)
	$(PY) benchmarks/step_cost.py
	$(PY) benchmarks/linear_solve.py
	$(PY) benchmarks/contact_cost.py
	$(PY) benchmarks/collision_cost.py
	$(PY) benchmarks/work_precision.py
	$(PY) benchmarks/env_throughput.py

soak: $(STAMP)  # the stability soak (about 10 minutes), not part of test or bench
	$(PY) benchmarks/soak.py

lint: $(STAMP)
	$(PY) -m ruff check .
	$(PY) -m ruff format --check .

format: $(STAMP)
	$(PY) -m ruff format .
	$(PY) -m ruff check --fix .

clean:
	rm -rf $(VENV) out .pytest_cache .ruff_cache
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
