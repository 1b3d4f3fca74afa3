"""The fenced code blocks of the README and the docs, read and run as a reader would paste them.

The conventions every page follows:

- every fence names its language; ``bash`` and ``python`` blocks are run, every other language
  (``text``, ``yaml``, ``toml``, ``json``, ``ini``, ...) is read only;
- ``<!-- not-run: REASON -->`` on the line directly above a fence: the block is not run, for REASON; a
  ``bash`` block that installs packages (``pip install``) must be so marked, since run it would change
  the environment the tests run in;
- ``<!-- background -->`` on the line directly above a ``bash`` fence: the block starts in the
  background, is taken as up once it has printed a line and then been quiet for a moment, and is
  stopped (its whole process group) when the page's blocks end.

A page's blocks run in order in one temporary folder, in which the repository's ``examples/`` folder is
reachable as ``examples/``: ``python`` blocks each in a fresh interpreter (the one running the tests),
``bash`` blocks with ``bash -euo pipefail``; the ``ptztrack`` and ``python`` they name are those of
that interpreter.
"""

import os
import re
import signal
import subprocess
import sys
import time
from contextlib import suppress
from dataclasses import dataclass
from pathlib import Path

import ptztrack

REPOSITORY = Path(__file__).resolve().parent.parent
RUN_LANGUAGES = ("bash", "python")
# Tags a reader's eye takes for runnable code but the runner would not run: one spelling each, so that
# no block is left out by its tag.
MISSPELT_LANGUAGES = {
    "sh": "bash",
    "shell": "bash",
    "console": "bash",
    "zsh": "bash",
    "py": "python",
    "python3": "python",
    "pycon": "python",
}
BLOCK_TIMEOUT_S = 120.0
BACKGROUND_UP_TIMEOUT_S = 60.0
BACKGROUND_QUIET_S = 1.0
"""A background block is taken as up once its first line is out and it has then printed nothing for this long."""
STOP_TIMEOUT_S = 10.0
COUNTS_PROPERTY = "docs_code_blocks"
"""The user property a page's test records its counts under: (blocks run, [(where, reason) not run])."""
OUTPUT_TAIL_LINES = 40

_FENCE = re.compile(r"^(?P<indent> *)(?P<fence>`{3,}|~{3,})(?P<info>.*)$")
_NOT_RUN = re.compile(r"^\s*<!--\s*not-run:(?P<reason>.*?)-->\s*$")
_BACKGROUND = re.compile(r"^\s*<!--\s*background\s*-->\s*$")
_INSTALLS = re.compile(r"\bpip3? install\b")
# What a misspelt marker looks like, so that it is refused rather than read as no marker.
_MARKER = re.compile(r"^\s*<!--\s*(not[\s_-]*run|background)", re.IGNORECASE)


class PageError(AssertionError):
    """A page that breaks the conventions, or a block of it that fails: the message names the page and line."""


@dataclass(frozen=True)
class Block:
    """One fenced block: its page (relative to the repository), the 1-based line of its opening fence,
    its language, its text (the fence's indentation removed), and how it runs: ``run``, ``background``
    or ``not-run`` (then ``reason`` says why)."""

    page: str
    line: int
    language: str
    code: str
    mode: str
    reason: str = ""

    @property
    def where(self) -> str:
        return f"{self.page}:{self.line}"


def pages() -> list[str]:
    """README.md and every page of docs/, relative to the repository."""
    docs = sorted(path.relative_to(REPOSITORY).as_posix() for path in (REPOSITORY / "docs").rglob("*.md"))
    return ["README.md", *docs]


def serves_in_background(text: str) -> bool:
    """Whether the Markdown ``text`` has a ``<!-- background -->`` block."""
    return any(_BACKGROUND.match(line) for line in text.splitlines())


def _marker(page: str, number: int, line: str, language: str) -> tuple[str, str]:
    """The block's mode and reason from the line above its fence (numbered ``number``)."""
    not_run = _NOT_RUN.match(line)
    if not_run:
        reason = not_run["reason"].strip()
        if not reason:
            raise PageError(f"{page}:{number}: <!-- not-run: REASON --> without a reason")
        return "not-run", reason
    if _BACKGROUND.match(line):
        if language != "bash":
            raise PageError(f"{page}:{number}: <!-- background --> above a {language} block; only bash runs so")
        return "background", ""
    if _MARKER.match(line):
        raise PageError(f"{page}:{number}: expected <!-- not-run: REASON --> or <!-- background -->: {line.strip()}")
    return ("run" if language in RUN_LANGUAGES else "read"), ""


def read_blocks(page: str, text: str) -> list[Block]:
    """Every fenced block of the Markdown ``text`` of ``page``, in order. A fence without a language, or
    tagged with another spelling of a run language, raises :class:`PageError` naming its line."""
    lines = text.splitlines()
    blocks = []
    index = 0
    while index < len(lines):
        opening = _FENCE.match(lines[index])
        if opening is None or ("`" in opening["info"] and opening["fence"][0] == "`"):
            index += 1
            continue
        indent, fence = len(opening["indent"]), opening["fence"]
        number = index + 1
        language = opening["info"].strip().split(" ")[0].strip("{}.").lower() if opening["info"].strip() else ""
        if not language:
            raise PageError(f"{page}:{number}: a fence without a language (bash, python, text, yaml, ...)")
        if language in MISSPELT_LANGUAGES:
            raise PageError(f"{page}:{number}: tag the block {MISSPELT_LANGUAGES[language]!r}, not {language!r}")
        closing = re.compile(rf"^ *{re.escape(fence[0])}{{{len(fence)},}}\s*$")
        body = []
        index += 1
        while index < len(lines) and not closing.match(lines[index]):
            line = lines[index]
            body.append(line[min(indent, len(line) - len(line.lstrip(" "))) :])
            index += 1
        if index == len(lines):
            raise PageError(f"{page}:{number}: the fence is never closed")
        index += 1
        mode, reason = _marker(page, number - 1, lines[number - 2] if number >= 2 else "", language)
        if mode == "run" and language == "bash" and any(_INSTALLS.search(line) for line in body):
            # Run, it would change the environment the tests run in (CI installs as .ci/run says).
            raise PageError(f"{page}:{number}: a block that installs packages: mark it <!-- not-run: REASON -->")
        blocks.append(Block(page, number, language, "\n".join(body) + "\n", mode, reason))
    return blocks


