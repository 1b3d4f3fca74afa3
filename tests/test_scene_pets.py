import gzip
from dataclasses import replace
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from ptztrack.config import pets_dataset
from ptztrack.geometry.calibration import (
    CalibrationError,
    imaged_radius,
    in_image,
    load_calibration,
    load_pinhole,
    load_tsai,
    pinhole_from_tsai,
    pixel_rays,
    project_pinhole,
    project_tsai,
)
from ptztrack.scene.pets import DatasetError, load_cvml, load_mot_ground_truth, read_video, recorded_scene

EXCERPT = Path(__file__).parent / "data" / "pets_s2l1_excerpt"


def ground_truth_points_mm():
    truth = load_mot_ground_truth(EXCERPT / "gt_mot15.txt")
    points_mm = np.concatenate([truth.ground_m * 1000.0, np.zeros((len(truth.frame), 1))], axis=1)
    return truth, points_mm


@pytest.mark.parametrize("project", ["tsai", "pinhole"])
def test_both_calibrations_put_the_ground_truth_on_the_annotated_feet(project):
    truth, points_mm = ground_truth_points_mm()
    if project == "tsai":
        pixels = project_tsai(load_tsai(EXCERPT / "View_001.xml"), points_mm)
    else:
        pixels = project_pinhole(load_pinhole(EXCERPT / "pinhole.json"), points_mm)
    error_px = np.linalg.norm(pixels - truth.feet_px, axis=1)
    assert np.median(error_px) < 3.0
    assert np.percentile(error_px, 90) < 6.0


def test_the_two_calibrations_agree_with_each_other():
    _, points_mm = ground_truth_points_mm()
    tsai = project_tsai(load_tsai(EXCERPT / "View_001.xml"), points_mm)
    pinhole = project_pinhole(load_pinhole(EXCERPT / "pinhole.json"), points_mm)
    assert np.median(np.linalg.norm(tsai - pinhole, axis=1)) < 3.0


def test_a_tsai_calibration_becomes_a_pinhole_camera_that_projects_the_same_over_the_whole_image():
    tsai = load_tsai(EXCERPT / "View_001.xml")
    pinhole = load_calibration(EXCERPT / "View_001.xml")
    width, height = tsai.image_size_px
    # Ground points behind every pixel: project a wide grid and keep those that land in the image.
    x_mm, y_mm = np.meshgrid(np.linspace(-30000, 30000, 121), np.linspace(-30000, 30000, 121))
    points_mm = np.stack([x_mm.ravel(), y_mm.ravel(), np.zeros(x_mm.size)], axis=-1)
    camera_z_mm = points_mm @ tsai.rotation[2] + tsai.translation_mm[2]
    expected_px = project_tsai(tsai, points_mm[camera_z_mm > 0])
    inside = np.all((expected_px >= 0) & (expected_px <= [width, height]), axis=1)
    assert inside.sum() > 1000
    converted_px = project_pinhole(pinhole, points_mm[camera_z_mm > 0][inside])
    assert np.abs(converted_px - expected_px[inside]).max() < 0.01
    np.testing.assert_array_equal(pinhole_from_tsai(tsai).dist[2:4], 0.0)


PETS_VIEWS = Path(__file__).resolve().parents[1] / "src" / "ptztrack" / "data" / "pets2009_s2l1"


@pytest.mark.parametrize("view", ["View_001", "View_003", "View_004", "View_005", "View_006", "View_007", "View_008"])
def test_every_pixels_ray_projects_back_onto_its_pixel(view):
    """Back-projection inverts the distortion: PETS View_007's is strong enough that OpenCV's default
    five steps of undistortion leave rays hundreds of pixels off."""
    tsai = load_tsai(PETS_VIEWS / f"{view}.xml")
    calibration = pinhole_from_tsai(tsai)
    width, height = tsai.image_size_px
    u, v = np.meshgrid(np.arange(0, width, 8) + 0.5, np.arange(0, height, 8) + 0.5)
    pixels = np.stack([u.ravel(), v.ravel()], axis=-1)
    centre_m, direction = pixel_rays(calibration, pixels)
    back_px = project_pinhole(calibration, (centre_m + 5.0 * direction) * 1000.0)
    assert np.abs(back_px - pixels).max() < 0.1


