"""A step of a run as plain JSON: what the web view draws, live or replayed.

Two halves, so that a watched run pays little. :meth:`ViewState.take` runs
on the run's thread and only keeps what a step's state is made of (a
:class:`StepView`: references to the step's pose, detections, tracks and
the policy's reward terms, the running figures, and the camera's image
where only the run can get it); :meth:`ViewState.state_json` turns one into
the JSON the page draws, on any thread: the image as JPEG (base64), the
detections, the tracks with their 2-sigma ellipses on the ground and in the
image, the truth, the field of view on the ground, the action grid's
rewards with each track's share, and running figures. The same JSON, a
line per step, is a run's ``view_states.jsonl``, which ``ptztrack view``
replays.
"""

import base64
import json
import time
from collections import deque
from collections.abc import Iterable, Iterator, MutableSequence, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import cv2
import numpy as np

from ptztrack.files import InputError, read_text, write_atomically
from ptztrack.geometry.ptz import ground_footprint
from ptztrack.loop.steps import StepObserver, World
from ptztrack.names import VIEW_STATES_FILE
from ptztrack.types import DecisionContext, Detections, Tracks
from ptztrack.view.video import SIGMAS, RenderView, ellipse_axes, image_ellipses

JPEG_QUALITY = 80  # enough to see people; a 640 x 480 synthetic view is then some 10 kB
FOOTPRINT_RANGE_M = 60.0  # a view of the horizon ends here on the map
RATE_WINDOW_STEPS = 20  # the step rate over the last steps: a pause leaves it soon
MAX_VIEW_STATES_BYTES = 4_000_000_000


@dataclass(frozen=True)
class StepView:
    """What one step's state is made of; nothing here is computed beyond what the run had.

    pose : (3,) where the image was taken (the commanded pose where a live camera gave none);
    commanded : (3,); action : flat index, -1 for a pose off the grid; reachable : (R,) flat indices;
    terms : the policy's ``last_terms`` (:class:`ptztrack.control.information_policy.RewardTerms`)
    or None; figures : running figures; image : (h, w, 3) uint8 BGR, JPEG bytes, or None.
    """

    step: int
    pose: np.ndarray
    commanded: np.ndarray
    action: int
    reachable: np.ndarray
    detections: Detections
    tracks: Tracks
    decision_s: float
    terms: object | None
    figures: dict
    image: np.ndarray | bytes | None = None


