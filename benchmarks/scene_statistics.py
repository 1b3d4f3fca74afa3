"""The synthetic scene's statistics as the paper describes its own: what a fixed camera sees.

With the 'fix' pose (the zoom-1 action that sees most of the area) and the
ideal detector, over the experiment's sequences (seeds 0..n-1): the
person-instances per sequence, the fraction detected and their mean pixel
height (the paper: 278.3 of 350, 79.5 %, at 49.1 px), and where the others
went: out of view (head or feet outside the image) or hidden by nearer
people (the ideal detector misses a person hidden by a fraction c with
probability c). These describe the scene, not a policy; the default
mounting and crowd were chosen with them (see the docs, the information-gain PTZ camera).

    python benchmarks/scene_statistics.py [--sequences 12] [--scenario FILE.yaml] [--json PATH]
"""

import argparse
from pathlib import Path

from ptztrack.config import load_scenario, scenario_from_dict
from ptztrack.experiments.ptz_tables import scene_statistics
from ptztrack.files import write_json


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sequences", type=int, default=12)
    parser.add_argument("--scenario", type=Path, help="a scenario YAML file (default: the built-in synthetic scene)")
    parser.add_argument("--json", type=Path, help="write the figures here")
    args = parser.parse_args()
    scenario = load_scenario(args.scenario) if args.scenario else scenario_from_dict({})
    figures = scene_statistics(scenario, args.sequences)
    print(
        f"{args.sequences} sequences, 'fix' with the ideal detector: {figures['detected']:.1f} of "
        f"{figures['instances']:.0f} person-instances detected per sequence ({figures['detected_fraction']:.1%}; "
        f"paper 278.3 of 350, 79.5 %) at {figures['height_px']:.1f} px (paper 49.1 px); lost: "
        f"{figures['hidden_fraction']:.1%} hidden by nearer people, {figures['out_of_view_fraction']:.1%} out of view"
    )
    if args.json:
        write_json(args.json, figures)


if __name__ == "__main__":
    main()
