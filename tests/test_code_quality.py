"""The promises about the code itself that a tool can check: layers, lint, types."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.slow


@pytest.mark.parametrize(
    "command",
    [
        ["lint-imports"],
        ["ruff", "check", "src", "tests", "benchmarks", "examples"],
        ["ruff", "format", "--check", "src", "tests", "benchmarks", "examples"],
        ["mypy"],
    ],
    ids=["layers", "lint", "format", "types"],
)
def test_the_code_keeps_its_contracts(command):
    """import-linter's contracts (pyproject.toml: layers, configuration at the edge, no cycles), ruff and mypy."""
    executable = shutil.which(command[0], path=str(Path(sys.executable).parent))
    assert executable is not None, f"{command[0]} is not installed: pip install '.[test]'"
    result = subprocess.run([executable, *command[1:]], cwd=ROOT, capture_output=True, text=True)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]


def test_no_module_is_over_500_lines_and_no_step_loop_lives_outside_the_loop_package():
    """A module a reader takes in whole; the closed loops (a camera observes, the belief is updated, a
    policy decides, step by step) written once, in ``ptztrack.loop``."""
    modules = sorted((ROOT / "src").rglob("*.py")) + sorted((ROOT / "tests").glob("*.py"))
    long = {str(path.relative_to(ROOT)): n for path in modules if (n := len(path.read_text().splitlines())) > 500}
    assert long == {}
    loop = ROOT / "src" / "ptztrack" / "loop"
    stepping = [
        str(path.relative_to(ROOT))
        for path in (ROOT / "src" / "ptztrack").rglob("*.py")
        if loop not in path.parents and "for step in range(" in path.read_text()
    ]
    assert stepping == []
