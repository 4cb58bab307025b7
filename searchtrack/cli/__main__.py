"""``python -m searchtrack.cli``: the ``searchtrack`` command."""

from __future__ import annotations

from searchtrack.cli import run

run()
