"""``searchtrack radio simulate|track|mission``: files in and out, bad input named with exit
status 2 and nothing written, Ctrl-C keeping what was done (130)."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

import searchtrack.cli as cli
from searchtrack.core.interrupt import clear_stop, request_stop


@pytest.fixture(autouse=True)
def _clean_stop() -> Iterator[None]:
    clear_stop()
    yield
    clear_stop()


def _scenario(tmp: Path, extra: str = "") -> str:
    path = tmp / "short.toml"
    path.write_text(f"duration_s = 6.0\n{extra}", encoding="utf-8")
    return str(path)


@pytest.fixture
def recorded(tmp_path: Path) -> Path:
    out = tmp_path / "run.npz"
    assert cli.main(["radio", "simulate", _scenario(tmp_path), "--seed", "2", "--out",
                     str(out), "--truth", str(tmp_path / "truth.json"), "--noise",
                     "0.01"]) == 0
    return out


def test_simulate_then_track(recorded: Path, tmp_path: Path,
                             capsys: pytest.CaptureFixture[str]) -> None:
    truth = json.loads((tmp_path / "truth.json").read_text())
    assert len(truth["times_s"]) == 6 and len(truth["tags"]) == 4
    for name in ("tbd", "dtt"):
        out = tmp_path / f"{name}.json"
        assert cli.main(["radio", "track", str(recorded), "--filter", name, "--particles",
                         "100", "--out", str(out)]) == 0
        est = json.loads(out.read_text())
        assert len(est["estimates"]) == 6 and est["filter"] == name
    assert "6 of 6 intervals" in capsys.readouterr().out


def test_mission_writes_log_and_figures(tmp_path: Path) -> None:
    folder = tmp_path / "mission"
    assert cli.main(["radio", "mission", _scenario(tmp_path), "--planner", "renyi",
                     "--particles", "100", "--plan-particles", "30", "--horizon", "1",
                     "--out", str(folder)]) == 0
    assert sorted(p.name for p in folder.iterdir()) == ["map.png", "mission.json", "ospa.png"]
    doc = json.loads((folder / "mission.json").read_text())
    assert doc["steps"] == 6 and doc["planner"] == "renyi"


def test_mission_options_beyond_the_paper(tmp_path: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    """Calibration, exploration, spread inflation, re-planning on a breach, roughening and the
    time-domain tempering reach the run; the summary names the range and the Fig. 5 scores."""
    folder = tmp_path / "mission"
    assert cli.main(["radio", "mission", _scenario(tmp_path), "--particles", "100",
                     "--plan-particles", "30", "--horizon", "1", "--calibration", "unscaled",
                     "--explore", "0.3", "--spread-inflation", "1.5", "--replan-on-breach",
                     "--roughening", "2", "--measurement", "time", "--out", str(folder)]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "calibration gain 0 dB" in out and "0 dB per-cell SNR at 37" in out
    assert "objects detected" in out and "cardinality within 0.5 of the truth" in out
    summary = json.loads((folder / "mission.json").read_text())["summary"]
    assert {"objects_detected", "cardinality_hit_fraction", "breach_replans"} <= set(summary)


@pytest.mark.parametrize(("args", "named"), [
    (["--r-min", "-5"], "r_min"),
    (["--p-void", "1.5"], "p_void"),
])
def test_unsafe_parameters_are_refused(tmp_path: Path, args: list[str], named: str,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    folder = tmp_path / "out"
    code = cli.main(["radio", "mission", _scenario(tmp_path), "--particles", "50",
                     "--out", str(folder), *args])
    assert code == 2 and named in capsys.readouterr().err
    assert not any(folder.glob("*"))


@pytest.mark.parametrize(("args", "named"), [
    (["--roughening", "-1"], "--roughening"),
    (["--roughening", "nan"], "--roughening"),
    (["--spread-inflation", "101"], "--spread-inflation"),
    (["--spread-inflation", "-0.5"], "--spread-inflation"),
])
def test_out_of_range_options_are_refused_when_parsed(
        tmp_path: Path, args: list[str], named: str,
        capsys: pytest.CaptureFixture[str]) -> None:
    """The command line refuses a value its settings would: one line naming the option, exit
    status 2, before the scenario is even read (it does not exist here)."""
    folder = tmp_path / "out"
    with pytest.raises(SystemExit) as done:
        cli.main(["radio", "mission", str(tmp_path / "none.toml"), "--out", str(folder), *args])
    err = capsys.readouterr().err
    assert done.value.code == 2 and len(err.strip().splitlines()) == 1
    assert f"argument {named}:" in err and not folder.exists()


def test_option_ranges_are_the_settings_ranges() -> None:
    """--spread-inflation and --roughening take exactly what RadioPlanSettings and
    RadioMissionConfig take: both ends of the range, nothing beyond."""
    import argparse

    from searchtrack.cli.radio import _roughening, _spread_inflation
    from searchtrack.core.errors import InvalidInputError
    from searchtrack.plan.radio import RadioPlanSettings
    from searchtrack.plan.radio.problem import MAX_SPREAD_INFLATION
    from searchtrack.sim.radio.config import MAX_ROUGHENING_M, RadioMissionConfig

    cases = ((_spread_inflation, MAX_SPREAD_INFLATION,
              lambda v: RadioPlanSettings(spread_inflation=v)),
             (_roughening, MAX_ROUGHENING_M, lambda v: RadioMissionConfig(roughening_m=v)))
    for parse, top, settings in cases:
        for ok in (0.0, top):
            settings(parse(repr(ok)))
        for bad in (-1e-9, top * (1 + 1e-9)):
            with pytest.raises(argparse.ArgumentTypeError):
                parse(repr(bad))
            with pytest.raises(InvalidInputError):
                settings(bad)


def test_unknown_scenario_key_is_named(tmp_path: Path,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run.npz"
    code = cli.main(["radio", "simulate", _scenario(tmp_path, "[signal]\nbogus = 1\n"),
                     "--out", str(out)])
    assert code == 2 and "bogus" in capsys.readouterr().err and not out.exists()


def test_nan_frames_are_refused(recorded: Path, tmp_path: Path,
                                capsys: pytest.CaptureFixture[str]) -> None:
    with np.load(recorded) as data:
        arrays = {k: data[k] for k in data.files}
    arrays["frames"][1, 0, 0] = np.nan
    bad = tmp_path / "bad.npz"
    with bad.open("wb") as fh:
        np.savez(fh, **arrays)
    out = tmp_path / "est.json"
    assert cli.main(["radio", "track", str(bad), "--out", str(out)]) == 2
    assert "frames" in capsys.readouterr().err and not out.exists()


def test_ctrl_c_keeps_the_steps_filtered(recorded: Path, tmp_path: Path,
                                         monkeypatch: pytest.MonkeyPatch) -> None:
    from searchtrack.estimate.radio import TbdLmbFilter

    step = TbdLmbFilter.step

    def stopping(self: TbdLmbFilter, z: np.ndarray, pose: np.ndarray) -> None:
        step(self, z, pose)
        request_stop()

    monkeypatch.setattr(TbdLmbFilter, "step", stopping)
    out = tmp_path / "est.json"
    assert cli.main(["radio", "track", str(recorded), "--particles", "50", "--out",
                     str(out)]) == 130
    est = json.loads(out.read_text())
    assert est["interrupted"] and len(est["estimates"]) == 1
