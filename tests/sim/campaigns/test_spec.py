"""Campaign files: validation errors name the file and dotted key; run keys are stable."""

from __future__ import annotations

from pathlib import Path

import pytest

import searchtrack
from searchtrack.core.errors import ParseError
from searchtrack.sim.campaigns.spec import read_spec, run_key
from tests.sim.campaigns.toy import toy_spec, write_toy_file


def test_a_file_expands_to_grid_times_seeds(tmp_path: Path) -> None:
    """Two values × two seeds give four runs with every parameter filled in."""
    spec = read_spec(write_toy_file(tmp_path, '[settings]\nsleep_s = 0\n[grid]\nvalue = [1, 2]\n'))
    runs = spec.runs()
    assert [(r.params["value"], r.seed) for r in runs] == [(1.0, 0), (1.0, 1), (2.0, 0), (2.0, 1)]
    assert runs[0].params == {"sleep_s": 0.0, "fail": False, "value": 1.0}
    assert spec.metrics == ("result", "seed_echo")


def test_keys_are_stable_and_distinct() -> None:
    """The same run has the same key every time; different runs have different keys."""
    a, b = toy_spec().runs(), toy_spec().runs()
    assert [r.key for r in a] == [r.key for r in b]
    assert len({r.key for r in a}) == len(a) == 6
    assert a[0].key == run_key("toy", a[0].params, a[0].seed)


def test_keys_change_with_the_package_version(monkeypatch: pytest.MonkeyPatch) -> None:
    """A new package version gives new keys (its results are not mixed with the old)."""
    before = toy_spec().runs()[0].key
    monkeypatch.setattr(searchtrack, "__version__", "9.9.9")
    assert toy_spec().runs()[0].key != before


@pytest.mark.parametrize(("body", "head", "field"), [
    ("[grid]\nvalue = [1]\n", 'name = "x"\nexperiment = "nope"\nseeds = [1]\n', "experiment"),
    ("[grid]\ncolour = [1]\n", None, "grid.colour"),
    ('[grid]\nvalue = ["big"]\n', None, "grid.value"),
    ("[grid]\nvalue = []\n", None, "grid.value"),
    ("[grid]\n", None, "grid"),
    ("[settings]\nfail = 3\n[grid]\nvalue = [1]\n", None, "settings.fail"),
    ("[grid]\nvalue = [1]\n", 'name = "x"\nexperiment = "toy"\nseeds = [1, 1]\n', "seeds"),
    ("[grid]\nvalue = [1]\n", 'name = "x"\nexperiment = "toy"\nseeds = {count = 0}\n',
     "seeds.count"),
    ("[grid]\nvalue = [1]\n", 'name = "x"\nexperiment = "toy"\n', "seeds"),
    ("[grid]\nvalue = [1]\nmetrics = 1\n", None, "grid.metrics"),
    ('metrics = ["speed"]\n[grid]\nvalue = [1]\n', None, "metrics"),
    ("colour = 1\n[grid]\nvalue = [1]\n", None, "colour"),
])
def test_bad_files_name_the_key(tmp_path: Path, body: str, head: str | None, field: str) -> None:
    """Each malformed file raises a ParseError naming the file and the dotted key."""
    path = write_toy_file(tmp_path, body) if head is None else write_toy_file(tmp_path, body, head)
    with pytest.raises(ParseError) as err:
        read_spec(path)
    assert err.value.field == field
    assert str(path) in str(err.value)


def test_malformed_toml_names_the_line(tmp_path: Path) -> None:
    """Text that is not TOML is reported with its line."""
    path = write_toy_file(tmp_path, "[grid\n")
    with pytest.raises(ParseError, match="line 4"):
        read_spec(path)


def test_cells_vary_parameters_together(tmp_path: Path) -> None:
    """``grid.cells`` lists tables of parameters that vary together: one axis of the product,
    not the product of their values."""
    path = write_toy_file(tmp_path, "[grid]\ncells = [{value = 1.0, sleep_s = 0.0}, "
                          "{value = 2.0, sleep_s = 0.01}]\nfail = [false, true]\n")
    runs = read_spec(path).runs()
    points = {(r.params["value"], r.params["sleep_s"], r.params["fail"]) for r in runs}
    assert points == {(1.0, 0.0, False), (1.0, 0.0, True), (2.0, 0.01, False),
                      (2.0, 0.01, True)}
    assert len(runs) == 4 * 2 and len({r.key for r in runs}) == 8


@pytest.mark.parametrize(("cells", "field"), [
    ("[{value = 1.0}, {sleep_s = 0.1}]", "grid.cells[1]"),
    ("[{value = 1.0}, {value = 1.0}]", "grid.cells"),
    ("[{value = \"x\"}]", "grid.cells[0].value"),
    ("[{fail = true}]", "grid.cells[0].fail"),
    ("[1.0, 2.0]", "grid.cells"),
])
def test_bad_cells_name_the_key(tmp_path: Path, cells: str, field: str) -> None:
    """Tables with other keys, a repeated table, a wrong type, a parameter also varied
    elsewhere, or values that are not tables are refused naming the key."""
    path = write_toy_file(tmp_path, f"[grid]\ncells = {cells}\nfail = [false]\n")
    with pytest.raises(ParseError) as info:
        read_spec(path)
    assert info.value.field == field, str(info.value)
