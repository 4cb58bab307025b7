# `make demo` and `make test` each create .venv when missing, install searchtrack, then run.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test lint typecheck bench bench-all clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e '.[test]'
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/searchtrack mission run searchtrack/data/scenarios/demo.toml --out out/demo
	$(BIN)/searchtrack optw solve searchtrack/data/optw/c101.txt --backend auto --time-limit 20
	$(BIN)/searchtrack optw solve searchtrack/data/optw/r101.txt --backend auto --time-limit 20 --vehicles 2

lint: $(STAMP)
	$(BIN)/ruff check searchtrack tests benchmarks examples

typecheck: $(STAMP)
	$(BIN)/mypy

test: lint typecheck
	$(BIN)/pytest -q

bench: $(STAMP)
	$(BIN)/python -m pip install -q -e '.[test,bench]'
	$(BIN)/python benchmarks/optw.py

# Every benchmark table in turn (about two hours on 2 cores; run on an idle machine).
bench-all: bench
	$(BIN)/python benchmarks/emd.py --graph osm
	$(BIN)/python benchmarks/association.py
	$(BIN)/python benchmarks/osm_reader.py
	$(BIN)/python benchmarks/road_missions.py step
	$(BIN)/python benchmarks/road_missions.py exp1
	$(BIN)/python benchmarks/road_missions.py exp2
	$(BIN)/python benchmarks/phd.py
	$(BIN)/python benchmarks/assign.py
	$(BIN)/python benchmarks/phd_search_experiments.py ideal
	$(BIN)/python benchmarks/phd_search_experiments.py search
	$(BIN)/python benchmarks/phd_search_experiments.py search --refinement mi
	$(BIN)/python benchmarks/phd_search_experiments.py horizon
	$(BIN)/python benchmarks/phd_tracking_experiments.py track
	$(BIN)/python benchmarks/gp_motion.py
	$(BIN)/python benchmarks/trajectory.py all

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache .mypy_cache .ruff_cache
