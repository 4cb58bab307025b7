"""searchtrack.estimate imports only searchtrack.models and searchtrack.core.errors from the package."""

from __future__ import annotations

import subprocess
import sys


def test_estimate_does_not_import_plan_or_sim() -> None:
    """Importing searchtrack.estimate in a fresh interpreter loads no plan or sim module."""
    code = ("import sys, searchtrack.estimate\n"
            "bad = [m for m in sys.modules\n"
            "       if m.startswith(('searchtrack.plan', 'searchtrack.sim'))]\n"
            "assert not bad, bad")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr[-2000:]
