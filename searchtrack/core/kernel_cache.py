"""Numba's on-disk cache for kernels that call kernels of other modules.

A ``cache=True`` kernel is stored with a stamp of *its own* source file only. A kernel that calls
a kernel of another module has that callee compiled into its machine code, so when only the
callee's file changes (an editable checkout, a patched install) numba would go on loading the
old machine code. :func:`follow_callees`, called at the end of such a module, keeps a second
stamp beside the module's cache: the source files of every kernel its namespace can reach in
other modules (directly, or as ``module.kernel``), followed transitively; when it differs from
the stamp stored with the cache, the module's cached kernels are flushed and compile afresh on
their next call.
"""

from __future__ import annotations

import hashlib
import logging
import os
import sys
from collections.abc import Iterator, Mapping
from pathlib import Path
from types import ModuleType
from typing import Any

from numba.core.registry import CPUDispatcher

from searchtrack.core.files import write_text_atomic

log = logging.getLogger(__name__)

#: ``njit`` options for a hot kernel that allocates nothing and gets every array from its caller:
#: compiled without numba's runtime, it skips the atomic reference-count updates numba makes on
#: each array handed to a helper, which can cost a loop most of its time.
NO_REFCOUNTS: dict[str, Any] = {"_nrt": False}


def _kernels(namespace: Mapping[str, object]) -> Iterator[CPUDispatcher]:
    """The numba dispatchers a namespace holds, directly or as attributes of modules in it."""
    for value in list(namespace.values()):
        if isinstance(value, CPUDispatcher):
            yield value
        elif isinstance(value, ModuleType) and value.__name__.startswith("searchtrack."):
            yield from (v for v in vars(value).values() if isinstance(v, CPUDispatcher))


def _disk_cache(kernel: CPUDispatcher) -> Any:
    """numba's on-disk cache of ``kernel``, ``None`` for a kernel without ``cache=True``."""
    cache = getattr(kernel, "_cache", None)
    return cache if hasattr(cache, "cache_path") else None


def callee_files(module: str, namespace: Mapping[str, object]) -> list[Path]:
    """Source files of the modules (other than ``module``) whose kernels ``namespace`` can
    reach, followed through those modules' namespaces, sorted."""
    seen: set[str] = {module}
    todo = [namespace]
    while todo:
        for kernel in _kernels(todo.pop()):
            owner = kernel.py_func.__module__
            if owner not in seen and owner in sys.modules:
                seen.add(owner)
                todo.append(vars(sys.modules[owner]))
    seen.discard(module)
    return sorted(Path(f) for m in seen if (f := getattr(sys.modules[m], "__file__", None)))


def follow_callees(module: str, namespace: Mapping[str, object]) -> None:
    """Flush the disk cache of ``module``'s ``cache=True`` kernels when a source file of the
    kernels they can call elsewhere (:func:`callee_files`) changed since the stamp was stored.

    Call it at the end of the module, as ``follow_callees(__name__, globals())``. Nothing is
    compiled; a cache that cannot be written (a read-only install) is left as it is.
    """
    own = [cache for k in _kernels(namespace)
           if k.py_func.__module__ == module and (cache := _disk_cache(k)) is not None]
    files = callee_files(module, namespace)
    if not own or not files:
        return
    hasher = hashlib.sha256()
    for path in files:
        stat = path.stat()
        hasher.update(f"{path}\0{stat.st_mtime_ns}\0{stat.st_size}\n".encode())
    stamp = hasher.hexdigest()
    where = Path(own[0].cache_path) / f"{module.rsplit('.', 1)[-1]}.callees"
    try:
        if where.read_text(encoding="utf-8") == stamp:
            return
    except OSError:
        pass
    try:
        for cache in own:
            cache.flush()
        os.makedirs(where.parent, exist_ok=True)
        write_text_atomic(where, stamp)
    except OSError as exc:  # read-only cache: numba cannot have written a stale one here either
        log.debug("kernel cache of %s not refreshed: %s", module, exc)
        return
    log.debug("kernel cache of %s flushed: a callee's source changed", module)
