"""A real (or virtual) ONVIF PTZ camera's geometry measured from its own pictures
(:mod:`ptztrack.geometry.self_calibration` has the maths): what ``ptztrack camera calibrate --geometry``
does with the camera.

Every move is a RelativeMove, which cameras without AbsoluteMove or positions have too, and every
picture is taken once the camera stands still (GetStatus's MoveStatus, then a picture that arrived
``image_delay_s`` later). The ground view is a preset of the camera (:data:`GROUND_PRESET`) at its
widest zoom, set where the ground points were picked (:func:`take_ground_snapshot`); the measurement
starts there and ends there:

1. a 5 x 5 grid of turns of up to a few tenths of the view, in pan, in tilt and both together, each
   pictured (their size from a small probe turn first) and every pair matched: the widest focal length
   and each axis' degrees per unit of the normalised translation space;
2. the zoom from the widest view to the narrowest in steps that each magnify by about
   ``TARGET_ZOOM_RATIO``, each picture matched to the one and the two before: the focal length at every
   step. It runs at the view of the grid with the most features in its middle, which the zoom keeps.
"""

import itertools
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ptztrack.camera.move_timing import fitted_move_time
from ptztrack.camera.onvif_client import CameraError, ONVIFClient
from ptztrack.camera.onvif_spaces import MoveTimes
from ptztrack.camera.stream import LatestFrame
from ptztrack.geometry.self_calibration import (
    ECC_RATIO_SD,
    HeadFit,
    ecc_zoom_ratio,
    fit_head,
    focals_from_ratios,
    matched_points,
    view_features,
    zoom_ratio,
)

GROUND_PRESET = "ptztrack-ground"
# A probe turn of this much of the normalised range sizes the turns; the turns then move the picture by
# TURN_FRACTION of its width (pan) or height (tilt), within [MIN_TURN, MAX_TURN] of the range.
PROBE_TURN, TURN_FRACTION, MIN_TURN, MAX_TURN = 0.02, 0.4, 0.002, 0.5
# The zoom's steps each magnify by about this much (SIFT matches a 160 x 120 view to one 1.35 times
# larger at times only), none less than MIN_ZOOM_STEP of the normalised range.
TARGET_ZOOM_RATIO, MIN_ZOOM_STEP = 1.2, 0.004
# How long a camera may take to begin moving before GetStatus is trusted to say it has (seconds), and to
# stand still at most.
MOVE_START_S, STILL_TIMEOUT_S = 0.3, 30.0
# A picture counts as taken where the camera stands once it arrived at least this long after the camera
# stood still, whatever the calibration's image_delay_s: an RTSP stream holds pictures back by 0.2-1 s, and
# a picture of the move would spoil the measurement, where waiting costs a second a picture.
SETTLED_AFTER_S = 1.0
# Still pictures averaged into one: the stream's compression noise, which moves features by a fraction of
# a pixel from picture to picture, averages out (a picture takes 40 ms at 25 fps).
AVERAGED_PICTURES = 5


class GeometryError(CameraError):
    """A step of the geometry's measurement that the camera's pictures cannot support (one line)."""


@dataclass(frozen=True)
class GeometryMeasurement:
    """What the camera's pictures tell of its geometry.

    ground_image : (h, w, 3) the ground view at the widest zoom; ground_position : (3,) its normalised
    position (NaN where the camera reports none); head : the widest focal length and the pan's and
    tilt's degrees per normalised unit, from the turns; zoom_normalised : (K,) the zoom steps from 0 to
    1; focal_px, focal_sd_px : (K,) the focal length at each and its standard deviation; move_times :
    the moves' times, from the calibration's own moves (:func:`timed_moves`).
    """

    ground_image: np.ndarray
    ground_position: np.ndarray
    head: HeadFit
    zoom_normalised: np.ndarray
    focal_px: np.ndarray
    focal_sd_px: np.ndarray
    move_times: MoveTimes

    @property
    def image_size_px(self) -> tuple[int, int]:
        return self.ground_image.shape[1], self.ground_image.shape[0]


TimedMoves = list[tuple[np.ndarray, float]]
"""Moves made: each RelativeMove's translation (3,) and the seconds from its command until the camera stood
still (at least ``MOVE_START_S``)."""


def moved(client: ONVIFClient, translation, timed: TimedMoves | None = None) -> None:
    """RelativeMove by ``translation`` (3,) (normalised) and wait until the camera stands still: a relative
    move counts from where the camera is when it arrives, so the next one must wait. The move and its
    time go into ``timed`` where given."""
    started_s = time.monotonic()
    client.relative_move(translation)
    stood_still(client)
    if timed is not None:
        timed.append((np.asarray(translation, dtype=float), time.monotonic() - started_s))


