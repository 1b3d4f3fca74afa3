"""Executors: run an experiment's cells in this process, on local processes, or on a Ray cluster.

Every cell is a pure function of its inputs (the seed fixes every draw), so
the serial, the local-process and the Ray executors give identical rows, in
cell order.
"""

import logging
import multiprocessing
import os
import signal
import sys
from collections.abc import Callable, Hashable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from contextlib import contextmanager

import cv2
from tqdm import tqdm

from ptztrack.names import EXECUTORS

_IGNORE_CTRL_C = (signal.SIGINT, signal.SIG_IGN)


def execute_cells(
    cells: Sequence,
    run: Callable,
    executor: str = "local",
    workers: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    together: Callable[[object], Hashable] | None = None,
) -> list:
    """Run every cell with ``run`` (a module-level function, so that it pickles) and return the results
    in cell order.

    executor : 'local' (a process pool of ``workers``, default all cores), 'ray' (tasks on the Ray
    cluster ``ray.init()`` connects to, a local one by default; needs the ``ray`` extra), or 'serial'
    (this process).
    progress : called with (cells done, cells in all) as cells finish.
    together : a key of a cell (None: every cell on its own). The cells of one key run one after the
    other in one task, so in one process, which keeps what they share (the HOG detector's memo of the
    views it has searched); the tasks with the most cells start first.
    """
    if executor not in EXECUTORS:
        raise ValueError(f"unknown executor {executor!r}; expected one of {', '.join(EXECUTORS)}")
    report = progress or (lambda done, total: None)
    groups: dict[Hashable, list[int]] = {}
    for index, cell in enumerate(cells):
        groups.setdefault(index if together is None else together(cell), []).append(index)
    tasks = sorted(groups.values(), key=len, reverse=True)
    rows: list = [None] * len(cells)
    done = 0
    for task, task_rows in _run_tasks([[cells[index] for index in task] for task in tasks], run, executor, workers):
        for index, row in zip(tasks[task], task_rows, strict=True):
            rows[index] = row
        done += len(task_rows)
        report(done, len(cells))
    return rows


def _run_together(run: Callable, cells: Sequence) -> list:
    """One task of :func:`execute_cells`: its cells, one after the other."""
    return [run(cell) for cell in cells]


def _run_tasks(tasks: list[list], run: Callable, executor: str, workers: int | None) -> Iterator[tuple[int, list]]:
    """(task index, its rows) for every task of :func:`execute_cells`, as the tasks finish."""
    if executor == "serial":
        for task, cells in enumerate(tasks):
            yield task, _run_together(run, cells)
    elif executor == "local":
        yield from _run_on_processes(tasks, run, workers)
    else:
        yield from _run_on_ray(tasks, run)


def _run_on_processes(tasks: list[list], run: Callable, workers: int | None) -> Iterator[tuple[int, list]]:
    """The tasks on a pool of forked processes, each with one OpenCV thread.

    The pool fills the cores with processes, so OpenCV's own threads in each would only compete for
    them. A forked worker cannot set its own: ``cv2.setNumThreads`` there waits forever for the
    parent's thread pool, which the fork did not copy (it hung whenever this process had used OpenCV's
    threads before the pool, as the two-fold PETS fits do). So this process sets one thread while it
    forks the workers, which inherit it, and sets its own back after.
    """
    threads = cv2.getNumThreads()
    cv2.setNumThreads(1)
    # Ctrl-C reaches the whole process group: the workers ignore it, and this process stops them.
    pool = ProcessPoolExecutor(workers or os.cpu_count(), initializer=signal.signal, initargs=_IGNORE_CTRL_C)
    try:
        futures = {pool.submit(_run_together, run, cells): task for task, cells in enumerate(tasks)}
        for future in as_completed(futures):
            yield futures[future], future.result()
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        for worker in multiprocessing.active_children():
            worker.terminate()
        raise
    finally:
        cv2.setNumThreads(threads)
    pool.shutdown()


