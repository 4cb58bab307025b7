"""``searchtrack track-roads``: DETECTIONS.json in, EST.json out (atomically); status 2 naming
the key of a bad file with nothing written; Ctrl-C keeps the steps filtered and exits 130."""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest

import searchtrack.cli as cli
from searchtrack.core.interrupt import clear_stop, request_stop
from searchtrack.estimate.road_rbpf import RoadRBPF
from tests.sim.road_particles.test_track_job import BAD_INPUTS, EXAMPLE, GOOD, mutated, write_json

Main = Callable[[list[str]], int]


@pytest.fixture
def main() -> Iterator[Main]:
    """``searchtrack.cli.main``, the stop flag cleared afterwards."""
    clear_stop()
    yield cli.main
    clear_stop()


def test_writes_estimates_for_every_step(tmp_path: Path, main: Main,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    """The shipped example: status 0, one estimate and entropy per step and target, no
    temporary file left beside EST.json."""
    out = tmp_path / "results" / "est.json"
    assert main(["track-roads", str(EXAMPLE), "--out", str(out)]) == 0
    assert "200 of 200 steps" in capsys.readouterr().out
    est = json.loads(out.read_text(encoding="utf-8"))
    assert np.shape(est["estimates"]) == (200, 2, 2) and np.shape(est["entropy"]) == (200, 2)
    assert len(est["combined_entropy"]) == 200 and est["ms_per_step"] > 0.0
    assert est["interrupted"] is False
    assert est["combined_entropy"][-1] < est["combined_entropy"][0]
    assert [p.name for p in out.parent.iterdir()] == ["est.json"]


def test_seed_option_overrides_the_file(tmp_path: Path, main: Main) -> None:
    """``--seed`` replaces the file's seed: the same seed gives the same EST.json, another seed
    another one."""
    doc = write_json(tmp_path, dict(GOOD, seed=1))
    runs = {}
    for name, extra in (("file", []), ("one", ["--seed", "1"]), ("two", ["--seed", "2"])):
        out = tmp_path / f"{name}.json"
        assert main(["track-roads", str(doc), "--out", str(out), *extra]) == 0
        runs[name] = json.loads(out.read_text(encoding="utf-8"))["estimates"]
    assert runs["file"] == runs["one"] != runs["two"]


@pytest.mark.parametrize(("path", "value", "field"), BAD_INPUTS,
                         ids=[f"{p}={v!r}"[:60] for p, v, _ in BAD_INPUTS])
def test_bad_files_exit_2_and_write_nothing(tmp_path: Path, main: Main,
                                            capsys: pytest.CaptureFixture[str], path: str,
                                            value: object, field: str) -> None:
    """A malformed DETECTIONS.json: status 2, one line naming the file and the key, no
    EST.json (an existing one is left as it was)."""
    bad = write_json(tmp_path, mutated(path, value))
    fresh, kept = tmp_path / "new" / "est.json", tmp_path / "old.json"
    kept.write_text("old", encoding="utf-8")
    for out in (fresh, kept):
        assert main(["track-roads", str(bad), "--out", str(out)]) == 2
        err = capsys.readouterr().err
        assert f"field '{field}'" in err and str(bad) in err.replace("\n", "")
    assert not fresh.parent.exists() and kept.read_text(encoding="utf-8") == "old"


def test_unreadable_inputs_and_bad_options(tmp_path: Path, main: Main,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    """Invalid JSON, a missing file and an output path that is a folder exit with 2 (the
    output checked before the input is read); bad options are argparse errors."""
    broken = tmp_path / "broken.json"
    broken.write_text('{"dt": [', encoding="utf-8")
    out = str(tmp_path / "est.json")
    assert main(["track-roads", str(broken), "--out", out]) == 2
    assert "line 1" in capsys.readouterr().err
    assert main(["track-roads", str(tmp_path / "missing.json"), "--out", out]) == 2
    assert "no such file" in capsys.readouterr().err
    assert main(["track-roads", str(broken), "--out", str(tmp_path)]) == 2
    assert "--out" in capsys.readouterr().err
    for argv in (["--seed", "-1"], ["--seed", "x"], []):
        with pytest.raises(SystemExit) as stop:
            main(["track-roads", str(EXAMPLE), *argv, *(["--out", out] if argv else [])])
        assert stop.value.code == 2
        assert ("seed" if argv else "--out") in capsys.readouterr().err
    assert not Path(out).exists()


def test_ctrl_c_keeps_the_steps_filtered(tmp_path: Path, main: Main,
                                         monkeypatch: pytest.MonkeyPatch,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    """A stop request (the first Ctrl-C) during step 4: status 130, EST.json holds the 5 steps
    filtered, marked interrupted."""
    predict = RoadRBPF.predict
    calls = []

    def predict_then_stop(self: RoadRBPF, dt_s: float, rng: np.random.Generator) -> None:
        calls.append(dt_s)
        if len(calls) == 5:
            request_stop()
        predict(self, dt_s, rng)

    monkeypatch.setattr(RoadRBPF, "predict", predict_then_stop)
    out = tmp_path / "est.json"
    assert main(["track-roads", str(EXAMPLE), "--out", str(out)]) == 130
    assert "interrupted" in capsys.readouterr().err
    est = json.loads(out.read_text(encoding="utf-8"))
    assert est["interrupted"] is True and len(est["estimates"]) == 5 == len(calls)
