"""Every fenced block of the README and the docs, run as a reader pastes it (the conventions:
:mod:`docs_blocks`): one test per page, in page order in a folder of its own. The blocks run and those
not run, with their reasons, are counted at the end of the run's output (conftest.py)."""

import os
import re

import pytest

from docs_blocks import (
    COUNTS_PROPERTY,
    REPOSITORY,
    RUN_LANGUAGES,
    PageError,
    page_folder,
    pages,
    read_blocks,
    run_page,
    serves_in_background,
)


def page_parameters() -> list:
    """Every page, those that serve something in the background in the live tests' xdist group: their
    servers take fixed ports (the virtual camera's 8080, say) and their live runs are live runs, one at a
    time and none beside the live tests (tests/test_loop_live_onvif.py). The others run anywhere."""
    return [
        pytest.param(page, marks=[pytest.mark.xdist_group("live-loop")])
        if serves_in_background((REPOSITORY / page).read_text(encoding="utf-8"))
        else page
        for page in pages()
    ]


@pytest.mark.parametrize("page", page_parameters())
def test_page_code_blocks_run_as_written(page, tmp_path, record_property):
    try:
        blocks = read_blocks(page, (REPOSITORY / page).read_text(encoding="utf-8"))
    except PageError as error:
        pytest.fail(str(error), pytrace=False)
    skipped = [
        (block.where, block.reason) for block in blocks if block.mode == "not-run" and block.language in RUN_LANGUAGES
    ]
    ran: list = []
    try:
        run_page(blocks, page_folder(tmp_path), ran)
    except PageError as error:
        pytest.fail(str(error), pytrace=False)
    finally:
        record_property(COUNTS_PROPERTY, (len(ran), skipped))


PAGE = """# A page

<!-- not-run: needs a physical ONVIF camera -->
```bash
ptztrack live --camera onvif://192.0.2.1 --calibration mine.yaml
```

1. A step in a list:

    ```python title="step.py"
    print("in a list")
    ```

~~~yaml
a: 1
~~~
"""


def test_blocks_are_read_with_their_language_line_and_marker():
    skipped, listed, read = read_blocks("page.md", PAGE)
    assert (skipped.line, skipped.mode, skipped.reason) == (4, "not-run", "needs a physical ONVIF camera")
    assert (listed.line, listed.language, listed.mode, listed.code) == (10, "python", "run", 'print("in a list")\n')
    assert (read.line, read.language, read.mode) == (14, "yaml", "read")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("text\n\n```\nls\n```\n", "page.md:3: a fence without a language"),
        ("```sh\nls\n```\n", "page.md:1: tag the block 'bash', not 'sh'"),
        ("<!-- not-run: -->\n```bash\nls\n```\n", "page.md:1: <!-- not-run: REASON --> without a reason"),
        ("<!-- not run: a typo -->\n```bash\nls\n```\n", "page.md:1: expected <!-- not-run: REASON -->"),
        ("```bash\nls\n", "page.md:1: the fence is never closed"),
        ("```bash\npip install ptztrack\n```\n", "page.md:1: a block that installs packages"),
    ],
)
def test_a_page_against_the_conventions_is_refused_at_its_line(text, message):
    with pytest.raises(PageError, match=re.escape(message)):
        read_blocks("page.md", text)


def test_a_failing_block_names_its_page_and_line_with_its_output_and_background_blocks_are_stopped(tmp_path):
    text = (
        "<!-- background -->\n```bash\necho $$ > server.pid; echo up; exec sleep 300\n```\n\n"
        "```bash\ntest -s server.pid\necho 'the last words'\nfalse\n```\n"
    )
    ran: list = []
    with pytest.raises(PageError, match=r"page\.md:6: exit status 1:\nthe last words$"):
        run_page(read_blocks("page.md", text), tmp_path, ran)
    assert [block.line for block in ran] == [2]
    server = int((tmp_path / "server.pid").read_text())
    with pytest.raises(ProcessLookupError):
        os.kill(server, 0)