def test_points_past_the_fold_of_the_distortion_are_not_seen():
    """OpenCV's polynomial turns back beyond the imaged radius (53 degrees off View_001's axis): it puts
    a point 60 degrees off the axis inside the image, which is 25 degrees wide; in_image does not."""
    calibration = pinhole_from_tsai(load_tsai(PETS_VIEWS / "View_001.xml"))
    limit = imaged_radius(calibration)
    k1, k2, _, _, k3 = calibration.dist
    assert 1 + 3 * k1 * limit**2 + 5 * k2 * limit**4 + 7 * k3 * limit**6 == pytest.approx(0.0, abs=1e-9)
    in_camera_mm = np.array([[np.tan(np.radians(60.0)), 0.0, 1.0], [np.tan(np.radians(10.0)), 0.0, 1.0]]) * 1000.0
    points_mm = (in_camera_mm - calibration.t) @ calibration.R  # R^T (camera - t) for each row
    assert np.all(
        (project_pinhole(calibration, points_mm)[:, 0] >= 0) & (project_pinhole(calibration, points_mm)[:, 0] < 768)
    )
    assert in_image(calibration, (768, 576), points_mm).tolist() == [False, True]
    assert imaged_radius(replace(calibration, dist=np.zeros(5))) == np.inf


def test_tsai_without_distortion_is_a_pinhole_projection():
    calibration = load_tsai(EXCERPT / "View_001.xml")
    plain = type(calibration)(**{**calibration.__dict__, "kappa1": 0.0})
    points_mm = np.array([[1000.0, -2000.0, 0.0], [-3000.0, 4000.0, 1700.0]])
    camera_mm = points_mm @ plain.rotation.T + np.asarray(plain.translation_mm)
    expected_u = plain.sx * plain.focal_mm * camera_mm[:, 0] / camera_mm[:, 2] / plain.dpx_mm + plain.centre_px[0]
    expected_v = plain.focal_mm * camera_mm[:, 1] / camera_mm[:, 2] / plain.dy_mm + plain.centre_px[1]
    np.testing.assert_allclose(project_tsai(plain, points_mm), np.stack([expected_u, expected_v], 1), rtol=1e-12)
    np.testing.assert_allclose(plain.rotation @ plain.rotation.T, np.eye(3), atol=1e-12)


def test_tsai_distortion_solves_the_radial_cubic():
    calibration = load_tsai(EXCERPT / "View_001.xml")
    pixels = project_tsai(calibration, np.array([[2000.0, 1000.0, 0.0]]))
    distorted = np.array(
        [
            (pixels[0, 0] - calibration.centre_px[0]) * calibration.dpx_mm / calibration.sx,
            (pixels[0, 1] - calibration.centre_px[1]) * calibration.dy_mm,
        ]
    )
    undistorted = distorted * (1 + calibration.kappa1 * np.sum(distorted**2))
    camera_mm = np.array([2000.0, 1000.0, 0.0]) @ calibration.rotation.T + np.asarray(calibration.translation_mm)
    np.testing.assert_allclose(undistorted, calibration.focal_mm * camera_mm[:2] / camera_mm[2], rtol=1e-10)


def test_the_two_annotation_formats_hold_the_same_boxes():
    mot = load_mot_ground_truth(EXCERPT / "gt_mot15.txt")
    cvml = load_cvml(EXCERPT / "PETS2009-S2L1.xml")
    assert mot.frame.min() == 0 and mot.frame.max() == 29
    assert set(zip(mot.frame, mot.person_id, strict=True)) <= set(zip(cvml.frame, cvml.person_id, strict=True))
    by_key = {(f, i): box for f, i, box in zip(cvml.frame, cvml.person_id, cvml.box_px, strict=True)}
    for frame, person, box in zip(mot.frame, mot.person_id, mot.box_px, strict=True):
        np.testing.assert_allclose(by_key[(frame, person)], box, atol=0.6)
    assert np.isnan(cvml.ground_m).all() and np.isfinite(mot.ground_m).all()


def test_video_frames_are_read_and_checked():
    video = read_video(EXCERPT / "View_001.avi", expected_frames=30, expected_size_px=(768, 576))
    assert video.shape == (30, 576, 768, 3) and video.dtype == np.uint8
    with pytest.raises(DatasetError, match="30 frames, expected 795"):
        read_video(EXCERPT / "View_001.avi", expected_frames=795)
    with pytest.raises(DatasetError, match="768x576 px, expected 640x480"):
        read_video(EXCERPT / "View_001.avi", expected_size_px=(640, 480))
    with pytest.raises(DatasetError, match="no such video file"):
        read_video(EXCERPT / "missing.avi")


