"""Names and defaults that the command line shows before any subsystem loads, and the subsystems use.

Plain Python values only: importing this module imports nothing else.
"""

RUN_FILES = (
    "metrics.json",
    "steps.csv",
    "detections.csv",
    "tracks.csv",
    "tracks_mot.txt",
    "truth_mot.txt",
    "episode.png",
    "episode.mp4",
)
"""The files a run writes into its ``--out`` folder (:mod:`ptztrack.evaluate.report`)."""
VIEW_STATES_FILE = "view_states.jsonl"
"""The web view's states of a run, beside its files (:mod:`ptztrack.evaluate.view_state`)."""
STRATEGIES = ("fix", "patrol", "rnd", "intg", "smpl")
"""The PTZ paper's strategies, as its tables name them ('rnd' is the 'random' policy)."""
POSE_SOURCES = ("oracle", "commanded", "registered")
"""Where the tracker takes the camera's pose from (:mod:`ptztrack.camera.pose_feedback`)."""
PROTOCOLS = ("a-priori", "two-fold")
"""How the PETS tables fix their detector's parameters (:func:`ptztrack.experiments.ptz_tables.protocol_folds`)."""
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
# The occupancy experiment's methods beside LPOM and the clustering baseline, which always run.
OCCUPANCY_MAP_METHODS = ("lpom-foreground", "pom")
"""Frames of each synthetic-plaza sequence of the occupancy experiment (20 s at PETS's 10 Hz)."""
EXECUTORS = ("local", "ray", "serial")
"""Where an experiment's cells run (:mod:`ptztrack.evaluate.executors`)."""
PASSWORD_VARIABLE = "PTZTRACK_CAMERA_PASSWORD"
"""The environment variable a camera's password is read from."""
LOOPBACK = "127.0.0.1"
"""The one interface ptztrack's servers listen on (the web view, the virtual ONVIF camera): never
another, as they show a camera's pictures to whoever connects."""
PEOPLE_LOOKS = ("cones", "pets-cutouts")
"""How ``ptztrack render`` draws the people: cone bodies, or pedestrians cut out of PETS 2009's View_001
(:mod:`ptztrack.builders.render`); the first is the default."""
