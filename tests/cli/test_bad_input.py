"""Every command answers malformed input with one line naming the file or key, exit status 2
(1 for a bench with a failed instance), no traceback and no output file."""

from __future__ import annotations

from pathlib import Path

import pytest

from searchtrack.cli import main
from tests.cli.probes import PROBES, Probe
from tests.cli.probes_radio import RADIO_PROBES
from tests.cli.probes_tools import TOOL_PROBES

ALL_PROBES = [*PROBES, *RADIO_PROBES, *TOOL_PROBES]


def _outputs(tmp: Path) -> set[Path]:
    return {p for p in tmp.rglob("*")
            if p.suffix in (".json", ".png", ".html") or p.name in ("out", "r.npz")}


@pytest.mark.parametrize("probe", ALL_PROBES, ids=[p[0] for p in ALL_PROBES])
def test_probe(probe: Probe, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The probe's exit status, its words in the error output, no output written."""
    _, build, status, words = probe
    argv = build(tmp_path)
    before = _outputs(tmp_path)
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse rejects the option itself
        code = int(exc.code) if isinstance(exc.code, int) else 2
    captured = capsys.readouterr()
    text = " ".join((captured.err + captured.out).split())
    assert code == status, text
    assert "Traceback" not in text
    for word in words:
        assert word in text, f"{word!r} not in: {text}"
    if status == 2:
        assert len(captured.err.strip().splitlines()) == 1, captured.err
        assert _outputs(tmp_path) == before
