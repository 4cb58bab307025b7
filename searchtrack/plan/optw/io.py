"""Reader and writer for the Vansteenwegen–Montemanni OPTW text format.

Line 1 is ``k v N t`` (N customers), line 2 is ignored, then one line per vertex
``i x y d S f a list... O C`` (``a`` list entries), vertex 0 being the depot whose closing time is
Tmax. Travel times are Euclidean distances truncated to ``decimals`` decimals: 1 for the Solomon
files, 2 for Cordeau's. By default the precision is inferred from the coordinates, which these
files write with one decimal more than the travel-time precision (``40.00`` vs ``-10.442``).
"""

from __future__ import annotations

from decimal import Decimal, InvalidOperation
from pathlib import Path

import numpy as np

from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.core.files import read_text
from searchtrack.plan.optw.instance import OPTWInstance

_FIELDS = ("i", "x", "y", "d", "S", "f", "a")

#: Most decimals of a travel time (ticks of 10⁻⁶ time units).
MAX_DECIMALS = 6

#: Largest instance file read (bytes, after bzip2): 100 000 vertices take about 8 MB.
MAX_INSTANCE_BYTES = 64 * 2**20


def _lines(path: Path) -> list[str]:
    return read_text(path, max_bytes=MAX_INSTANCE_BYTES).splitlines()


def _number(path: Path, line: int, field: str, token: str) -> Decimal:
    try:
        value = Decimal(token)
    except InvalidOperation:
        raise ParseError(path, line, field, f"not a number: {token!r}") from None
    if not value.is_finite():
        raise ParseError(path, line, field, f"not a finite number: {token!r}")
    return value


def _numeric(token: str) -> bool:
    """Whether ``token`` reads as a number."""
    try:
        float(token)
    except ValueError:
        return False
    return True


def _integer(path: Path, line: int, field: str, token: str) -> int:
    value = _number(path, line, field, token)
    if value != value.to_integral_value():
        raise ParseError(path, line, field, f"not an integer: {token!r}")
    return int(value)


def _decimals(token: str) -> int:
    return len(token.split(".", 1)[1]) if "." in token else 0