def environment() -> dict[str, str]:
    """The blocks' environment: ``python`` and ``ptztrack`` first on the PATH are this interpreter's, and
    the ptztrack they import is the one under test; figures drawn to files, never to a screen."""
    variables = dict(os.environ)
    variables["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), variables.get("PATH", "")])
    package_parent = str(Path(ptztrack.__file__).resolve().parent.parent)
    variables["PYTHONPATH"] = os.pathsep.join(filter(None, [package_parent, variables.get("PYTHONPATH")]))
    variables["MPLBACKEND"] = "Agg"
    return variables


def _command(block: Block, folder: Path) -> list[str]:
    script = folder / f".block-{block.line}.{'py' if block.language == 'python' else 'sh'}"
    script.write_text(block.code)
    if block.language == "python":
        return [sys.executable, script.name]
    return ["bash", "-euo", "pipefail", script.name]


def _tail(output: str) -> str:
    return "\n".join(output.splitlines()[-OUTPUT_TAIL_LINES:])


def run_block(block: Block, folder: Path, variables: dict[str, str]) -> None:
    """Run ``block`` in ``folder`` to its end; a :class:`PageError` with the page, the line and the
    output's tail if it fails or outlasts BLOCK_TIMEOUT_S (its whole process group then stopped)."""
    process = subprocess.Popen(
        _command(block, folder),
        cwd=folder,
        env=variables,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
    )
    try:
        output, _ = process.communicate(timeout=BLOCK_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        with suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)
        output, _ = process.communicate()
        raise PageError(f"{block.where}: still running after {BLOCK_TIMEOUT_S:.0f} s:\n{_tail(output)}") from None
    if process.returncode != 0:
        raise PageError(f"{block.where}: exit status {process.returncode}:\n{_tail(output)}")


@dataclass
class Background:
    """A background block's process and the file its output goes to."""

    block: Block
    process: subprocess.Popen
    output: Path

    def printed(self) -> str:
        return self.output.read_text(errors="replace")


def start_background(block: Block, folder: Path, variables: dict[str, str]) -> Background:
    """Start ``block`` in a process group of its own and return once it is up (a line printed, then
    BACKGROUND_QUIET_S of quiet); a :class:`PageError` if it ends first or is not up in time."""
    output = folder / f".block-{block.line}.out"
    with open(output, "w") as sink:
        process = subprocess.Popen(
            _command(block, folder),
            cwd=folder,
            env={**variables, "PYTHONUNBUFFERED": "1"},
            stdin=subprocess.DEVNULL,
            stdout=sink,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    started = Background(block, process, output)
    deadline = time.monotonic() + BACKGROUND_UP_TIMEOUT_S
    size, quiet_since = 0, time.monotonic()
    while time.monotonic() < deadline:
        if process.poll() is not None:
            raise PageError(f"{block.where}: a background block ended, status {process.returncode}:\n"
                            f"{_tail(started.printed())}")  # fmt: skip
        now_size = output.stat().st_size
        if now_size != size:
            size, quiet_since = now_size, time.monotonic()
        elif size > 0 and time.monotonic() - quiet_since >= BACKGROUND_QUIET_S:
            return started
        time.sleep(0.1)
    stop_background(started)
    raise PageError(f"{block.where}: a background block not up (a line printed, then quiet) within "
                    f"{BACKGROUND_UP_TIMEOUT_S:.0f} s:\n{_tail(started.printed())}")  # fmt: skip


def stop_background(started: Background) -> None:
    """Stop a background block's whole process group: SIGTERM, then SIGKILL after STOP_TIMEOUT_S."""
    with suppress(ProcessLookupError):
        os.killpg(started.process.pid, signal.SIGTERM)
    try:
        started.process.wait(timeout=STOP_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        with suppress(ProcessLookupError):
            os.killpg(started.process.pid, signal.SIGKILL)
        started.process.wait()
    # Whatever the block's own processes left in its group (a server's children) goes with it.
    with suppress(ProcessLookupError):
        os.killpg(started.process.pid, signal.SIGKILL)


def page_folder(folder: Path) -> Path:
    """``folder``, made a page's: the repository's examples reachable in it as ``examples/``."""
    (folder / "examples").symlink_to(REPOSITORY / "examples", target_is_directory=True)
    return folder


def run_page(blocks: list[Block], folder: Path, ran: list[Block]) -> None:
    """Run a page's ``run`` and ``background`` blocks in order in ``folder`` (see :func:`page_folder`),
    appending each to ``ran`` as it completes or comes up; the background ones are stopped at the end,
    whatever happens."""
    variables = environment()
    backgrounds: list[Background] = []
    try:
        for block in blocks:
            if block.mode == "run":
                run_block(block, folder, variables)
            elif block.mode == "background":
                backgrounds.append(start_background(block, folder, variables))
            else:
                continue
            ran.append(block)
    finally:
        for started in reversed(backgrounds):
            stop_background(started)