def stood_still(client: ONVIFClient) -> None:
    """Wait until the camera, sent a move just before, stands still (GetStatus's MoveStatus)."""
    time.sleep(MOVE_START_S)
    if client.wait_still(time.monotonic() + STILL_TIMEOUT_S).moving:
        raise CameraError(f"{client.address}: still moving after {STILL_TIMEOUT_S:g} s")


def settled_picture(
    client: ONVIFClient, latest: LatestFrame, image_delay_s: float, translation, timed: TimedMoves | None = None
) -> np.ndarray:
    """RelativeMove by ``translation`` (3,) (timed into ``timed`` where given), then the mean of the first
    ``AVERAGED_PICTURES`` pictures that arrived ``image_delay_s`` (at least ``SETTLED_AFTER_S``) after the
    camera stood still."""
    moved(client, translation, timed)
    still_s = time.time()
    deadline_s = time.monotonic() + STILL_TIMEOUT_S
    number, taken = 0, []
    while time.monotonic() < deadline_s:
        frame = latest.newer(number, 1.0)
        if frame is None:
            continue
        if frame.time_s >= still_s + max(image_delay_s, SETTLED_AFTER_S):
            taken.append(frame.image.astype(np.float32))
            if len(taken) == AVERAGED_PICTURES:
                return np.rint(np.mean(taken, axis=0)).astype(np.uint8)
        number = frame.number
    raise CameraError(f"{client.address}: no picture from its stream for {STILL_TIMEOUT_S:g} s")


def ground_preset(client: ONVIFClient) -> str | None:
    """The token of the camera's :data:`GROUND_PRESET`, None if it has none."""
    return next((token for token, name in client.presets().items() if name == GROUND_PRESET), None)


def take_ground_snapshot(client: ONVIFClient, latest: LatestFrame, image_delay_s: float) -> np.ndarray:
    """Zoom the camera out fully where it looks, store that as :data:`GROUND_PRESET` (replacing an
    earlier one) and return its picture (h, w, 3): the picture to pick ground points in."""
    image = settled_picture(client, latest, image_delay_s, (0.0, 0.0, -1.0))
    token = ground_preset(client)
    if token is not None:
        client.remove_preset(token)
    client.set_preset(GROUND_PRESET)
    return image


def _turn(
    client: ONVIFClient, latest: LatestFrame, image_delay_s: float, translation, timed: TimedMoves | None = None
) -> np.ndarray:
    """Turn by ``translation`` (3,), take the picture there and turn back (both moves timed into ``timed``
    where given); the picture."""
    image = settled_picture(client, latest, image_delay_s, translation, timed)
    moved(client, -np.asarray(translation, dtype=float), timed)
    return image


def _probe(client, latest, image_delay_s: float, ground, axis: int, report) -> float:
    """The picture's shift (px) on ``axis`` (0 pan: u, 1 tilt: v) for a turn of PROBE_TURN on that axis;
    ``ground`` the ground view's :func:`view_features`."""
    probe = np.zeros(3)
    probe[axis] = PROBE_TURN
    name = ("pan", "tilt")[axis]
    image = _turn(client, latest, image_delay_s, probe)
    points_a, points_b = matched_points(ground, view_features(image))
    if len(points_a) == 0:
        raise GeometryError(f"the {name} probe did not register against the ground view: too few features match")
    return float(np.median(points_b[:, axis] - points_a[:, axis]))


