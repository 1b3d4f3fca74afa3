"""A recording made from nothing, and a virtual PTZ camera tracking people in it through its dataset file.

    python examples/render_and_track.py [--frames 40] [--people 5] [--detector ideal] [--out rendered]

``ptztrack.render_dataset`` draws people walking in front of one fixed camera and writes a recording
into ``--out``: the video, its calibration, the ground truth and ``dataset.yaml``, which names them (the
same as ``ptztrack render``). ``load_dataset`` reads that file as it would read a real recording's, and
``dataset_scenario`` puts the PTZ paper's virtual camera (160 x 120 px, 5 steps a second) inside the video;
an episode of each policy then runs on it. The ``ideal`` detector finds the annotated people the virtual
camera shows whole; ``--detector hog`` runs OpenCV's people detector on its pictures instead.
"""

import argparse
from pathlib import Path

import ptztrack


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=40)
    parser.add_argument("--people", type=int, default=5)
    parser.add_argument("--detector", default="ideal")
    parser.add_argument("--policies", nargs="+", default=["fix", "smpl"])
    parser.add_argument("--out", type=Path, default=Path("rendered"))
    args = parser.parse_args()

    # One fixed camera 5 m up at the middle of a side of a 16 x 12 m area, aimed at its centre.
    scene = ptztrack.scenario_from_dict(
        {
            "area_m": [16.0, 12.0],
            "frames": args.frames,
            "frame_rate_hz": 10.0,
            "people": {"count": args.people},
            "camera": {"position_m": [8.0, 0.0, 5.0], "image_size_px": [640, 360], "f_min_px": 300.0},
        }
    )
    dataset_file = ptztrack.render_dataset(scene, args.out, seed=0, overwrite=True)
    print(f"rendered {args.frames} frames of {args.people} people: {dataset_file}")

    recording = ptztrack.dataset_scenario(ptztrack.load_dataset(dataset_file), **{"detector.kind": args.detector})
    for policy in args.policies:
        metrics = ptztrack.episode_metrics(ptztrack.run_episode(recording, policy, seed=0))
        print(f"{policy:>6}: MOTA {metrics['mota']:.1%}, {metrics['detections']:.0f} detections, "
              f"mean zoom {metrics['zoom']:.2f}")  # fmt: skip


if __name__ == "__main__":
    main()
