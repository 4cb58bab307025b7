"""Reader and writer of the OPTW text format: good files and every class of malformed input."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from searchtrack.core.errors import ParseError
from searchtrack.plan.optw import read_optw, write_optw

DATA = Path(__file__).parents[2] / "data" / "optw"
BENCH = Path(__file__).parents[3] / "searchtrack" / "data" / "optw"


def test_reads_solomon_c101() -> None:
    """c101 has 100 customers, Tmax 1236 and one-decimal truncated travel times."""
    inst = read_optw(DATA / "c101.txt")
    assert inst.n == 101 and inst.name == "c101"
    assert inst.time_scale == 10
    assert inst.latest_finish == 12360
    assert inst.profit.sum() == 1810
    # customer 1 at (45, 68), depot at (40, 50): sqrt(25 + 324) = 18.68.. -> 18.6
    assert inst.travel[0, 1] == 186
    assert inst.service[1] == 900 and inst.open[1] == 9120 and inst.close[1] == 9670


def test_reads_tiny_hand_made_file() -> None:
    """The tiny file's fields land where they belong, with exact truncated distances."""
    inst = read_optw(DATA / "tiny5.txt")
    assert inst.n == 6
    assert inst.travel[0, 1] == 50  # 3-4-5 triangle, exactly 5.0
    assert inst.travel[1, 2] == 50
    assert inst.travel[0, 2] == 100
    assert list(inst.profit) == [0, 10, 20, 5, 7, 99]


def test_reads_every_shipped_benchmark() -> None:
    """All 39 one-vehicle benchmark files parse; Cordeau files get two-decimal times."""
    files = sorted([*BENCH.glob("solomon100/*.txt"), *BENCH.glob("cordeau/*.txt")])
    assert len(files) == 39
    for f in files:
        inst = read_optw(f)
        assert inst.time_scale == (100 if f.parent.name == "cordeau" else 10)
        assert np.all(inst.travel >= 0)


def test_round_trip(tmp_path: Path) -> None:
    """Writing and reading back gives the same instance."""
    inst = read_optw(DATA / "c101.txt")
    write_optw(inst, tmp_path / "c.txt")
    back = read_optw(tmp_path / "c.txt")
    for field in ("travel", "service", "open", "close", "profit"):
        assert np.array_equal(getattr(inst, field), getattr(back, field)), field


GOOD = (DATA / "tiny5.txt").read_text().splitlines()


def _with(lines: list[str]) -> str:
    return "\n".join(lines) + "\n"


MALFORMED = {
    "missing field": (_with([*GOOD[:3], " 1 3.00 4.00 1.00 10.00 1 1 1 0", *GOOD[4:]]), 4, "a"),
    "extra field": (_with([*GOOD[:3], " 1 3.00 4.00 1.00 10.00 1 1 1 0 50 7", *GOOD[4:]]), 4, "a"),
    "not a number": (_with([*GOOD[:3], " 1 3.00 four 1.00 10.00 1 1 1 0 50", *GOOD[4:]]), 4, "y"),
    "too few vertices": (_with(GOOD[:-1]), 7, "N"),
    "too many vertices": (_with([*GOOD, " 6 1.00 1.00 0.00 1.00 1 0 0 100"]), 9, "N"),
    "close before open": (_with([*GOOD[:3], " 1 3.00 4.00 1.00 10.00 1 1 1 60 50", *GOOD[4:]]),
                          4, "C"),
    "negative time": (_with([*GOOD[:3], " 1 3.00 4.00 -1.00 10.00 1 1 1 0 50", *GOOD[4:]]), 4,
                      "d"),
    "negative profit": (_with([*GOOD[:3], " 1 3.00 4.00 1.00 -10.00 1 1 1 0 50", *GOOD[4:]]), 4,
                        "S"),
    "duplicate id": (_with([*GOOD[:4], " 1 6.00 8.00 1.00 20.00 1 1 1 10 60", *GOOD[5:]]), 5, "i"),
    "bad header": (_with(["4 1 5", *GOOD[1:]]), 1, "k v N t"),
    "non-integer count": (_with([*GOOD[:3], " 1 3.00 4.00 1.00 10.00 1 x 1 0 50", *GOOD[4:]]), 4,
                          "a"),
    "infinite value": (_with([*GOOD[:3], " 1 3.00 inf 1.00 10.00 1 1 1 0 50", *GOOD[4:]]), 4, "y"),
}


@pytest.mark.parametrize("case", sorted(MALFORMED))
def test_malformed_input_names_file_line_and_field(case: str, tmp_path: Path) -> None:
    """Each malformed-input class raises a ParseError naming file, line and field."""
    text, line, field = MALFORMED[case]
    path = tmp_path / "bad.txt"
    path.write_text(text)
    with pytest.raises(ParseError) as info:
        read_optw(path)
    err = info.value
    assert err.path == str(path) and err.line == line and err.field == field, str(err)
    assert "bad.txt" in str(err) and f"line {line}" in str(err)


def test_missing_and_empty_files(tmp_path: Path) -> None:
    """A missing file and an empty file get clear errors, not tracebacks from inside."""
    with pytest.raises(ParseError, match="no such file"):
        read_optw(tmp_path / "nope.txt")
    (tmp_path / "empty.txt").write_text("")
    with pytest.raises(ParseError, match="too short"):
        read_optw(tmp_path / "empty.txt")


def test_too_many_decimals_for_precision(tmp_path: Path) -> None:
    """A window finer than the travel-time precision is rejected, not silently rounded."""
    lines = list(GOOD)
    lines[3] = " 1 3.00 4.00 1.00 10.00 1 1 1 0.05 50"
    (tmp_path / "fine.txt").write_text(_with(lines))
    with pytest.raises(ParseError, match="decimals"):
        read_optw(tmp_path / "fine.txt")