def read_optw(
    path: str | Path, *, decimals: int | None = None, vehicles: int = 1
) -> OPTWInstance:
    """Read an OPTW instance file (plain or ``.bz2``).

    Parameters
    ----------
    path
        The file.
    decimals
        Travel-time precision (1 for Solomon, 2 for Cordeau); inferred when ``None``.
    vehicles
        Number of routes of the (team) OPTW; the file's own vehicle count is not the benchmark's.

    Raises
    ------
    ParseError
        Naming file, line and field, for any malformed content.
    InvalidInputError
        ``decimals`` outside ``[0, MAX_DECIMALS]``, or ``vehicles`` not an integer from 1 to the
        number of customers (more routes than customers would only add empty ones).
    """
    if decimals is not None and (isinstance(decimals, bool) or not isinstance(decimals, int)
                                 or not 0 <= decimals <= MAX_DECIMALS):
        raise InvalidInputError("decimals", decimals, f"must be an integer in [0, {MAX_DECIMALS}]")
    if isinstance(vehicles, bool) or not isinstance(vehicles, int) or vehicles < 1:
        raise InvalidInputError("vehicles", vehicles, "must be an integer ≥ 1")
    p = Path(path)
    numbered = [(k + 1, ln.split()) for k, ln in enumerate(_lines(p))]
    numbered = [(k, toks) for k, toks in numbered if toks]
    if len(numbered) < 2:
        raise ParseError(p, None, None, "too short: needs a header, a second line and vertices")
    hline, header = numbered[0]
    if len(header) != 4 or not all(_numeric(tok) for tok in header):
        start = " ".join(header)
        raise ParseError(p, hline, "k v N t",
                         "not an OPTW instance in the Solomon/Cordeau text format (its first "
                         "line is four numbers 'k v N t'; this one reads "
                         f"{start[:40]!r}{'…' if len(start) > 40 else ''})")
    n_customers = _integer(p, hline, "N", header[2])
    if n_customers < 0:
        raise ParseError(p, hline, "N", f"must be non-negative, got {n_customers}")
    rows = numbered[2:]
    if len(rows) != n_customers + 1:
        last = rows[-1][0] if rows else numbered[-1][0]
        raise ParseError(
            p, last, "N", f"header announces {n_customers} customers + depot, "
            f"found {len(rows)} vertex lines"
        )
    ids: list[int] = []
    xy: list[tuple[Decimal, Decimal]] = []
    service, profit, opn, close = [], [], [], []
    coord_decimals = 0
    seen: dict[int, int] = {}
    for line, toks in rows:
        if len(toks) < 9:
            raise ParseError(p, line, None, f"expected at least 9 fields, found {len(toks)}")
        vals = {f: toks[k] for k, f in enumerate(_FIELDS)}
        a = _integer(p, line, "a", vals["a"])
        if a < 0 or len(toks) != 9 + a:
            raise ParseError(
                p, line, "a", f"{a} list entries announced, line has {len(toks)} fields "
                f"(expected {9 + max(a, 0)})"
            )
        vid = _integer(p, line, "i", vals["i"])
        if vid in seen:
            raise ParseError(p, line, "i", f"duplicate vertex id {vid} (first on line {seen[vid]})")
        seen[vid] = line
        for f in ("f", *(f"list[{j}]" for j in range(a))):
            tok = vals[f] if f == "f" else toks[7 + int(f[5:-1])]
            _integer(p, line, f, tok)
        x = _number(p, line, "x", vals["x"])
        y = _number(p, line, "y", vals["y"])
        coord_decimals = max(coord_decimals, _decimals(vals["x"]), _decimals(vals["y"]))
        d = _number(p, line, "d", vals["d"])
        s = _number(p, line, "S", vals["S"])
        o = _number(p, line, "O", toks[-2])
        c = _number(p, line, "C", toks[-1])
        for name, v in (("d", d), ("S", s), ("O", o), ("C", c)):
            if v < 0:
                raise ParseError(p, line, name, f"must be non-negative, got {v}")
        if c < o:
            raise ParseError(p, line, "C", f"window closes ({c}) before it opens ({o})")
        ids.append(vid)
        xy.append((x, y))
        service.append(d)
        profit.append(s)
        opn.append(o)
        close.append(c)
    customers = len(rows) - 1
    if vehicles > max(1, customers):
        raise InvalidInputError("vehicles", vehicles, f"more routes than the {customers} "
                                f"customers of {p.name}")
    if decimals is None:
        decimals = min(max(coord_decimals - 1, 0), MAX_DECIMALS)
    scale = 10**decimals
    for name, values in (("d", service), ("O", opn), ("C", close)):
        for (line, _), v in zip(rows, values, strict=True):
            if v * scale != (v * scale).to_integral_value():
                raise ParseError(p, line, name, f"{v} has more than {decimals} decimals")
    try:
        return OPTWInstance.from_coordinates(
            np.array([[float(x), float(y)] for x, y in xy]),
            profit=np.array([float(s) for s in profit]),
            service=np.array([float(v) for v in service]),
            open=np.array([float(v) for v in opn]),
            close=np.array([float(v) for v in close]),
            decimals=decimals,
            start=0,
            end=0,
            vehicles=vehicles,
            name=p.name.split(".")[0],
            ids=ids,
        )
    except InvalidInputError as exc:
        raise ParseError(p, None, exc.field, exc.reason) from None


def _fmt(ticks: int, decimals: int) -> str:
    return f"{ticks / 10**decimals:.{decimals}f}"


def write_optw(instance: OPTWInstance, path: str | Path) -> None:
    """Write ``instance`` in the standard text format (it needs coordinates and start = end).

    Raises
    ------
    InvalidInputError
        If the instance has no coordinates, or its travel times are not the truncated Euclidean
        distances the format implies, or its start and end differ.
    """
    if instance.coords is None:
        raise InvalidInputError("coords", None, "the text format needs vertex coordinates")
    if instance.end != instance.start:
        raise InvalidInputError("end", instance.end, "the text format needs end == start")
    decimals = len(str(instance.time_scale)) - 1
    if 10**decimals != instance.time_scale:
        raise InvalidInputError("time_scale", instance.time_scale, "must be a power of 10")
    check = OPTWInstance.from_coordinates(
        instance.coords, instance.profit, np.zeros(instance.n), np.zeros(instance.n),
        np.zeros(instance.n), decimals=decimals,
    )
    if not np.array_equal(check.travel, instance.travel):
        raise InvalidInputError(
            "travel", "…", "not the truncated Euclidean distances of the coordinates"
        )
    order = [instance.start] + [v for v in range(instance.n) if v != instance.start]
    out = [
        f"4 {instance.vehicles} {instance.n - 1} 1",
        f"0 {_fmt(instance.latest_finish, decimals)}",
    ]
    for v in order:
        x, y = instance.coords[v]
        out.append(
            f"{instance.ids[v]} {x:.{decimals + 1}f} {y:.{decimals + 1}f} "
            f"{_fmt(int(instance.service[v]), decimals)} {instance.profit[v]:g} 0 0 "
            f"{_fmt(int(instance.open[v]), decimals)} {_fmt(int(instance.close[v]), decimals)}"
        )
    Path(path).write_text("\n".join(out) + "\n", encoding="utf-8")
