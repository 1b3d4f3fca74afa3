"""The service's configuration file (``ptztrack serve CONFIG``): its cameras and where their tracks and
events go, validated, with errors of one line naming the file, the field and the value.

Paths in the file (``output``, ``events``, a camera's ``calibration`` and ``scenario``) are relative to
the file's folder unless absolute.
"""

from pathlib import Path
from typing import Annotated, Literal

import pydantic
from pydantic import Field, model_validator

from ptztrack.config import ScenarioError, read_yaml
from ptztrack.config.fields import NonNegativeFloat, PositiveFloat, _registered, _Strict, at_most, at_most_items
from ptztrack.config.reading import _first_error_line

# A camera's name is a part of MQTT topics and of file names: letters, digits, '-' and '_' only.
_Name = Annotated[str, Field(pattern=r"^[A-Za-z0-9_-]{1,64}$")]
_Port = Annotated[int, Field(ge=0, le=65535)]
_Seconds = Annotated[PositiveFloat, at_most(7 * 86400, "seconds: a week")]


class ServiceCamera(_Strict):
    """One camera of the service.

    name : its name in topics, file names and metrics; url : ``onvif://[user[:password]@]host[:port]``
    (a real camera, or a virtual one of ``ptztrack serve-camera``); calibration : its calibration YAML
    (``ptztrack camera calibrate``), or 'virtual' for ``serve-camera``'s; policy, detector : registered
    names; scenario : 'pets' (built in) or a scenario YAML, what the camera looks at (its grid, area,
    tracker); time_scale : the scenario's seconds per wall-clock second (1 for a real camera); seed :
    the seed of every random draw of the camera's loop; pose : the camera's pose from GetStatus
    ('status') or registered from its pictures ('registered', as ``ptztrack live --pose``); transport :
    RTSP over 'tcp' or 'udp'.
    """

    name: _Name
    url: Annotated[str, Field(min_length=1, max_length=512)]
    calibration: str = "virtual"
    policy: Annotated[str, _registered("policies")] = "smpl"
    detector: Annotated[str, _registered("detectors")] = "hog"
    scenario: str = "pets"
    time_scale: Annotated[PositiveFloat, at_most(100, "times the wall clock")] = 1.0
    seed: Annotated[int, Field(ge=0)] = 0
    pose: Literal["status", "registered"] = "status"
    transport: Literal["tcp", "udp"] = "tcp"


class MQTTSection(_Strict):
    """The MQTT broker the events are published to (QoS 1).

    host : the broker's host name or address; port : its TCP port; topic_prefix : the first levels of
    every topic: topics are ``<prefix>/<camera>/events`` and ``<prefix>/<camera>/status``.
    """

    host: Annotated[str, Field(min_length=1, max_length=253)] = "127.0.0.1"
    port: Annotated[int, Field(ge=1, le=65535)] = 1883
    topic_prefix: Annotated[str, Field(pattern=r"^[A-Za-z0-9_-]{1,64}(/[A-Za-z0-9_-]{1,64})*$")] = "ptztrack"


class ServiceConfig(_Strict):
    """The service: its cameras, and where their tracks and events go.

    cameras : the cameras the service runs, each with its own loop, tracker and detector model (section
    ``cameras``; their names differ).
    output : the folder of every camera's tracks (``<output>/<camera>/``) and learned detector model;
    events : 'stdout' or a file the events are appended to as JSON lines; mqtt : the broker (null: none);
    position_rate_hz : how often a track's ground position is published (an 'update' event), per track;
    track_end_s : how long a track unreported is still the same event (then an 'end'); http_port : the
    port of /healthz, /metrics and the web view on 127.0.0.1 (0: any free port; null: none);
    model_save_s : how often each camera's learned detector model is saved (and at the stop);
    rotate_s : how often the tracks' files are rotated (an hour; shorter in a test); engine : where the
    cameras' loops run, 'threads' (each in a thread of the service's process), 'ray' (every camera but
    the first, whose loop feeds the web view, in a Ray actor: a process of its own on the cluster of
    ``RAY_ADDRESS``, else a local one; needs the ``ray`` extra) or 'auto' ('threads' while the cameras
    are no more than the machine's cores, else 'ray'); see :func:`camera_engines`.
    """

    cameras: Annotated[list[ServiceCamera], Field(min_length=1), at_most_items(64, "cameras of one service")]
    output: str = "ptztrack-output"
    events: str = "stdout"
    mqtt: MQTTSection | None = None
    position_rate_hz: Annotated[PositiveFloat, at_most(30, "per second: a camera's frame rate")] = 1.0
    track_end_s: Annotated[NonNegativeFloat, at_most(3600, "seconds")] = 10.0
    http_port: _Port | None = 0
    model_save_s: _Seconds = 300.0
    rotate_s: _Seconds = 3600.0
    engine: Literal["auto", "threads", "ray"] = "auto"

    @model_validator(mode="after")
    def _unique_names(self):
        names = [camera.name for camera in self.cameras]
        repeated = sorted({name for name in names if names.count(name) > 1})
        if repeated:
            raise ValueError(f"camera names must differ: {', '.join(repeated)} appears more than once")
        return self


def camera_engines(config: ServiceConfig, cores: int) -> list[str]:
    """Where each camera of ``config`` runs on a machine of ``cores`` cores: 'thread' (a thread of the
    service's process) or 'ray' (a Ray actor), by ``config.engine``; the first camera is always a thread."""
    count = len(config.cameras)
    actors = config.engine == "ray" or (config.engine == "auto" and count > cores)
    return ["thread"] + ["ray" if actors else "thread"] * (count - 1)


def load_service_config(path: str | Path) -> ServiceConfig:
    """Read and validate a service YAML file, its relative paths made relative to its folder; a
    :class:`ScenarioError` of one line if it is not one."""
    path = Path(path)
    data = read_yaml(path, "service configuration", ScenarioError)
    if not isinstance(data, dict):
        raise ScenarioError(f"{path}: expected a mapping of service fields (got {type(data).__name__})")
    try:
        config = ServiceConfig.model_validate(data)
    except pydantic.ValidationError as error:
        raise ScenarioError(_first_error_line(error, str(path))) from None
    # Absolute: a camera in a Ray actor reads and writes them from another process, whose folder may differ.
    folder = path.absolute().parent

    def beside(value: str, keep: tuple[str, ...]) -> str:
        return value if value in keep else str(folder / value)

    cameras = [
        camera.model_copy(
            update={
                "calibration": beside(camera.calibration, ("virtual",)),
                "scenario": beside(camera.scenario, ("pets", "synthetic")),
            }
        )
        for camera in config.cameras
    ]
    return config.model_copy(
        update={"cameras": cameras, "output": beside(config.output, ()), "events": beside(config.events, ("stdout",))}
    )
