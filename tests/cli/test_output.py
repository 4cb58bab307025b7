"""Output paths are checked before any work and create nothing until a file is written."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from searchtrack.cli.output import OutputError, output_dir, output_file
from searchtrack.core.files import write_text_atomic


def test_a_new_file_in_new_folders_is_accepted_and_nothing_is_created(tmp_path: Path) -> None:
    """A file under folders that do not exist yet passes the check, which creates nothing;
    the atomic write makes the folders."""
    path = tmp_path / "a" / "b" / "r.json"
    assert output_file("--json", path) == path
    assert not (tmp_path / "a").exists()
    write_text_atomic(path, "{}\n")
    assert path.read_text(encoding="utf-8") == "{}\n"
    assert [p.name for p in path.parent.iterdir()] == ["r.json"]


def test_a_folder_given_as_a_file_is_refused(tmp_path: Path) -> None:
    """A file option pointing at a folder names the option and says so."""
    with pytest.raises(OutputError, match=r"--json .*: is a folder"):
        output_file("--json", tmp_path)


@pytest.mark.parametrize("check", [output_file, output_dir])
def test_a_file_in_the_way_is_refused(tmp_path: Path, check) -> None:  # type: ignore[no-untyped-def]
    """A file where a folder is needed (the output itself or an ancestor) is refused."""
    blocker = tmp_path / "f"
    blocker.write_text("x", encoding="utf-8")
    with pytest.raises(OutputError, match="is a file, not a folder"):
        check("--out", blocker / "deeper" / "x")


def test_an_existing_file_is_not_an_output_folder(tmp_path: Path) -> None:
    """``--out`` naming an existing file is refused."""
    blocker = tmp_path / "f"
    blocker.write_text("x", encoding="utf-8")
    with pytest.raises(OutputError, match=r"--out .*f is a file"):
        output_dir("--out", blocker)


def test_an_unwritable_folder_is_refused(tmp_path: Path,
                                         monkeypatch: pytest.MonkeyPatch) -> None:
    """A folder without write permission is refused before any work (permissions are faked:
    root may write anywhere)."""
    locked = tmp_path / "locked"
    locked.mkdir()
    monkeypatch.setattr(os, "access", lambda path, mode: Path(path) != locked)
    with pytest.raises(OutputError, match="not writable"):
        output_file("--json", locked / "r.json")
    with pytest.raises(OutputError, match="cannot create a folder in"):
        output_dir("--out", locked / "new")
