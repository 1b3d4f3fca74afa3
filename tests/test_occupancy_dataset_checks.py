"""A dataset's views against its area: a view that sees none of it is refused in one line naming the
view and why (exit status 2), a part that no view sees is warned of; and against its ground truth: a
view whose calibration puts the people far from its detections is warned of."""

import logging
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from bad_dataset_inputs import calibration_fit_case
from bad_input_files import _pinhole_with_k_scaled
from bad_inputs import write_case
from ptztrack.builders.occupancy import recording_from_dataset
from ptztrack.cli import main
from ptztrack.config import load_dataset

PETS = Path(__file__).resolve().parents[1] / "src" / "ptztrack" / "data" / "pets2009_s2l1"
DETECTIONS = "1,-1,300,200,40,100,0.9,-1,-1,-1\n2,-1,302,201,40,100,0.9,-1,-1,-1\n"
GROUND_TRUTH = "1,9,499,158,31.03,75.17,1,-4.1554,-7.3591,0\n2,9,497,158,31.03,75.17,1,-4.1744,-7.3156,0\n"
SEEN_WHOLE = "[[-12, -13], [-3, -5]]"  # by View_001, and by View_003
BEHIND = "[[-60, -60], [-40, -40]]"  # View_001 stands at (-28.9, -19.5) m, looking towards +x +y
BESIDE = "[[-40, 0], [-30, 10]]"  # in front of View_001, left of its 25 degrees


def write_dataset(directory: Path, area: str, views=("View_001",)) -> Path:
    """A small dataset of PETS views given by their Tsai files and two frames of boxes each, over ``area``."""
    lines = []
    for view in views:
        shutil.copy(PETS / f"{view}.xml", directory / f"{view}.xml")
        lines.append(f"  - {{name: {view}, calibration: {view}.xml, detections: det.txt}}\n")
    (directory / "det.txt").write_text(DETECTIONS)
    (directory / "gt.txt").write_text(GROUND_TRUTH)
    path = directory / "small.yaml"
    path.write_text(f"name: small\nframe_rate_hz: 10\narea_m: {area}\nground_truth: gt.txt\nviews:\n{''.join(lines)}")
    return path


