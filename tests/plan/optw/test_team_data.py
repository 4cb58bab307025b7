"""Shipped team-OPTW instances (Solomon c2/r2/rc2, Cordeau pr11–pr20) and the TOPTW BKV table.

Checks that every file parses, has the documented size, horizon and precision, matches the sha256 in
the folder's README, and that ``benchmarks/toptw_best_known.csv`` is well formed and consistent
with the instances and with the proven single-vehicle optima.
"""

from __future__ import annotations

import csv
import hashlib
import itertools
import re
from functools import cache
from pathlib import Path

import pytest

import searchtrack
from searchtrack.plan.optw import read_optw

PACKAGE_DATA = Path(searchtrack.__file__).parent / "data" / "optw"
TEAMS = PACKAGE_DATA.parent / "toptw"
REPO = Path(__file__).parents[3]
BKV_CSV = REPO / "benchmarks" / "toptw_best_known.csv"

CORDEAU_CUSTOMERS = {
    "pr11": 48, "pr12": 96, "pr13": 144, "pr14": 192, "pr15": 240,
    "pr16": 288, "pr17": 72, "pr18": 144, "pr19": 216, "pr20": 288,
}
SOLOMON = (
    [f"c20{k}" for k in range(1, 9)]
    + [f"r2{k:02d}" for k in range(1, 12)]
    + [f"rc20{k}" for k in range(1, 9)]
)
#: Relative path -> number of customers, for every file that must be shipped.
EXPECTED = {
    **{f"solomon200/{n}.txt": 100 for n in SOLOMON},
    **{f"cordeau/{n}.txt": c for n, c in CORDEAU_CUSTOMERS.items()},
}
#: Depot closing time (Tmax) in time units, by name prefix.
TMAX = {"c": 3390, "r": 1000, "rc": 960, "pr": 1000}

_ROW = re.compile(
    r"^\|\s*((?:solomon200|cordeau)/\w+\.txt)\s*\|\s*(\d+)\s*\|\s*([0-9a-f]{64})\s*\|$"
)


def _prefix(name: str) -> str:
    return name.rstrip("0123456789")


@cache
def _readme_table() -> dict[str, tuple[int, str]]:
    table: dict[str, tuple[int, str]] = {}
    for line in (TEAMS / "README.md").read_text(encoding="utf-8").splitlines():
        m = _ROW.match(line.strip())
        if m:
            assert m.group(1) not in table, f"{m.group(1)} listed twice in README"
            table[m.group(1)] = (int(m.group(2)), m.group(3))
    return table


def test_exactly_the_expected_files_are_shipped() -> None:
    """27 Solomon 200-series and 10 Cordeau files, nothing missing and nothing extra."""
    shipped = {p.relative_to(TEAMS).as_posix() for p in TEAMS.glob("*/*.txt")}
    assert shipped == set(EXPECTED)
    assert len(shipped) == 37


def test_readme_lists_every_file_with_its_size() -> None:
    """The README checksum table covers exactly the shipped files, with the right sizes."""
    table = _readme_table()
    assert set(table) == set(EXPECTED)
    for rel, (customers, _) in table.items():
        assert customers == EXPECTED[rel], rel


@pytest.mark.parametrize("rel", sorted(EXPECTED))
def test_sha256_matches_readme(rel: str) -> None:
    """Each file is byte-for-byte the one documented (and verified) in the README."""
    digest = hashlib.sha256((TEAMS / rel).read_bytes()).hexdigest()
    assert digest == _readme_table()[rel][1]


@pytest.mark.parametrize("rel", sorted(EXPECTED))
def test_parses_with_documented_size_horizon_and_precision(rel: str) -> None:
    """read_optw reads every file: customer count, Tmax and time scale as documented."""
    path = TEAMS / rel
    name = path.stem
    inst = read_optw(path, vehicles=4)
    assert inst.name == name
    assert inst.n == EXPECTED[rel] + 1
    assert inst.vehicles == 4
    cordeau = rel.startswith("cordeau/")
    assert inst.time_scale == (100 if cordeau else 10)
    assert inst.latest_finish == TMAX[_prefix(name)] * inst.time_scale
    assert inst.profit[0] == 0
    assert (inst.profit[1:] > 0).all()
    assert inst.open[0] == 0


