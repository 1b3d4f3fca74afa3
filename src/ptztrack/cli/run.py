"""``ptztrack run``: one closed-loop episode and its metrics; ``ptztrack view``: a finished run replayed."""

import argparse
from functools import partial

from ptztrack.builders.budget import refuse_if_too_large
from ptztrack.builders.episode import episode_world, make_policy, run_episode
from ptztrack.cli.options import RUN_FOLDER_FILES
from ptztrack.cli.scenario import command_scenario
from ptztrack.cli.watch import Watch
from ptztrack.evaluate.metrics import episode_metrics, format_figures
from ptztrack.evaluate.report import write_outputs
from ptztrack.files import run_folder
from ptztrack.loop.executors import Progress
from ptztrack.view.video import view_renderer
from ptztrack.view.view_state import ViewState, read_view_states
from ptztrack.view.web_view import ViewHub, ViewServer, replay

DETECTOR_MODEL_FILE = "detector_model.json"  # what run adds to RUN_FOLDER_FILES: the detector model as the run ended
RUN_FIGURES = ("mota", "motp_m", "idf1", "height_px", "detections", "zoom", "switches")


def format_metrics(metrics: dict) -> str:
    """The run's figures of RUN_FIGURES that ``metrics`` has (a run without ground truth has no scores), one
    a line (:func:`~ptztrack.evaluate.metrics.format_figures`)."""
    return format_figures(metrics, [key for key in RUN_FIGURES if key in metrics])


def run_command(args: argparse.Namespace) -> int:
    scenario = command_scenario(args, args.scenario)
    refuse_if_too_large(scenario, (args.policy,))
    world = episode_world(scenario, args.seed)
    policy = make_policy(args.policy, scenario, world)
    view = partial(run_view, label=args.policy)
    watch = Watch(args.view, args.out is not None, view, Progress("step", args.quiet), args.view_wait)
    with watch:
        episode = run_episode(scenario, policy, args.seed, world, observer=watch.observe(world, policy))
    metrics = episode_metrics(episode)
    print(
        f"scenario {args.scenario if scenario.recording is None else scenario.recording.name}, "
        f"policy {args.policy}, detector {scenario.detector.kind}, "
        f"seed {args.seed}, {len(episode.actions)} steps, {episode.truth.positions_m.shape[1]} people"
    )
    print(format_metrics(metrics))
    if args.out is not None:
        title = f"{args.policy}, {scenario.detector.kind} detector, seed {args.seed}: MOTA {metrics['mota']:.1%}"
        with run_folder(args.out, args.overwrite) as folder:
            write_outputs(folder, episode, metrics, title, view_renderer(world))
            watch.write(folder)
            if world.detector_model is not None:
                world.detector_model.save(folder / DETECTOR_MODEL_FILE)
        print(f"wrote {', '.join((*RUN_FOLDER_FILES, DETECTOR_MODEL_FILE))} into {args.out}")
    return 0


def run_view(world, policy, label: str) -> ViewState:
    """The view of a run in ``world``: the backend's images (the synthetic scene's drawn), its grid."""
    return ViewState(world, policy, world.truth.positions_m.shape[0], label, view_renderer(world))


def view_command(args: argparse.Namespace) -> int:
    lines = read_view_states(args.folder)
    hub = ViewHub(paused=True, resume_on_connect=True)
    with ViewServer(hub, args.port) as server:
        print(f"view at {server.address} (the replay of {len(lines)} steps starts when a page opens it)", flush=True)
        replay(hub, lines, args.steps_per_s)
    return 0
