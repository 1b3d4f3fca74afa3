"""Frigate's own ONVIF code against ``ptztrack serve-camera``: does it initialise it, tilt it up and calibrate it?

Frigate's ``frigate/ptz/onvif.py`` (``OnvifController``) and its autotracker's move calibration
(``frigate/ptz/autotrack.py``, ``PtzAutoTracker._calibrate_camera``, run when ``calibrate_on_startup``
is set) are imported unchanged from a checkout of Frigate and pointed at a virtual camera this script
starts (``python -m ptztrack.cli serve-camera --port 0 --truth-log ...``, 127.0.0.1 only, no
discovery). For each camera mode the installed ptztrack offers (the default one, and ``--no-positions``,
``--relative-only``, ``--geometry-seed 1`` where ``serve-camera --help`` lists them) and each of
Frigate's zooming modes (disabled, absolute, relative), in a process of its own:

1. The camera gets a preset ``home`` (ONVIF SetPreset at its start pose): the ``return_preset`` that
   Frigate's autotracking requires the camera to have.
2. A Frigate config file (``version`` current, MQTT off, one camera whose onvif section points at
   127.0.0.1, the camera's port, user and password, autotracking on with ``calibrate_on_startup``, the
   zooming mode and a required zone covering the picture) is loaded by ``FrigateConfig.load()`` from
   ``$CONFIG_FILE``, a temporary file, as Frigate loads it. Its detector is a zmq one: Frigate's default
   (cpu) exists only where its TFLite runtime is installed; no detector runs here.
3. Init and up: ``OnvifController(config, ptz_metrics)`` and its ``handle_command(camera, init)``
   (``_init_onvif``: profiles, PTZ configuration options, FOV translation space, zoom modes); then
   Frigate's ``move_up`` (a ContinuousMove of PanTilt y = +0.5) for ``MOVE_UP_S`` and its ``stop``.
   The camera's truth log (its pose at every picture; tilt_deg is a depression, positive down) says
   whether the view went up: the tilt after the stop is below the tilt before the move.
4. Calibration: a new ``OnvifController`` and ``PtzAutoTrackerThread(config, onvif, ptz_metrics,
   dispatcher, stop_event)`` built as Frigate's ``app.py`` builds them (its constructor runs
   ``_autotracker_setup``: ``_init_onvif``, the FOV and MoveStatus checks, ``_calibrate_camera``,
   ``_calculate_move_coefficients``, which writes ``movement_weights`` into the config file). The thread
   is not started (its loop only maintains tracking). The weights are read back from the file, and the
   zoom factors the camera went through while calibrating from its truth log.

Stand-ins, only for what Frigate's process hands these classes: the Dispatcher (Frigate's own
``Dispatcher``) gets one communicator that records what is published, in place of MQTT and the web
socket, and no config publisher (only its command handlers use one); ``frigate/version.py`` is made
by Frigate's ``make version``, and stood in for if absent. The move durations the calibration timed
are reported too, with their least-squares line (Frigate's own fit of the same numbers; it writes the
weights only if the intercept is 0.1-10 s and the slope in (0, 2] s).

Each case's files (Frigate's config file with the weights it wrote, the camera's truth log and stderr)
stay in its ``work_dir``. Prints one line per case; ``--json`` writes ``{"cases": [{"camera_mode", "zooming", "init",
"up_tilts_up", "calibrated", "movement_weights", "error", ...}], "frigate_commit"}``.

Frigate's source and its environment (Frigate pins its packages in docker/main/requirements-wheels.txt;
this is the part its ONVIF and autotracker modules import; opencv-python-headless goes into this
venv only, never into ptztrack's environment)::

    git clone https://github.com/blakeblackshear/frigate /tmp/frigate-git   # or any bare copy: G=...
    G=/tmp/frigate-git/.git
    mkdir -p /tmp/frigate-src && git --git-dir=$G archive HEAD frigate labelmap.txt | tar -x -C /tmp/frigate-src
    echo "VERSION = \\"0.18.0-$(git --git-dir=$G rev-parse HEAD)\\"" > /tmp/frigate-src/frigate/version.py
    python3.11 -m venv /tmp/frigate-venv
    /tmp/frigate-venv/bin/pip install "onvif-zeep-async==4.0.*" "numpy==1.26.*" "scipy==1.16.*" \\
        "norfair==2.3.*" "pydantic==2.10.*" "ruamel.yaml==0.18.*" "pyzmq==26.2.*" "unidecode==1.3.*" \\
        "opencv-python-headless==4.11.0.*" "peewee==3.17.*" "peewee_migrate==1.14.*" "psutil==7.1.*" \\
        "requests==2.32.*" "pytz==2025.*" "tzlocal==5.2" "titlecase==2.4.*" "pathvalidate==3.3.*" \\
        "paho-mqtt==2.1.*" "setproctitle==1.3.*" "filelock==3.8.*" "py-vapid==1.9.*" "pywebpush==2.0.*" \\
        "sherpa-onnx==1.12.*" "librosa==0.11.*" py3nvml

Run it with the venv's Python; the camera runs under ``--camera-python``, a Python with ptztrack::

    /tmp/frigate-venv/bin/python benchmarks/frigate_onvif.py --frigate-src /tmp/frigate-src \\
        [--camera-python python] [--camera-src SRC] [--camera-modes default no-positions ...] \\
        [--zooming disabled absolute relative] [--case-timeout-s 600] [--json PATH]

``--camera-src`` runs the camera from another ptztrack ``src`` directory (first on its PYTHONPATH), e.g.
a commit's: ``git archive HEAD src | tar -x -C /tmp/ptztrack-head`` then ``--camera-src
/tmp/ptztrack-head/src``; the JSON's ``camera_source`` says which ptztrack the camera ran.

(Frigate's detector plugins log an error for each runtime missing here, onnxruntime, openvino,
ai_edge_litert; they are silenced: no detector runs.)
"""

