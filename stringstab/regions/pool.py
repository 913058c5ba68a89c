"""Running a region map's work in worker processes: its blocks, its files, a background task.

Knows nothing of what a block holds: :func:`run_blocks` calls the evaluation function it is
given on each block and yields the results as they finish, with at most two blocks per
worker in flight (memory bounded by the block size, not the grid).  :func:`map_forked` runs
one callable on every item of a list in forked processes (a map's figures), and
:func:`in_background` one task in a forked process while this one works on.
"""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing
import os
from collections.abc import Callable, Iterator, Sequence
from typing import Any

from ..errors import StringStabError

__all__ = ["Block", "cpu_count", "in_background", "in_daemon", "map_forked", "run_blocks"]

#: A block [i0:i1, j0:j1, :] of the internal 3-D grid.
Block = tuple[int, int, int, int]


def cpu_count() -> int:
    """The cores this process may run on.

    Returns
    -------
    int
        The number of usable cores (at least 1).
    """
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


def in_daemon() -> bool:
    """Whether this process is a daemon (e.g. a multiprocessing.Pool worker: no children).

    Returns
    -------
    bool
        True in a daemon process, which may not start children.
    """
    return bool(multiprocessing.current_process().daemon)


def run_blocks(
    evaluate: Callable[..., dict[str, Any]], spec: Any, blocks: Sequence[Block], workers: int,
    warm: Callable[[Any], None] | None = None, executor: cf.Executor | None = None,
) -> Iterator[tuple[Block, dict[str, Any]]]:
    """``evaluate(spec, *block)`` for every block, yielding ``(block, result)`` as they finish.

    With ``workers`` > 1 the blocks go to a pool of forked processes (``warm(spec)`` runs
    first here, so the workers inherit its imports and caches, and once in each worker).
    With ``executor`` (any :class:`concurrent.futures.Executor`, e.g. a Dask client's
    ``get_executor()``) they go there instead, ``2 × workers`` in flight (``evaluate`` and
    ``spec`` are pickled; no warm-up).

    Parameters
    ----------
    evaluate : callable
        ``evaluate(spec, i0, i1, j0, j1) -> dict``: the results of one block of the grid.
    spec : object
        Everything ``evaluate`` needs besides the block (passed to it unchanged).
    blocks : sequence of Block
        The blocks ``(i0, i1, j0, j1)`` of the internal 3-D grid to evaluate.
    workers : int
        Worker processes; ≤ 1 evaluates the blocks here, in order.
    warm : callable, optional
        ``warm(spec)``: a warm-up (imports, caches) run here and in each forked worker.
    executor : concurrent.futures.Executor, optional
        Run the blocks there instead of a local pool.

    Yields
    ------
    (Block, dict)
        Each block with its result, in completion order (in block order when ``workers`` ≤ 1).
    """
    if executor is not None:
        yield from _submit_all(executor, evaluate, spec, blocks, max(int(workers), 1))
        return
    if workers <= 1:
        for b in blocks:
            yield b, evaluate(spec, *b)
        return
    if warm is not None:
        warm(spec)
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("fork" if "fork" in methods else None)
    init: Any = warm
    args: Any = (spec,) if warm is not None else ()
    with cf.ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=init,
                                initargs=args) as ex:
        yield from _submit_all(ex, evaluate, spec, blocks, workers)


def _submit_all(ex: cf.Executor, evaluate: Callable[..., dict[str, Any]], spec: Any,
                blocks: Sequence[Block], workers: int) -> Iterator[tuple[Block, dict[str, Any]]]:
    """The blocks through ``ex``, at most two per worker in flight, as they finish."""
    pending: dict[cf.Future[dict[str, Any]], Block] = {}
    it = iter(blocks)
    try:
        for b in it:
            pending[ex.submit(evaluate, spec, *b)] = b
            if len(pending) >= 2 * workers:
                break
        while pending:
            done, _ = cf.wait(pending, return_when=cf.FIRST_COMPLETED)
            for fut in done:
                b = pending.pop(fut)
                yield b, fut.result()
                nxt = next(it, None)
                if nxt is not None:
                    pending[ex.submit(evaluate, spec, *nxt)] = nxt
    finally:
        for fut in pending:
            fut.cancel()


def in_background(fn: Callable[..., Any], *args: Any) -> Callable[[], None]:
    """Start ``fn(*args)`` in a forked process; returns ``join()``, to call when it must be done.

    ``join()`` waits for the process and raises :class:`StringStabError` with the child's
    error (one line) if it failed.  Where processes cannot be forked (no ``fork`` start
    method, or this process is a daemon), ``fn(*args)`` runs here, now, and ``join()`` does
    nothing.  Used to draw a map's figures while its data files are written.

    Parameters
    ----------
    fn : callable
        The work to run; its return value is discarded.
    *args
        Its arguments (inherited by the forked child, not pickled).

    Returns
    -------
    callable
        ``join()``: waits for the child; raises :class:`StringStabError` if it failed.
    """
    if "fork" not in multiprocessing.get_all_start_methods() or in_daemon():
        fn(*args)
        return lambda: None
    ctx = multiprocessing.get_context("fork")
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(send, fn, args), daemon=False)
    proc.start()
    send.close()

    def join() -> None:
        try:
            error = recv.recv()
        except EOFError:  # the child died without a word
            error = None
        proc.join()
        recv.close()
        if error is not None or proc.exitcode != 0:
            raise StringStabError(error or f"a background process ended with exit code {proc.exitcode}")

    return join


def _child(send: Any, fn: Callable[..., Any], args: tuple[Any, ...]) -> None:
    try:
        fn(*args)
        send.send(None)
    except BaseException as e:  # reported by join() in the parent
        msg = str(e) if isinstance(e, StringStabError) else f"{type(e).__name__}: {e}"
        send.send(msg.replace("\n", " "))
    finally:
        send.close()


def map_forked(fn: Callable[[Any], Any], items: Sequence[Any], workers: int) -> None:
    """``fn(item)`` for every item, in ``workers`` forked processes (``fn`` is inherited, not sent).

    The callable and whatever it holds (a region map, say) are inherited by the forked
    processes, not pickled; only the items are.  Where processes cannot be forked (no
    ``fork`` start method, or this process is a daemon), or with ``workers`` ≤ 1 or one item,
    the items are done here, in order.  Return values are discarded.

    Parameters
    ----------
    fn : callable
        The work on one item.
    items : sequence
        The items (picklable).
    workers : int
        The largest number of processes.

    Raises
    ------
    Exception
        Whatever ``fn`` raised, in this process or re-raised from a worker.
    """
    if workers <= 1 or len(items) <= 1 or "fork" not in multiprocessing.get_all_start_methods() \
            or in_daemon():
        for item in items:
            fn(item)
        return
    global _FORKED
    _FORKED = fn
    try:
        with multiprocessing.get_context("fork").Pool(min(workers, len(items))) as pool:
            pool.map(_call_forked, items, chunksize=1)
    finally:
        _FORKED = None


#: The callable of the running :func:`map_forked` (inherited by its forked workers).
_FORKED: Callable[[Any], Any] | None = None


def _call_forked(item: Any) -> None:
    assert _FORKED is not None
    _FORKED(item)
