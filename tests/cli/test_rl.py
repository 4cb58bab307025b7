"""``searchtrack rl train|evaluate``."""

from __future__ import annotations

from pathlib import Path

import pytest

from searchtrack.cli import main
from searchtrack.plan.road_rl import RoadPolicy

pytest.importorskip("stable_baselines3", reason="the rl extra (make test installs it)")


def test_train_writes_a_policy_that_evaluate_flies(tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "policy.npz"
    assert main(["rl", "train", "--timesteps", "32", "--duration", "10", "--out", str(out)]) == 0
    assert "policy (" in capsys.readouterr().out
    policy = RoadPolicy.load(out)
    assert policy.n_actions == 4
    assert main(["rl", "evaluate", "--policy", str(out), "--episodes", "1",
                 "--duration", "5"]) == 0
    text = capsys.readouterr().out
    assert "rl" in text and "random" in text


def test_bad_input_exits_2_and_writes_nothing(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    folder = tmp_path / "folder"
    folder.mkdir()
    assert main(["rl", "train", "--timesteps", "32", "--out", str(folder)]) == 2
    with pytest.raises(SystemExit) as usage:  # argparse: one-line usage error, status 2
        main(["rl", "train", "--timesteps", "0", "--out", str(tmp_path / "p.npz")])
    assert usage.value.code == 2
    junk = tmp_path / "junk.npz"
    junk.write_text("junk", encoding="utf-8")
    assert main(["rl", "evaluate", "--policy", str(junk), "--episodes", "1"]) == 2
    assert "not a policy" in capsys.readouterr().err
    assert not (tmp_path / "p.npz").exists()