import argparse
import asyncio
import json
import logging
import multiprocessing as mp
import os
import re
import secrets
import signal
import subprocess
import sys
import tempfile
import time
import traceback
import types
from pathlib import Path

CAMERA = "ptz"
HOME_PRESET = "home"
# The camera requires a user (WS-Security UsernameToken): onvif-zeep-async 4.0, which Frigate pins, signs
# every request and fails on a camera configured without a user (zeep's UsernameToken of None).
CAMERA_USER = "frigate"
# The camera modes: the name reported, serve-camera's flags, and the flag --help must list for the mode to exist.
CAMERA_MODES = {
    "default": ([], None),
    "no-positions": (["--no-positions"], "--no-positions"),
    "relative-only": (["--relative-only"], "--relative-only"),
    "geometry-seed-1": (["--geometry-seed", "1"], "--geometry-seed"),
}
ZOOMING_MODES = ["disabled", "absolute", "relative"]
# How long Frigate's move_up runs before its stop, and how long after the stop the pose is read.
MOVE_UP_S = 0.6
SETTLE_S = 1.5
# A tilt change smaller than this is no move.
TILT_MOVED_DEG = 0.5
CAMERA_START_TIMEOUT_S = 120.0
FRIGATE_LOG_FORMAT = "%(asctime)s %(levelname)s %(name)s: %(message)s"


def frigate_commit(frigate_src: Path) -> str:
    """The commit of the Frigate checkout: git's, or the hash ``make version`` put into frigate/version.py."""
    if (frigate_src / ".git").exists():
        try:
            result = subprocess.run(
                ["git", "-C", str(frigate_src), "rev-parse", "HEAD"], capture_output=True, text=True, check=True
            )
            return result.stdout.strip()
        except (OSError, subprocess.CalledProcessError):
            pass
    version_file = frigate_src / "frigate" / "version.py"
    if version_file.is_file():
        match = re.search(r"-([0-9a-f]{7,40})\"", version_file.read_text())
        if match:
            return match.group(1)
    return "unknown"


