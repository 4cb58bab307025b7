# `make demo` and `make test` each create .venv when missing, install searchtrack, then run.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
TORCH ?= 2.13.0

.PHONY: demo test lint typecheck browser docs bench bench-fast bench-all campaigns clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	# The rl extra trains the RL road planner; torch is pinned to the CPU build (a plain
	# `torch` from the registry is a CUDA build of several GB). About 25 s and 1 GB here.
	$(BIN)/python -m pip install -q 'torch==$(TORCH)'
	$(BIN)/python -m pip install -q -e '.[test,rl,docs]'
	# Compile the numba kernels into numba's on-disk cache now (about 30 s once), so the first
	# solve answers at once instead of compiling inside it.
	$(BIN)/searchtrack warm-up
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/searchtrack mission run searchtrack/data/scenarios/demo.toml --out out/demo
	$(BIN)/searchtrack optw solve searchtrack/data/optw/c101.txt --backend auto --time-limit 20
	$(BIN)/searchtrack optw solve searchtrack/data/optw/r101.txt --backend auto --time-limit 20 --vehicles 2

lint: $(STAMP)
	$(BIN)/ruff check searchtrack tests benchmarks examples

typecheck: $(STAMP)
	$(BIN)/mypy

# The replay-page test drives a headless Chromium: Debian's chromium package (about 20 s to
# install). Where it cannot be installed (no root, no apt) that one test is skipped and says why.
CHROMIUM ?= /usr/bin/chromium

browser:
	@test -x $(CHROMIUM) || { command -v apt-get >/dev/null && [ "$$(id -u)" = 0 ] && \
	  apt-get update -qq >/dev/null && \
	  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null; } || \
	  echo "note: no Chromium at $(CHROMIUM); the replay-page browser test will be skipped"

# The documentation site (mkdocs-material + mkdocstrings), warnings as errors, into out/site.
docs: $(STAMP)
	$(BIN)/mkdocs build --strict --site-dir out/site

# The suite runs on TEST_WORKERS processes (pytest-xdist): about 4 minutes on 2 cores.
TEST_WORKERS ?= 2

test: lint typecheck browser
	$(BIN)/pytest -q -n $(TEST_WORKERS)

# The fast subset (about 5 minutes): every family's table at reduced size and one campaign cell
# per paper; run it on two trees to compare them (see benchmarks/fast.sh).
bench-fast: $(STAMP)
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
