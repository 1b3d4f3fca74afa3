"""Measure the clutter density of OpenCV's HOG detector on PETS 2009 virtual views, for the CJPDAF.

Runs the detector on the virtual views of every 8th step at the whole-frame
pose (zoom 1) and zoomed 2x around it. A box whose feet lie more than
5 px x zoom from the feet of every annotated person (occluded ones
included) is a false detection; the recall is the fraction of the annotated,
unoccluded people fully in view with a box within that distance. Prints
lambda (false detections per px^2) and the parametric PDA's
C = lambda (1 - P_D P_G) / P_D with P_G = 0.99, the value of
``Tracker.clutter_density_per_px2`` for this detector (about a minute).

    python benchmarks/hog_clutter.py
"""

import numpy as np
from scipy.spatial.distance import cdist

from ptztrack.builders.recording import pets_scenario
from ptztrack.builders.world import build_world


def main() -> None:
    scenario = pets_scenario("hog")
    world = build_world(scenario, np.random.default_rng(0))
    grid, backend = world.grid, world.backend
    rng = np.random.default_rng(0)
    width_px, height_px = scenario.camera.image_size_px
    steps = range(0, world.truth.positions_m.shape[0], 8)
    gate_probability = scenario.tracker.gate_probability
    for zoom_index in (0, 1):
        pose = grid.poses[np.flatnonzero(np.all(grid.axis_indices == [3, 2, zoom_index], axis=1))[0]]
        radius_px = 5.0 * pose[2]
        false = found = visible = 0
        for step in steps:
            boxes = world.detector.detect(backend, step, pose, rng).feet_px
            people = backend.people(step, pose)
            annotated = people.feet_px[people.in_view]
            seen = people.feet_px[people.in_view & (people.hidden <= scenario.recording.occluded_above)]
            if len(boxes):
                nearest = cdist(boxes, annotated).min(axis=1) if len(annotated) else np.full(len(boxes), np.inf)
                false += int((nearest > radius_px).sum())
            visible += len(seen)
            if len(seen) and len(boxes):
                found += int((cdist(seen, boxes).min(axis=1) <= radius_px).sum())
        density = false / len(steps) / (width_px * height_px)
        recall = found / visible
        clutter = density * (1 - recall * gate_probability) / recall
        print(
            f"zoom {pose[2]:.0f}: {false / len(steps):.2f} false detections per view ({density:.2e} per px^2), "
            f"recall {recall:.2f} ({visible} people), C = {clutter:.2e} per px^2"
        )


if __name__ == "__main__":
    main()
