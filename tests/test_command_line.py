"""The command line a user expects: ``--version``, one name per policy in every command (a former name taken
with one line saying the current one), every option's help with its default, and an address's password
never shown. The mistakes of the command line are in the bad-input corpus (tests/bad_command_inputs.py)."""

import argparse
import os
import re
import subprocess
import sys
import tomllib
from importlib.metadata import version
from pathlib import Path

import pytest

from docs_blocks import read_blocks
from ptztrack import registry
from ptztrack.cli import main, parser
from ptztrack.service import load_service_config

DOCS = Path(__file__).parents[1] / "docs"
RENAMED_LINE = "ptztrack: the policy 'random' is now called 'rnd' (the old name will go in a later release)"


def commands(command: argparse.ArgumentParser):
    """``command`` and every subcommand under it."""
    yield command
    for action in command._actions:
        if isinstance(action, argparse._SubParsersAction):
            for subcommand in dict.fromkeys(action.choices.values()):
                yield from commands(subcommand)


def help_entries(command: argparse.ArgumentParser) -> dict[str, str]:
    """Each option's entry in the command's ``--help``, by its first flag, its lines joined."""
    entries: dict[str, str] = {}
    flag = None
    for line in command.format_help().splitlines():
        if line.startswith("  -"):
            flag = line.split()[0].rstrip(",")
            entries[flag] = line
        elif flag is not None and line.startswith("    "):
            entries[flag] += " " + line
        else:
            flag = None
    return {flag: " ".join(entry.split()) for flag, entry in entries.items()}


def help_of(argv: list[str], capsys) -> str:
    with pytest.raises(SystemExit) as exited:
        main([*argv, "--help"])
    assert exited.value.code == 0
    return " ".join(capsys.readouterr().out.split())


def test_version_is_the_installed_distributions(capsys):
    with pytest.raises(SystemExit) as exited:
        main(["--version"])
    assert exited.value.code == 0
    assert capsys.readouterr().out == f"ptztrack {version('ptztrack')}\n"


def test_every_option_of_every_command_has_help_that_ends_in_its_default():
    for command in commands(parser()):
        entries = help_entries(command)
        for action in command._actions:
            if not action.option_strings or isinstance(action, argparse._HelpAction | argparse._VersionAction):
                continue
            entry = entries[action.option_strings[0]]
            assert action.help, (command.prog, action.option_strings)
            if action.default is not None and action.default is not False:
                assert "default" in entry, (command.prog, entry)


def test_the_help_shows_the_policy_seed_sequences_and_strategies_defaults(capsys):
    run = help_of(["run"], capsys)
    assert "how the camera picks its next view" in run and "(default smpl)" in run and "(default 0)" in run
    synthetic = help_of(["experiment", "synthetic"], capsys)
    assert "the table's columns (default fix patrol rnd intg smpl)" in synthetic
    assert "sequences every strategy runs on (seeds 0 .. n-1) (default 12)" in synthetic
    assert "(default local)" in help_of(["experiment", "pets"], capsys)


def test_every_command_names_the_policies_one_way():
    for command in commands(parser()):
        for action in command._actions:
            if action.dest in ("policy", "strategies"):
                assert list(action.choices) == registry.names("policies"), (command.prog, action.dest)
    assert "rnd" in registry.names("policies") and "random" not in registry.names("policies")


def run_command(argv: list[str], cwd: Path) -> subprocess.CompletedProcess:
    """The command in a fresh process (a former name is told once a process)."""
    command = [sys.executable, "-m", "ptztrack.cli", *argv]
    return subprocess.run(command, capture_output=True, text=True, cwd=cwd, env=os.environ, timeout=120)


@pytest.mark.parametrize(
    ("argv", "printed"),
    [
        (["run", "--policy", "random", "--frames", "2", "--detector", "ideal"], "policy rnd,"),
        (["experiment", "synthetic", "--strategies", "fix", "random", "--sequences", "1", "--frames", "2",
          "--executor", "serial"], " rnd"),
    ],
    ids=["run --policy random", "experiment --strategies random"],
)  # fmt: skip
def test_the_former_name_random_runs_rnd_with_one_line_saying_so(tmp_path, argv, printed):
    result = run_command(argv, tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stderr.splitlines()[0] == RENAMED_LINE and result.stderr.count("random") == 1, result.stderr
    assert printed in result.stdout


def test_a_service_file_with_the_former_name_runs_rnd(tmp_path):
    config = tmp_path / "serve.yaml"
    config.write_text("cameras:\n  - {name: a, url: 'onvif://127.0.0.1:9', calibration: virtual, policy: random}\n")
    assert load_service_config(config).cameras[0].policy == "rnd"


def test_an_address_without_its_scheme_never_shows_its_password(capfd):
    with pytest.raises(SystemExit) as exited:
        main(["live", "--camera", "op:secret@camera.local:80", "--calibration", "virtual"])
    assert exited.value.code == 2
    (line,) = capfd.readouterr().err.splitlines()
    assert "onvif://camera.local:80" in line and "secret" not in line


def code_blocks(page: Path, language: str) -> list[str]:
    """The text of ``page``'s fenced blocks in ``language``, read as the docs' block runner reads them."""
    return [block.code for block in read_blocks(str(page), page.read_text()) if block.language == language]


def test_the_extending_pages_policy_runs_as_pasted(tmp_path):
    (snippet,) = code_blocks(DOCS / "extending.md", "python")
    (tmp_path / "mine.py").write_text(snippet)
    result = subprocess.run(
        [sys.executable, "mine.py"], capture_output=True, text=True, cwd=tmp_path, env=os.environ, timeout=300
    )
    assert result.returncode == 0, result.stderr
    assert "one episode: MOTA" in result.stdout
    assert re.search(r"fix +rnd +stay_put", result.stdout), result.stdout


def test_the_extending_pages_entry_points_are_ptztracks_groups():
    (toml,) = code_blocks(DOCS / "extending.md", "toml")
    groups = tomllib.loads(toml)["project"]["entry-points"]
    assert set(groups) == {registry.ENTRY_POINT_GROUPS["policies"], registry.ENTRY_POINT_GROUPS["detectors"]}