def camera_environment(camera_src: Path | None) -> dict[str, str]:
    """The camera's environment: ``camera_src`` (a ptztrack ``src`` directory) first on its PYTHONPATH."""
    environment = dict(os.environ)
    if camera_src is not None:
        environment["PYTHONPATH"] = os.pathsep.join(filter(None, [str(camera_src), os.environ.get("PYTHONPATH")]))
    return environment


def camera_source(camera_python: str, camera_src: Path | None) -> dict:
    """Which ptztrack the camera runs: its package's path, and the commit of its git work tree (read only)
    with the package's files that differ from it."""
    package = subprocess.run(
        [camera_python, "-c", "import ptztrack; print(ptztrack.__file__)"],
        capture_output=True,
        text=True,
        check=True,
        env=camera_environment(camera_src),
    ).stdout.strip()
    source = {"ptztrack": str(Path(package).parent)}
    git = ["git", "--no-optional-locks", "-C", str(Path(package).parent)]
    try:
        source["commit"] = subprocess.run(
            [*git, "rev-parse", "HEAD"], capture_output=True, text=True, check=True
        ).stdout.strip()
        status = subprocess.run([*git, "status", "--porcelain", "--", "."], capture_output=True, text=True, check=True)
        source["modified"] = sorted(line[3:] for line in status.stdout.splitlines())
    except (OSError, subprocess.CalledProcessError):
        source["commit"] = None
    return source


def available_camera_modes(camera_python: str, camera_src: Path | None) -> tuple[list[str], dict[str, str]]:
    """The camera modes the installed ``serve-camera`` has, and why the others are left out."""
    help_text = subprocess.run(
        [camera_python, "-m", "ptztrack.cli", "serve-camera", "--help"],
        capture_output=True,
        text=True,
        check=True,
        env=camera_environment(camera_src),
    ).stdout
    present, absent = [], {}
    for name, (_, flag) in CAMERA_MODES.items():
        if flag is None or flag in help_text:
            present.append(name)
        else:
            absent[name] = f"serve-camera --help has no {flag}"
    return present, absent


# The parent: one child process per case.


def run_cases(args: argparse.Namespace) -> int:
    commit = frigate_commit(args.frigate_src)
    present, absent = available_camera_modes(args.camera_python, args.camera_src)
    source = camera_source(args.camera_python, args.camera_src)
    modes = [mode for mode in args.camera_modes if mode in present]
    for mode in args.camera_modes:
        if mode in absent:
            print(f"{mode:16s} skipped: {absent[mode]}", flush=True)
    print(f"Frigate {commit} from {args.frigate_src}; the camera's ptztrack: {source}", flush=True)
    cases = []
    with tempfile.TemporaryDirectory(prefix="frigate_onvif_") as directory:
        for mode in modes:
            for zooming in args.zooming:
                case_json = Path(directory) / f"{mode}_{zooming}.json"
                case = run_case_process(args, mode, zooming, case_json)
                cases.append(case)
                print(case_line(case), flush=True)
    if args.json:
        report = {
            "cases": cases,
            "frigate_commit": commit,
            "camera_source": source,
            "skipped_camera_modes": {mode: absent[mode] for mode in args.camera_modes if mode in absent},
            "move_up_s": MOVE_UP_S,
        }
        Path(args.json).write_text(json.dumps(report, indent=2) + "\n")
    return 0


def run_case_process(args: argparse.Namespace, mode: str, zooming: str, case_json: Path) -> dict:
    """Run one case in a child process (its own session: on a timeout, it and its camera are ended)."""
    command = [
        sys.executable,
        str(Path(__file__).resolve()),
        "--frigate-src",
        str(args.frigate_src),
        "--camera-python",
        args.camera_python,
        *(["--camera-src", str(args.camera_src)] if args.camera_src else []),
        "--case",
        f"{mode}:{zooming}",
        "--case-json",
        str(case_json),
    ]
    child = subprocess.Popen(command, start_new_session=True)
    timed_out = False
    try:
        child.wait(timeout=args.case_timeout_s)
    except subprocess.TimeoutExpired:
        timed_out = True
        for sent, wait_s in ((signal.SIGTERM, 10.0), (signal.SIGKILL, 10.0)):
            try:
                os.killpg(child.pid, sent)  # the child's session: the child and the camera it started
            except ProcessLookupError:
                break
            try:
                child.wait(timeout=wait_s)
                break
            except subprocess.TimeoutExpired:
                continue
    case = json.loads(case_json.read_text()) if case_json.is_file() else empty_case(mode, zooming)
    if timed_out:
        case["error"] = f"timed out after {args.case_timeout_s:g} s; last: {case.get('error')}"
    elif child.returncode != 0 and case.get("error") is None:
        case["error"] = f"the case's process exited with {child.returncode}"
    return case


