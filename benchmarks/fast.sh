#!/bin/sh
# The fast benchmark subset (about 5 minutes on 2 cores): OPTW, EMD, SMC-PHD, assignment,
# trajectory, RBPF and radio-filter tables at reduced sizes, then one campaign cell of each
# paper (benchmarks/cells/*.toml, in-process). Run on an idle machine to compare two trees:
#     sh benchmarks/fast.sh [PYTHON] [OUT]        (defaults: .venv/bin/python, out/bench-fast)
set -e
PY=${1:-.venv/bin/python}
OUT=${2:-out/bench-fast}
HERE=$(dirname "$0")
ST=$(dirname "$PY")/searchtrack
mkdir -p "$OUT"
"$PY" "$HERE/optw.py" exact --only c101 r101 rc101 pr01 --limit 20
"$PY" "$HERE/emd.py" --sizes 200 1000 --repeat 3 --no-pot
"$PY" "$HERE/phd.py" --seeds 2 --skip-gm --skip-stonesoup
"$PY" "$HERE/assign.py" --only greedy --instances 50 --seeds 2 --repeats 3
"$PY" "$HERE/trajectory.py" solve --steps 60
"$PY" "$HERE/rbpf.py" --repeats 20 --seeds 2
"$PY" "$HERE/radio_filter.py" --particles 1000 5000
for cell in thesis p000 p002 p003 p004; do
  rm -f "$OUT/$cell.duckdb"
  "$ST" campaign run "$HERE/cells/$cell.toml" --db "$OUT/$cell.duckdb" --workers 0
  "$ST" campaign report "$OUT/$cell.duckdb"
done
