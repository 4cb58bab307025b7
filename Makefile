# `make demo` and `make test` each create .venv when missing, install searchtrack, then run.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test lint typecheck bench clean

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

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache .mypy_cache .ruff_cache
