"""What the experiments share: a cell of (scenario, strategy, seed), the run of one, and how cells run.

An experiment is a list of cells, each a function of its inputs; the
executors of :mod:`ptztrack.loop.executors` run them in this process, on
local processes or on a Ray cluster, with the same rows.
"""

import copy
from dataclasses import dataclass

from ptztrack.builders.episode import PolicySpec, run_episode
from ptztrack.builders.world import CameraSpec, DetectorSpec
from ptztrack.config import Scenario
from ptztrack.evaluate.metrics import episode_metrics
from ptztrack.loop.executors import Progress, execute_cells
from ptztrack.loop.steps import Episode

INFORMATION_STRATEGIES = ("intg", "smpl")


def strategy_name(strategy: PolicySpec) -> str:
    """A strategy's column name: itself for a name, else the object's ``name`` or its type's name."""
    if isinstance(strategy, str):
        return strategy
    name = getattr(strategy, "name", None) or getattr(strategy, "__name__", None)
    return str(name or type(strategy).__name__)


@dataclass(frozen=True)
class Cell:
    """One episode of an experiment: a scenario run with one strategy and one sequence seed.

    strategy : a registered policy's name (the paper's ``STRATEGIES`` among them), a policy object (each
        cell runs a fresh copy) or a policy factory.
    label : the table column it belongs to (the strategy, with beta where the table has several).
    camera, detector : in place of the scenario's (see :func:`ptztrack.builders.world.build_world`).
    fold : which scoring of a table under a protocol with several
        (:func:`ptztrack.experiments.ptz_tables.protocol_folds`).
    """

    scenario: Scenario
    strategy: PolicySpec
    seed: int
    label: str = ""
    camera: CameraSpec | None = None
    detector: DetectorSpec | None = None
    fold: int | None = None

    @property
    def column(self) -> str:
        return self.label or strategy_name(self.strategy)


def cell_policy(cell: Cell) -> PolicySpec:
    """The policy spec a cell runs: its registered name, or a fresh copy of its object."""
    if isinstance(cell.strategy, str):
        return cell.strategy
    return copy.deepcopy(cell.strategy)


def cell_metrics(cell: Cell) -> dict:
    """Run one cell; returns its metrics with ``strategy``, ``label``, ``beta`` (None for baselines) and ``seed``."""
    episode = run_episode(cell.scenario, cell_policy(cell), cell.seed, camera=cell.camera, detector=cell.detector)
    assert isinstance(episode, Episode), "a table's cell runs one camera"
    beta = cell.scenario.control.beta if cell.strategy in INFORMATION_STRATEGIES else None
    name = strategy_name(cell.strategy)
    fold = {} if cell.fold is None else {"fold": cell.fold}
    return {"strategy": name, "label": cell.column, "beta": beta, "seed": cell.seed, **fold, **episode_metrics(episode)}


@dataclass(frozen=True)
class Execution:
    """Where an experiment's cells run: ``executor`` ('local', 'ray' or 'serial') with ``workers``
    processes of the local one (None: all cores), as :func:`ptztrack.loop.executors.execute_cells`
    takes them; ``quiet``: no progress bar (there is none either where stderr is not a terminal)."""

    executor: str
    workers: int | None
    quiet: bool


def run_experiment_cells(cells: list, run, execution: Execution, noun: str = "episode", together=None) -> list:
    """An experiment's cells run with ``run`` on ``execution``, counted by a progress bar of ``noun``s;
    ``together`` as :func:`ptztrack.loop.executors.execute_cells`'."""
    with Progress(noun, execution.quiet) as progress:
        return execute_cells(cells, run, execution.executor, execution.workers, progress, together)
