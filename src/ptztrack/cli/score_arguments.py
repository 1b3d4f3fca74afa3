"""The parser of ``ptztrack score`` (see :mod:`ptztrack.cli.arguments`): a MOTChallenge pair of files."""

from pathlib import Path

from ptztrack.cli.options import positive_float
from ptztrack.names import GATE_M, MATCH_MIN_IOU, SCORE_COORDINATES

MOT_ROWS = "MOTChallenge rows frame,id,left,top,width,height,conf,x,y,z, frames from 1"


def add_score_parser(commands) -> None:
    score = commands.add_parser(
        "score", help="score any tracker's MOTChallenge file against its truth, as run scores (MOTA, MOTP, IDF1)"
    )
    score.add_argument(
        "truth",
        type=Path,
        metavar="TRUTH",
        help=f"the people: {MOT_ROWS}; rows of conf below 1 (MOTChallenge's 0: a person not to score) are left "
        "out; e.g. a run's truth_mot.txt",
    )
    score.add_argument(
        "tracks", type=Path, metavar="TRACKS", help=f"the tracks: {MOT_ROWS}, e.g. a run's tracks_mot.txt"
    )
    score.add_argument(
        "--coordinates",
        choices=SCORE_COORDINATES,
        help="world: match tracks to people by x, y (columns 8-9) in metres, within --gate-m; image: by their "
        f"boxes in pixels, at an intersection over union of {MATCH_MIN_IOU:g} or more, as MOTChallenge "
        "(default: world if both files fill columns 8-9, not -1 on every row, else image)",
    )
    score.add_argument(
        "--gate-m",
        type=positive_float,
        metavar="M",
        help=f"world coordinates: the farthest a track may be from a person to match, in metres (default {GATE_M:g}, "
        "as run)",
    )
    score.add_argument(
        "--json", type=Path, metavar="PATH", help="also write the metrics there, as JSON like a run's metrics.json"
    )
    score.set_defaults(handler="ptztrack.cli.score:score_command")