def test_solomon_200_series_share_their_customers() -> None:
    """Within c2, r2 and rc2 only the time windows differ (Solomon's design)."""
    groups: dict[str, list[Path]] = {}
    for name in SOLOMON:
        groups.setdefault(_prefix(name), []).append(TEAMS / "solomon200" / f"{name}.txt")
    for paths in groups.values():
        first = read_optw(paths[0])
        for p in paths[1:]:
            other = read_optw(p)
            assert (other.travel == first.travel).all(), p.name
            assert (other.profit == first.profit).all(), p.name
            assert (other.service == first.service).all(), p.name


# --- best known values ----------------------------------------------------------------------


def _known_instance_files() -> dict[str, Path]:
    files = {p.stem: p for p in TEAMS.glob("*/*.txt")}
    files.update({p.stem: p for p in PACKAGE_DATA.glob("*/*.txt")})
    return files


@cache
def _bkv_rows() -> list[dict[str, str]]:
    with BKV_CSV.open(newline="", encoding="utf-8") as f:
        reader = csv.DictReader(f)
        assert reader.fieldnames == [
            "instance", "vehicles", "best_known", "source", "where", "proven",
        ]
        return list(reader)


def _optima() -> dict[str, int]:
    """Proven m = 1 optima from the packaged optima.csv."""
    out: dict[str, int] = {}
    with (PACKAGE_DATA / "optima.csv").open(newline="", encoding="utf-8") as f:
        for row in csv.DictReader(f):
            if row["status"] == "proven":
                value = int(row["optimum"])
                assert out.setdefault(row["instance"], value) == value, row["instance"]
    return out


def test_bkv_csv_is_well_formed() -> None:
    """Unique (instance, m), m in 1..4, positive integer values, sources given."""
    rows = _bkv_rows()
    assert rows
    keys = [(r["instance"], int(r["vehicles"])) for r in rows]
    assert len(keys) == len(set(keys))
    for r in rows:
        assert re.fullmatch(r"(c|r|rc)[12]\d\d|pr\d\d", r["instance"]), r
        assert 1 <= int(r["vehicles"]) <= 4, r
        assert r["best_known"].isdigit() and int(r["best_known"]) > 0, r
        assert r["source"].strip() and r["where"].strip(), r
        assert r["proven"] in {"yes", "unknown"}, r


def test_bkv_instances_exist() -> None:
    """Every instance named is shipped with the package."""
    files = _known_instance_files()
    for r in _bkv_rows():
        assert r["instance"] in files, r["instance"]


def test_bkv_not_above_total_profit_and_non_decreasing_in_m() -> None:
    """A BKV never exceeds the sum of profits, and more vehicles never collect less."""
    files = _known_instance_files()
    by_inst: dict[str, dict[int, int]] = {}
    for r in _bkv_rows():
        by_inst.setdefault(r["instance"], {})[int(r["vehicles"])] = int(r["best_known"])
    for name, values in by_inst.items():
        if name in files:
            total = read_optw(files[name]).profit.sum()
            assert max(values.values()) <= total, name
        ms = sorted(values)
        for a, b in itertools.pairwise(ms):
            assert values[a] <= values[b], (name, a, b)


def test_single_vehicle_bkv_agrees_with_proven_optima() -> None:
    """m = 1 BKVs never beat a proven optimum, and rows marked proven equal it."""
    optima = _optima()
    assert optima
    for r in _bkv_rows():
        if int(r["vehicles"]) != 1 or r["instance"] not in optima:
            continue
        bkv, opt = int(r["best_known"]), optima[r["instance"]]
        assert bkv <= opt, (r["instance"], bkv, opt)
        if r["proven"] == "yes":
            assert bkv == opt, r["instance"]


def test_bounds_csv_lists_only_bounds_below_the_list() -> None:
    """``benchmarks/toptw_bounds.csv``: unique rows of shipped instances, each an integer bound
    strictly below the listed best known value (the point of the file), its backend named."""
    bkv = {(r["instance"], int(r["vehicles"])): int(r["best_known"]) for r in _bkv_rows()}
    with (REPO / "benchmarks" / "toptw_bounds.csv").open(encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert rows
    keys = [(r["instance"], int(r["vehicles"])) for r in rows]
    assert len(keys) == len(set(keys))
    for r, key in zip(rows, keys, strict=True):
        assert r["bound"].isdigit() and int(r["bound"]) < bkv[key], r
        assert r["optimal"] in {"yes", "no"} and r["backend"] in {"labelling", "bp"}, r
        assert float(r["time_limit_s"]) > 0 and r["command"].strip(), r