def empty_case(mode: str, zooming: str) -> dict:
    return {
        "camera_mode": mode,
        "zooming": zooming,
        "init": False,
        "up_tilts_up": False,
        "calibrated": False,
        "movement_weights": None,
        "error": None,
    }


def add_error(case: dict, text: str) -> None:
    """One more problem of the case, after those found before it."""
    case["error"] = text if case.get("error") is None else f"{case['error']}; {text}"


def case_line(case: dict) -> str:
    def yes(value) -> str:
        return "yes" if value else "no"

    tilt = case.get("tilt_deg_before_after")
    tilt_text = f" (tilt {tilt[0]:.1f} -> {tilt[1]:.1f} deg)" if tilt else ""
    weights = case.get("movement_weights")
    weights_text = f" weights {', '.join(f'{w:.4g}' for w in weights)}" if weights else ""
    fit = case.get("move_fit_intercept_slope_s")
    fit_text = f" (moves: {fit[0]:.3f} s + {fit[1]:.3f} s per unit)" if fit else ""
    zooming = case["zooming"]
    effective = case.get("zooming_after_init")
    if effective and effective != zooming:
        zooming = f"{zooming}->{effective}"
    line = (
        f"{case['camera_mode']:16s} zooming={zooming:18s} init={yes(case['init'])} "
        f"up_tilts_up={yes(case['up_tilts_up'])}{tilt_text} calibrated={yes(case['calibrated'])}"
        f"{weights_text}{fit_text}"
    )
    return line + (f"  error: {case['error']}" if case.get("error") else "")


# The child: one case.


class FrigateLog(logging.Handler):
    """Frigate's log records of one case (debug ones too: Frigate logs what a camera lacks at debug)."""

    def __init__(self):
        super().__init__(logging.DEBUG)
        self.setFormatter(logging.Formatter("%(levelname)s %(name)s:%(lineno)d: %(message)s"))
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)

    def mark(self) -> int:
        return len(self.records)

    def warnings_since(self, mark: int) -> list[str]:
        """The warnings and errors since record ``mark``."""
        return [self.format(record) for record in self.records[mark:] if record.levelno >= logging.WARNING]

    def unsupported(self) -> list[str]:
        """The lines where Frigate found the camera without something it asked for, once each."""
        lines = [
            self.format(record)
            for record in self.records
            if re.search(r"not supported|does not support|Unable to|unavailable", record.getMessage())
        ]
        return list(dict.fromkeys(line.split("\n")[0][:300] for line in lines))

    def first_problem(self, since: int = 0) -> str | None:
        """The first warning or error since record ``since``, preferring the calibration's verdict and
        the lines that turn autotracking off."""
        problems = [record for record in self.records[since:] if record.levelno >= logging.WARNING]
        for pattern in ("calibration failed", "Disabling autotracking", "recalibration is required"):
            for record in problems:
                if pattern in record.getMessage():
                    return self.format(record)
        return self.format(problems[0]) if problems else None


def frigate_frame(error: BaseException, frigate_src: Path) -> str:
    """``error`` with the innermost line of Frigate's code it passed through (file:line in the checkout)."""
    frames = [
        frame for frame in traceback.extract_tb(error.__traceback__) if frame.filename.startswith(str(frigate_src))
    ]
    where = f" at {Path(frames[-1].filename).relative_to(frigate_src)}:{frames[-1].lineno}" if frames else ""
    return f"{type(error).__name__}: {error}{where}"


