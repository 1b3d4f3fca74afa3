"""The command line's arguments of the commands of several cameras at once: ``ptztrack experiment
occupancy`` (people on the ground from several calibrated views), ``ptztrack experiment network`` (a
camera network) and ``ptztrack render`` (a scenario's people and cameras rendered into a multi-view
dataset).
"""

from pathlib import Path

from ptztrack.cli.options import (
    add_detector_model_arguments,
    add_executor_arguments,
    add_quiet_argument,
    add_recording_arguments,
    non_negative_float,
    non_negative_int,
    occupancy_frames,
    occupancy_lead_in,
    positive_int,
    protocol_field,
)
from ptztrack.names import OCCUPANCY_MAP_METHODS, PLAZA_FRAMES, ROOM_FRAMES, NetworkProtocol


def network_help(name: str) -> str:
    """The help of the network experiment's option ``name``: its :class:`~ptztrack.names.NetworkProtocol`
    field's, with the default (None in the parser: an option of the other setting is refused)."""
    return protocol_field(NetworkProtocol, name)["help"]


def add_occupancy_parser(experiments) -> None:
    occupancy = experiments.add_parser(
        "occupancy", help="the LPOM paper: people on the ground from several calibrated views, against clustering"
    )
    occupancy.add_argument(
        "dataset",
        help="'synthetic-room' (near, steep cameras), 'synthetic-plaza' (PETS S2.L1's far, shallow cameras, "
        "rendered) or 'pets' (built in), or a multi-view dataset YAML file",
    )
    occupancy.add_argument(
        "--frames",
        type=occupancy_frames,
        help=f"frames to use (synthetic-room: {ROOM_FRAMES}, synthetic-plaza: {PLAZA_FRAMES} per sequence; else all)",
    )
    occupancy.add_argument(
        "--seed", type=non_negative_int, default=0, help="synthetic-room, synthetic-plaza: draws people and textures"
    )
    occupancy.add_argument(
        "--lead-in",
        type=occupancy_lead_in,
        metavar="FRAMES",
        help="synthetic-plaza: frames rendered before the first, which only the background models learn "
        "(default: half the background model's history, after which it learns at its steady rate)",
    )
    occupancy.add_argument(
        "--methods",
        nargs="*",
        choices=OCCUPANCY_MAP_METHODS,
        default=list(OCCUPANCY_MAP_METHODS),
        help="the methods to run beside LPOM and the clustering baseline (default: both; none: neither; "
        "lpom-foreground needs a view with video, pom every view's image size)",
    )
    occupancy.add_argument(
        "--out", type=Path, help="directory for maps, video, detections and tracks per recording; written whole"
    )
    occupancy.add_argument("--overwrite", action="store_true", help="replace a non-empty --out folder")
    occupancy.add_argument("--images-every", type=positive_int, default=10, help="a map picture every N frames")
    occupancy.add_argument("--json", type=Path, help="write one row per method (and people count) here")
    add_quiet_argument(occupancy)
    occupancy.set_defaults(handler="ptztrack.cli.occupancy:occupancy_experiment_command")


def add_network_parser(experiments, detectors: list[str]) -> None:
    network = experiments.add_parser(
        "network",
        help="a camera network: PTZ cameras deciding jointly, each alone or fixed, with a wide fixed one; or the "
        "PETS PTZ camera with six views' published detections",
    )
    network.add_argument(
        "setting",
        choices=("synthetic", "pets"),
        help="synthetic: 1 to --max-ptz cameras around the area; pets: the virtual PTZ camera over a dataset's "
        "view (--dataset, --view; default PETS 2009 S2.L1's View_001) and its other views' detections as fixed cameras",
    )
    network.add_argument(
        "--detector",
        choices=detectors,
        help="the cameras' detector (synthetic: default realistic; pets, the PTZ camera's: hog or ideal, default hog)",
    )
    add_detector_model_arguments(network)
    network.add_argument("--sequences", type=positive_int, help=network_help("sequences"))
    network.add_argument("--first-sequence", type=non_negative_int, help=network_help("first_sequence"))
    network.add_argument("--frames", type=positive_int, help="overrides the scenario's number of frames")
    network.add_argument("--max-ptz", type=positive_int, help=network_help("max_ptz"))
    network.add_argument("--seeds", type=positive_int, help=network_help("seeds"))
    network.add_argument("--beta", type=non_negative_float, help=network_help("beta"))
    network.add_argument(
        "--method", choices=("intg", "smpl"), default="intg", help="the PTZ cameras' expected information"
    )
    add_recording_arguments(network, files=False)
    add_executor_arguments(network, "one row per configuration")
    network.set_defaults(handler="ptztrack.cli.network:network_experiment_command")


def add_render_parser(commands) -> None:
    """``ptztrack render``: a scenario's people and cameras rendered into a multi-view dataset folder."""
    from ptztrack.names import PEOPLE_LOOKS

    render = commands.add_parser(
        "render", help="render a scenario's people and cameras into a dataset: videos, calibration, ground truth"
    )
    render.add_argument(
        "--scenario",
        required=True,
        help="a scenario YAML file without a recording (its cameras, or its one camera, aimed at the area's "
        "centre; its area, frames, frame rate and people), or 'synthetic' (built in)",
    )
    render.add_argument(
        "--out",
        type=Path,
        required=True,
        help="the dataset folder: dataset.yaml, calibration.json, a video and a gt_*.txt per view; written whole or "
        "not at all",
    )
    render.add_argument(
        "--seed", type=non_negative_int, default=0, help="draws the people's walks, textures and clothes (default 0)"
    )
    render.add_argument("--overwrite", action="store_true", help="replace a non-empty --out folder")
    render.add_argument(
        "--people-look",
        choices=PEOPLE_LOOKS,
        default=PEOPLE_LOOKS[0],
        help="the people drawn as textured cone bodies, or as pedestrians cut out of PETS 2009 View_001 "
        f"(default {PEOPLE_LOOKS[0]}: to HOG, the closer to real people)",
    )
    add_quiet_argument(render)
    render.set_defaults(handler="ptztrack.cli.render:render_command")