def _zoom_ladder(
    client: ONVIFClient,
    latest: LatestFrame,
    image_delay_s: float,
    widest: np.ndarray,
    first_step: float,
    report: Callable[[str], None],
    timed: TimedMoves,
) -> tuple[np.ndarray, list[tuple[int, int, float, float]]]:
    """Zoom from the widest view (normalised 0) to normalised 1 in steps sized so that each magnifies by
    about ``TARGET_ZOOM_RATIO`` (the first ``first_step``; a step that does not register is halved, down to
    ``MIN_ZOOM_STEP``), each picture matched to the one and the two before (SIFT), or where SIFT cannot
    match it to the one before, registered to that one by its intensities (:func:`ecc_zoom_ratio`), every
    move timed into ``timed``. The steps' normalised zooms (K + 1,) and the scales (i, j, s_ij, sd_ij)
    between them."""
    features, zooms, previous = [view_features(widest)], [0.0], widest
    ratios: list[tuple[int, int, float, float]] = []
    step_size, rate = first_step, np.log(TARGET_ZOOM_RATIO) / first_step  # log scale per normalised unit
    while zooms[-1] < 1.0 - 1e-9:
        # The last step takes the rest of the range when less than half a step would be left after it: a
        # sliver of a step magnifies too little to measure.
        remaining = 1.0 - zooms[-1]
        step_size = remaining if remaining < 1.5 * step_size else step_size
        picture = settled_picture(client, latest, image_delay_s, (0.0, 0.0, step_size), timed)
        step = len(features)
        picture_features = view_features(picture)
        where = f"zoom step {step} (normalised zoom {zooms[-1] + step_size:.3f})"
        found = []
        for before in range(step - 1, max(step - 3, -1), -1):
            points_a, points_b = matched_points(features[before], picture_features)
            if len(points_a):
                found.append((before, step, *zoom_ratio(points_a, points_b, widest.shape[1::-1])))
        if not found or found[0][0] != step - 1 or found[0][2] <= 1.0:
            # Too few features to match (a long zoom's blur, the stream's compression): the intensities.
            scale = ecc_zoom_ratio(previous, picture, float(np.exp(rate * step_size)))
            found = [] if scale is None or scale <= 1.0 else [(step - 1, step, scale, ECC_RATIO_SD * scale)]
        if not found:
            if step_size / 2 < MIN_ZOOM_STEP:
                raise GeometryError(f"{where} did not register against the step before: too few features match")
            report(f"{where} did not register against the step before: half the step")
            step_size /= 2
            moved(client, (0.0, 0.0, -step_size), timed)
            continue
        ratio = found[0][2]
        report(f"{where}: x{ratio:.4f} +- {found[0][3]:.4f} on the step before")
        features.append(picture_features)
        zooms.append(zooms[-1] + step_size)
        ratios.extend(found)
        previous, rate = picture, np.log(ratio) / step_size
        step_size *= np.log(TARGET_ZOOM_RATIO) / np.log(ratio)
    return np.array(zooms), ratios


def _middle_features(keypoints_px: list[np.ndarray], size_px: tuple[int, int]) -> np.ndarray:
    """How many of each view's keypoints (K, 2) px lie in the middle of the picture, the quarter of its
    width and height around the centre, where a zoom of 4 looks: (views,) counts."""
    centre, half = np.array(size_px) / 2.0, np.array(size_px) / 8.0
    return np.array([np.sum(np.all(np.abs(points - centre) <= half, axis=1)) for points in keypoints_px])


