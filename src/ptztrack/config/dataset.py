"""Multi-view datasets and the occupancy-map detector (the LPOM paper): their models, the dataset file's
reader and the built-in PETS 2009 S2.L1 dataset."""

import math
from importlib import resources
from pathlib import Path
from typing import Annotated, Any

import pydantic
from pydantic import Field, model_validator

from ptztrack.config.fields import _MAX_FRAMES, NonNegativeFloat, Pixels, PositiveFloat, _Strict, at_most, at_most_items
from ptztrack.config.reading import FILE_KINDS, ScenarioError, _first_error_line, read_yaml, refuse_another_kind
from ptztrack.config.scenario import Tracker
from ptztrack.occupancy.parameters import OccupancyParameters


class DatasetView(_Strict):
    """One fixed camera of a multi-view dataset.

    name : the view's name, different for every view: how a scenario's ``recording.dataset_view`` and
    the command line's ``--dataset-view`` pick it, and its key in a pinhole JSON unless
    ``calibration_view`` says otherwise.
    calibration : a Tsai XML (PETS 2009) or a pinhole JSON (``{view: {K, dist, R, t}}``, world in mm);
    calibration_view : the view's key in a pinhole JSON (default: ``name``).
    image_size_px : (width, height); read from a Tsai XML, checked against it when given; needed with
    a pinhole JSON. video, images : the view's frames, a video file or a folder of images in the sorted
    order of their names (one or the other, not both): the occupancy map's motion edges read either, the
    virtual PTZ camera's pictures need a video; detections : a MOTChallenge detection file
    (``frame,-1,left,top,width,height,score,...``, frames from 1), for views without frames, the
    clustering baseline and the PTZ camera's ``detections`` detector. ground_truth : the view's own
    annotations (MOTChallenge rows, boxes in its pixels, world x, y in metres), where the dataset's boxes
    are another view's. weight : ``w_c``, the view's relative weight in the occupancy map (each view's
    loci are scaled to total its weight, the weights normalised to sum to 1).
    """

    name: str
    calibration: str
    calibration_view: str | None = None
    image_size_px: tuple[Pixels, Pixels] | None = None
    video: str | None = None
    images: str | None = None
    detections: str | None = None
    ground_truth: str | None = None
    weight: Annotated[PositiveFloat, at_most(1e6, "a relative weight")] = 1.0

    @model_validator(mode="after")
    def _has_evidence(self):
        if self.video is not None and self.images is not None:
            raise ValueError("give video or images, not both")
        if self.video is None and self.images is None and self.detections is None:
            raise ValueError("a view needs video, images or detections")
        return self


_PersonHeight = Annotated[PositiveFloat, at_most(10, "metres: a person")]
_GroundDistance = Annotated[PositiveFloat, at_most(1000, "metres")]
_LOCUS_MEMORY = "memory: the locus tables hold every block's points for every height"
MAX_PERSON_HEIGHTS = 100
MAX_GROUND_CELLS = 10_000_000
"""Cells of an occupancy map: 80 MB a map in float64, several kept per frame."""
MAX_DATASET_FRAMES = _MAX_FRAMES


