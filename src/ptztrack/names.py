"""Names and defaults that the command line shows before any subsystem loads, and the subsystems use.

Plain Python values, and frozen dataclasses of them whose fields carry their one-line help
(``metadata["help"]``): importing this module imports nothing else of ptztrack.
"""

from dataclasses import dataclass, field
from importlib.metadata import PackageNotFoundError, version

# The installed distribution's version: ``ptztrack --version``, ``ptztrack.__version__``, the virtual
# camera's firmware.
try:
    VERSION = version("ptztrack")
except PackageNotFoundError:  # a source tree that was not installed
    VERSION = "0+unknown"

TRUTH_MOT_FILE = "truth_mot.txt"
"""The truth of a run's ``--out`` folder in the MOTChallenge layout (none for a run without ground truth)."""
RUN_FILES = (
    "metrics.json",
    "steps.csv",
    "detections.csv",
    "tracks.csv",
    "tracks_mot.txt",
    TRUTH_MOT_FILE,
    "episode.png",
    "episode.mp4",
)
"""The files a run writes into its ``--out`` folder (:mod:`ptztrack.evaluate.report`)."""
VIEW_STATES_FILE = "view_states.jsonl"
"""The web view's states of a run, beside its files (:mod:`ptztrack.view.view_state`)."""
STRATEGIES = ("fix", "patrol", "rnd", "intg", "smpl")
"""The PTZ paper's strategies, as its tables name them: the built-in policies' names."""
POSE_SOURCES = ("oracle", "commanded", "registered")
"""Where the tracker takes the camera's pose from (:mod:`ptztrack.camera.pose_feedback`)."""
DETECTOR_MODELS = ("a-priori", "online", "true")
"""What the policies and the tracker may know of the detector (``detector.model``, besides a
``detector_model.json``): its prior curve kept, learned online from the prior, or a simulation's own curve."""
KEPT_DETECTOR_MODELS = ("a-priori", "true")
"""The ``DETECTOR_MODELS`` whose curve is kept, not learned."""
PROTOCOLS = ("a-priori", "two-fold")
"""How the PETS tables fix their detector's parameters (:func:`ptztrack.experiments.ptz_tables.protocol_folds`)."""
GATE_M = 1.0
"""The farthest a track may lie from a person on the ground, in metres, to be matched to them (MOTA, MOTP, IDF1)."""
MATCH_MIN_IOU = 0.5
"""In image coordinates, the least intersection over union of a track's box with a person's to match them
(MOTChallenge's)."""
SCORE_COORDINATES = ("world", "image")
"""What ``ptztrack score`` matches tracks to people by: ground positions in metres, or boxes in pixels."""


@dataclass(frozen=True)
class SyntheticProtocol:
    """The PTZ paper's synthetic tables (Tables 1-2, section 5.1), ``ptztrack experiment synthetic``."""

    sequences: int = field(default=12, metadata={"help": "sequences every strategy runs on (seeds 0 .. n-1)"})
    detector: str = field(default="realistic", metadata={"help": "the simulated or registered detector"})
    strategies: tuple[str, ...] = field(default=STRATEGIES, metadata={"help": "the table's columns"})


@dataclass(frozen=True)
class PetsProtocol:
    """The PTZ paper's realistic tables (Tables 3-4, section 5.2) on a recording, ``ptztrack experiment pets``."""

    detector: str = field(
        default="ideal",
        metadata={
            "help": "ideal (the annotations), hog, detections (the dataset view's own boxes) or a registered one"
        },
    )
    betas: tuple[float, ...] = field(default=(9.0, 1.0), metadata={"help": "a weight of the patrolling term"})
    strategies: tuple[str, ...] = field(default=STRATEGIES, metadata={"help": "the table's columns"})
    protocol: str = field(
        default="a-priori",
        metadata={
            "help": "a-priori: every parameter fixed before looking at the recording; two-fold: the detector's model "
            "fitted on one half of the frames, the table scored on the other, both ways"
        },
    )
    seeds: int = field(default=5, metadata={"help": "runs of a strategy whose run depends on its seed"})


@dataclass(frozen=True)
class NetworkProtocol:
    """The camera network's tables, ``ptztrack experiment network synthetic`` and ``pets``: each setting's
    options and their defaults (an option of the other setting is refused)."""

    sequences: int = field(default=12, metadata={"help": "synthetic: sequences"})
    first_sequence: int = field(
        default=0,
        metadata={"help": "synthetic: the first sequence's seed (the table's; from 1000: development sequences)"},
    )
    max_ptz: int = field(default=4, metadata={"help": "synthetic: the most PTZ cameras"})
    seeds: int = field(default=5, metadata={"help": "pets: seeds of the runs with the PTZ camera"})
    beta: float = field(default=9.0, metadata={"help": "pets: the PTZ camera's weight of the patrolling term"})


FOLLOW_TRACKERS = ("particle", "csrt", "mil")
"""The follow camera's trackers: the paper's particle filter and OpenCV's two."""
OTB_TRACKS = 5
"""People the follow experiment's one-pass (OTB) protocol runs by default."""
MAX_FRAMES = 100_000
"""The most frames a run or a recording may use: a run keeps every step's history, the occupancy
experiment every frame's map and modes."""
ROOM_FRAMES = 300
"""Frames of each synthetic-room sequence of the occupancy experiment."""
PLAZA_FRAMES = 200
"""Frames of each synthetic-plaza sequence of the occupancy experiment (20 s at PETS's 10 Hz)."""
# The occupancy experiment's methods beside LPOM and the clustering baseline, which always run.
OCCUPANCY_MAP_METHODS = ("lpom-foreground", "pom")
EXECUTORS = ("local", "ray", "serial")
"""Where an experiment's cells run (:mod:`ptztrack.loop.executors`)."""
PASSWORD_VARIABLE = "PTZTRACK_CAMERA_PASSWORD"
"""The environment variable a camera's password is read from."""
LOOPBACK = "127.0.0.1"
"""The one interface ptztrack's servers listen on (the web view, the virtual ONVIF camera): never
another, as they show a camera's pictures to whoever connects."""
PEOPLE_LOOKS = ("cones", "pets-cutouts")
"""How ``ptztrack render`` draws the people: cone bodies, or pedestrians cut out of PETS 2009's View_001
(:mod:`ptztrack.builders.render`); the first is the default."""