@pytest.mark.parametrize(
    "loader, name, text, message",
    [
        (load_mot_ground_truth, "gt.txt", "1,2,3\n", "line 1 has 3 fields, expected 10"),
        (load_mot_ground_truth, "gt.txt", "1,9,499,158,31,75,1,x,-7.3,0\n", "line 1 has a field that is not a number"),
        (load_mot_ground_truth, "gt.txt", "0,9,499,158,31,75,1,-4.1,-7.3,0\n", "frames are numbered from 1"),
        (load_mot_ground_truth, "gt.txt", "", "no ground-truth rows"),
        (load_cvml, "gt.xml", "<dataset><frame number='0'><objectlist>", "not valid XML"),
        (
            load_cvml,
            "gt.xml",
            "<dataset><frame number='0'><objectlist><object id='3'/></objectlist></frame></dataset>",
            "frame '0' object '3'",
        ),
        (load_cvml, "gt.xml", "<dataset></dataset>", "no annotated objects"),
    ],
)
def test_malformed_annotation_files_are_named_with_the_problem(tmp_path, loader, name, text, message):
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(DatasetError, match=message) as error:
        loader(path)
    assert str(path) in str(error.value)


def test_malformed_calibrations_are_named_with_the_problem(tmp_path):
    bad_xml = tmp_path / "view.xml"
    bad_xml.write_text("<Camera><Geometry width='768'/></Camera>")
    with pytest.raises(CalibrationError, match="<Geometry> has no attribute 'height'"):
        load_tsai(bad_xml)
    bad_json = tmp_path / "pinhole.json"
    bad_json.write_text(
        '{"View_001": {"K": [[1, 0], [0, 1]], "dist": [0, 0, 0, 0, 0], "R": [[1,0,0],[0,1,0],[0,0,1]], "t": [0, 0, 0]}}'
    )
    with pytest.raises(CalibrationError, match=r"View_001.K has shape \(2, 2\), expected \(3, 3\)"):
        load_pinhole(bad_json)
    with pytest.raises(CalibrationError, match="no view 'View_009'"):
        load_pinhole(EXCERPT / "pinhole.json", view="View_009")
    with pytest.raises(CalibrationError, match="no such calibration file"):
        load_tsai(tmp_path / "nothing.xml")


def test_the_steps_of_a_recording_may_start_at_a_later_frame():
    annotations = load_mot_ground_truth(EXCERPT / "gt_mot15.txt")
    later = recorded_scene(annotations, frame_step=3, steps=4, frame_rate_hz=5.0, frame_range=(10, 30))
    np.testing.assert_array_equal(later.video_frame, [10, 13, 16, 19])
    whole = recorded_scene(annotations, frame_step=1, steps=30, frame_rate_hz=5.0)
    columns = np.searchsorted(whole.person_id, later.person_id)
    np.testing.assert_array_equal(later.truth.positions_m, whole.truth.positions_m[[10, 13, 16, 19]][:, columns])


def test_the_tracking_area_holds_the_cropped_annotations_away_from_its_edge(tmp_path):
    """Every row of the full ground truth more than 0.25 m inside or outside the tracking area is in the
    cropped annotations exactly when it is inside (boxes matched within 0.6 px, frame by frame); at the
    edge, the cropped file's ground positions may differ from the MOT file's by a few centimetres."""
    data = resources.files("ptztrack.data") / "pets2009_s2l1"
    cropped_xml = tmp_path / "cropped.xml"
    with gzip.open(data / "PETS2009-S2L1-cropped.xml.gz") as source:
        cropped_xml.write_bytes(source.read())
    cropped = load_cvml(cropped_xml)
    full = load_mot_ground_truth(data / "gt_mot15.txt")
    (x0, y0), (x1, y1) = pets_dataset().tracking_area_m
    x_m, y_m = full.ground_m.T
    inside = (x0 <= x_m) & (x_m <= x1) & (y0 <= y_m) & (y_m <= y1)
    to_edge_m = np.min(np.abs([x_m - x0, x_m - x1, y_m - y0, y_m - y1]), axis=0)
    in_cropped = np.zeros(len(full.frame), dtype=bool)
    for row in range(len(full.frame)):
        boxes = cropped.box_px[cropped.frame == full.frame[row]]
        in_cropped[row] = len(boxes) > 0 and np.abs(boxes - full.box_px[row]).max(axis=1).min() < 0.6
    away = to_edge_m > 0.25
    assert away.sum() > 4000
    np.testing.assert_array_equal(in_cropped[away], inside[away])
    assert in_cropped.sum() == len(cropped.frame)
