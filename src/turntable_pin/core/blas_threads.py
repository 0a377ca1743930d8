"""Running a computation with one BLAS thread (OpenBLAS as bundled with numpy and scipy).

A diagnosis multiplies tall, thin matrices (300,000 x 12) and factors many small blocks; on busy
cores OpenBLAS's threads wait for each other and a call took 10 to 20 times longer than on one
thread (a blocked QR 0.10 s instead of 0.014 s on two busy cores). :func:`one_blas_thread` sets
every loaded OpenBLAS to one thread for a ``with`` block (Linux; elsewhere it does nothing).
"""

from __future__ import annotations

import contextlib
import ctypes
from collections.abc import Iterator

__all__ = ["blas_thread_controls", "one_blas_thread"]

_SYMBOLS = (
    ("scipy_openblas_set_num_threads64_", "scipy_openblas_get_num_threads64_"),
    ("scipy_openblas_set_num_threads", "scipy_openblas_get_num_threads"),
    ("openblas_set_num_threads64_", "openblas_get_num_threads64_"),
    ("openblas_set_num_threads", "openblas_get_num_threads"),
)


def blas_thread_controls() -> list[tuple]:
    """``(set, get)`` thread-count functions of every OpenBLAS loaded in this process (Linux:
    found in ``/proc/self/maps``); empty when there is none or it cannot be read."""
    try:
        with open("/proc/self/maps", encoding="utf-8", errors="replace") as handle:
            paths = sorted(
                {
                    line.split(maxsplit=5)[-1].strip()
                    for line in handle
                    if "openblas" in line.lower() and ".so" in line
                }
            )
    except OSError:
        return []
    controls = []
    for path in paths:
        try:
            library = ctypes.CDLL(path)
        except OSError:
            continue
        for set_name, get_name in _SYMBOLS:
            setter = getattr(library, set_name, None)
            getter = getattr(library, get_name, None)
            if setter is not None and getter is not None:
                getter.restype = ctypes.c_int
                controls.append((setter, getter))
                break
    return controls


@contextlib.contextmanager
def one_blas_thread() -> Iterator[None]:
    """Run the ``with`` block with one OpenBLAS thread; the thread counts are restored after."""
    controls = blas_thread_controls()
    before = [int(get()) for _, get in controls]
    for set_threads, _ in controls:
        set_threads(1)
    try:
        yield
    finally:
        for (set_threads, _), count in zip(controls, before, strict=True):
            set_threads(max(count, 1))
