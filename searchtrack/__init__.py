"""searchtrack: teams of UAVs that search for and track an unknown number of moving targets.

Layers, each importing only those before it:
``models`` → ``estimate`` → ``plan`` → ``sim`` → ``cli``.
"""

from __future__ import annotations

__version__ = "0.1.0"

__all__ = ["__version__"]