def measure_geometry(
    client: ONVIFClient,
    latest: LatestFrame,
    image_delay_s: float,
    zoom_steps: int = 20,
    report: Callable[[str], None] = print,
) -> GeometryMeasurement:
    """Measure the camera's geometry from its ground preset (see the module); the camera ends there.

    latest : its stream's newest picture (a started :class:`~ptztrack.camera.stream.FrameStream`);
    image_delay_s : how late its pictures are; report : where each step's line goes. A
    :class:`GeometryError` names the step whose pictures did not register.
    """
    token = ground_preset(client)
    if token is None:
        raise GeometryError(
            f"the camera has no preset {GROUND_PRESET!r}: take the ground view first (camera calibrate --geometry "
            "--snapshot PATH)"
        )
    client.goto_preset(token)
    stood_still(client)
    ground = settled_picture(client, latest, image_delay_s, (0.0, 0.0, -1.0))
    ground_position = client.status().position
    report(f"ground view: {ground.shape[1]}x{ground.shape[0]} px")
    size_px = (ground.shape[1], ground.shape[0])
    ground_features = view_features(ground)
    shifts_px = np.array([_probe(client, latest, image_delay_s, ground_features, axis, report) for axis in (0, 1)])
    turn = np.clip(
        PROBE_TURN * TURN_FRACTION * np.array(size_px) / np.maximum(np.abs(shifts_px), 1e-3), MIN_TURN, MAX_TURN
    )
    # A pan (depression) that grows moves the picture's content left (up): f dtheta = -shift, f ~ the width.
    initial_deg_per_unit = np.rad2deg(-shifts_px / size_px[0]) / PROBE_TURN
    # A 5 x 5 grid of turns, half and whole turns each way on each axis and together: a pan's axis,
    # vertical, is tilted in a tilted view, so the diagonals turn the picture as well as shift it, and
    # every view is another sampling of the scene, whose texture sets how well the focal length is pinned.
    fractions = (-1.0, -0.5, 0.0, 0.5, 1.0)
    steps = [np.zeros(2)]
    features = [ground_features]
    turned: TimedMoves = []
    for pan_fraction, tilt_fraction in itertools.product(fractions, fractions):
        if pan_fraction == tilt_fraction == 0.0:
            continue
        translation = np.array([pan_fraction * turn[0], tilt_fraction * turn[1], 0.0])
        steps.append(translation[:2])
        features.append(view_features(_turn(client, latest, image_delay_s, translation, turned)))
    # Every pair of views that registers, the turned ones with each other too: more pairs, and wider ones.
    matches, registered = [], set()
    still: list[list[np.ndarray]] = [[] for _ in steps]  # each view's matched keypoints
    for first in range(len(features)):
        for second in range(first + 1, len(features)):
            points_a, points_b = matched_points(features[first], features[second])
            if len(points_a):
                matches.append((steps[first], steps[second], points_a, points_b))
                registered |= {first, second}
                still[first].append(points_a)
                still[second].append(points_b)
    for index in range(1, len(steps)):
        if index not in registered:
            pan, tilt = steps[index]
            report(f"turn of {pan:+.3f} pan, {tilt:+.3f} tilt: did not register with any view, left out")
    report(f"{len(registered - {0})} of {len(steps) - 1} turns registered, {len(matches)} pairs of views")
    for axis, name in enumerate(("pan", "tilt")):
        if not any(steps[index][axis] != 0 for index in registered):
            raise GeometryError(f"no turn with a {name} registered against the other views")
    head = fit_head(matches, size_px, tuple(initial_deg_per_unit), float(size_px[0]))
    report(
        f"widest focal length {head.focal_px:.1f} +- {head.focal_sd_px:.1f} px, pan {head.pan_deg_per_unit:+.3f} "
        f"and tilt {head.tilt_deg_per_unit:+.3f} deg per normalised unit (rms {head.rms_px:.2f} px over "
        f"{head.pairs} of {len(matches)} pairs of views)"
    )
    # The zoom magnifies the view's middle, so it runs where the middle shows the most still texture (the
    # features matched between views taken seconds apart): a long zoom into plain ground (or a wall)
    # leaves too few features to match, and one into a passer-by changes from picture to picture.
    views = sorted(registered)
    middles = _middle_features([np.unique(np.concatenate(still[index]), axis=0) for index in views], size_px)
    ladder = views[int(np.argmax(middles))]
    report(
        f"zoom steps at the turn of {steps[ladder][0]:+.3f} pan, {steps[ladder][1]:+.3f} tilt: "
        f"{middles.max()} still features in the middle of its view"
    )
    widest = settled_picture(client, latest, image_delay_s, (*steps[ladder], 0.0))
    zoomed: TimedMoves = []
    zoom_normalised, ratios = _zoom_ladder(client, latest, image_delay_s, widest, 1.0 / zoom_steps, report, zoomed)
    client.goto_preset(token)
    focal_px, focal_sd_px = focals_from_ratios(head.focal_px, head.focal_sd_px, len(zoom_normalised) - 1, ratios)
    move_times = timed_moves(turned, zoomed, head, zoom_normalised, focal_px / focal_px[0])
    report(
        f"moves: {move_times.pan[0]:.2f} s + {move_times.pan[1] * 1e3:.1f} ms/deg pan, {move_times.tilt[0]:.2f} s + "
        f"{move_times.tilt[1] * 1e3:.1f} ms/deg tilt, {move_times.zoom[0]:.2f} s + {move_times.zoom[1]:.3f} s per "
        "unit of zoom"
    )
    return GeometryMeasurement(
        ground_image=ground,
        ground_position=np.asarray(ground_position, dtype=float),
        head=head,
        zoom_normalised=zoom_normalised,
        focal_px=focal_px,
        focal_sd_px=focal_sd_px,
        move_times=move_times,
    )


def timed_moves(turned: TimedMoves, zoomed: TimedMoves, head: HeadFit, zoom_normalised, zoom_factors) -> MoveTimes:
    """The camera's move times (:class:`MoveTimes`, Frigate's line per axis) from the calibration's own
    moves: the turns on one axis alone at the head's degrees per unit, and the zoom ladder's moves (all
    relative, from normalised zoom 0) at the zoom factors (K,) of its steps' normalised zooms (K,)."""
    fits = []
    for axis, per_unit in ((0, head.pan_deg_per_unit), (1, head.tilt_deg_per_unit)):
        alone = [(abs(move[axis]) * abs(per_unit), s) for move, s in turned if move[axis] != 0 and move[1 - axis] == 0]
        fits.append(fitted_move_time(*zip(*alone, strict=True)))
    ends = np.cumsum([0.0] + [move[2] for move, _ in zoomed])
    factors = np.interp(ends, zoom_normalised, zoom_factors)
    fits.append(fitted_move_time(np.abs(np.diff(factors)), [s for _, s in zoomed]))
    return MoveTimes(*fits)
