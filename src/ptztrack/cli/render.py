"""``ptztrack render``: a scenario rendered into a multi-view dataset folder."""

import argparse

from ptztrack.builders.render import render_dataset
from ptztrack.cli.scenario import build_scenario
from ptztrack.loop.executors import Progress


def render_command(args: argparse.Namespace) -> int:
    scenario = build_scenario(args.scenario)
    with Progress("image", args.quiet) as progress:
        path = render_dataset(scenario, args.out, args.seed, progress, args.overwrite, args.people_look)
    views = len(scenario.cameras) or 1
    print(f"wrote {path}: {views} view{'s' * (views > 1)}, {scenario.frames} frames at {scenario.frame_rate_hz:g} Hz")
    return 0