# A local Ray cluster started by ptztrack stays on the loopback interface.
# Ray would otherwise advertise the machine's network address (found by
# "connecting" to 8.8.8.8); with cluster mode off it uses 127.0.0.1, as it
# does on macOS and Windows. Its dashboard also probes cloud metadata servers
# (169.254.169.254, metadata.google.internal) over HTTP even with usage
# statistics off: the dead loopback proxy below turns those requests into
# refused connections to 127.0.0.1, with no DNS lookup.
LOOPBACK_RAY_ENVIRONMENT = {
    "RAY_USAGE_STATS_ENABLED": "0",
    "RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER": "0",
    "HTTP_PROXY": "http://127.0.0.1:9",
    "HTTPS_PROXY": "http://127.0.0.1:9",
    "NO_PROXY": "127.0.0.1,localhost",
}


@contextmanager
def _environment(values: dict[str, str]) -> Iterator[None]:
    """The process environment with ``values`` set inside the block, and after it as it was before
    (also undoing what the block itself set: ``ray.init`` sets variables of its own)."""
    saved = dict(os.environ)
    os.environ.update(values)
    try:
        yield
    finally:
        os.environ.clear()
        os.environ.update(saved)


def connect_ray(num_cpus: int | None = None):
    """Ray, connected to the cluster of ``RAY_ADDRESS`` or of an earlier ``ray.init()``; else to a local
    cluster started here with ``num_cpus`` (None: every core). Returns the ``ray`` module.

    A local cluster started here names 127.0.0.1 as its node and has no
    dashboard, and the environment above is set while Ray is imported and
    started (the processes it starts inherit it), then restored. Ray reads
    some network settings when it is first imported, so a local cluster is
    on the loopback interface for sure only if Ray is first imported here.
    """
    local = not os.environ.get("RAY_ADDRESS")
    with _environment(LOOPBACK_RAY_ENVIRONMENT if local else {}):
        try:
            import ray
        except ImportError:
            raise RuntimeError("the ray executor needs Ray: pip install 'ptztrack[ray]'") from None
        if not ray.is_initialized():
            if local:
                ray.init(
                    num_cpus=num_cpus,
                    _node_ip_address="127.0.0.1",
                    include_dashboard=False,
                    logging_level=logging.ERROR,
                    log_to_driver=False,
                )
            else:
                ray.init(log_to_driver=False)
    return ray


def _run_on_ray(tasks: list[list], run: Callable) -> Iterator[tuple[int, list]]:
    """Run on the cluster :func:`connect_ray` connects to."""
    ray = connect_ray()
    remote_task = ray.remote(_run_together)
    pending = {remote_task.remote(run, cells): task for task, cells in enumerate(tasks)}
    remaining = list(pending)
    while remaining:
        finished, remaining = ray.wait(remaining, num_returns=1)
        yield pending[finished[0]], ray.get(finished[0])


class Progress:
    """A progress bar on stderr (tqdm): how many are done, the rate, the time left; none where stderr
    is not a terminal (a log, a pipe), or where ``quiet``.

    Call it with (done, total) as things finish (``execute_cells``' ``progress``); a count that starts
    again (passes over several recordings' frames) starts a new bar. As a context manager it closes
    the bar at the end of the block, a failure or Ctrl-C included.

    noun : what is counted, singular ('episode': the bar reads "episode/s").
    """

    def __init__(self, noun: str = "episode", quiet: bool = False):
        self.noun, self.quiet = noun, quiet
        self._bar: tqdm | None = None

    def __call__(self, done: int, total: int) -> None:
        if self._bar is None or done < self._bar.n or total != self._bar.total:
            self.close()
            self._bar = tqdm(
                total=total, desc=f"{self.noun}s", unit=self.noun, file=sys.stderr, disable=True if self.quiet else None
            )
        self._bar.update(done - self._bar.n)
        if done >= total:
            self.close()

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self) -> "Progress":
        return self

    def __exit__(self, *failure) -> None:
        self.close()
