"""``ptztrack camera calibrate --geometry``: a camera's geometry measured from its own pictures
(:mod:`ptztrack.camera.geometry_calibration`), written into the calibration file ``live`` reads.

First ``--snapshot PATH`` zooms the camera out where it looks, stores that view as its ground preset and
saves its picture; the user picks four or more ground points in it. Then ``--ground-points FILE``
measures the focal lengths and the pan and tilt mapping from the preset and places the camera on the
ground with the points; the file is replaced whole once everything succeeded.
"""

import argparse
from pathlib import Path

import cv2
import numpy as np

from ptztrack.camera.geometry_calibration import (
    GROUND_PRESET,
    GeometryMeasurement,
    ground_preset,
    measure_geometry,
    take_ground_snapshot,
)
from ptztrack.camera.onvif_client import ONVIFClient, camera_address
from ptztrack.camera.stream import FrameStream, LatestFrame, rtsp_pictures
from ptztrack.config import (
    CameraCalibrationFile,
    GroundViewSection,
    MoveTimesSection,
    ScenarioError,
    load_camera_calibration,
    write_camera_calibration,
)
from ptztrack.config.ground_points import GroundPoints, load_ground_points
from ptztrack.files import check_output_file, write_atomically
from ptztrack.geometry.self_calibration import GroundPose, ground_points_problem, ground_pose

# How well a user places a ground point in the picture (px): a priori, a click on a pixel.
POINT_SD_PX = 1.0
# The first picture of the stream is awaited this long (an RTSP stream takes seconds to open).
FIRST_PICTURE_S = 20.0


def calibrate_geometry_command(args: argparse.Namespace, credentials: dict | None) -> int:
    existing = load_camera_calibration(args.calibration) if Path(args.calibration).exists() else None
    check_output_file(args.calibration, "--calibration")
    if args.snapshot is not None:
        check_output_file(args.snapshot, "--snapshot")
    elif args.ground_points is None:
        raise ScenarioError("camera calibrate --geometry: give --snapshot PATH (first) or --ground-points FILE")
    points = None if args.ground_points is None else load_ground_points(args.ground_points)
    if points is not None:
        _check_points(args.ground_points, points, None)
    image_delay_s = CameraCalibrationFile.model_fields["image_delay_s"].default
    image_delay_s = existing.image_delay_s if existing is not None else image_delay_s
    client = ONVIFClient(camera_address(args.camera, credentials), args.timeout_s)
    stream = None
    try:
        client.connect()
        stream = FrameStream(rtsp_pictures(client.stream_uri()), delay_s=0.0)
        stream.start()
        first = _first_picture(stream.latest, str(client.address))
        if args.snapshot is not None:
            image = take_ground_snapshot(client, stream.latest, image_delay_s)
            _write_picture(args.snapshot, image)
            print(
                f"wrote {args.snapshot} ({image.shape[1]}x{image.shape[0]} px), the camera's preset {GROUND_PRESET!r}: "
                "pick 4 or more ground points in it (docs: Real cameras) and run again with --ground-points FILE"
            )
            return 0
        assert points is not None
        _check_points(args.ground_points, points, (first.shape[1], first.shape[0]))
        measured = measure_geometry(client, stream.latest, image_delay_s, args.zoom_steps)
        token = ground_preset(client)
    finally:
        if stream is not None:
            stream.stop()
        client.close()
    assert token is not None
    head = measured.head
    ground = ground_pose(
        points.pixels_px, points.ground_m, head.focal_px, measured.image_size_px, head.focal_sd_px, POINT_SD_PX
    )
    calibration = calibration_of(measured, ground, token, existing)
    write_camera_calibration(args.calibration, calibration)
    _print_geometry(measured, ground, calibration)
    print(f"wrote the geometry into {args.calibration}")
    return 0


def calibration_to_time(path: Path) -> CameraCalibrationFile:
    """The calibration file that ``camera calibrate`` (without ``--geometry``) times a camera's moves into;
    a missing one is refused naming the command that starts one."""
    if not Path(path).exists():
        raise ScenarioError(
            f"--calibration {path}: no such file; start one with ptztrack camera calibrate --geometry --snapshot "
            "PICTURE.png (docs: Real cameras), then time the moves into it"
        )
    return load_camera_calibration(path)


def _first_picture(latest: LatestFrame, camera: str) -> np.ndarray:
    frame = latest.newer(0, FIRST_PICTURE_S)
    if frame is None:
        raise ScenarioError(f"{camera}: no picture from its stream within {FIRST_PICTURE_S:g} s")
    return frame.image


