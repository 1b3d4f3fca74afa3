"""The command line's arguments of the real and virtual cameras: ``ptztrack live``, ``ptztrack camera
calibrate``, ``ptztrack serve-camera`` and ``ptztrack serve``.
"""

from pathlib import Path

from ptztrack.cli.options import (
    POLICY_HELP,
    RUN_FOLDER_FILES,
    add_detector_model_arguments,
    add_recording_arguments,
    add_view_argument,
    non_negative_int,
    onvif_url,
    policy_name,
    port_number,
    positive_float,
    positive_int,
)
from ptztrack.names import PASSWORD_VARIABLE


def add_camera_commands(commands, policies: list[str]) -> None:
    """``ptztrack live`` and ``ptztrack serve-camera``: real ONVIF cameras, and a virtual one to test with."""
    live = commands.add_parser("live", help="drive an ONVIF PTZ camera in real time: capture, detect, track, decide")
    live.add_argument(
        "--camera",
        type=onvif_url,
        required=True,
        action="append",
        help="onvif://[user[:password]@]host[:port]; repeated: a network of cameras with one ground belief",
    )
    live.add_argument("--credentials", type=Path, help="a YAML file with username and password")
    live.add_argument(
        "--calibration",
        required=True,
        action="append",
        help="the camera's calibration YAML, or 'virtual' for ptztrack serve-camera; one for every camera, "
        "or one per --camera in their order",
    )
    live.add_argument(
        "--coordination",
        choices=("joint", "independent"),
        default="joint",
        help="a network's decisions: joint (greedy, each camera on the views before it) or each camera alone",
    )
    live.add_argument("--policy", type=policy_name, choices=policies, default="smpl", help=POLICY_HELP)
    live.add_argument("--scenario", default="pets", help="'pets' (built in) or a scenario YAML file")
    add_recording_arguments(live, files=False)
    live.add_argument("--detector", default="hog", help="the scenario's detector (default hog)")
    add_detector_model_arguments(live)
    live.add_argument(
        "--steps", type=positive_int, help="use at most this many pictures (default: the scenario's frames)"
    )
    live.add_argument(
        "--time-scale", type=positive_float, default=1.0, help="the scenario's seconds per second (serve-camera's)"
    )
    live.add_argument("--transport", choices=("tcp", "udp"), default="tcp", help="RTSP's transport (default tcp)")
    live.add_argument(
        "--pose",
        choices=("status", "registered"),
        default="status",
        help="the camera's pose: GetStatus's position (default), or registered from its pictures against "
        "reference views it sweeps at the start (moves by RelativeMove; for cameras without positions)",
    )
    live.add_argument("--timeout-s", type=positive_float, default=5.0, help="the longest wait for any camera call")
    live.add_argument(
        "--truth", type=Path, help="score against a virtual camera's truth log (serve-camera --truth-log)"
    )
    live.add_argument(
        "--seed", type=non_negative_int, default=0, help="fixes the run's random draws (rnd's and smpl's, say)"
    )
    live.add_argument(
        "--out", type=Path, help=f"directory for {', '.join(RUN_FOLDER_FILES)}; written whole, Ctrl-C too"
    )
    live.add_argument("--overwrite", action="store_true", help="replace a non-empty --out folder")
    add_view_argument(live)
    live.set_defaults(handler="ptztrack.cli.camera:live_command")

    camera = commands.add_parser("camera", help="tools for a real camera").add_subparsers(dest="tool", required=True)
    calibrate = camera.add_parser(
        "calibrate",
        help="time the camera's moves, or (--geometry) measure its focal lengths, pan and tilt mapping and "
        "place on the ground from its pictures, and write them into its calibration",
    )
    calibrate.add_argument("--camera", type=onvif_url, required=True, help="onvif://[user[:password]@]host[:port]")
    calibrate.add_argument("--credentials", type=Path, help="a YAML file with username and password")
    calibrate.add_argument(
        "--calibration", type=Path, required=True, help="the camera's calibration YAML (updated; --geometry: created)"
    )
    calibrate.add_argument(
        "--geometry", action="store_true", help="measure the geometry from the camera's pictures (docs: Real cameras)"
    )
    calibrate.add_argument(
        "--snapshot", type=Path, help="--geometry's first step: store the widest view as a preset, save its picture"
    )
    calibrate.add_argument(
        "--ground-points", type=Path, help="--geometry: 4+ ground points in the snapshot (YAML, CSV u_px,v_px,x_m,y_m)"
    )
    calibrate.add_argument(
        "--zoom-steps", type=positive_int, default=20, help="--geometry: zoom steps from the widest view (default 20)"
    )
    calibrate.add_argument("--timeout-s", type=positive_float, default=5.0, help="the longest wait for any camera call")
    calibrate.set_defaults(handler="ptztrack.cli.camera:calibrate_camera_command")

    serve = commands.add_parser(
        "serve-camera", help="serve a recording's virtual PTZ camera over ONVIF on 127.0.0.1 (default PETS 2009 S2.L1)"
    )
    serve.add_argument("--port", type=port_number, default=8080, help="the first camera's port (0: any free port each)")
    serve.add_argument(
        "--cameras", type=positive_int, default=1, help="serve this many cameras, on --port and the ports after it"
    )
    serve.add_argument("--scenario", default="pets", help="'pets' (built in) or a recording scenario YAML file")
    add_recording_arguments(serve, files=False)
    serve.add_argument("--time-scale", type=positive_float, default=1.0, help="the recording's speed")
    serve.add_argument("--user", help=f"require this user (password: --credentials or ${PASSWORD_VARIABLE})")
    serve.add_argument("--credentials", type=Path, help="a YAML file with username and password to require")
    serve.add_argument(
        "--truth-log", type=Path, help="append every picture's time, step and pose here (CSV; the first camera's)"
    )
    serve.add_argument(
        "--presets",
        type=Path,
        help="keep the presets in this JSON file across restarts, as a real camera does (default: in memory); "
        "with --cameras, camera k >= 2 in FILE with -k before its suffix",
    )
    serve.add_argument(
        "--supersample",
        type=positive_int,
        default=1,
        help="render each picture N times finer and average it down, as a lens and sensor do (default 1: "
        "point-sampled, as the offline tables render)",
    )
    serve.add_argument(
        "--no-positions", action="store_true", help="a camera that does not report its position (GetStatus, presets)"
    )
    serve.add_argument(
        "--relative-only", action="store_true", help="a camera without AbsoluteMove and absolute position spaces"
    )
    hidden = serve.add_mutually_exclusive_group()
    hidden.add_argument(
        "--geometry",
        type=Path,
        help="the camera's true pan, tilt and zoom mapping, not told to clients (a calibration YAML)",
    )
    hidden.add_argument(
        "--geometry-seed", type=non_negative_int, help="a true mapping drawn from this seed, not told to clients"
    )
    serve.set_defaults(handler="ptztrack.cli.camera:serve_camera_command")

    service = commands.add_parser(
        "serve",
        help="run the cameras of a service configuration until SIGTERM or Ctrl-C: tracks to rotated files, "
        "events as JSON lines and over MQTT, /healthz and /metrics (docs: ptztrack as a service)",
    )
    service.add_argument("config", type=Path, help="the service's YAML file (cameras, output, events, mqtt, ...)")
    service.set_defaults(handler="ptztrack.cli.serve:serve_command")
