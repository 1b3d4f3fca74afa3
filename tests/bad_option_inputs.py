"""Bad command-line options, output paths and camera addresses, of every command.

Numbers out of range or not numbers (seeds, betas, ports, frame counts, sequences), output folders and files
that exist, are missing or cannot be written, the options of one setting given to another, and the
``live``, ``serve-camera`` and ``view`` commands' addresses, calibrations and folders.
"""

from bad_input_files import A_FEW_STEPS, Case


def option_cases() -> list[Case]:
    """The cases of the command line's options."""
    return [
        Case("--seed -5", ("run", *A_FEW_STEPS, "--seed", "-5")),
        Case(
            "follow --target x",
            ("follow", "--target", "x"),
            says=("error: argument --target: expected a whole number >= 0, got 'x'",),
        ),
        Case("--beta nan", ("experiment", "pets", "--beta", "nan", *A_FEW_STEPS)),
        Case("--beta -3", ("experiment", "pets", "--beta", "-3", *A_FEW_STEPS)),
        Case("--beta inf", ("experiment", "pets", "--beta", "inf", *A_FEW_STEPS)),
        Case("--out names a file", ("run", *A_FEW_STEPS, "--out", "{dir}/file"), {"file": "keep me\n"}),
        Case("--out in a missing folder", ("run", *A_FEW_STEPS, "--out", "{dir}/missing/out")),
        Case("--out not empty", ("run", *A_FEW_STEPS, "--out", "{dir}/out"), {"out/metrics.json": "{}\n"}),
        # The folder the command runs in, or one that holds it, cannot be replaced by the run's folder.
        Case("--out .", ("run", *A_FEW_STEPS, "--out", ".", "--overwrite"), says=("--out .: is the current folder",)),
        Case("--out ''", ("run", *A_FEW_STEPS, "--out", ""), says=("--out .: is the current folder",)),
        Case("--out ..", ("run", *A_FEW_STEPS, "--out", "..", "--overwrite"), says=("--out ..: is the current",)),
        Case("follow --out .", ("follow", "--target", "1", "--out", "."), says=("--out .: is the current folder",)),
        Case("--view-wait alone", ("run", *A_FEW_STEPS, "--view-wait"), says=("--view-wait: goes with --view",)),
        Case(
            "--out where nothing can be written",
            ("run", *A_FEW_STEPS, "--out", "/proc/x"),
            says=("--out /proc/x: cannot write into /proc (",),
        ),
        Case(
            "serve-camera: --truth-log where nothing can be written",
            ("serve-camera", "--port", "0", "--truth-log", "/proc/x.csv"),
            says=("--truth-log /proc/x.csv: cannot write into /proc (",),
        ),
        Case(
            "--json in a missing folder",
            ("experiment", "synthetic", "--sequences", "1", *A_FEW_STEPS, "--json", "{dir}/missing/x.json"),
        ),
        Case("--json names a folder", ("experiment", "synthetic", "--sequences", "1", *A_FEW_STEPS, "--json", "{dir}")),
        Case("network: no setting", ("experiment", "network")),
        Case("network: --max-ptz 0", ("experiment", "network", "synthetic", "--max-ptz", "0")),
        Case("network: --first-sequence -1", ("experiment", "network", "synthetic", "--first-sequence", "-1")),
        Case(
            "network pets: the development sequences of the synthetic setting",
            ("experiment", "network", "pets", "--first-sequence", "1000", *A_FEW_STEPS),
            says=("--first-sequence",),
        ),
        Case(
            "network pets: the synthetic setting's option",
            ("experiment", "network", "pets", "--max-ptz", "2", *A_FEW_STEPS),
            says=("--max-ptz",),
        ),
        Case(
            "network pets: a view the dataset does not have",
            ("experiment", "network", "pets", "--dataset-view", "View_009", *A_FEW_STEPS),
            says=("no view 'View_009'", "View_001, View_003"),
        ),
        Case(
            "network: --json in a missing folder",
            ("experiment", "network", "synthetic", "--sequences", "1", *A_FEW_STEPS, "--json", "{dir}/missing/x.json"),
        ),
        Case("--plot in a missing folder", ("experiment", "msg", "--runs", "1", "--plot", "{dir}/missing/x.png")),
        Case("--trails in a missing folder", ("experiment", "msg", "--runs", "1", "--trails", "{dir}/missing/x.png")),
        Case(
            "experiment follow: a person not annotated after one who is",
            ("experiment", "follow", "--targets", "9", "999"),
            says=("gt_mot15.txt: no person 999 (the people are 1, 2,",),
        ),
        Case(
            "experiment follow: --otb-tracks 0",
            ("experiment", "follow", "--otb-tracks", "0"),
            says=("expected 1 to 19",),
        ),
        Case(
            "experiment follow: --otb-tracks 1000",
            ("experiment", "follow", "--otb-tracks", "1000"),
            says=("--otb-tracks 1000: expected 1 to 19, as ",),
        ),
        Case(
            "occupancy --lead-in on the room",
            ("experiment", "occupancy", "synthetic-room", "--lead-in", "5"),
            says=("--lead-in", "synthetic-plaza only"),
        ),
        Case(
            "occupancy --lead-in negative",
            ("experiment", "occupancy", "synthetic-plaza", "--lead-in", "-1"),
            says=("--lead-in",),
        ),
        Case("live: not an ONVIF URL", ("live", "--camera", "rtsp://op:pw@127.0.0.1/x", "--calibration", "virtual")),
        Case(
            "live: port 0",
            ("live", "--camera", "onvif://127.0.0.1:0", "--calibration", "virtual"),
            says=("--camera onvif://127.0.0.1:0: the port is not a number from 1 to 65535",),
        ),
        Case(
            "live: a truth log that is not there",
            ("live", "--camera", "onvif://127.0.0.1:9", "--calibration", "virtual", "--truth", "{dir}/missing.csv"),
            says=("{dir}/missing.csv: no such truth log file",),
        ),
        Case(
            "live: --time-scale 0",
            ("live", "--camera", "onvif://127.0.0.1", "--calibration", "virtual", "--time-scale", "0"),
        ),
        Case(
            "live: a zoom curve that falls",
            ("live", "--camera", "onvif://127.0.0.1:9", "--calibration", "{dir}/c.yaml"),
            {"c.yaml": "pan_deg: [-90, 90]\ntilt_deg: [-45, 45]\nzoom_curve: [[0, 4], [1, 1]]\n"},
        ),
        Case(
            "live: two cameras, three calibrations",
            ("live", "--camera", "onvif://127.0.0.1:9", "--camera", "onvif://127.0.0.1:10")
            + ("--calibration", "virtual") * 3,
            says=("3 --calibration for 2 --camera",),
        ),
        Case(
            "live: a network deciding by fix",
            ("live", "--camera", "onvif://127.0.0.1:9", "--camera", "onvif://127.0.0.1:10", "--calibration", "virtual")
            + ("--policy", "fix"),
            says=("intg or smpl", "fix"),
        ),
        Case("serve-camera: a user without a password", ("serve-camera", "--port", "0", "--user", "op")),
        Case(
            "serve-camera: cameras past the last port",
            ("serve-camera", "--port", "65535", "--cameras", "2"),
            says=("past port 65535",),
        ),
        Case(
            "serve-camera: a geometry that is not there",
            ("serve-camera", "--port", "0", "--geometry", "{dir}/missing.yaml"),
            says=("serve-camera --geometry: {dir}/missing.yaml: no such",),
        ),
        Case(
            "serve-camera: a geometry without the recording's start pose",
            ("serve-camera", "--port", "0", "--geometry", "{dir}/g.yaml"),
            {"g.yaml": "pan_deg: [-90, 0]\ntilt_deg: [80, -10]\nzoom_curve: [[0, 1], [1, 8]]\n"},
            says=("--geometry", "{dir}/g.yaml: pan_deg [-90.0, 0.0] does not contain the recording's start pan 57.3"),
        ),
        Case(
            "serve-camera: a geometry elsewhere than the recording camera",
            ("serve-camera", "--port", "0", "--geometry", "{dir}/g.yaml"),
            {"g.yaml": "pan_deg: [-170, 170]\ntilt_deg: [80, -10]\nzoom_curve: [[0, 1], [1, 8]]\nf_min_px: 300\n"},
            says=("--geometry", "f_min_px 300.0 is not the recording camera's 235.9"),
        ),
        Case(
            "serve-camera: --geometry-seed -1",
            ("serve-camera", "--port", "0", "--geometry-seed", "-1"),
            says=("argument --geometry-seed: expected a whole number >= 0, got '-1'",),
        ),
        Case(
            "serve-camera: --geometry with --geometry-seed",
            ("serve-camera", "--port", "0", "--geometry", "{dir}/g.yaml", "--geometry-seed", "1"),
            says=("--geometry-seed: not allowed with argument --geometry",),
        ),
        Case(
            "serve-camera: a presets file that is not JSON",
            ("serve-camera", "--port", "0", "--presets", "{dir}/presets.json"),
            {"presets.json": "{not json"},
            says=("{dir}/presets.json: not valid JSON",),
        ),
        Case(
            "serve-camera: a presets file of the wrong shape",
            ("serve-camera", "--port", "0", "--presets", "{dir}/presets.json"),
            {"presets.json": '{"presets": [{"token": "1", "name": "door", "pose": [0, 1]}]}'},
            says=("{dir}/presets.json: expected", "pose"),
        ),
        Case(
            "serve-camera: --presets in a missing folder",
            ("serve-camera", "--port", "0", "--presets", "{dir}/missing/presets.json"),
            says=("--presets {dir}/missing/presets.json: the folder",),
        ),
        Case("view: a folder without view states", ("view", "{dir}")),
        Case("view: a file, not a folder", ("view", "{dir}/f"), {"f": "keep me\n"}),
        Case("view: a line that is not a state", ("view", "{dir}/run"), {"run/view_states.jsonl": '{"step": 0}\n'}),
        Case("view: --steps-per-s 0", ("view", "{dir}", "--steps-per-s", "0")),
        Case(
            "occupancy --frames 1e6",
            ("experiment", "occupancy", "synthetic-room", "--frames", "1000000"),
            says=("--frames", "at most 100000"),
        ),
    ]
