"""The embedded cluster's worker set-up hook."""

from __future__ import annotations

import signal
import subprocess
import sys
import threading

from searchtrack.sim.campaigns.worker_setup import dask_setup


def test_ignores_sigint_in_the_main_thread() -> None:
    before = signal.getsignal(signal.SIGINT)
    try:
        dask_setup(object())
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, before)


def test_leaves_signals_alone_off_the_main_thread() -> None:
    before = signal.getsignal(signal.SIGINT)
    worker = threading.Thread(target=dask_setup, args=(object(),))
    worker.start()
    worker.join()
    assert signal.getsignal(signal.SIGINT) is before


def test_is_light_to_import() -> None:
    """Workers import it before they start: it must not pull in the experiments."""
    code = ("import sys, searchtrack.sim.campaigns.worker_setup; "
            "print(any(m.startswith(('searchtrack.sim.campaigns.experiments', "
            "'searchtrack.estimate', 'scipy', 'numba')) for m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False"
