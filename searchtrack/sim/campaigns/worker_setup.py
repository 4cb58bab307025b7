"""Set-up of an embedded LocalCluster worker process, kept light so that workers start fast."""

from __future__ import annotations

import signal
import threading


def dask_setup(worker: object) -> None:
    """Dask preload hook run in each embedded LocalCluster worker process: ignore SIGINT there.

    Ctrl-C at a terminal reaches the whole process group, workers included; the client answers
    it (it stops submitting, cancels what is pending and closes the cluster), so a worker does
    not die with a traceback mid-run.
    """
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
