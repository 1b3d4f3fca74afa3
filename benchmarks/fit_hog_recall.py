"""Fit the recall curve of OpenCV's HOG detector on PETS 2009 virtual views.

Runs the detector on the virtual views of every 20th step of the recording
(the whole frame and views zoomed 2x to 4x around it), matches its boxes to
the annotated, unoccluded people fully in view, and prints the maximum-
likelihood Kd and r0 of recall = 1 - exp(-Kd (r - r0)) with the empirical
recall per height band, next to the paper's Caltech curve (Kd 0.0098, r0 21.29).

    python benchmarks/fit_hog_recall.py
"""

import numpy as np

from ptztrack.builders.recording import pets_scenario
from ptztrack.builders.world import build_world
from ptztrack.detect.recall_fit import detection_trials, fit_recall
from ptztrack.detect.simulated import realistic_recall


def main() -> None:
    scenario = pets_scenario("hog")
    world = build_world(scenario, np.random.default_rng(0))
    grid = world.grid
    poses = grid.poses[np.all(np.abs(grid.axis_indices[:, :2] - [3, 2]) <= [2, 1], axis=1)]
    steps = range(0, world.truth.positions_m.shape[0], 20)
    occluded_above = scenario.required_recording("the recall fit").occluded_above
    trials = detection_trials(world.backend, world.detector, world.camera, world.truth, poses, steps, occluded_above)
    heights, detected = trials.height_px, trials.detected
    kd, r0 = fit_recall(heights, detected)
    print(f"{len(heights)} annotated people in view, {detected.sum()} found by HOG")
    print(f"fitted Kd = {kd:.4f} per px, r0 = {r0:.2f} px (paper, Caltech HOG: 0.0098, 21.29)")
    print(f"{'height [px]':>12}{'people':>8}{'recall':>8}{'fitted':>8}{'paper':>8}")
    for low in (10, 15, 20, 25, 30, 40, 50, 70, 100):
        band = (heights >= low) & (heights < low * 1.4)
        if band.any():
            middle = np.median(heights[band])
            print(
                f"{low:>5}-{low * 1.4:<6.0f}{band.sum():>8}{detected[band].mean():>8.2f}"
                f"{realistic_recall(middle, kd, r0):>8.2f}{realistic_recall(middle, 0.0098, 21.29):>8.2f}"
            )


if __name__ == "__main__":
    main()
