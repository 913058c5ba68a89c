"""One BLAS thread while fitting, where threads cost more than they give.

The fits' matrices are tall and thin (10⁴ × 10), and on a shared machine a multi-threaded
OpenBLAS waiting for busy cores made the same fit 6-8x slower (``analysis/bench_identify.py``).

:func:`single_threaded_blas` sets the thread count of every OpenBLAS library loaded in the
process (NumPy's and SciPy's wheels each bundle one) to 1 and restores it afterwards — what
``threadpoolctl`` does, for the two symbol spellings those wheels use.  Where no such library
is found it does nothing.
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
from collections.abc import Iterator
from typing import Any

__all__ = ["single_threaded_blas"]

_NAMES = (("scipy_openblas_get_num_threads64_", "scipy_openblas_set_num_threads64_"),
          ("scipy_openblas_get_num_threads", "scipy_openblas_set_num_threads"),
          ("openblas_get_num_threads64_", "openblas_set_num_threads64_"),
          ("openblas_get_num_threads", "openblas_set_num_threads"))


@functools.lru_cache(maxsize=1)
def _libraries() -> list[tuple[Any, Any]]:
    """(get, set) thread-count functions of the OpenBLAS libraries mapped in this process.

    Looked up once: call after NumPy and SciPy's linear algebra are imported.
    """
    try:
        with open("/proc/self/maps", encoding="utf-8") as fh:
            paths = sorted({ln.split()[-1] for ln in fh if "openblas" in ln.lower() and ".so" in ln})
    except OSError:
        return []
    out = []
    for p in paths:
        try:
            lib = ctypes.CDLL(p)
        except OSError:
            continue
        for get, put in _NAMES:
            g, s = getattr(lib, get, None), getattr(lib, put, None)
            if g is not None and s is not None:
                out.append((g, s))
                break
    return out


@contextlib.contextmanager
def single_threaded_blas() -> Iterator[None]:
    """Run the block with one OpenBLAS thread; the previous counts are restored after it.

    Yields
    ------
    None
        Control returns to the block with one BLAS thread.
    """
    libs = _libraries()
    saved = []
    for g, s in libs:
        try:
            saved.append((s, int(g())))
            s(1)
        except (OSError, ValueError, TypeError):  # pragma: no cover - an unexpected library
            continue
    try:
        yield
    finally:
        for s, n in saved:
            s(n)