class ViewState:
    """Each step's state for one run in ``world``.

    policy : may expose ``last_terms`` (its last decision's rewards, term by term).
    render : the camera's image at (step, pose) (:func:`ptztrack.view.video.view_renderer`), or
        None where the run's record carries it (a live camera's ``image``, None where it gave none).
    truth : whether ``world.truth`` is the truth of what the camera sees (not for a live camera).
    grid : whether the policy chooses among the grid's actions (not the follow camera's controller,
        which commands a pose of its own every step: the page then shows no reward map).
    target_point_px : (2,) where a follow camera wants its person, drawn in the image.
    """

    def __init__(
        self,
        world: World,
        policy: object,
        steps: int,
        label: str = "",
        render: RenderView | None = None,
        truth: bool = True,
        grid: bool = True,
        target_point_px=None,
    ):
        self.world, self.policy, self.steps, self.render, self.truth = world, policy, steps, render, truth
        self.step_times_s: deque[float] = deque(maxlen=RATE_WINDOW_STEPS)
        self.detections = 0
        self.zoom_sum = 0.0
        camera, actions = world.camera, world.grid
        scene = {
            "label": label,
            "area_m": _rounded(world.area_polygon_m, 3),
            "camera_m": _rounded(camera.centre_m[:2], 3),
            "image_size_px": [camera.image_width_px, camera.image_height_px],
            "grid": {"pan_deg": _rounded(actions.pan_deg, 2), "tilt_deg": _rounded(actions.tilt_deg, 2),
                     "zoom": _rounded(actions.zoom, 2)} if grid else None,
            "target_point_px": None if target_point_px is None else _rounded(target_point_px, 1),
            "sigmas": SIGMAS,
        }  # fmt: skip
        # The same every step, and sent each time all the same (a page that opens late needs nothing else):
        # encoded once.
        self._scene_json = json.dumps(scene, allow_nan=False)

    def count(self, record: dict) -> None:
        """Running figures over every step, shown or not (cheap: call it at every step)."""
        self.step_times_s.append(time.perf_counter())
        self.detections += len(record["detections"])
        self.zoom_sum += float(_seen_pose(record)[2])

    def take(self, step: int, context: DecisionContext, record: dict) -> StepView:
        """What the state after ``step`` is made of (call :meth:`count` with the step's record first).

        Without :attr:`render` the record's image is taken now, as JPEG (a live camera's frames are
        large); with one, the image is drawn later from the step and the pose.
        """
        times_s = self.step_times_s
        elapsed_s = times_s[-1] - times_s[0] if len(times_s) > 1 else 0.0
        figures = {
            "steps_per_s": round((len(times_s) - 1) / elapsed_s, 2) if elapsed_s > 0 else None,
            "detections": self.detections,
            "tracks": len(record["tracks"]),
            "mean_zoom": round(self.zoom_sum / (step + 1), 2),
        }
        taken = record.get("image") if self.render is None else None
        return StepView(
            step=step,
            pose=_seen_pose(record),
            commanded=record["commanded"],
            action=int(record["actions"]),
            reachable=context.reachable,
            detections=record["detections"],
            tracks=record["tracks"],
            decision_s=float(record["decision_s"]),
            terms=getattr(self.policy, "last_terms", None),
            figures=figures,
            image=_jpeg(taken) if taken is not None else None,
        )

    def observer(self, publish=None, keep: MutableSequence[StepView] | None = None) -> StepObserver:
        """The loop's observer: it counts every step, keeps each step's :class:`StepView` in ``keep``
        (for :meth:`write`) and hands each step to ``publish(step, last, take)`` (a live view's
        :meth:`ViewHub.after_step <ptztrack.view.web_view.ViewHub.after_step>`), which calls
        ``take()`` only when a page can take a state; that returns the function that builds its JSON."""

        def observe(step: int, context: DecisionContext, record: dict) -> None:
            self.count(record)
            kept = None
            if keep is not None:
                kept = self.take(step, context, record)
                keep.append(kept)
            if publish is not None:

                def take():
                    view = kept if kept is not None else self.take(step, context, record)
                    if self.render is not None:  # drawn on the run's thread: a recording's reader is not shared
                        view = replace(view, image=self.render(step, view.pose))
                    return lambda: self.state_json(view)

                publish(step, step == self.steps - 1, take)

        return observe

    def state_json(self, view: StepView) -> str:
        """The state of ``view`` as one line of JSON (the image encoded here where it is still BGR)."""
        return self.scene_appended(json.dumps(self.state(view), allow_nan=False))

    def scene_appended(self, state_json: str) -> str:
        """A state's JSON object with the run's ``scene`` (encoded once) as its last member."""
        return f'{state_json[:-1]}, "scene": {self._scene_json}}}'

    def camera_state(self, view: StepView) -> dict:
        """What the page draws of one camera of a network beside the one map: its picture, pose,
        detections, the tracks in its image, its field of view on the ground, where it stands (m) and
        its image's size (px)."""
        state = self.state(view)
        camera = self.world.camera
        return {
            **{name: state[name] for name in ("step", "pose", "commanded", "image_jpeg", "detections_px")},
            "tracks": [{"id": track["id"], "image": track["image"]} for track in state["tracks"]],
            "footprint_m": state["footprint_m"],
            "camera_m": _rounded(camera.centre_m[:2], 3),
            "image_size_px": [camera.image_width_px, camera.image_height_px],
        }

    def state(self, view: StepView) -> dict:
        """The state of ``view`` as a JSON-ready dict, without the scene (:meth:`state_json`)."""
        camera, pose, tracks = self.world.camera, view.pose, view.tracks
        position_m, covariance_m2 = tracks.mean[:, :2], tracks.covariance[:, :2, :2]
        ground_axes_m, ground_angle_deg = ellipse_axes(covariance_m2)
        centre_px, in_front, axes_px, angle_px_deg = image_ellipses(camera, pose, position_m, covariance_m2)
        image_size_px = np.array([camera.image_width_px, camera.image_height_px])
        # In the image only tracks near it: towards the horizon the linearised ellipse grows without bound.
        near = in_front & np.all(np.abs(centre_px - image_size_px / 2) <= image_size_px, axis=1)
        track_rows = [
            {
                "id": int(tracks.ids[k]),
                "mean_m": _rounded(position_m[k], 3),
                "ellipse_m": _ellipse(ground_axes_m[k], ground_angle_deg[k], "half_axes_m", 3),
                "image": _ellipse(axes_px[k], angle_px_deg[k], "half_axes_px", 1, centre_px[k]) if near[k] else None,
            }
            for k in range(len(tracks))
        ]
        image = view.image
        if isinstance(image, np.ndarray):
            image = _jpeg(image)
        detections = view.detections
        truth = self.world.truth
        state = {
            "step": view.step,
            "steps": self.steps,
            "pose": _rounded(pose, 2),
            "commanded": _rounded(view.commanded, 2),
            "image_jpeg": None if image is None else base64.b64encode(image).decode("ascii"),
            # feet (u, v) and height, null where the detector gave none
            "detections_px": [
                [*feet, None if np.isnan(height) else height]
                for feet, height in zip(_rounded(detections.feet_px, 1), _rounded(detections.height_px, 1), strict=True)
            ],
            "tracks": track_rows,
            "truth_m": _rounded(truth.positions_m[view.step, truth.present[view.step]], 3) if self.truth else None,
            "footprint_m": _rounded(ground_footprint(camera, pose, max_range_m=FOOTPRINT_RANGE_M), 2),
            "decision": {
                "action": view.action,
                "reachable": view.reachable.tolist(),
                **_terms(view.terms, self.world.grid.size),
                "decision_ms": round(1e3 * view.decision_s, 2),
            },
            "metrics": view.figures,
        }
        return state

    def lines(self, views: Iterable[StepView]) -> Iterator[str]:
        """Each view's state, its image drawn by :attr:`render` where there is one."""
        for view in views:
            drawn = view if self.render is None else replace(view, image=self.render(view.step, view.pose))
            yield self.state_json(drawn)

    def write(self, path: Path, views: Iterable[StepView]) -> None:
        """The states of ``views`` into ``path`` (``view_states.jsonl``: a line of JSON per step), atomically."""
        write_atomically(Path(path), "".join(line + "\n" for line in self.lines(views)).encode())


