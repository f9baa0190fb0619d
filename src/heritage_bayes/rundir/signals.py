"""Critical sections that an interrupt waits for.

A group of files written together (a checkpoint's commit, a run folder's swap, a
comparison's data and page) must be whole or absent: :class:`DeferSignals` records
SIGINT and SIGTERM during the section and acts on them after it. Used by the run-folder
writer here and by every layer above that writes such a group.
"""

from __future__ import annotations

import signal
import threading

__all__ = ["DeferSignals"]


class DeferSignals:
    """Record SIGINT and SIGTERM instead of acting on them, for a critical section.

    ``received`` is the first signal number seen (or None). On exit the previous handlers
    come back and, with ``redeliver=True``, a recorded signal is raised again, so an
    interrupt during a checkpoint commit takes effect right after it. Only the main
    thread receives signals in Python; elsewhere this does nothing.
    """

    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self, redeliver: bool = True):
        self.redeliver = redeliver
        self.received: int | None = None
        self._old: dict = {}

    def __enter__(self):
        self.received = None
        if threading.current_thread() is threading.main_thread():
            for s in self.SIGNALS:
                if signal.getsignal(s) is signal.SIG_IGN:
                    continue  # ignored on purpose (nohup, a background job): keep it so
                old = signal.signal(s, self._record)
                self._old[s] = signal.SIG_DFL if old is None else old
        return self

    def _record(self, signum, frame):
        if self.received is None:
            self.received = signum

    def __exit__(self, *exc):
        for s, h in self._old.items():
            signal.signal(s, h)
        self._old = {}
        if self.redeliver and self.received is not None and exc[0] is None:
            signal.raise_signal(self.received)
        return False
