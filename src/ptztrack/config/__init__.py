"""The validated configuration of a run, loadable from YAML, one module per subject.

:mod:`~ptztrack.config.scenario` (the scenario and its sections, with those of
:mod:`~ptztrack.config.camera` and :mod:`~ptztrack.config.follow`), :mod:`~ptztrack.config.dataset`
(multi-view datasets and the occupancy map), :mod:`~ptztrack.config.camera_calibration` (a real
camera's calibration file), :mod:`~ptztrack.config.reading` (YAML files, credentials files and
one-line errors) and :mod:`~ptztrack.config.fields` (the models' building blocks). Every public name of
these modules is importable from here.
"""

from ptztrack.config.camera import Actions, AxisRange, Camera, LiveView, PoseError, PoseFeedback
from ptztrack.config.camera_calibration import (
    VIRTUAL_CAMERA_CALIBRATION,
    CameraCalibrationFile,
    GroundViewSection,
    MoveTimesSection,
    load_camera_calibration,
    write_camera_calibration,
)
from ptztrack.config.dataset import (
    DATASET_PATH_FIELDS,
    MAX_DATASET_FRAMES,
    MAX_GROUND_CELLS,
    MAX_PERSON_HEIGHTS,
    PETS_DATASET_FILE,
    DatasetView,
    MultiViewDataset,
    Occupancy,
    OccupancyTracker,
    dataset_from_dict,
    load_dataset,
    pets_dataset,
)
from ptztrack.config.fields import (
    Degrees,
    NonNegativeFloat,
    Options,
    Pixels,
    PositiveFloat,
    at_most,
    at_most_items,
)
from ptztrack.config.follow import Follow, Fraction, Patch
from ptztrack.config.reading import SCENARIO_MAX_BYTES, YAML_MAX_VALUES, ScenarioError, load_credentials, read_yaml
from ptztrack.config.scenario import (
    DETECTOR_MODELS,
    Control,
    Detector,
    MountedCamera,
    People,
    Recording,
    Scenario,
    Tracker,
    load_scenario,
    scenario_from_dict,
)

__all__ = [
    "DATASET_PATH_FIELDS",
    "DETECTOR_MODELS",
    "MAX_DATASET_FRAMES",
    "MAX_GROUND_CELLS",
    "MAX_PERSON_HEIGHTS",
    "PETS_DATASET_FILE",
    "SCENARIO_MAX_BYTES",
    "VIRTUAL_CAMERA_CALIBRATION",
    "YAML_MAX_VALUES",
    "Actions",
    "AxisRange",
    "Camera",
    "CameraCalibrationFile",
    "GroundViewSection",
    "Control",
    "DatasetView",
    "Degrees",
    "Detector",
    "Follow",
    "Fraction",
    "LiveView",
    "MountedCamera",
    "MoveTimesSection",
    "MultiViewDataset",
    "NonNegativeFloat",
    "Occupancy",
    "OccupancyTracker",
    "Options",
    "Patch",
    "People",
    "Pixels",
    "PoseError",
    "PoseFeedback",
    "PositiveFloat",
    "Recording",
    "Scenario",
    "ScenarioError",
    "Tracker",
    "at_most",
    "at_most_items",
    "dataset_from_dict",
    "load_camera_calibration",
    "load_credentials",
    "load_dataset",
    "load_scenario",
    "pets_dataset",
    "read_yaml",
    "scenario_from_dict",
    "write_camera_calibration",
]
