"""Returning freed memory to the system between the stages of a run (the
peak memory of ``hbayes compare``)."""

from __future__ import annotations

__all__ = ["release_memory"]


def release_memory() -> None:
    """Hand the memory of a finished calibration back to the system.

    A calibration leaves many small Python objects behind (figures, tables); after a
    garbage collection glibc keeps the freed heap until ``malloc_trim`` returns it, so
    the process would hold its peak while it waits for the workers, and the report,
    which reads the run back from its files, would grow on top of the heap the outputs
    left. No-op where the C library has no ``malloc_trim`` (macOS, musl, Windows).
    """
    import ctypes
    import ctypes.util
    import gc

    gc.collect()
    try:
        ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):
        pass