def import_frigate(frigate_src: Path) -> dict:
    """Frigate's modules, imported from the checkout unchanged."""
    sys.path.insert(0, str(frigate_src))
    try:
        import frigate.version  # noqa: F401  (written by Frigate's `make version`)
    except ImportError:
        version = types.ModuleType("frigate.version")
        version.VERSION = f"0.0.0-{frigate_commit(frigate_src)}"
        sys.modules["frigate.version"] = version
    # The detector plugins log an error per missing runtime at import; no detector runs here.
    logging.getLogger("frigate.detectors").setLevel(logging.CRITICAL)
    from frigate.camera import PTZMetrics
    from frigate.comms.base_communicator import Communicator
    from frigate.comms.dispatcher import Dispatcher
    from frigate.config import FrigateConfig
    from frigate.ptz.autotrack import PtzAutoTrackerThread
    from frigate.ptz.onvif import OnvifCommandEnum, OnvifController
    from frigate.util.config import CURRENT_CONFIG_VERSION

    return {
        "PTZMetrics": PTZMetrics,
        "Communicator": Communicator,
        "Dispatcher": Dispatcher,
        "FrigateConfig": FrigateConfig,
        "PtzAutoTrackerThread": PtzAutoTrackerThread,
        "OnvifCommandEnum": OnvifCommandEnum,
        "OnvifController": OnvifController,
        "CURRENT_CONFIG_VERSION": CURRENT_CONFIG_VERSION,
    }


def start_camera(
    camera_python: str, camera_src: Path | None, flags: list[str], truth_log: Path, stderr_path: Path, password: str
):
    """Start ``serve-camera`` on a free port, user ``CAMERA_USER`` and ``password`` required; the process,
    its ONVIF port and its RTSP URI (or None)."""
    command = [
        *(camera_python, "-m", "ptztrack.cli", "serve-camera", "--port", "0", "--truth-log", str(truth_log)),
        *("--user", CAMERA_USER, *flags),
    ]
    stderr_file = open(stderr_path, "w")  # noqa: SIM115  (the camera's whole life)
    environment = {**camera_environment(camera_src), "PTZTRACK_CAMERA_PASSWORD": password}
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=stderr_file, text=True, env=environment)
    port, rtsp_uri = None, None
    deadline_s = time.monotonic() + CAMERA_START_TIMEOUT_S
    while time.monotonic() < deadline_s:
        line = process.stdout.readline()
        if not line:
            raise RuntimeError(f"serve-camera ended at start: {stderr_path.read_text()[-2000:]}")
        if match := re.search(r"onvif://127\.0\.0\.1:(\d+)", line):
            port = int(match.group(1))
        elif match := re.search(r"(rtsp://127\.0\.0\.1:\d+/)", line):
            rtsp_uri = match.group(1) + "video_main"
        elif line.startswith("the recording plays"):
            break
    if port is None:
        raise RuntimeError("serve-camera printed no ONVIF port")
    return process, port, rtsp_uri


def stop_camera(process: subprocess.Popen) -> None:
    if process.poll() is None:
        process.send_signal(signal.SIGINT)  # serve-camera stops its camera on Ctrl-C
        try:
            process.wait(timeout=15)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


async def set_preset(port: int, password: str, name: str) -> str:
    """Store the camera's current pose as preset ``name`` (what a user does in the camera's own UI)."""
    from importlib.util import find_spec

    from onvif import ONVIFCamera

    wsdl_dir = str(Path(find_spec("onvif").origin).parent / "wsdl")
    camera = ONVIFCamera("127.0.0.1", port, CAMERA_USER, password, wsdl_dir=wsdl_dir)
    try:
        await camera.update_xaddrs()
        media = await camera.create_media_service()
        ptz = await camera.create_ptz_service()
        profiles = await media.GetProfiles()
        return await ptz.SetPreset({"ProfileToken": profiles[0].token, "PresetName": name})
    finally:
        await camera.close()


def read_truth(path: Path) -> list[tuple[float, float, float, float]]:
    """The truth log's (epoch s, pan_deg, tilt_deg, zoom) rows."""
    rows = []
    for line in path.read_text().splitlines()[1:]:
        values = line.split(",")
        if len(values) == 5:
            rows.append((float(values[0]), float(values[2]), float(values[3]), float(values[4])))
    return rows


