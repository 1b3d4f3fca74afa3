"""Every fenced block of the README and the docs, run as a reader pastes it (the conventions:
:mod:`docs_blocks`): one test per page, in page order in a folder of its own. The blocks run and those
not run, with their reasons, are counted at the end of the run's output (conftest.py)."""

import pytest

from docs_blocks import REPOSITORY, RUN_LANGUAGES, PageError, page_folder, pages, read_blocks, run_page

# The pages' servers take fixed ports (the virtual camera's 8080, say), and their live runs are live runs:
# one page at a time, and none beside the live tests (tests/test_loop_live_onvif.py).
pytestmark = pytest.mark.xdist_group("live-loop")

COUNTS_PROPERTY = "docs_code_blocks"
"""The user property a page's test records its counts under: (blocks run, [(where, reason) not run])."""


@pytest.mark.parametrize("page", pages())
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
        with page_folder(tmp_path) as folder:
            run_page(blocks, folder, ran)
    except PageError as error:
        pytest.fail(str(error), pytrace=False)
    finally:
        record_property(COUNTS_PROPERTY, (len(ran), skipped))
