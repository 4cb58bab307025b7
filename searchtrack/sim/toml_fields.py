"""Typed reads from a parsed TOML table; every failure names the file and the dotted key."""

from __future__ import annotations

import math
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from searchtrack.core.errors import ParseError

#: Largest magnitude of a scenario number: far past any physical value in SI units (a
#: continent is 1e7 m), small enough that squares and sums never overflow.
MAX_MAGNITUDE = 1e9


class Table:
    """A TOML table read field by field; unknown keys are reported by :meth:`done`.

    Parameters
    ----------
    data
        The table as parsed by :mod:`tomllib`.
    path
        The file it came from (for messages).
    prefix
        Dotted name of the table (``""`` at the top level).
    """

    def __init__(self, data: dict[str, Any], path: Path, prefix: str = "") -> None:
        self._data = data
        self._path = path
        self._prefix = prefix
        self._seen: set[str] = set()

    def key(self, name: str) -> str:
        """The dotted name of ``name`` in this table."""
        return f"{self._prefix}.{name}" if self._prefix else name

    def fail(self, name: str, reason: str) -> ParseError:
        """A :class:`ParseError` for field ``name``."""
        return ParseError(self._path, None, self.key(name), reason)

    def has(self, name: str) -> bool:
        """Whether ``name`` is present."""
        return name in self._data

    def raw(self, name: str, default: Any = None) -> Any:
        """The raw value of ``name`` (``default`` when absent)."""
        self._seen.add(name)
        return self._data.get(name, default)

    def table(self, name: str, *, required: bool = False) -> Table:
        """Sub-table ``name`` (empty when absent and not ``required``)."""
        value = self.raw(name)
        if value is None:
            if required:
                raise self.fail(name, "missing table")
            value = {}
        if not isinstance(value, dict):
            raise self.fail(name, f"must be a table, got {type(value).__name__}")
        return Table(value, self._path, self.key(name))

    def number(self, name: str, default: float | None = None, *, positive: bool = False,
               minimum: float | None = None, maximum: float | None = None) -> float:
        """A finite real number, optionally ``> 0`` and within ``[minimum, maximum]``."""
        value = self.raw(name, default)
        if value is None:
            raise self.fail(name, "missing number")
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(name, f"must be a number, got {value!r}")
        x = float(value)
        if not math.isfinite(x):
            raise self.fail(name, f"must be finite, got {value!r}")
        if abs(x) > MAX_MAGNITUDE:
            raise self.fail(name, f"must be within ±{MAX_MAGNITUDE:g} (SI units), got {value!r}")
        if positive and x <= 0.0:
            raise self.fail(name, f"must be > 0, got {value!r}")
        if minimum is not None and x < minimum:
            raise self.fail(name, f"must be ≥ {minimum}, got {value!r}")
        if maximum is not None and x > maximum:
            raise self.fail(name, f"must be ≤ {maximum}, got {value!r}")
        return x

    def optional_number(self, name: str, *, positive: bool = False, minimum: float | None = None,
                        maximum: float | None = None) -> float | None:
        """Like :meth:`number`, ``None`` when absent."""
        if not self.has(name):
            self._seen.add(name)
            return None
        return self.number(name, positive=positive, minimum=minimum, maximum=maximum)

    def integer(self, name: str, default: int | None = None, *, minimum: int = 0) -> int:
        """An integer ``≥ minimum``."""
        value = self.raw(name, default)
        if value is None:
            raise self.fail(name, "missing integer")
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(name, f"must be an integer, got {value!r}")
        if value < minimum:
            raise self.fail(name, f"must be ≥ {minimum}, got {value!r}")
        return value

    def string(self, name: str, default: str | None = None, *,
               choices: Iterable[str] | None = None) -> str:
        """A string, optionally one of ``choices``."""
        value = self.raw(name, default)
        if value is None:
            raise self.fail(name, "missing string")
        if not isinstance(value, str):
            raise self.fail(name, f"must be a string, got {value!r}")
        if choices is not None:
            allowed = list(choices)
            if value not in allowed:
                raise self.fail(name, f"{value!r} is not one of {allowed}")
        return value

    def boolean(self, name: str, default: bool) -> bool:
        """A boolean."""
        value = self.raw(name, default)
        if not isinstance(value, bool):
            raise self.fail(name, f"must be true or false, got {value!r}")
        return value

    def done(self) -> None:
        """Raise for any key that was never read (a typo would otherwise be ignored)."""
        unknown = sorted(set(self._data) - self._seen)
        if unknown:
            raise self.fail(unknown[0], f"unknown key (known here: {sorted(self._seen)})")
