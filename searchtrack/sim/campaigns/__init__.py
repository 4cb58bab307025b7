"""Monte Carlo campaigns: a registered experiment × a parameter grid × seeds, run on Dask
distributed (or in-process) into a resumable DuckDB results database.

:mod:`.experiments` (what an experiment declares, and the registry that finds every domain's
experiment modules), :mod:`.experiment_builtin` (the package's own ``toy`` and
``optw_instance``), :mod:`.spec` (the validated TOML campaign file), :mod:`.store` (the ``runs``
table), :mod:`.runner` (execution), :mod:`.report` and :mod:`.series` (tables beside the claims,
figures).
"""
