"""The scenario a command runs: a built-in one or a YAML file, with the command line's overrides."""

import argparse
import difflib
from pathlib import Path

from ptztrack.builders.recording import dataset_scenario, pets_scenario
from ptztrack.config import (
    PETS_DATASET_FILE,
    Scenario,
    ScenarioError,
    load_dataset,
    load_scenario,
    pets_dataset,
    scenario_from_dict,
)

BUILT_IN_SCENARIOS = ("synthetic", "pets")


def build_scenario(
    name_or_path: str,
    detector: str | None = None,
    frames: int | None = None,
    recording_paths: dict | None = None,
    association: str | None = None,
    measurement_source: str | None = None,
    detector_model: str | None = None,
    prior_shift_px: float | None = None,
    dataset: str | None = None,
    view: str | None = None,
    protocol: dict | None = None,
    overrides: dict | None = None,
) -> Scenario:
    """The built-in synthetic or PETS scene or a YAML file, with command-line overrides applied.

    dataset, view : a dataset file's view as the recording ('pets': the built-in one), under the
    built-in ``protocol`` (default the PTZ tables'), or under the scenario file's own settings.
    overrides : further scenario overrides (``"section.field": value``).

    recording_paths : {'video' | 'calibration' | 'ground_truth': path} replacing the recording's files.
    association : 'hungarian' or 'cjpdaf', replacing ``tracker.association``.
    measurement_source : 'detector' or 'spatiogram', replacing ``tracker.measurement_source``.
    detector_model, prior_shift_px : replacing ``detector.model`` and ``detector.prior_shift_px``.
    """
    overrides = {**recording_overrides(recording_paths or {}), **(overrides or {})}
    options = {
        "detector.model": detector_model,
        "detector.prior_shift_px": prior_shift_px,
        "tracker.association": association,
        "tracker.measurement_source": measurement_source,
        "detector.kind": detector,
        "frames": frames,
    }
    overrides.update({field: value for field, value in options.items() if value is not None})
    if dataset is not None or view is not None:
        return _dataset_scenario(name_or_path, dataset, view, protocol, overrides)
    if name_or_path == "synthetic":
        return scenario_from_dict({}, "synthetic", **overrides)
    if name_or_path == "pets":
        return pets_scenario(str(overrides.pop("detector.kind", "ideal")), **overrides)
    return load_scenario(scenario_file(name_or_path), **overrides)


def _dataset_scenario(
    name_or_path: str, dataset: str | None, view: str | None, protocol: dict | None, overrides: dict
) -> Scenario:
    """The view ``view`` of ``dataset`` (None or 'pets': the built-in one), under the built-in protocol for
    'synthetic' and 'pets', else under the scenario file's settings (its recording replaced)."""
    if dataset in (None, "pets"):
        loaded, path = pets_dataset(), str(PETS_DATASET_FILE)
    else:
        loaded, path = load_dataset(dataset), dataset
    if name_or_path not in BUILT_IN_SCENARIOS:
        protocol = load_scenario(scenario_file(name_or_path)).model_dump(exclude_unset=True, exclude={"recording"})
    return dataset_scenario(loaded, view, protocol, path, **overrides)


def scenario_file(name: str, built_in: tuple[str, ...] = BUILT_IN_SCENARIOS) -> str:
    """``name``, a ``--scenario`` other than the ``built_in`` names, if there is such a file (or folder, which
    the reader refuses as such); else refused suggesting the closest built-in name or YAML file beside it."""
    path = Path(name)
    if path.exists():
        return name
    folder = path.parent
    files = [str(folder / each.name) for each in sorted(folder.glob("*.y*ml"))] if folder.is_dir() else []
    close = difflib.get_close_matches(name, [*built_in, *files], n=1)
    hint = f"did you mean {close[0]!r}?" if close else f"expected {', '.join(built_in)} (built in) or a YAML file"
    raise ScenarioError(f"--scenario {name}: no such scenario file; {hint}")


def command_scenario(args: argparse.Namespace, name_or_path: str) -> Scenario:
    """The scenario of a command that takes the recording's files, ``--detector``, ``--frames``, the
    tracker's options and the detector model's (run, experiment pets, experiment registration)."""
    return build_scenario(
        name_or_path,
        args.detector,
        args.frames,
        recording_paths(args),
        args.association,
        args.measurement_source,
        args.detector_model,
        getattr(args, "prior_shift_px", None),
        args.dataset,
        args.dataset_view,
    )


def recording_paths(args: argparse.Namespace) -> dict:
    """The recording files of ``--video``, ``--calibration`` and ``--gt`` (None: the scenario's own)."""
    return {"video": args.video, "calibration": args.calibration, "ground_truth": args.gt}


def recording_overrides(paths: dict) -> dict[str, object]:
    """The scenario overrides ``recording.<key>`` of ``paths`` ({key: path}; a None path: the scenario's own)."""
    return {f"recording.{key}": str(path) for key, path in paths.items() if path is not None}