class Occupancy(_Strict):
    """The occupancy-map detector and its baseline (docs: the occupancy map): the fields of
    :class:`~ptztrack.occupancy.parameters.OccupancyParameters`, whose defaults it takes and where
    their meaning is given.
    """

    min_height_m: _PersonHeight = OccupancyParameters.min_height_m
    max_height_m: _PersonHeight = OccupancyParameters.max_height_m
    height_step_m: _PersonHeight = OccupancyParameters.height_step_m
    width_m: Annotated[PositiveFloat, at_most(10, "metres: a person")] = OccupancyParameters.width_m
    samples_per_height: Annotated[int, Field(ge=1), at_most(1000, _LOCUS_MEMORY)] = (
        OccupancyParameters.samples_per_height
    )
    cell_m: PositiveFloat = OccupancyParameters.cell_m
    kernel_sigma_m: _GroundDistance = OccupancyParameters.kernel_sigma_m
    block_px: Annotated[int, Field(ge=1), at_most(256, "pixels")] = OccupancyParameters.block_px
    separation_m: _GroundDistance = OccupancyParameters.separation_m
    window_m: _GroundDistance = OccupancyParameters.window_m
    canny_low: Annotated[NonNegativeFloat, at_most(10_000, "a gradient magnitude")] = OccupancyParameters.canny_low
    canny_high: Annotated[NonNegativeFloat, at_most(10_000, "a gradient magnitude")] = OccupancyParameters.canny_high
    difference_threshold: Annotated[NonNegativeFloat, at_most(255, "grey levels")] = (
        OccupancyParameters.difference_threshold
    )
    dilation_px: Annotated[int, Field(ge=0), at_most(256, "pixels")] = OccupancyParameters.dilation_px
    outline_points_per_box: Annotated[int, Field(ge=4), at_most(10_000, _LOCUS_MEMORY)] = (
        OccupancyParameters.outline_points_per_box
    )
    min_box_score: float = Field(OccupancyParameters.min_box_score, ge=0, le=1)
    linkage_m: _GroundDistance = OccupancyParameters.linkage_m
    blob_min_area_px: Annotated[int, Field(ge=1), at_most(8192 * 8192, "an image's pixels")] = (
        OccupancyParameters.blob_min_area_px
    )

    @model_validator(mode="after")
    def _heights_ordered(self):
        if self.max_height_m < self.min_height_m:
            raise ValueError(f"max_height_m must be at least min_height_m ({self.min_height_m})")
        heights = (self.max_height_m - self.min_height_m) / self.height_step_m
        if heights > MAX_PERSON_HEIGHTS:
            raise ValueError(
                f"height_step_m {self.height_step_m:g} gives {heights:.3g} heights; at most "
                f"{MAX_PERSON_HEIGHTS} ({_LOCUS_MEMORY})"
            )
        if self.canny_low > self.canny_high:
            raise ValueError(
                f"canny_low ({self.canny_low:g}) must be at most canny_high ({self.canny_high:g}): an edge starts "
                "above canny_high and goes on above canny_low"
            )
        return self


class OccupancyTracker(Tracker):
    """The ground tracker fed by the occupancy map: the scenario's tracker section, but a track is
    reported from its second detection on (the map's one-off ghosts, loci of two views crossing by
    chance, rarely repeat at the same place)."""

    confirmation_hits: int = Field(2, ge=1)


