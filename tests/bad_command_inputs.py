"""Mistakes in the command line itself: a word a command does not take, a scenario's name mistyped, a file
of one kind (scenario, dataset, camera calibration) given as another, and the cameras' addresses without
their scheme, credentials files without a user or a password, and a calibration file to time a camera into
that is not there yet.
"""

from bad_input_files import A_FEW_STEPS, Case

DATASET = "frame_rate_hz: 7\narea_m: [[0, 0], [10, 10]]\nviews: [{name: v, calibration: c.json, detections: d.txt}]\n"
SCENARIO = "people: {count: 3}\ncamera: {f_min_px: 300}\n"
CALIBRATION = "pan_deg: [-90, 90]\ntilt_deg: [-45, 45]\nzoom_curve: [[0, 1], [1, 4]]\n"
A_CAMERA = ("--camera", "onvif://127.0.0.1:9")  # never called: each case is refused before
NEEDS_BOTH = "expected a mapping with username and password"


def command_cases() -> list[Case]:
    """The cases of the command line's own mistakes."""
    return [
        Case(
            "run synthetic: a word run does not take",
            ("run", "synthetic"),
            says=("ptztrack run: error: unrecognized arguments: synthetic (see ptztrack run --help)",),
        ),
        Case(
            "experiment synthetic: a word it does not take",
            ("experiment", "synthetic", "smpl"),
            says=("ptztrack experiment synthetic: error: unrecognized arguments: smpl (see ptztrack experiment",),
        ),
        Case(
            "--scenario synthetc",
            ("run", "--scenario", "synthetc", *A_FEW_STEPS),
            says=("--scenario synthetc: no such scenario file; did you mean 'synthetic'?",),
        ),
        Case(
            "--scenario a file's name mistyped",
            ("run", "--scenario", "{dir}/scenaro.yaml", *A_FEW_STEPS),
            {"scenario.yaml": "frames: 5\n"},
            says=("--scenario {dir}/scenaro.yaml: no such scenario file; did you mean '{dir}/scenario.yaml'?",),
        ),
        Case(
            "follow --scenario pest",
            ("follow", "--target", "1", "--scenario", "pest"),
            says=("--scenario pest: no such scenario file; did you mean 'pets'?",),
        ),
        Case(
            "--scenario a dataset file",
            ("run", "--scenario", "{dir}/d.yaml", *A_FEW_STEPS),
            {"d.yaml": DATASET},
            says=("{dir}/d.yaml: a dataset file (it has views), not a scenario file",),
        ),
        Case(
            "--dataset a scenario file",
            ("run", "--dataset", "{dir}/s.yaml", *A_FEW_STEPS),
            {"s.yaml": SCENARIO},
            says=("{dir}/s.yaml: a scenario file (it has camera, people), not a dataset file",),
        ),
        Case(
            "experiment occupancy: a scenario file as the dataset",
            ("experiment", "occupancy", "{dir}/s.yaml"),
            {"s.yaml": SCENARIO},
            says=("{dir}/s.yaml: a scenario file (it has camera, people), not a dataset file",),
        ),
        Case(
            "--scenario a camera calibration file",
            ("run", "--scenario", "{dir}/c.yaml", *A_FEW_STEPS),
            {"c.yaml": CALIBRATION},
            says=("{dir}/c.yaml: a camera calibration file (it has pan_deg, tilt_deg, zoom_curve), not a scenario",),
        ),
        Case(
            "live: a scenario file as the calibration",
            ("live", *A_CAMERA, "--calibration", "{dir}/s.yaml"),
            {"s.yaml": SCENARIO},
            says=("{dir}/s.yaml: a scenario file (it has camera, people), not a camera calibration file",),
        ),
        Case(
            "live: an address without its scheme",
            ("live", "--camera", "127.0.0.1:8080", "--calibration", "virtual"),
            says=(
                "argument --camera: '127.0.0.1:8080' has no scheme; expected onvif://[user[:password]@]host[:port], "
                "as onvif://127.0.0.1:8080",
            ),
        ),
        Case(
            "live: credentials without a password",
            ("live", *A_CAMERA, "--calibration", "virtual", "--credentials", "{dir}/login.yaml"),
            {"login.yaml": "username: op\n"},
            says=(f"{{dir}}/login.yaml: password: missing or empty; {NEEDS_BOTH}",),
        ),
        Case(
            "camera calibrate: credentials without a user, nor one in the address",
            ("camera", "calibrate", *A_CAMERA, "--calibration", "{dir}/c.yaml", "--credentials", "{dir}/login.yaml"),
            {"c.yaml": CALIBRATION, "login.yaml": "password: pw\n"},
            says=(f"{{dir}}/login.yaml: username: missing or empty; {NEEDS_BOTH}",),
        ),
        Case(
            "serve-camera: credentials with an empty password",
            ("serve-camera", "--port", "0", "--credentials", "{dir}/login.yaml"),
            {"login.yaml": "username: op\npassword: ''\n"},
            says=("{dir}/login.yaml: password: missing or empty",),
        ),
        Case(
            "camera calibrate: a calibration that is not there yet",
            ("camera", "calibrate", *A_CAMERA, "--calibration", "{dir}/new.yaml"),
            says=("--calibration {dir}/new.yaml: no such file;", "start one with ptztrack camera calibrate --geometry"),
        ),
    ]
