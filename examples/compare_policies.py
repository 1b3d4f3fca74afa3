"""Two camera policies on the same sequences: each one's MOTA per sequence, its mean and spread, and
their difference paired sequence by sequence.

    python examples/compare_policies.py [--policies fix smpl] [--sequences 3] [--frames 25]

Sequence ``k`` is the synthetic scene of seed ``k``: the same people walking the same paths for every
policy, so the paired difference leaves out how hard each sequence is. The spread is the standard
deviation over the sequences; the difference's standard error is ``sd / sqrt(n)`` of the paired
differences.
"""

import argparse

import numpy as np

import ptztrack


def mota_of(scenario, policy: str, seed: int) -> float:
    """The MOTA of one episode of ``policy`` on the scene of ``seed``."""
    return ptztrack.episode_metrics(ptztrack.run_episode(scenario, policy, seed))["mota"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--policies", nargs=2, default=["fix", "smpl"])
    parser.add_argument("--sequences", type=int, default=3)
    parser.add_argument("--frames", type=int, default=25)
    args = parser.parse_args()

    scenario = ptztrack.scenario_from_dict({"frames": args.frames, "detector": {"kind": "realistic"}})
    seeds = range(args.sequences)
    mota = {policy: np.array([mota_of(scenario, policy, seed) for seed in seeds]) for policy in args.policies}
    print(f"MOTA over {args.sequences} sequences of {args.frames} steps, realistic detector")
    for policy, values in mota.items():
        runs = " ".join(f"{value:6.1%}" for value in values)
        print(f"  {policy:>6}: {runs}   mean {values.mean():.1%} +- {values.std(ddof=1):.1%} (sd)")
    first, second = args.policies
    difference = mota[second] - mota[first]
    standard_error = difference.std(ddof=1) / np.sqrt(len(difference))
    print(
        f"  {second} - {first}: {100 * difference.mean():+.1f} +- {100 * standard_error:.1f} points"
        " (se, paired by sequence)"
    )


if __name__ == "__main__":
    main()