def _check_points(path: Path, points: GroundPoints, image_size_px: tuple[int, int] | None) -> None:
    """Refuse, before any move, points that cannot place the camera (with the pictures' size: outside them)."""
    problem = ground_points_problem(points.pixels_px, points.ground_m, image_size_px)
    if problem is not None:
        raise ScenarioError(f"{path}: {problem}")


def _write_picture(path: Path, image: np.ndarray) -> None:
    ok, encoded = cv2.imencode(Path(path).suffix or ".png", image)
    if not ok:
        raise ScenarioError(f"--snapshot {path}: not an image file name OpenCV can write (.png, .jpg)")
    write_atomically(Path(path), encoded.tobytes())


def calibration_of(
    measured: GeometryMeasurement, ground: GroundPose, preset: str, existing: CameraCalibrationFile | None
) -> CameraCalibrationFile:
    """The calibration file of a measured geometry: the spaces' degrees at normalised -1 and +1 through the
    ground view's pose (from its reported position, or from the preset, which then stands at 0), the zoom
    curve as zoom factors of the widest focal length with their standard deviations, the position on the
    ground and the ground view; the stream's delay kept from ``existing``, and its move times where it has
    measured ones (else the geometry's own moves' times)."""
    # The points refine the widest focal length; the turns' angles trade against it (a shift is f theta).
    refined = ground.focal_px / measured.head.focal_px
    pan_per_unit, tilt_per_unit = measured.head.pan_deg_per_unit / refined, measured.head.tilt_deg_per_unit / refined
    position = measured.ground_position
    positions = bool(np.all(np.isfinite(position)))
    at = position if positions else np.zeros(3)
    ends = np.array([-1.0, 1.0])
    pan_deg = ground.pan_deg + pan_per_unit * (ends - at[0])
    pan_deg -= 360.0 * np.round(pan_deg.mean() / 360.0)
    tilt_deg = ground.tilt_deg + tilt_per_unit * (ends - at[1])
    widest_px = float(measured.focal_px[0])
    fields = {
        "pan_deg": tuple(round(float(value), 4) for value in pan_deg),
        "tilt_deg": tuple(round(float(value), 4) for value in tilt_deg),
        "zoom_curve": [
            (round(float(z), 6), round(float(f / widest_px), 6))
            for z, f in zip(measured.zoom_normalised, measured.focal_px, strict=True)
        ],
        "zoom_curve_sd": [round(float(sd / widest_px), 6) for sd in measured.focal_sd_px],
        "position_m": tuple(round(float(value), 4) for value in ground.position_m),
        "f_min_px": round(widest_px * refined, 3),
        "positions": positions,
        "ground_view": GroundViewSection(
            preset=preset,
            pan_deg=round(ground.pan_deg, 4),
            tilt_deg=round(ground.tilt_deg, 4),
            roll_deg=round(ground.roll_deg, 4),
            reprojection_error_px=round(ground.rms_px, 4),
        ),
    }
    kept = {} if existing is None else existing.model_dump(include={"move_times", "image_delay_s", "capture_time_sd_s"})
    # Times that `camera calibrate` measured (AbsoluteMove and GetStatus) are kept; a camera that has not
    # been timed so gets the times of the geometry's own relative moves.
    if existing is None or existing.move_times == MoveTimesSection():
        times = measured.move_times
        fields["move_times"] = MoveTimesSection(pan=times.pan, tilt=times.tilt, zoom=times.zoom)
    return CameraCalibrationFile.model_validate({**kept, **fields})


def _print_geometry(measured: GeometryMeasurement, ground: GroundPose, calibration: CameraCalibrationFile) -> None:
    x_m, y_m, height_m = ground.position_m
    print(
        f"camera at ({x_m:.2f}, {y_m:.2f}) m, {height_m:.2f} m up; ground view pan {ground.pan_deg:.2f} deg, "
        f"tilt {ground.tilt_deg:.2f} deg, roll {ground.roll_deg:.2f} deg; ground points' reprojection error "
        f"{ground.rms_px:.2f} px rms (largest {ground.residuals_px.max():.2f} px)"
    )
    pan_per_unit, tilt_per_unit = (np.diff(ends)[0] / 2 for ends in (calibration.pan_deg, calibration.tilt_deg))
    counted = "from its positions" if calibration.positions else "from the ground preset: no positions"
    print(f"pan {pan_per_unit:+.3f} deg and tilt {tilt_per_unit:+.3f} deg per normalised unit ({counted})")
    scale = ground.focal_px / measured.focal_px[0]
    print(
        f"focal length {ground.focal_px:.1f} +- {scale * measured.focal_sd_px[0]:.1f} px at the widest (the turns "
        f"gave {measured.focal_px[0]:.1f}, the ground points refined it) to {scale * measured.focal_px[-1]:.1f} px "
        f"at normalised zoom 1 ({len(measured.focal_px)} steps)"
    )
