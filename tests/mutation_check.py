"""Plant known faults in a copy of the package and check that the fast tests catch each one.

    python tests/mutation_check.py [--tests PATHS...] [--faults NAMES...] [--skip-baseline] [--list]

``src/ptztrack`` is copied once into a temporary directory (a snapshot: others may be editing the working
tree meanwhile), and for each fault the snapshot is copied again and the fault planted there by an
exact text replacement (the old text must occur exactly once in its module, or the script stops: the
code has moved and the fault must be pointed at its new place), and

    python -m pytest -q -x -m "not slow" -p no:cacheprovider [PATHS...]

runs from the repository with ``PYTHONPATH`` set to the copy's ``src``, which Python searches before
the editable install (checked for every copy: ``ptztrack.__file__`` must lie in it). The tests are the
repository's own; only the package is the copy. The working tree is never changed.

One line per fault: ``caught`` with the first failing test's id (and, below, the statement it failed at
and its error), or ``NOT caught`` (no test failed, or a test file could not even be imported, which tells
nothing about the fault).
Before the faults, the same tests run on an unchanged copy (the baseline; ``--skip-baseline`` leaves it
out): a suite that fails without any fault would "catch" every fault. Exit status 1 when a fault is not
caught (or the baseline fails), 2 when a fault cannot be planted.

Not collected by pytest (its name does not start with ``test_``).
"""

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parents[1]
PACKAGE = REPOSITORY / "src" / "ptztrack"


@dataclass(frozen=True)
class Fault:
    """A fault: ``old`` replaced by ``new`` in ``module`` (a path relative to ``src/ptztrack``)."""

    name: str
    module: str
    old: str
    new: str
    what: str


FAULTS = [
    Fault(
        "evidence-reads-truth",
        "track/tracker.py",
        "            evidence = tracker_evidence(tracks, update, detections.feet_px, self.camera, pose, detectable,"
        " parameters)\n",
        "            evidence = tracker_evidence(tracks, update, detections.feet_px, self.camera, pose, detectable,"
        " parameters)\n"
        '            truth = getattr(getattr(getattr(view, "func", None), "__self__", None), "truth", None)\n'
        "            if truth is not None:\n"
        "                people_m = truth.positions_m[view.args[0]]\n"
        "                near_m = np.linalg.norm(evidence.mean_m[:, None, :] - people_m[None, :, :], axis=-1)\n"
        "                evidence = replace(evidence, detected=np.any(near_m < 1.0, axis=1))\n",
        "the detector model's evidence counts a track as detected where a true person stands (the truth of the "
        "simulated camera, read through the step's image source)",
    ),
    Fault(
        "draw-ignored",
        "detect/detector_model.py",
        "        drawn = self.rng.beta(successes, failures)\n",
        "        drawn = successes / (successes + failures)\n",
        "the planning curve is fitted to the posterior means instead of a Thompson draw",
    ),
    Fault(
        "gate-off",
        "track/association.py",
        "    allowed = pairable[:, None] & (distance2 <= chi2.ppf(gate_probability, df=2))\n",
        "    allowed = np.ones(distance2.shape, dtype=bool)\n",
        "every detection is admissible to every track (no gate)",
    ),
    Fault(
        "existence-skipped",
        "track/tracker.py",
        "    existence = existence_after_miss(tracks.existence, detectable)\n"
        '    if parameters.existence_update == "fixed" or likelihood is None:\n'
        "        existence[track_index] = parameters.existence_when_detected\n"
        "    else:\n"
        "        existence[track_index] = existence_after_detection(\n"
        "            tracks.existence[track_index],\n"
        "            detectable[track_index],\n"
        "            likelihood[track_index],\n"
        "            parameters.clutter_density_per_px2,\n"
        "            parameters.existence_when_detected,\n"
        "        )\n",
        "    existence = tracks.existence.copy()\n"
        '    if parameters.existence_update == "fixed" or likelihood is None:\n'
        "        existence[track_index] = parameters.existence_when_detected\n",
        "the Bayes update of a track's existence keeps the prior existence (miss and detection alike)",
    ),
    Fault(
        "patrol-zero",
        "control/exploration.py",
        "        return self.detection_probability(actions) @ binary_entropy_nats(self.occupancy)\n",
        "        return 0.0 * (self.detection_probability(actions) @ binary_entropy_nats(self.occupancy))\n",
        "the patrolling term I_p(a) is zero for every action",
    ),
]
FAULT_NAMES = [fault.name for fault in FAULTS]