def pose_at(rows, time_s: float):
    """The last pose pictured at or before ``time_s`` (epoch s)."""
    before = [row for row in rows if row[0] <= time_s]
    return before[-1] if before else None


def frigate_config_yaml(
    version: str, labelmap: Path, port: int, password: str, rtsp_uri: str | None, zooming: str
) -> str:
    # Nothing reads the stream, and no detector runs: the default one (cpu) is a plugin only where its TFLite
    # runtime is installed (Frigate's image has a wheel from GitHub), the zmq one is one without a runtime.
    stream = rtsp_uri or "rtsp://127.0.0.1:554/none"
    return f"""version: {version}
mqtt:
  enabled: false
model:
  labelmap_path: {labelmap}
detectors:
  unused:
    type: zmq
cameras:
  {CAMERA}:
    ffmpeg:
      inputs:
        - path: {stream}
          roles:
            - detect
    detect:
      width: 768
      height: 576
      fps: 5
    zones:
      whole_picture:
        coordinates: 0,0,1,0,1,1,0,1
    onvif:
      host: 127.0.0.1
      port: {port}
      user: "{CAMERA_USER}"
      password: "{password}"
      autotracking:
        enabled: true
        calibrate_on_startup: true
        zooming: {zooming}
        return_preset: {HOME_PRESET}
        required_zones:
          - whole_picture
"""


def written_weights(config_file: Path) -> list[float] | None:
    """The movement_weights Frigate wrote into the config file, or None."""
    from ruamel.yaml import YAML

    data = YAML().load(config_file.read_text())
    weights = data["cameras"][CAMERA]["onvif"]["autotracking"].get("movement_weights")
    if not weights:
        return None
    values = weights.split(",") if isinstance(weights, str) else weights
    return [float(value) for value in values]


def wait_for_camera_entry(controller, timeout_s: float = 10.0) -> bool:
    """OnvifController creates its ONVIFCamera on its own loop after construction."""
    deadline_s = time.monotonic() + timeout_s
    while CAMERA not in controller.cams and time.monotonic() < deadline_s:
        time.sleep(0.05)
    return CAMERA in controller.cams


def save_case(path: str, case: dict) -> None:
    """Write the case, with what Frigate found the camera without."""
    frigate_log = case.get("_log")
    if frigate_log is not None:
        case["frigate_unsupported"] = frigate_log.unsupported()
    Path(path).write_text(json.dumps({key: value for key, value in case.items() if key != "_log"}, indent=2))


def run_one_case(args: argparse.Namespace, case: dict) -> None:
    mode, zooming = case["camera_mode"], case["zooming"]

    def save() -> None:
        save_case(args.case_json, case)

    save()
    logging.basicConfig(level=logging.WARNING, format=FRIGATE_LOG_FORMAT, stream=sys.stderr)
    logging.getLogger().handlers[0].setLevel(logging.INFO)  # Frigate's debug lines are kept, not printed
    frigate_log = FrigateLog()
    case["_log"] = frigate_log
    logging.getLogger("frigate").addHandler(frigate_log)
    logging.getLogger("frigate").setLevel(logging.DEBUG)
    frigate = import_frigate(args.frigate_src)
    print(f"[{mode}, zooming {zooming}] Frigate imported", file=sys.stderr, flush=True)

    directory = Path(tempfile.mkdtemp(prefix=f"frigate_onvif_{mode}_{zooming}_"))
    truth_log = directory / "truth.csv"
    password = secrets.token_hex(8)
    camera, port, rtsp_uri = start_camera(
        args.camera_python, args.camera_src, CAMERA_MODES[mode][0], truth_log, directory / "camera_stderr.txt", password
    )
    case["onvif_port"], case["work_dir"] = port, str(directory)
    try:
        try:
            case["home_preset_token"] = asyncio.run(set_preset(port, password, HOME_PRESET))
        except Exception as error:
            case["home_preset_error"] = f"{type(error).__name__}: {error}"
        # Frigate's image has its labelmap at /labelmap.txt (docker/main/Dockerfile); here the checkout's.
        labelmap = args.frigate_src / "labelmap.txt"
        if not labelmap.is_file():
            labelmap = directory / "labelmap.txt"
            labelmap.write_text("0  person\n")
        config_file = directory / "config.yml"
        config_file.write_text(
            frigate_config_yaml(frigate["CURRENT_CONFIG_VERSION"], labelmap, port, password, rtsp_uri, zooming)
        )
        os.environ["CONFIG_FILE"] = str(config_file)  # where Frigate loads its config and writes the weights
        init_and_up(frigate, frigate_log, case, truth_log)
        save()
        calibrate(frigate, frigate_log, case, config_file, truth_log)
        save()
    finally:
        stop_camera(camera)


