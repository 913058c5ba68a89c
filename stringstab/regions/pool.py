"""Running a region map's blocks in worker processes, as they finish, memory bounded.

Knows nothing of what a block holds: :func:`run_blocks` calls the evaluation function it is
given on each block and yields the results as they finish, with at most two blocks per
worker in flight (memory bounded by the block size, not the grid).  The workers are a
:func:`stringstab.parallel.process_pool` (the package's one start-method policy: forked only
from a single-threaded process, dying with their parent).
"""

from __future__ import annotations

import concurrent.futures as cf
from collections.abc import Callable, Generator, Iterator, Sequence
from typing import Any

from ..parallel import process_pool, start_method

__all__ = ["Block", "run_blocks"]

#: A block [i0:i1, j0:j1, :] of the internal 3-D grid.
Block = tuple[int, int, int, int]

#: Modules a forkserver imports before forking the workers (when the pool is not forked).
PRELOAD = ("stringstab.regions.grid",)


def run_blocks(
    evaluate: Callable[..., dict[str, Any]], spec: Any, blocks: Sequence[Block], workers: int,
    warm: Callable[[Any], None] | None = None, executor: cf.Executor | None = None,
) -> Generator[tuple[Block, dict[str, Any]], None, None]:
    """``evaluate(spec, *block)`` for every block, yielding ``(block, result)`` as they finish.

    With ``workers`` > 1 the blocks go to a :func:`stringstab.parallel.process_pool`
    (``warm(spec)`` runs once in each worker and, when the workers are forked, first here,
    so that they inherit its imports and caches).
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
        ``warm(spec)``: a warm-up (imports, caches) run in each worker (a module-level
        function: pickled when the workers are not forked).
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
    method = start_method()
    if warm is not None and method == "fork":
        warm(spec)  # here, before the fork: the workers inherit its imports and caches
    init: Any = warm
    args: Any = (spec,) if warm is not None else ()
    with process_pool(workers, init, args, method=method, preload=PRELOAD) as ex:
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
