"""Every script of examples/ runs as its docstring says (``python examples/NAME.py``, in a folder of its
own, with its small defaults) and prints or writes what it shows; each is listed in the gallery
(docs/examples.md)."""

import importlib.util
import json
import re
import subprocess
import sys

import pytest

from docs_blocks import REPOSITORY, environment

EXAMPLES = REPOSITORY / "examples"
TIMEOUT_S = 120.0


def run_example(name: str, folder, *arguments: str) -> str:
    """What ``python examples/NAME.py ARGUMENTS`` prints, run in ``folder``; it must exit 0."""
    try:
        done = subprocess.run(
            [sys.executable, str(EXAMPLES / name), *arguments],
            cwd=folder,
            env=environment(),
            capture_output=True,
            text=True,
            timeout=TIMEOUT_S,
        )
    except subprocess.TimeoutExpired as timeout:
        streams = (timeout.stdout, timeout.stderr)
        printed = [text.decode() if isinstance(text, bytes) else text or "" for text in streams]
        pytest.fail(f"examples/{name} ran over {TIMEOUT_S:.0f} s:\n" + "".join(printed)[-4000:], pytrace=False)
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout


def check_first_episode(printed, folder):
    assert re.search(r"MOTA -?[\d.]+%, MOTP [\d.]+ m, IDF1 [\d.]+%", printed), printed
    metrics = json.loads((folder / "first-episode" / "metrics.json").read_text())
    assert f"MOTA {metrics['mota']:.1%}" in printed
    for name in ("steps.csv", "tracks.csv", "tracks_mot.txt", "truth_mot.txt", "episode.png"):
        assert (folder / "first-episode" / name).stat().st_size > 0, name


def check_compare_policies(printed, folder):
    for policy in ("fix", "smpl"):
        runs = r"( +-?[\d.]+%){3}"
        assert re.search(rf"^ +{policy}: {runs} +mean -?[\d.]+% \+- [\d.]+% \(sd\)$", printed, re.M), printed
    assert re.search(r"smpl - fix: [+-][\d.]+ \+- [\d.]+ points", printed), printed


def check_score_tracker_files(printed, folder):
    assert "the run's own metrics agree with its files' scores" in printed, printed
    assert re.search(r"^noisy \(0\.3 m\) +[\d.]+%", printed, re.M), printed
    assert (folder / "scored-run" / "other_tracker_mot.txt").stat().st_size > 0


def check_render_and_track(printed, folder):
    assert (folder / "rendered" / "dataset.yaml").is_file()
    for policy in ("fix", "smpl"):
        assert re.search(rf"^ *{policy}: MOTA -?[\d.]+%, [1-9]\d* detections", printed, re.M), printed


def check_custom_detector(printed, folder):
    assert re.search(r"^detectors: .*\bnear-sighted\b", printed, re.M), printed
    assert re.search(r"^near-sighted: MOTA -?[\d.]+%, [1-9]\d* detections", printed, re.M), printed


def check_plot_run(printed, folder):
    assert re.search(r"^wrote run\.png \([1-9]\d* tracks of 7 people\)$", printed, re.M), printed
    assert (folder / "run.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def check_custom_policy(printed, folder):
    assert re.search(r"^one episode: MOTA -?[\d.]+%", printed, re.M), printed
    assert re.search(r"fix +smpl +follow_the_most_uncertain", printed), printed


def check_virtual_camera_live(printed, folder):
    assert re.search(r"^virtual camera at onvif://127\.0\.0\.1:\d+$", printed, re.M), printed
    assert re.search(r"^8 pictures used of \d+ received", printed, re.M), printed


CHECKS = {
    "first_episode.py": check_first_episode,
    "compare_policies.py": check_compare_policies,
    "score_tracker_files.py": check_score_tracker_files,
    "render_and_track.py": check_render_and_track,
    "custom_detector.py": check_custom_detector,
    "plot_run.py": check_plot_run,
    "custom_policy.py": check_custom_policy,
}
LIVE = "virtual_camera_live.py"


@pytest.mark.parametrize("name", CHECKS)
def test_example_runs_and_shows_what_it_says(name, tmp_path):
    CHECKS[name](run_example(name, tmp_path), tmp_path)


# A live run: one at a time, as the live tests run (tests/test_loop_live_onvif.py).
@pytest.mark.onvif
@pytest.mark.xdist_group("live-loop")
def test_virtual_camera_example_runs_the_live_loop_for_its_pictures(tmp_path):
    if importlib.util.find_spec("ipycam") is None:
        pytest.skip("the virtual ONVIF camera needs ipycam (pip install --no-deps ipycam==1.3.0)")
    check_virtual_camera_live(run_example(LIVE, tmp_path), tmp_path)


def test_every_example_is_run_here_and_listed_in_the_gallery():
    scripts = {path.name for path in EXAMPLES.glob("*.py")}
    assert scripts == {*CHECKS, LIVE}
    gallery = (REPOSITORY / "docs" / "examples.md").read_text(encoding="utf-8")
    assert not [name for name in scripts if f"examples/{name}" not in gallery]
