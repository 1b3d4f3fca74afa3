"""Fixtures that more than one test file uses.

Session-scoped ones are built once and are read-only (the arrays are marked so): a test that needs to
change one works on a copy.
"""

import os
from pathlib import Path

import pytest
from hypothesis import settings

from ptztrack.config import load_scenario
from ptztrack.scene.pets import read_video

# Every property test draws the same examples on every run (a seed per test), as everything else in
# the suite does: a failure is a fact about the code, not about the run.
settings.register_profile("ptztrack", derandomize=True)
settings.load_profile("ptztrack")

EXCERPT = Path(__file__).parent / "data" / "pets_s2l1_excerpt"
"""Frames 0-29 of PETS 2009 S2L1 View_001 (video, ground truth, both calibrations)."""


@pytest.fixture(scope="session")
def excerpt_frames():
    """The excerpt's 30 frames, (30, 576, 768, 3) uint8 BGR, decoded once; read-only."""
    frames = read_video(EXCERPT / "View_001.avi")
    frames.flags.writeable = False
    return frames


def _excerpt_scenario(directory: Path, **overrides):
    """A small PETS scenario on the excerpt (15 frames at 5 Hz, a 160 x 120 camera, a few actions, the
    ideal detector without noise), written as a file into ``directory`` that names its ground truth
    relative to itself, and loaded with ``overrides``."""
    path = directory / "pets.yaml"
    path.write_text(
        f"""
frames: 15
frame_rate_hz: 5.0
camera: {{image_size_px: [160, 120]}}
actions:
  pan_deg: {{start: -14, stop: 14, count: 7}}
  tilt_deg: {{start: -10, stop: 10, count: 5}}
  zoom: [1, 2, 3, 4]
detector: {{kind: ideal, pixel_noise_px: 0.0}}
recording:
  ground_truth: {os.path.relpath(EXCERPT / "gt_mot15.txt", directory)}
  calibration: {EXCERPT / "pinhole.json"}
  frame_step: 2
  recorded_size_px: [768, 576]
"""
    )
    return load_scenario(path, **overrides)


@pytest.fixture(scope="session")
def excerpt_scenario():
    """``excerpt_scenario(directory, **overrides)``: the small PETS scenario file of the excerpt, written
    into ``directory`` (a test's tmp_path) and loaded."""
    return _excerpt_scenario


def pytest_collection_modifyitems(config, items):
    """Tests that share a module-scoped fixture run in one worker (one xdist group per module), so the
    fixture is built once for the whole run rather than once per worker."""
    for item in items:
        if item.get_closest_marker("xdist_group") is not None:
            continue
        definitions = getattr(item, "_fixtureinfo", None)
        scopes = {
            definition.scope
            for defs in (definitions.name2fixturedefs.values() if definitions else ())
            for definition in defs
        }
        if "module" in scopes:
            item.add_marker(pytest.mark.xdist_group(item.module.__name__))


def pytest_terminal_summary(terminalreporter):
    """The docs' code blocks run and not run (tests/test_docs_code_blocks.py), one line, then the reasons
    of those not run with their counts; from the pages' reports, so also when xdist's workers ran them."""
    from collections import Counter

    from docs_blocks import COUNTS_PROPERTY

    ran, reasons, pages = 0, Counter(), 0
    for reports in terminalreporter.stats.values():
        for report in reports:
            if getattr(report, "when", None) != "call":
                continue
            for name, value in getattr(report, "user_properties", ()):
                if name == COUNTS_PROPERTY:
                    pages += 1
                    ran += value[0]
                    reasons.update(reason for _, reason in value[1])
    if pages:
        terminalreporter.write_line(f"docs code blocks: {ran} run, {sum(reasons.values())} skipped")
        for reason, count in reasons.most_common():
            terminalreporter.write_line(f"  {count} x {reason}")