def init_and_up(frigate: dict, frigate_log: FrigateLog, case: dict, truth_log: Path) -> None:
    """OnvifController's init, then Frigate's move_up and stop, judged by the camera's truth."""
    command = frigate["OnvifCommandEnum"]
    config = frigate["FrigateConfig"].load()
    ptz_metrics = {CAMERA: frigate["PTZMetrics"](autotracker_enabled=True)}
    controller = frigate["OnvifController"](config, ptz_metrics)
    try:
        if not wait_for_camera_entry(controller):
            add_error(case, frigate_log.first_problem() or "OnvifController made no camera entry")
            return
        mark = frigate_log.mark()
        controller.handle_command(CAMERA, command.init)
        state = controller.cams[CAMERA]
        case["init"] = bool(state["init"])
        case["features"] = list(state["features"])
        case["presets"] = sorted(state["presets"])
        case["zooming_after_init"] = config.cameras[CAMERA].onvif.autotracking.zooming.value
        case["init_warnings"] = frigate_log.warnings_since(mark)
        if not case["init"]:
            add_error(case, frigate_log.first_problem(mark) or "_init_onvif returned False")
            return
        time.sleep(1.0)  # a picture or more of the pose before the move
        mark = frigate_log.mark()
        moved_s = time.time()
        controller.handle_command(CAMERA, command.move_up)
        time.sleep(MOVE_UP_S)
        controller.handle_command(CAMERA, command.stop)
        stopped_s = time.time()
        time.sleep(SETTLE_S)  # the truth log is written every 0.5 s
        rows = read_truth(truth_log)
        before, after = pose_at(rows, moved_s), pose_at(rows, stopped_s + SETTLE_S)
        if before is None or after is None:
            add_error(case, "the truth log has no picture before the move or after the stop")
            return
        case["tilt_deg_before_after"] = [before[2], after[2]]
        case["pan_deg_before_after"] = [before[1], after[1]]
        # tilt_deg is a depression: the view goes up when it decreases.
        case["up_tilts_up"] = after[2] < before[2] - TILT_MOVED_DEG
        if not case["up_tilts_up"]:
            add_error(
                case,
                f"move_up (ContinuousMove PanTilt y=+0.5, {MOVE_UP_S:g} s) took tilt_deg (a depression) from "
                f"{before[2]:.1f} to {after[2]:.1f}: the view did not go up",
            )
        problem = frigate_log.first_problem(mark)
        if problem:
            case["move_up_warning"] = problem
    finally:
        controller.close()


