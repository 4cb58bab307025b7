"""Monte Carlo campaigns: a registered experiment × a parameter grid × seeds, run on Dask
distributed (or in-process) into a resumable DuckDB results database.

:mod:`.experiments` (what a run computes), :mod:`.spec` (the validated TOML campaign file),
:mod:`.store` (the ``runs`` table), :mod:`.runner` (execution).
"""
