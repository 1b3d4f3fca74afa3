"""A detector of one's own, registered by name and chosen in the scenario like a built-in one.

    python examples/custom_detector.py [--min-height-px 40] [--frames 30]

The detector sees only people at least ``min_height_px`` tall in the picture, finds each of them with
probability ``recall``, and reports their feet with ``noise_px`` pixels of Gaussian noise: a plain class
with a ``detect`` method (:class:`ptztrack.Detector`). ``ptztrack.register("detectors", NAME, factory)``
names its factory ``(scenario, scene) -> detector`` in this process, and ``detector: {kind: NAME,
options: {...}}`` in a scenario then builds it, the options passed on unread. (For the ``ptztrack``
command, a package names it through an entry point: docs, Your own policy, detector, camera or tracker.)
An episode with it runs beside one with the built-in realistic detector.
"""

import argparse

import ptztrack

NAME = "near-sighted"


class NearSightedDetector:
    def __init__(self, min_height_px: float, recall: float, noise_px: float):
        self.min_height_px, self.recall, self.noise_px = min_height_px, recall, noise_px

    def detect(self, camera, step, pose, rng, believed_pose=None) -> ptztrack.Detections:
        people = camera.people(step, pose)  # a simulation knows who is in view; a real camera's backend does not
        if people is None:
            return ptztrack.Detections.empty()
        found = rng.random(len(people.in_view)) < self.recall
        seen = people.in_view & (people.height_px >= self.min_height_px) & found
        feet_px = people.feet_px[seen] + rng.normal(0.0, self.noise_px, size=(int(seen.sum()), 2))
        return ptztrack.Detections(feet_px, people.height_px[seen], people.person_index[seen])


def near_sighted(scenario, scene) -> NearSightedDetector:
    options = {"min_height_px": 40.0, "recall": 0.9, "noise_px": 2.0, **scenario.detector.options}
    return NearSightedDetector(**options)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--min-height-px", type=float, default=40.0)
    parser.add_argument("--frames", type=int, default=30)
    args = parser.parse_args()

    ptztrack.register("detectors", NAME, near_sighted)
    print(f"detectors: {', '.join(ptztrack.registered_names('detectors'))}")
    detectors = {
        "realistic": {"kind": "realistic"},
        NAME: {"kind": NAME, "options": {"min_height_px": args.min_height_px}},
    }
    for label, detector in detectors.items():
        scenario = ptztrack.scenario_from_dict({"frames": args.frames, "detector": detector})
        metrics = ptztrack.episode_metrics(ptztrack.run_episode(scenario, "smpl", seed=0))
        print(f"{label:>12}: MOTA {metrics['mota']:.1%}, {metrics['detections']:.0f} detections, "
              f"mean height {metrics['height_px']:.0f} px, mean zoom {metrics['zoom']:.2f}")  # fmt: skip


if __name__ == "__main__":
    main()