class PlantingError(Exception):
    """A fault's old text is not found exactly once in its module."""


def copy_package(destination: Path, package: Path = PACKAGE) -> Path:
    """``package`` (by default ``src/ptztrack``) copied to ``destination/src/ptztrack`` (no byte code);
    returns the copy's ``src``."""
    src = destination / "src"
    shutil.copytree(package, src / "ptztrack", ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    return src


def planted(fault: Fault, package: Path = PACKAGE) -> str:
    """The text of the fault's module in ``package`` with the fault planted."""
    path = package / fault.module
    if not path.is_file():
        raise PlantingError(f"{fault.name}: no module {fault.module} in src/ptztrack (has the code moved?)")
    text = path.read_text()
    count = text.count(fault.old)
    if count != 1:
        raise PlantingError(
            f"{fault.name}: the old text occurs {count} times in {fault.module}, not exactly once "
            f"(has the code moved or changed?):\n{fault.old}"
        )
    return text.replace(fault.old, fault.new)


def plant(src: Path, fault: Fault) -> None:
    """Plant the fault in the copy of the package under ``src``."""
    (src / "ptztrack" / fault.module).write_text(planted(fault, src / "ptztrack"))


def environment(src: Path) -> dict[str, str]:
    """The environment of a run against the copy under ``src``: it first on ``PYTHONPATH``, no byte code."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(src), *filter(None, [env.get("PYTHONPATH")])])
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    env["COLUMNS"] = "400"  # wide enough for pytest's summary to keep the failure's message
    return env


def check_imported_from(src: Path) -> str:
    """``ptztrack.__file__`` as a subprocess with the copy's environment imports it; it must lie in ``src``."""
    result = subprocess.run(
        [sys.executable, "-c", "import ptztrack; print(ptztrack.__file__)"],
        cwd=REPOSITORY,
        env=environment(src),
        capture_output=True,
        text=True,
        check=True,
    )
    imported = Path(result.stdout.strip())
    if not imported.resolve().is_relative_to(src.resolve()):
        raise SystemExit(f"ptztrack was imported from {imported}, not from the copy in {src}: PYTHONPATH had no effect")
    return str(imported)


@dataclass(frozen=True)
class Outcome:
    exit_code: int
    first_failure: str  # the first failing test's id, or "" where no test failed
    where: str  # the statement it failed at and the start of its error
    seconds: float
    uncollected: bool  # a test file could not be collected (imported): no test told anything

    @property
    def caught(self) -> bool:
        """A test failed (or erred while it ran), not a file that could not be imported. Pytest exits with 1,
        or with 2 where ``-x`` stops parallel workers (the project's ``addopts`` run pytest-xdist)."""
        return self.exit_code in (1, 2) and "::" in self.first_failure and not self.uncollected


def failure_where(output: str) -> str:
    """The first failure's report in pytest's ``output``, in one line: the last statement shown (``>``) and
    the first lines of its error (``E``)."""
    sections = re.split(r"^_{3,} .+ _{3,}$", output, flags=re.MULTILINE)
    if len(sections) < 2:
        return ""
    report = sections[1].split("short test summary info")[0].splitlines()
    statements = [line[1:].strip() for line in report if line.startswith(">")]
    errors = [line[1:].strip() for line in report if line.startswith("E ") and line[1:].strip()]
    where = " | ".join([*statements[-1:], *errors[:3]])
    return where if len(where) <= 300 else where[:297] + "..."


def run_tests(src: Path, tests: list[str]) -> Outcome:
    """The fast tests ``tests`` (None: the whole fast suite) against the copy under ``src``."""
    command = [sys.executable, "-m", "pytest", "-q", "-x", "-m", "not slow", "-p", "no:cacheprovider", *tests]
    started = time.perf_counter()
    result = subprocess.run(command, cwd=REPOSITORY, env=environment(src), capture_output=True, text=True)
    failures = re.findall(r"^(?:FAILED|ERROR) (\S+)", result.stdout, flags=re.MULTILINE)
    first = failures[0] if failures else ""
    uncollected = bool(re.search(r"^_{3,} ERROR collecting ", result.stdout, flags=re.MULTILINE))
    seconds = time.perf_counter() - started
    return Outcome(result.returncode, first, failure_where(result.stdout), seconds, uncollected)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--tests", nargs="+", default=[], metavar="PATH", help="test files (or ids) to run; default: the fast suite"
    )
    parser.add_argument(
        "--faults", nargs="+", default=FAULT_NAMES, choices=FAULT_NAMES, metavar="NAME", help=f"of {FAULT_NAMES}"
    )
    parser.add_argument("--skip-baseline", action="store_true", help="do not run the tests on an unchanged copy first")
    parser.add_argument("--list", action="store_true", help="list the faults, where they go and what they do; run none")
    args = parser.parse_args(argv)
    faults = [fault for fault in FAULTS if fault.name in args.faults]
    width = max(len(fault.name) for fault in faults)
    if args.list:
        for fault in faults:
            print(f"{fault.name:<{width}}  src/ptztrack/{fault.module}: {fault.what}")
        return 0
    print("tests:", " ".join(args.tests) or "the fast suite (-m 'not slow')", flush=True)

    with tempfile.TemporaryDirectory(prefix="ptztrack-mutants-") as directory:
        # One snapshot of the package for every run (others may be editing the working tree meanwhile).
        snapshot = copy_package(Path(directory) / "snapshot") / "ptztrack"
        for fault in faults:  # every fault's old text is found before any test runs
            planted(fault, snapshot)

        src = copy_package(Path(directory) / "baseline", snapshot)
        print(f"{'baseline':<{width}}  imports {check_imported_from(src)}", flush=True)
        if not args.skip_baseline:
            outcome = run_tests(src, args.tests)
            if outcome.exit_code != 0:
                print(f"{'baseline':<{width}}  FAILS without any fault: {outcome.first_failure or outcome.exit_code}")
                print(f"{'':<{width}}    {outcome.where}")
                return 1
            print(f"{'baseline':<{width}}  passes ({outcome.seconds:.0f} s)", flush=True)

        missed = []
        for fault in faults:
            src = copy_package(Path(directory) / fault.name, snapshot)
            plant(src, fault)
            check_imported_from(src)
            outcome = run_tests(src, args.tests)
            if outcome.caught:
                verdict = f"caught      by {outcome.first_failure}"
            elif outcome.exit_code == 0:
                verdict, missed = "NOT caught", [*missed, fault.name]
            elif outcome.uncollected:
                verdict = f"NOT caught  ({outcome.first_failure} could not be collected)"
                missed = [*missed, fault.name]
            else:
                verdict, missed = f"NOT caught  (pytest exited {outcome.exit_code})", [*missed, fault.name]
            print(f"{fault.name:<{width}}  {verdict}  ({outcome.seconds:.0f} s)", flush=True)
            if outcome.where:
                print(f"{'':<{width}}    {outcome.where}", flush=True)
            shutil.rmtree(src.parent)
    return 1 if missed else 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except PlantingError as error:
        print(f"cannot plant: {error}", file=sys.stderr)
        sys.exit(2)