@dataclass(frozen=True)
class NetworkStepView:
    """What one decision's state of a camera network is made of: ``camera``, the index of the camera whose
    picture led to it, and ``views``, every camera's latest :class:`StepView` (None before its first)."""

    camera: int
    views: tuple[StepView | None, ...]


class NetworkViewState:
    """Each decision's state for a network of cameras with one belief (a live network run): the state of
    the camera whose picture led to the decision, as its :class:`ViewState` makes it (its image, the map
    and its reward map), with ``cameras``: every camera's latest picture and field of view
    (:meth:`ViewState.camera_state`), drawn beside the one map.

    cameras : each camera's :class:`ViewState`, in the network's order; the records the observer is
    given carry their camera's index as ``camera``.
    """

    def __init__(self, cameras: Sequence[ViewState]):
        self.cameras = tuple(cameras)
        self.steps = self.cameras[0].steps
        # Each camera's latest step, context and record: taken into a view only when a state is due.
        self._latest: list[tuple[int, DecisionContext, dict] | None] = [None] * len(self.cameras)

    def observer(self, publish=None, keep: MutableSequence[NetworkStepView] | None = None) -> StepObserver:
        """The loop's observer, as :meth:`ViewState.observer`'s, over every camera's latest step."""

        def observe(step: int, context: DecisionContext, record: dict) -> None:
            camera = int(record["camera"])
            self.cameras[camera].count(record)
            self._latest[camera] = (step, context, record)
            kept = None
            if keep is not None:
                kept = self._take(camera)
                keep.append(kept)
            if publish is not None:

                def take():
                    view = kept if kept is not None else self._take(camera)
                    return lambda: self.state_json(view)

                publish(step, step == self.steps - 1, take)

        return observe

    def _take(self, camera: int) -> NetworkStepView:
        """Every camera's latest view, on the run's thread (a recording's reader is not shared), the
        deciding ``camera``'s with it."""
        views = []
        for view_state, latest in zip(self.cameras, self._latest, strict=True):
            view = None if latest is None else view_state.take(*latest)
            if view is not None and view_state.render is not None:
                view = replace(view, image=view_state.render(view.step, view.pose))
            views.append(view)
        return NetworkStepView(camera, tuple(views))

    def state_json(self, view: NetworkStepView) -> str:
        """The state of ``view`` as one line of JSON: the deciding camera's state and ``cameras``."""
        deciding = self.cameras[view.camera]
        own = view.views[view.camera]
        assert own is not None, "the deciding camera's step is the latest it has"
        state = deciding.state(own)
        state["cameras"] = [
            None if camera_view is None else {"camera": index, **view_state.camera_state(camera_view)}
            for index, (view_state, camera_view) in enumerate(zip(self.cameras, view.views, strict=True))
        ]
        return deciding.scene_appended(json.dumps(state, allow_nan=False))

    def write(self, path: Path, views: Iterable[NetworkStepView]) -> None:
        """The states of ``views`` into ``path`` (``view_states.jsonl``), atomically."""
        write_atomically(Path(path), "".join(self.state_json(view) + "\n" for view in views).encode())


