"""Every layer's exported names resolve, including those imported on first use."""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest

LAYERS = ("searchtrack", "searchtrack.core", "searchtrack.models", "searchtrack.estimate",
          "searchtrack.plan", "searchtrack.sim")


@pytest.mark.parametrize("name", LAYERS)
def test_every_exported_name_resolves(name: str) -> None:
    module = importlib.import_module(name)
    missing = [n for n in getattr(module, "__all__", ()) if getattr(module, n, None) is None]
    assert not missing, missing
    with pytest.raises(AttributeError):
        getattr(module, "no_such_name")  # noqa: B009


def test_importing_estimate_loads_no_solver() -> None:
    """``import searchtrack.estimate`` stays cheap: no SciPy optimiser or Numba until used."""
    code = ("import sys, searchtrack.estimate; "
            "print(sorted(m for m in ('scipy.optimize', 'numba') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]"