def calibrate(frigate: dict, frigate_log: FrigateLog, case: dict, config_file: Path, truth_log: Path) -> None:
    """Frigate's startup: a new OnvifController, then the autotracker, whose setup calibrates."""
    config = frigate["FrigateConfig"].load()
    ptz_metrics = {CAMERA: frigate["PTZMetrics"](autotracker_enabled=True)}
    controller = frigate["OnvifController"](config, ptz_metrics)
    published: list[tuple[str, str]] = []

    class RecordedComms(frigate["Communicator"]):
        """In place of MQTT and the web socket: what the dispatcher publishes."""

        def publish(self, topic: str, payload, retain: bool = False) -> None:
            published.append((topic, str(payload)))

        def subscribe(self, receiver) -> None:
            pass

        def stop(self) -> None:
            pass

    # No config publisher: only the dispatcher's command handlers use it, and none runs here.
    dispatcher = frigate["Dispatcher"](config, None, controller, ptz_metrics, [RecordedComms()])
    stop_event = mp.Event()
    autotracker = None
    mark = frigate_log.mark()
    try:
        if not wait_for_camera_entry(controller):
            add_error(case, frigate_log.first_problem(mark) or "OnvifController made no camera entry")
            return
        started_s, started_epoch_s = time.monotonic(), time.time()
        autotracker = frigate["PtzAutoTrackerThread"](config, controller, ptz_metrics, dispatcher, stop_event)
        case["calibration_s"] = round(time.monotonic() - started_s, 2)
        time.sleep(SETTLE_S)  # the truth log is written every 0.5 s
        poses = [row for row in read_truth(truth_log) if row[0] >= started_epoch_s]
        if poses:
            case["calibration_zoom_min_max"] = [min(row[3] for row in poses), max(row[3] for row in poses)]
        tracker = autotracker.ptz_autotracker
        moves = tracker.move_metrics.get(CAMERA, [])
        case["calibration_moves"] = len(moves)
        if moves:
            import numpy as np

            amounts = np.array([abs(move["pan"]) + abs(move["tilt"]) for move in moves])
            durations_s = np.array([move["end_timestamp"] - move["start_timestamp"] for move in moves])
            slope_s, intercept_s = np.polyfit(amounts, durations_s, 1)
            case["move_fit_intercept_slope_s"] = [float(intercept_s), float(slope_s)]
            case["move_durations_s_min_max"] = [float(durations_s.min()), float(durations_s.max())]
        case["min_max_zoom"] = [ptz_metrics[CAMERA].min_zoom.value, ptz_metrics[CAMERA].max_zoom.value]
        case["autotracking_enabled_after"] = bool(config.cameras[CAMERA].onvif.autotracking.enabled)
        case["movement_weights"] = written_weights(config_file)
        case["calibrated"] = case["movement_weights"] is not None
        case["published"] = published
        case["calibration_warnings"] = frigate_log.warnings_since(mark)
        problem = frigate_log.first_problem(mark)
        if not case["calibrated"]:
            add_error(case, problem or "no movement_weights written")
    finally:
        stop_event.set()
        if autotracker is not None:
            autotracker.ptz_autotracker.config_subscriber.stop()
        dispatcher.stop()
        controller.close()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--frigate-src", type=Path, required=True, help="a checkout of Frigate (its frigate/ package)")
    parser.add_argument(
        "--camera-python",
        default="python",
        help="a Python with ptztrack, to run serve-camera (default: python)",
    )
    parser.add_argument(
        "--camera-src", type=Path, help="a ptztrack src directory to run the camera from (first on its PYTHONPATH)"
    )
    parser.add_argument("--camera-modes", nargs="+", default=list(CAMERA_MODES), choices=list(CAMERA_MODES))
    parser.add_argument("--zooming", nargs="+", default=ZOOMING_MODES, choices=ZOOMING_MODES)
    parser.add_argument("--case-timeout-s", type=float, default=600.0, help="end a case after this long")
    parser.add_argument("--json", help="write the cases and Frigate's commit here")
    parser.add_argument("--case", help=argparse.SUPPRESS)
    parser.add_argument("--case-json", help=argparse.SUPPRESS)
    args = parser.parse_args()
    args.frigate_src = args.frigate_src.resolve()
    if args.case is None:
        return run_cases(args)
    status = 0
    case = empty_case(*args.case.split(":"))
    try:
        run_one_case(args, case)
    except Exception as error:
        case["exception"] = frigate_frame(error, args.frigate_src)
        add_error(case, case["exception"])
        save_case(args.case_json, case)
        logging.getLogger(__name__).exception("the case failed")
        status = 1
    sys.stdout.flush()
    sys.stderr.flush()
    # Frigate's ZeroMQ sockets and event-loop threads are not all closed by its stop()s: end the process.
    os._exit(status)


if __name__ == "__main__":
    sys.exit(main())
