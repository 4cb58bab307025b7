"""Typed reads from a parsed JSON document: every failure is a :class:`ParseError` naming the
file (or what the document is) and the dotted field (``sensor.pd``, ``scans[3][1]``)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from searchtrack.core.errors import ParseError

#: The field name of the document itself: its keys are named without a prefix.
TOP_LEVEL = "(top level)"


def shown(value: object, limit: int | None = None) -> str:
    """``repr(value)``, cut to ``limit`` characters (ending ``...``) when longer (``None``: not
    cut)."""
    text = repr(value)
    if limit is None or len(text) <= limit:
        return text
    return text[:limit - 3] + "..."


class JsonFields:
    """Field checks on a parsed JSON document, raising :class:`ParseError` naming ``source``
    and the field.

    Messages avoid ``[x, y]``-like text where they can: the CLI prints them through rich,
    which would read it as markup.

    Parameters
    ----------
    source
        The file read (or a description of the document), named in every message.
    low, high
        The bounds :meth:`number` applies when a call gives none.
    shown_chars
        Longest text of a bad value in a message (see :func:`shown`); ``None``: whole.
    finite_in_range
        Whether :meth:`number` refuses a non-finite and an out-of-range value with one reason,
        ``must be a finite number in [low, high]``, rather than ``must be finite`` and
        ``must be in [low, high]``.
    """

    def __init__(self, source: str | Path, *, low: float = -math.inf, high: float = math.inf,
                 shown_chars: int | None = None, finite_in_range: bool = False) -> None:
        self.source = source
        self.low = low
        self.high = high
        self.shown_chars = shown_chars
        self.finite_in_range = finite_in_range

    def fail(self, field: str, reason: str) -> ParseError:
        """The :class:`ParseError` for ``field`` (to raise)."""
        return ParseError(self.source, None, field, reason)

    def shown(self, value: object) -> str:
        """``value`` as a message shows it (shortened to ``shown_chars``)."""
        return shown(value, self.shown_chars)

    def check_keys(self, obj: Mapping[str, Any], field: str, known: tuple[str, ...], *,
                   unknown: str = "unknown key") -> None:
        """Refuse a key of ``obj`` (the object at ``field``) not in ``known``: the first in
        sorted order is named, dotted under ``field`` (bare at :data:`TOP_LEVEL`), with the
        reason ``"{unknown}; expected one of [...]"``."""
        extra = sorted(set(obj) - set(known))
        if extra:
            prefix = "" if field == TOP_LEVEL else field + "."
            raise self.fail(prefix + extra[0], f"{unknown}; expected one of {list(known)}")

    def obj(self, value: Any, field: str, known: tuple[str, ...] | None = None) -> dict[str, Any]:
        """A JSON object, without keys outside ``known`` when it is given (see
        :meth:`check_keys`); a mapping that is not a ``dict`` is copied into one."""
        if not isinstance(value, Mapping):
            raise self.fail(field, f"must be a JSON object, got {type(value).__name__}")
        if known is not None:
            self.check_keys(value, field, known)
        return value if isinstance(value, dict) else dict(value)

    def get(self, obj: Mapping[str, Any], key: str, prefix: str = "") -> Any:
        """``obj[key]``; missing, the field ``prefix + key`` is named."""
        if key not in obj:
            raise self.fail(prefix + key, "missing key")
        return obj[key]

    def number(self, value: Any, field: str, *, low: float | None = None, low_open: bool = False,
               high: float | None = None, high_open: bool = False) -> float:
        """A finite number (not a bool) in ``[low, high]`` (ends excluded where ``low_open``,
        ``high_open``; an unset bound is the reader's)."""
        lo_x = self.low if low is None else low
        hi_x = self.high if high is None else high
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(field, f"must be a number, got {self.shown(value)}")
        try:
            x = float(value)
        except OverflowError:  # an integer beyond the float range
            x = math.inf
        finite = math.isfinite(x)
        if not finite and not self.finite_in_range:
            raise self.fail(field, f"must be finite, got {self.shown(value)}")
        if (not finite or (x <= lo_x if low_open else x < lo_x)
                or (x >= hi_x if high_open else x > hi_x)):
            span = f"{'(' if low_open else '['}{lo_x:g}, {hi_x:g}{')' if high_open else ']'}"
            what = "a finite number in" if self.finite_in_range else "in"
            raise self.fail(field, f"must be {what} {span}, got {self.shown(value)}")
        return x

    def integer(self, value: Any, field: str, low: int, high: int) -> int:
        """An integer (not a bool) in ``[low, high]``."""
        if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
            raise self.fail(field, f"must be an integer in [{low}, {high}], "
                            f"got {self.shown(value)}")
        return value

    def text(self, value: Any, field: str) -> str:
        """A string."""
        if not isinstance(value, str):
            raise self.fail(field, f"must be a string, got {type(value).__name__}")
        return value

    def items(self, value: Any, field: str, what: str, *, allow_empty: bool = False) -> list[Any]:
        """A JSON list (non-empty unless ``allow_empty``) of ``what`` (for the message)."""
        if not isinstance(value, list) or not (value or allow_empty):
            size = "" if allow_empty else "non-empty "
            raise self.fail(field, f"must be a {size}list of {what}")
        return value
