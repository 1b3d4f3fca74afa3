"""The executors: every one gives the same rows in cell order; cells run together share a worker."""

import importlib.util
import os

import cv2
import numpy as np
import pytest

from ptztrack.config import scenario_from_dict
from ptztrack.experiments.cells import cell_metrics
from ptztrack.experiments.ptz_tables import synthetic_cells
from ptztrack.loop.executors import execute_cells

SMALL = scenario_from_dict({"frames": 8})


def test_serial_and_local_process_executors_give_identical_rows():
    cells = synthetic_cells(SMALL, sequences=2)
    progress = []
    local = execute_cells(
        cells, cell_metrics, "local", workers=2, progress=lambda done, total: progress.append((done, total))
    )
    assert local == execute_cells(cells, cell_metrics, "serial")
    assert [row["strategy"] for row in local] == [cell.strategy for cell in cells]
    assert progress[-1] == (len(cells), len(cells)) and len(progress) == len(cells)


def worker_and_threads(value: int) -> tuple[int, int, int, int]:
    """A cell's value, the process that ran it, OpenCV's threads there and a sum OpenCV computed there."""
    image = np.full((600, 800), value, np.uint8)
    return value, os.getpid(), cv2.getNumThreads(), int(cv2.resize(image, (400, 300)).sum())


def test_cells_run_together_in_one_worker_with_one_opencv_thread_and_come_back_in_order():
    threads = cv2.getNumThreads()
    # This process's OpenCV threads have worked before the pool forks (a worker that then set its own
    # threads would wait forever for them).
    cv2.resize(np.zeros((2000, 2000), np.uint8), (1000, 1000))
    progress = []
    rows = execute_cells(
        list(range(7)),
        worker_and_threads,
        "local",
        workers=2,
        progress=lambda done, total: progress.append((done, total)),
        together=lambda value: value % 3 == 0,
    )
    assert [row[0] for row in rows] == list(range(7))
    assert [row[3] for row in rows] == [value * 400 * 300 for value in range(7)]
    assert {row[1] for row in rows if row[0] % 3 == 0} != {os.getpid()}
    assert len({row[1] for row in rows if row[0] % 3 == 0}) == 1 == len({row[1] for row in rows if row[0] % 3})
    assert {row[2] for row in rows} == {1}
    assert cv2.getNumThreads() == threads
    assert progress[-1] == (7, 7) and len(progress) == 2
    serial = execute_cells(list(range(7)), worker_and_threads, "serial", together=lambda value: value % 3 == 0)
    assert [(row[0], row[3]) for row in serial] == [(row[0], row[3]) for row in rows]


@pytest.mark.slow
@pytest.mark.xdist_group("ray")
@pytest.mark.skipif(importlib.util.find_spec("ray") is None, reason="needs the ray extra")
def test_ray_executor_gives_the_same_rows():
    # Not imported here: the executor must import Ray itself, after setting
    # the environment that keeps a local cluster on the loopback interface.
    cells = synthetic_cells(SMALL, sequences=2, strategies=("rnd", "smpl"))
    environment = dict(os.environ)
    assert execute_cells(cells, cell_metrics, "ray") == execute_cells(cells, cell_metrics, "serial")
    # The loopback settings were for Ray's start only: the caller's environment is as it was.
    assert dict(os.environ) == environment
