"""How well the camera learns its detector: the online model of a PETS HOG run against the annotations.

Runs `smpl` (beta 1, seed 0, the a-priori protocol) with OpenCV's HOG on the
PETS 2009 S2.L1 virtual views and the online detector model, then, only for
this report, matches each step's detections to the annotated people fully in
view and hidden at most ``recording.occluded_above`` (a detection's feet
within 0.3 of the person's annotated height of theirs, as the recall fit
does) and prints, per height bin, the learned recall beside the annotated
one. Both bin a person by the height the model gives a track: that of a
person of the policies' height (1.75 m) standing at the ground point, here
the annotated one (an annotated box is taller or shorter by the person's
own height and the box's margins).

    python benchmarks/detector_model.py [--json PATH]
"""

import argparse
import json
from pathlib import Path

import numpy as np

from ptztrack.builders.episode import episode_world, run_episode
from ptztrack.builders.recording import pets_scenario
from ptztrack.detect.detector_model import HEIGHT_BIN_EDGES_PX
from ptztrack.detect.recall_fit import MATCH_FRACTION_OF_HEIGHT
from ptztrack.evaluate.metrics import episode_metrics
from ptztrack.geometry.ptz import project_people

MIN_PEOPLE = 50


def annotated_recall_trials(world, episode, scenario, occluded_above: float) -> tuple[np.ndarray, np.ndarray]:
    """The annotated people fully in view at each step's pose: their heights (K,) px, as the model
    measures a track's (a person of the policies' height standing at the annotated ground point), and
    whether a detection of that step found them (K,)."""
    views = zip(range(len(episode.poses)), episode.poses, episode.detections, strict=True)
    return view_recall_trials(world, views, scenario, occluded_above)


def view_recall_trials(world, views, scenario, occluded_above: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`annotated_recall_trials` over any views: ``views`` yields (step, pose, detections) of the
    world's camera. A person is found by a detection whose feet lie within ``MATCH_FRACTION_OF_HEIGHT`` of
    their annotated height of their annotated feet."""
    heights, found = [np.zeros(0)], [np.zeros(0, dtype=bool)]
    for step, pose, detections in views:
        people = world.backend.people(step, pose)
        visible = people.in_view & (people.hidden <= occluded_above)
        if not visible.any():
            continue
        distance_px = np.linalg.norm(people.feet_px[visible, None] - detections.feet_px[None], axis=-1)
        near = distance_px <= MATCH_FRACTION_OF_HEIGHT * people.height_px[visible, None]
        ground_m = world.truth.positions_m[step, people.person_index[visible]]
        modelled = project_people(
            world.camera, pose, ground_m, scenario.control.person_height_m, scenario.people.width_m
        )
        heights.append(modelled.height_px)
        found.append(near.any(axis=1) if len(detections) else np.zeros(visible.sum(), dtype=bool))
    return np.concatenate(heights), np.concatenate(found)


def recall_by_bin(heights, found) -> list[tuple[int, float | None]]:
    """Per height bin (``HEIGHT_BIN_EDGES_PX``): how many trials, and the share found (None without any)."""
    which = np.digitize(heights, HEIGHT_BIN_EDGES_PX) - 1
    counts = [int(np.sum(which == index)) for index in range(len(HEIGHT_BIN_EDGES_PX) - 1)]
    return [(count, float(found[which == index].mean()) if count else None) for index, count in enumerate(counts)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", type=Path, help="write the bins here")
    args = parser.parse_args()
    scenario = pets_scenario("hog", **{"control.beta": 1.0, "detector.model": "online"})
    world = episode_world(scenario, 0)
    episode = run_episode(scenario, "smpl", 0, world)
    model = world.detector_model.as_dict()
    occluded_above = scenario.required_recording("the annotated recall").occluded_above
    heights, found = annotated_recall_trials(world, episode, scenario, occluded_above)
    annotated_bins = recall_by_bin(heights, found)
    print(f"smpl b1, seed 0: MOTA {episode_metrics(episode)['mota']:.1%}, mean zoom {episode.poses[:, 2].mean():.2f}")
    curve = model["curve"]
    print(
        f"learned curve: Kd {curve['kd_per_px']:.4f} per px, r0 {curve['r0_px']:.2f} px, plateau "
        f"{curve['plateau']:.2f}; clutter {model['clutter_per_view']:.3f} per view, pixel noise "
        f"{model['pixel_noise_px']:.2f} px"
    )
    print(f"{'height [px]':>12}{'annotated':>10}{'annotated recall':>18}{'learned':>9}{'+-':>6}{'trials':>8}")
    bins = []
    for index, (centre, (people, annotated)) in enumerate(zip(model["height_px"], annotated_bins, strict=True)):
        row = {
            "height_px": centre,
            "annotated_people": people,
            "recall_learned": model["recall"][index],
            "recall_learned_sd": model["recall_sd"][index],
            "recall_annotated": annotated,
            "trials": model["trials"][index],
        }
        bins.append(row)
        if people:
            mark = "" if people >= MIN_PEOPLE else "  (fewer than 50 people)"
            print(
                f"{centre:>12.1f}{people:>10}{annotated:>18.2f}{row['recall_learned']:>9.2f}"
                f"{row['recall_learned_sd']:>6.2f}{row['trials']:>8.1f}{mark}"
            )
    compared = [row for row in bins if row["annotated_people"] >= MIN_PEOPLE]
    worst = max(abs(row["recall_learned"] - row["recall_annotated"]) for row in compared) if compared else None
    print(f"largest |learned - annotated| over bins with >= {MIN_PEOPLE} people: {worst}")
    if args.json is not None:
        document = {"bins": bins, "curve": curve, "max_abs_error": worst, "min_people": MIN_PEOPLE}
        args.json.write_text(json.dumps(document, indent=1))
        print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