def refused(path: Path, capsys) -> str:
    """The one line of a refused dataset (exit status 2)."""
    assert main(["experiment", "occupancy", str(path)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1, lines
    return lines[0]


def test_a_view_with_the_whole_area_behind_it_is_named(tmp_path, capsys):
    path = write_dataset(tmp_path, BEHIND)
    assert refused(path, capsys) == (
        f"ptztrack: error: {tmp_path / 'View_001.xml'}: views.0 (View_001) sees none of area_m: "
        "the whole area is behind the camera"
    )


def test_a_view_whose_image_holds_none_of_the_area_is_named(tmp_path, capsys):
    path = write_dataset(tmp_path, BESIDE)
    assert refused(path, capsys) == (
        f"ptztrack: error: {tmp_path / 'View_001.xml'}: views.0 (View_001) sees none of area_m: "
        "the whole area projects outside its 768x576 px image"
    )


def test_the_view_that_sees_nothing_is_named_among_views_that_see(tmp_path, capsys):
    """View_005 (720 x 576 px) sees none of an area that View_001 and View_003 see whole; View_007, which
    sees part of another, passes."""
    path = write_dataset(tmp_path, SEEN_WHOLE, views=("View_001", "View_003", "View_007"))
    assert main(["experiment", "occupancy", str(path), "--methods"]) == 0
    capsys.readouterr()
    path = write_dataset(tmp_path, "[[0, 3], [6, 8]]", views=("View_001", "View_003", "View_005"))
    assert refused(path, capsys) == (
        f"ptztrack: error: {tmp_path / 'View_005.xml'}: views.2 (View_005) sees none of area_m: "
        "the whole area projects outside its 720x576 px image"
    )


def test_a_part_that_no_view_sees_is_a_warning(tmp_path, capsys, caplog):
    path = write_dataset(tmp_path, "[[-20, -15], [20, 25]]")
    with caplog.at_level(logging.WARNING):
        assert main(["experiment", "occupancy", str(path), "--quiet", "--methods"]) == 0
    warnings = [record.getMessage() for record in caplog.records if record.levelno >= logging.WARNING]
    assert warnings == [
        "small: 36.0% of area_m is seen by no view (all of it within x -20.0 to 20.0 m, y -15.0 to 25.0 m); "
        "people there can only be missed"
    ]
    assert "lpom" in capsys.readouterr().out


def test_an_area_seen_whole_gets_no_warning(tmp_path, caplog):
    path = write_dataset(tmp_path, SEEN_WHOLE, views=("View_001", "View_003"))
    with caplog.at_level(logging.WARNING):
        assert main(["experiment", "occupancy", str(path), "--quiet", "--methods"]) == 0
    assert [record.getMessage() for record in caplog.records if record.levelno >= logging.WARNING] == []


def test_a_calibration_that_projects_the_ground_truth_onto_the_views_detections_gets_no_warning(tmp_path, caplog):
    """View_001's detections are the ground truth's own boxes, and PETS's pinhole calibration projects the
    people onto them (the same with K halved is warned of: tests/bad_dataset_inputs.py)."""
    case = calibration_fit_case("fit", 1.0, ("--quiet", "--methods"))
    with caplog.at_level(logging.WARNING):
        assert main(write_case(case, tmp_path)) == 0
    assert [record.getMessage() for record in caplog.records if record.levelno >= logging.WARNING] == []


@pytest.mark.parametrize("k_scale, warned", [(1.0, False), (0.5, True)])
def test_a_detector_that_finds_only_the_nearest_people_does_not_pass_for_a_wrong_calibration(
    tmp_path, caplog, k_scale, warned
):
    """View_001's shipped Keypoint R-CNN boxes cut to the tallest fifth of each frame (a detector that finds
    only the nearest people, as HOG does in a far view): with the view's calibration no warning, since the
    boxes that exist stand on projected people; with K halved, the warning."""
    table = np.loadtxt(PETS / "View_001_det.txt.gz", delimiter=",")
    table = table[table[:, 6] >= 0.5]
    frames = table[:, 0]
    tallest = np.concatenate(
        [
            np.flatnonzero(frames == frame)[table[frames == frame, 5] >= np.percentile(table[frames == frame, 5], 80)]
            for frame in np.unique(frames)
            if frame <= 100
        ]
    )
    np.savetxt(tmp_path / "det.txt", table[np.sort(tallest)], delimiter=",", fmt="%g")
    (tmp_path / "c.json").write_text(_pinhole_with_k_scaled(k_scale))
    shutil.copy(PETS / "gt_mot15.txt", tmp_path / "gt.txt")
    path = tmp_path / "nearest.yaml"
    path.write_text(
        "name: nearest\nframe_rate_hz: 10\nframes: 100\narea_m: [[-21.0, -17.5], [8.5, 9.0]]\nground_truth: gt.txt\n"
        "views:\n  - {name: View_001, calibration: c.json, image_size_px: [768, 576], detections: det.txt}\n"
    )
    with caplog.at_level(logging.WARNING):
        recording_from_dataset(load_dataset(path))
    warnings = [
        record.getMessage() for record in caplog.records if "is this the view's calibration" in record.getMessage()
    ]
    assert len(warnings) == int(warned)


@pytest.mark.slow
def test_the_command_exits_2_with_the_line_and_warns_on_stderr(tmp_path):
    """As a user runs it: the refusal's exit status and line, and the warning as a line of its own."""
    command, options = [sys.executable, "-m", "ptztrack.cli", "experiment", "occupancy"], ["--quiet", "--methods"]
    behind = write_dataset(tmp_path, BEHIND)
    result = subprocess.run([*command, str(behind), *options], capture_output=True, text=True)
    assert result.returncode == 2
    assert result.stderr.strip().endswith("views.0 (View_001) sees none of area_m: the whole area is behind the camera")
    partly = write_dataset(tmp_path, "[[-20, -15], [20, 25]]")
    result = subprocess.run([*command, str(partly), *options], capture_output=True, text=True)
    assert result.returncode == 0
    assert result.stderr.strip().splitlines() == [
        "ptztrack: small: 36.0% of area_m is seen by no view (all of it within x -20.0 to 20.0 m, y -15.0 to "
        "25.0 m); people there can only be missed"
    ]
