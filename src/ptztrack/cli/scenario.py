"""The scenario a command runs: a built-in one or a YAML file, with the command line's overrides."""

import argparse

from ptztrack.config import Scenario, load_scenario, pets_scenario, scenario_from_dict


def build_scenario(
    name_or_path: str,
    detector: str | None = None,
    frames: int | None = None,
    recording_paths: dict | None = None,
    association: str | None = None,
    measurement_source: str | None = None,
    detector_model: str | None = None,
    prior_shift_px: float | None = None,
) -> Scenario:
    """The built-in synthetic or PETS scene or a YAML file, with command-line overrides applied.

    recording_paths : {'video' | 'calibration' | 'ground_truth': path} replacing the recording's files.
    association : 'hungarian' or 'cjpdaf', replacing ``tracker.association``.
    measurement_source : 'detector' or 'spatiogram', replacing ``tracker.measurement_source``.
    detector_model, prior_shift_px : replacing ``detector.model`` and ``detector.prior_shift_px``.
    """
    overrides = recording_overrides(recording_paths or {})
    options = {
        "detector.model": detector_model,
        "detector.prior_shift_px": prior_shift_px,
        "tracker.association": association,
        "tracker.measurement_source": measurement_source,
        "detector.kind": detector,
        "frames": frames,
    }
    overrides.update({field: value for field, value in options.items() if value is not None})
    if name_or_path == "synthetic":
        return scenario_from_dict({}, "synthetic", **overrides)
    if name_or_path == "pets":
        return pets_scenario(str(overrides.pop("detector.kind", "ideal")), **overrides)
    return load_scenario(name_or_path, **overrides)


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
    )


def recording_paths(args: argparse.Namespace) -> dict:
    """The recording files of ``--video``, ``--calibration`` and ``--gt`` (None: the scenario's own)."""
    return {"video": args.video, "calibration": args.calibration, "ground_truth": args.gt}


def recording_overrides(paths: dict) -> dict[str, object]:
    """The scenario overrides ``recording.<key>`` of ``paths`` ({key: path}; a None path: the scenario's own)."""
    return {f"recording.{key}": str(path) for key, path in paths.items() if path is not None}