class MultiViewDataset(_Strict):
    """A calibrated multi-view recording (docs: multi-view dataset files). Relative paths in a
    dataset file are relative to it.

    area_m : [[x0, y0], [x1, y1]] the ground the map covers, metres (people outside it are not scored);
    tracking_area_m : [[x0, y0], [x1, y1]] m where the annotations are complete, if the recording has such
    a rectangle (the camera network's table scores there too, its TA columns);
    frames : how many frames to use (default: all that every view and the ground truth have);
    ground_truth : MOTChallenge rows with world x, y in metres in columns 8-9 (frames from 1).
    name : the dataset's name in titles and messages. frame_rate_hz : frames per second of the recording
    (its views' frames and the ground truth's frame numbers). views : the fixed cameras (section
    ``views``; their names differ). occupancy : the occupancy-map detector and its clustering baseline
    (section ``occupancy``). tracker : the ground tracker fed by the occupancy map's modes (section
    ``tracker``; Hungarian association only).
    """

    name: str = "dataset"
    frame_rate_hz: Annotated[PositiveFloat, at_most(1000, "frames per second")]
    frames: (
        Annotated[int, Field(ge=1), at_most(MAX_DATASET_FRAMES, "memory: every frame's map and modes are kept")] | None
    ) = None
    area_m: tuple[tuple[float, float], tuple[float, float]]
    tracking_area_m: tuple[tuple[float, float], tuple[float, float]] | None = None
    ground_truth: str | None = None
    views: Annotated[list[DatasetView], Field(min_length=1), at_most_items(64, "time: every view's loci, every frame")]
    occupancy: Occupancy = Occupancy()
    tracker: OccupancyTracker = OccupancyTracker()

    @model_validator(mode="after")
    def _area_and_names(self):
        (x0, y0), (x1, y1) = self.area_m
        if not (x1 > x0 and y1 > y0):
            raise ValueError("area_m must be [[x0, y0], [x1, y1]] with x1 > x0 and y1 > y0")
        cells = (x1 - x0) * (y1 - y0) / self.occupancy.cell_m**2
        if cells > MAX_GROUND_CELLS:
            raise ValueError(
                f"area_m at occupancy.cell_m {self.occupancy.cell_m:g} m makes {cells:.3g} cells; at most "
                f"{MAX_GROUND_CELLS:g} (memory: a map of float64 cells per frame): make the cells larger"
            )
        if self.occupancy.cell_m > self.occupancy.separation_m:
            columns, rows = math.ceil((x1 - x0) / self.occupancy.cell_m), math.ceil((y1 - y0) / self.occupancy.cell_m)
            raise ValueError(
                f"area_m at occupancy.cell_m {self.occupancy.cell_m:g} m makes {columns} x {rows} cells; expected "
                f"cells of at most occupancy.separation_m ({self.occupancy.separation_m:g} m), so that two people "
                "that close are two modes"
            )
        names = [view.name for view in self.views]
        if len(set(names)) != len(names):
            raise ValueError(f"view names must differ (got {names})")
        if self.tracker.association != "hungarian":
            raise ValueError("the occupancy map's modes are associated by the Hungarian assignment only")
        return self


DATASET_PATH_FIELDS = ("calibration", "video", "images", "detections", "ground_truth")


FILE_KINDS["dataset"] = MultiViewDataset


def dataset_from_dict(data: Any, source: str = "dataset") -> MultiViewDataset:
    """Validate a multi-view dataset mapping; a :class:`ScenarioError` of one line naming the field."""
    if not isinstance(data, dict):
        raise ScenarioError(f"{source}: expected a mapping of dataset fields (got {type(data).__name__})")
    try:
        return MultiViewDataset.model_validate(data)
    except pydantic.ValidationError as error:
        raise ScenarioError(_first_error_line(error, source)) from None


def load_dataset(path: str | Path) -> MultiViewDataset:
    """Read and validate a multi-view dataset YAML file, its relative paths made relative to it."""
    path = Path(path)
    data = read_yaml(path, "dataset", ScenarioError)
    if isinstance(data, dict):
        refuse_another_kind(path, data, "dataset")
        base = path.parent
        if isinstance(data.get("ground_truth"), str):
            data = {**data, "ground_truth": str(base / data["ground_truth"])}
        if isinstance(data.get("views"), list):
            views = [
                {
                    **view,
                    **{key: str(base / view[key]) for key in DATASET_PATH_FIELDS if isinstance(view.get(key), str)},
                }
                if isinstance(view, dict)
                else view
                for view in data["views"]
            ]
            data = {**data, "views": views}
    return dataset_from_dict(data, str(path))


PETS_DATASET_FILE = Path(str(resources.files("ptztrack.data") / "pets2009_s2l1" / "dataset.yaml"))
"""The built-in recording, PETS 2009 S2.L1 (seven views with published detections; View_002 has none)."""


def pets_dataset(**overrides) -> MultiViewDataset:
    """The built-in PETS 2009 S2.L1 dataset (:data:`PETS_DATASET_FILE`), with top-level fields replaced by
    ``overrides``."""
    dataset = load_dataset(PETS_DATASET_FILE)
    if not overrides:
        return dataset
    return dataset_from_dict({**dataset.model_dump(), **overrides}, dataset.name)
