"""The vehicle models package stays in the models layer: NumPy only, no CasADi."""

from __future__ import annotations


def test_vehicle_models_do_not_import_casadi() -> None:
    """Importing searchtrack.models.vehicles loads neither CasADi nor the plan layer."""
    import subprocess
    import sys

    code = ("import sys, searchtrack.models.vehicles\n"
            "bad = [m for m in sys.modules if m.startswith(('casadi', 'searchtrack.plan'))]\n"
            "assert not bad, bad")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr[-2000:]
