"""Process-pool workers die with their parent.

A campaign killed with SIGKILL (or a crashed parent) left its spawned workers running, each
holding ~113 MB until it finished its run. :func:`die_with_parent` runs in each worker's
initializer: on Linux the kernel sends the worker SIGKILL when the parent exits
(``prctl(PR_SET_PDEATHSIG)``); everywhere a daemon thread checks every second that the parent
is still the worker's parent and exits the worker otherwise (also covering a parent that died
before the prctl call).
"""

from __future__ import annotations

import os
import signal
import sys
import threading

__all__ = ["die_with_parent"]

_PR_SET_PDEATHSIG = 1
POLL_S = 1.0
"""[s] period of the parent check of the watchdog thread."""


def _parent_pid() -> int | None:
    import multiprocessing

    parent = multiprocessing.parent_process()
    return parent.pid if parent is not None else None


def die_with_parent(parent_pid: int | None = None) -> None:
    """Make this worker process exit when ``parent_pid`` (default: the multiprocessing
    parent) exits. Safe to call in any process; does nothing without a known parent."""
    pid = parent_pid if parent_pid is not None else _parent_pid()
    if pid is None:
        return
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
        except (OSError, AttributeError):
            pass
    if os.getppid() != pid:  # the parent died before the prctl call
        os._exit(1)

    def watch() -> None:
        event = threading.Event()
        while not event.wait(POLL_S):
            if os.getppid() != pid:
                os._exit(1)

    threading.Thread(target=watch, name="lugrip-parent-watch", daemon=True).start()
