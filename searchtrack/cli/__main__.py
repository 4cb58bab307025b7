"""``python -m searchtrack.cli``: the ``searchtrack`` command."""

from __future__ import annotations

import sys

from searchtrack.cli import main

sys.exit(main())