def read_view_states(folder: Path) -> list[str]:
    """The lines of a run folder's ``view_states.jsonl``, each checked to be a step's state."""
    path = Path(folder) / VIEW_STATES_FILE
    if not Path(folder).is_dir():
        raise InputError(f"{folder}: not a folder (expected a run's --out folder)")
    if not path.is_file():
        raise InputError(f"{folder}: no {VIEW_STATES_FILE} (written by ptztrack run, follow and live with --out)")
    lines = read_text(path, "view states", MAX_VIEW_STATES_BYTES).splitlines()
    for number, line in enumerate(lines, start=1):
        try:
            state = json.loads(line)
        except json.JSONDecodeError:
            state = None
        if not (
            isinstance(state, dict) and isinstance(state.get("step"), int) and isinstance(state.get("scene"), dict)
        ):
            raise InputError(f"{path}: line {number} is not a step's state (a JSON object with step and scene)")
    if not lines:
        raise InputError(f"{path}: no steps")
    return lines


def _terms(terms, actions: int) -> dict:
    """The rewards of every action of the grid (null where not scored) and, for the actions scored, each
    track's share and the patrolling term's (nats); all null for a policy that exposes none."""
    if terms is None:
        return {"reward_nats": None, "terms": None}
    reward = [None] * actions
    for action, value in zip(terms.actions.tolist(), _rounded(terms.total_nats, 4), strict=True):
        reward[action] = value
    return {
        "reward_nats": reward,
        "terms": {  # rows in the order of the scored actions (the decision's reachable ones)
            "actions": terms.actions.tolist(),
            "track_ids": terms.track_ids.tolist(),
            "track_nats": _rounded(terms.track_nats, 4),
            "patrol_nats": _rounded(terms.patrol_nats, 4),
        },
    }


def _seen_pose(record: dict) -> np.ndarray:
    """The pose the step's image was taken at: a live camera's (NaN where it gave none: then the commanded)."""
    pose = record["poses"]
    return pose if np.all(np.isfinite(pose)) else record["commanded"]


def _jpeg(image_bgr: np.ndarray) -> bytes:
    ok, jpeg = cv2.imencode(".jpg", image_bgr, [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY])
    if not ok:
        raise RuntimeError("OpenCV could not encode the camera's view as JPEG")
    return jpeg.tobytes()


def _ellipse(half_axes, angle_deg: float, unit: str, decimals: int, centre_px=None) -> dict:
    """A 2-sigma ellipse: half axes (major, minor), the major's angle from the first axis towards the
    second (clockwise in an image), and in the image its centre."""
    ellipse = {unit: _rounded(half_axes, decimals), "angle_deg": round(float(angle_deg), 1)}
    if centre_px is not None:
        ellipse["centre_px"] = _rounded(centre_px, 1)
    return ellipse


def _rounded(values, decimals: int) -> list:
    """Nested lists of floats rounded to ``decimals``: a JSON message a few times smaller."""
    return np.round(np.asarray(values, dtype=float), decimals).tolist()
