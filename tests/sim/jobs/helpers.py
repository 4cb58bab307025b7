"""What the ``searchtrack plan`` family tests share: problem files, edits of a problem document
by dotted key, and the checks every reader must pass (a bad key named, broken JSON refused)."""

from __future__ import annotations

import copy
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from searchtrack.core.errors import ParseError

Edit = Callable[[dict[str, Any]], None]


def write_problem(tmp_path: Path, doc: Any) -> Path:
    """``doc`` as ``tmp_path/problem.json``."""
    path = tmp_path / "problem.json"
    path.write_text(json.dumps(doc), encoding="utf-8")
    return path


def _step(target: Any, part: str) -> Any:
    return target[int(part)] if isinstance(target, list) else target[part]


def _parent(doc: dict[str, Any], key: str) -> tuple[Any, Any]:
    """The container of the dotted ``key`` (a number indexes a list) and its last part."""
    *parents, last = key.split(".")
    target: Any = doc
    for p in parents:
        target = _step(target, p)
    return target, int(last) if isinstance(target, list) else last


def drop(key: str) -> Edit:
    """An edit deleting the dotted ``key``."""
    def edit(doc: dict[str, Any]) -> None:
        target, last = _parent(doc, key)
        del target[last]
    return edit


def set_key(key: str, value: Any) -> Edit:
    """An edit setting the dotted ``key`` to ``value``."""
    def edit(doc: dict[str, Any]) -> None:
        target, last = _parent(doc, key)
        target[last] = value
    return edit


def assert_bad_key_named(read: Callable[[Path], Any], tmp_path: Path, doc: dict[str, Any],
                         edit: Edit, key: str) -> None:
    """``read`` of ``doc`` changed by ``edit`` raises a ParseError naming the file and ``key``."""
    changed = copy.deepcopy(doc)
    edit(changed)
    with pytest.raises(ParseError, match=key.replace("[", r"\[").replace("]", r"\]")) as info:
        read(write_problem(tmp_path, changed))
    assert "problem.json" in str(info.value)


def assert_refuses_broken_json(read: Callable[[Path], Any], tmp_path: Path, first_key: str) -> None:
    """Broken JSON is refused naming its line; a top-level list is refused."""
    path = tmp_path / "problem.json"
    path.write_text("{\n  \"" + first_key + "\": ,\n}", encoding="utf-8")
    with pytest.raises(ParseError, match="line 2"):
        read(path)
    with pytest.raises(ParseError, match="JSON object"):
        read(write_problem(tmp_path, [1, 2]))


def plan_cli(tmp_path: Path, family: str, doc: dict[str, Any], *options: str
             ) -> tuple[int, dict[str, Any]]:
    """``searchtrack plan FAMILY`` on ``doc`` with ``options``: the exit status and PLAN.json
    (empty when none was written)."""
    from searchtrack.cli import main

    problem = tmp_path / "problem.json"
    out = tmp_path / "plan.json"
    out.unlink(missing_ok=True)
    problem.write_text(json.dumps(doc), encoding="utf-8")
    code = main(["plan", family, str(problem), "--out", str(out), *options])
    return code, json.loads(out.read_text(encoding="utf-8")) if out.exists() else {}
