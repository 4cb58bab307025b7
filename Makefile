# `make demo` and `make test` each create .venv when missing, install what their job needs, then
# run: `make demo` the package alone; `make test` also the test, docs and (CPU-only) RL tools.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
TEST_STAMP := $(VENV)/.installed-test
TORCH ?= 2.13.0
TORCH_CPU_INDEX ?= https://download.pytorch.org/whl/cpu

.PHONY: demo test lint typecheck browser docs bench bench-fast bench-all campaigns clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e .
	# Compile the numba kernels into numba's on-disk cache now (one process per core, about 50 s
	# once on 2 cores), so the first solve answers at once instead of compiling inside it.
	$(BIN)/searchtrack warm-up
	touch $(STAMP)

# The rl extra (the RL road planner's trainer) runs on PyTorch, and a plain `torch` from the
# registry is, on Linux, a CUDA build with several GB of GPU libraries. Only the CPU build is
# asked for (the `+cpu` version exists only as a local wheel or on PyTorch's CPU index, so pip
# can never fall back to the CUDA build); where neither is reachable the RL extra is left out
# and the trainer's tests are skipped, each saying why.
$(TEST_STAMP): $(STAMP)
	$(BIN)/python -m pip install -q -e '.[test,docs]'
	$(BIN)/python -m pip install -q 'torch==$(TORCH)+cpu' 2>/dev/null || \
	  $(BIN)/python -m pip install -q --timeout 20 --retries 1 --extra-index-url $(TORCH_CPU_INDEX) \
	    'torch==$(TORCH)+cpu' || \
	  echo "note: no CPU build of torch reachable; the RL trainer's tests will be skipped"
	$(BIN)/python -c 'import torch' 2>/dev/null && $(BIN)/python -m pip install -q -e '.[rl]' || true
	touch $(TEST_STAMP)

demo: $(STAMP)
	$(BIN)/searchtrack mission run searchtrack/data/scenarios/demo.toml --out out/demo
	$(BIN)/searchtrack optw solve searchtrack/data/optw/c101.txt --backend auto --time-limit 20
	$(BIN)/searchtrack optw solve searchtrack/data/optw/r101.txt --backend auto --time-limit 20 --vehicles 2

lint: $(TEST_STAMP)
	$(BIN)/ruff check searchtrack tests benchmarks examples

typecheck: $(TEST_STAMP)
	$(BIN)/mypy

# The replay-page test drives a headless Chromium: Debian's chromium package (about 20 s to
# install). Where it cannot be installed (no root, no apt) that one test is skipped and says why.
CHROMIUM ?= /usr/bin/chromium

browser:
	@test -x $(CHROMIUM) || { command -v apt-get >/dev/null && [ "$$(id -u)" = 0 ] && \
	  apt-get update -qq >/dev/null && \
	  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null; } || \
	  echo "note: no Chromium at $(CHROMIUM); the replay-page browser test will be skipped"

# The documentation site (mkdocs-material + mkdocstrings), warnings as errors, into out/site;
# the paper pages' figures are drawn first by docs/_ext/gallery.py (kept in out/gallery).
docs: $(TEST_STAMP)
	$(BIN)/mkdocs build --strict --site-dir out/site

# The suite runs on TEST_WORKERS processes (pytest-xdist; the tests that share the built
# documentation site stay on one of them): about 3 minutes on 2 cores.
TEST_WORKERS ?= 2

# mypy (about 25 s on one core, cold in a fresh clone) runs beside the suite rather than before
# it; either failing fails the target.
test: lint browser
	$(BIN)/mypy & mypy=$$!; \
	$(BIN)/pytest -q -n $(TEST_WORKERS) --dist loadgroup; status=$$?; \
	wait $$mypy || status=1; exit $$status

# The fast subset (about 5 minutes): every family's table at reduced size and one campaign cell
# per paper; run it on two trees to compare them (see benchmarks/fast.sh).
bench-fast: $(TEST_STAMP)
	sh benchmarks/fast.sh $(BIN)/python out/bench-fast

bench: $(STAMP)
	$(BIN)/python -m pip install -q -e '.[test,bench]'
	$(BIN)/python benchmarks/optw.py

# Every benchmark table in turn (about two hours on 2 cores; run on an idle machine). The Monte
# Carlo experiments are campaigns: resumable, their rows in out/campaigns/*.duckdb, reports and
# figures beside them; the scripts left are timing and solver-quality tables.
CAMPAIGNS := thesis_exp1 thesis_exp2 phd_standard p003_tracking p004_search p004_search_mi p004_search_fov \
	p004_horizon p000_planners p000_osm p000_osm_city

bench-all: bench campaigns
	$(BIN)/python benchmarks/emd.py --graph osm
	$(BIN)/python benchmarks/association.py
	$(BIN)/python benchmarks/osm_reader.py
	$(BIN)/python benchmarks/road_missions.py step
	$(BIN)/python benchmarks/phd.py
	$(BIN)/python benchmarks/assign.py
	$(BIN)/python benchmarks/phd_search_experiments.py ideal
	$(BIN)/python benchmarks/gp_motion.py
	$(BIN)/python benchmarks/trajectory.py all
	$(BIN)/python benchmarks/campaign.py

campaigns: $(STAMP)
	mkdir -p out/campaigns
	for c in $(CAMPAIGNS); do \
	  $(BIN)/searchtrack campaign run searchtrack/data/campaigns/$$c.toml --db out/campaigns/$$c.duckdb && \
	  $(BIN)/searchtrack campaign report out/campaigns/$$c.duckdb --out out/campaigns || exit $$?; \
	done

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache .mypy_cache .ruff_cache
