"""``ptztrack score``: any tracker's MOTChallenge file scored against its truth (:mod:`ptztrack.evaluate.score`)."""

import argparse

from ptztrack.evaluate.metrics import format_figures
from ptztrack.evaluate.report import metrics_json
from ptztrack.evaluate.score import score_files
from ptztrack.files import write_atomically

SCORE_FIGURES = {
    "world": ("mota", "motp_m", "idf1", "switches", "false_positives", "misses", "matches", "objects"),
    "image": ("mota", "motp_iou", "idf1", "switches", "false_positives", "misses", "matches", "objects"),
}
"""What ``score`` prints in each coordinates: a run's tracking figures, and the counts they come from."""


def score_command(args: argparse.Namespace) -> int:
    metrics = score_files(args.truth, args.tracks, args.coordinates, args.gate_m)
    matched_by = (
        f"ground positions within {metrics['gate_m']:g} m"
        if metrics["coordinates"] == "world"
        else f"boxes overlapping at IoU >= {metrics['min_iou']:g}"
    )
    print(
        f"{args.tracks} against {args.truth}: {metrics['frames']} frames, {metrics['people']} people, "
        f"{metrics['tracks']} tracks, matched by {matched_by}"
    )
    print(format_figures(metrics, SCORE_FIGURES[metrics["coordinates"]]))
    if args.json is not None:
        write_atomically(args.json, metrics_json(metrics))
        print(f"wrote {args.json}")
    return 0
