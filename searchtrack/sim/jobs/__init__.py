"""Plan families of ``searchtrack plan FAMILY PROBLEM.json``: one module per family.

Each module exposes the same small interface, which :mod:`searchtrack.cli.plan` calls:

- ``FAMILY`` (the name on the command line) and ``DESCRIPTION`` (one line for ``--help``);
- ``backends() -> list[str]``: the backend names of the family's registry, ``"auto"`` first;
- ``read_problem(path)``: the validated problem, or a
  :class:`~searchtrack.core.errors.ParseError` naming the file and the dotted JSON key;
- ``solve(problem, *, backend, time_limit_s, seed) -> Result``;
- ``plan_json(problem, result) -> dict``: the family's ``"plan"`` object of PLAN.json (called
  only when the result carries a plan);
- ``figure(problem, result, path) -> Path | None``: an optional PNG of the plan.
"""
