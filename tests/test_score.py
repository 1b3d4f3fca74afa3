"""``ptztrack score TRUTH TRACKS``: a MOTChallenge pair scored with the run's metrics, on the ground or by boxes."""

import json
import re

import pytest

from ptztrack.cli import main

SCORED_BY_BOTH = ("mota", "motp_m", "idf1", "switches", "false_positives", "misses", "matches", "objects")
PRINTED_BY_BOTH = ("MOTA", "MOTP [m]", "IDF1", "ID switches")


def mot_file(path, rows) -> str:
    """``rows`` of (frame, id, left, top, width, height, conf, x, y, z) written as a MOTChallenge file."""
    path.write_text("".join(",".join(f"{value:g}" for value in row) + "\n" for row in rows))
    return str(path)


def ground_rows(rows, conf=1):
    """MOTChallenge rows of (frame, id, x_m, y_m) on the ground, without boxes."""
    return [(frame, person, -1, -1, -1, -1, conf, x_m, y_m, 0) for frame, person, x_m, y_m in rows]


def box_rows(rows):
    """MOTChallenge rows of (frame, id, left, top, width, height) px, without world positions."""
    return [(frame, person, *box_px, 1, -1, -1, -1) for frame, person, *box_px in rows]


def printed_figures(text: str) -> dict[str, str]:
    """The figures printed one a line as ``label  value``: {label: value}."""
    pairs = (re.split(r"\s{2,}", line.strip()) for line in text.splitlines())
    return {pair[0]: pair[1] for pair in pairs if len(pair) == 2}


@pytest.mark.slow
def test_score_on_the_files_of_a_run_reproduces_its_metrics(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["run", "--frames", "40", "--seed", "2", "--quiet", "--out", str(out)]) == 0
    run_printed = capsys.readouterr().out
    expected = json.loads((out / "metrics.json").read_text())
    assert expected["matches"] > 0 and expected["misses"] + expected["false_positives"] > 0

    scored_json = tmp_path / "scored.json"
    truth, tracks = str(out / "truth_mot.txt"), str(out / "tracks_mot.txt")
    assert main(["score", truth, tracks, "--json", str(scored_json)]) == 0
    score_printed = capsys.readouterr().out

    scored = json.loads(scored_json.read_text())
    assert {key: scored[key] for key in SCORED_BY_BOTH} == {key: expected[key] for key in SCORED_BY_BOTH}
    assert scored["coordinates"] == "world" and scored["gate_m"] == 1.0
    run_figures, score_figures = printed_figures(run_printed), printed_figures(score_printed)
    assert {label: score_figures[label] for label in PRINTED_BY_BOTH} == {
        label: run_figures[label] for label in PRINTED_BY_BOTH
    }
    assert f"wrote {scored_json}" in score_printed


def test_a_hand_computed_example_on_the_ground(tmp_path, capsys):
    """People 10 at (0, 0) and 20 at (5, 0) m in frames 1-3, 10 alone in frame 4; person 30 has conf 0
    (not to be scored) in frame 1. The tracks, their rows out of frame order:

    frame 1: track 1 at 0.1 m from 10, track 2 at 0.2 m from 20: two matches;
    frame 2: track 1 at 0.3 m from 10, track 2 at 0.4 m from 20: two matches;
    frame 3: track 3 at 0.2 m from 10 (an identity switch from track 1), track 2 at 0.1 m from 20, and
    track 4 at (10, 10) m, 5 m from anyone: a false positive;
    frame 4: track 3 at 0.2 m from 10: a match.
    Person-frames 7 (30 left out), matches 7, misses 0, false positives 1, switches 1:
    MOTA = 1 - (0 + 1 + 1) / 7 = 5/7; MOTP = (0.1 + 0.2 + 0.3 + 0.4 + 0.2 + 0.1 + 0.2) / 7 = 1.5/7 m.
    IDF1: truth positions 4 + 3 = 7, track positions 2 + 3 + 2 + 1 = 8; the best one-to-one pairing of
    ids, 10-1 (or 10-3) with 2 frames and 20-2 with 3, gives IDTP = 5: IDF1 = 2 * 5 / (7 + 8) = 2/3.
    With a gate of 0.05 m nothing matches: 7 misses and 8 false positives, MOTA = 1 - 15/7 = -8/7.
    """
    people = [(frame, 10, 0, 0) for frame in (1, 2, 3, 4)] + [(frame, 20, 5, 0) for frame in (1, 2, 3)]
    truth = mot_file(tmp_path / "gt.txt", ground_rows(people) + ground_rows([(1, 30, 2, 2)], conf=0))
    tracks = mot_file(
        tmp_path / "tracks.txt",
        ground_rows(
            [(3, 3, 0, 0.2), (3, 2, 5, 0.1), (3, 4, 10, 10), (4, 3, 0, 0.2)]
            + [(1, 1, 0.1, 0), (1, 2, 5, 0.2), (2, 1, 0, 0.3), (2, 2, 5.4, 0)]
        ),
    )
    scored_json = tmp_path / "scored.json"
    assert main(["score", truth, tracks, "--json", str(scored_json)]) == 0
    printed = capsys.readouterr().out
    assert "4 frames, 2 people, 4 tracks, matched by ground positions within 1 m" in printed
    scored = json.loads(scored_json.read_text())
    assert (scored["objects"], scored["matches"], scored["misses"]) == (7, 7, 0)
    assert (scored["false_positives"], scored["switches"]) == (1, 1)
    assert scored["mota"] == pytest.approx(5 / 7)
    assert scored["motp_m"] == pytest.approx(1.5 / 7)
    assert scored["idf1"] == pytest.approx(2 / 3)
    assert printed_figures(printed)["MOTA"] == f"{5 / 7:.1%}"

    assert main(["score", truth, tracks, "--gate-m", "0.05", "--json", str(scored_json)]) == 0
    assert "within 0.05 m" in capsys.readouterr().out
    scored = json.loads(scored_json.read_text())
    assert (scored["matches"], scored["misses"], scored["false_positives"]) == (0, 7, 8)
    assert scored["mota"] == pytest.approx(-8 / 7)
    assert scored["motp_m"] is None and "MOTP is a mean over matches" in scored["undefined"]["motp_m"]


def test_a_hand_computed_example_in_the_image(tmp_path, capsys):
    """People 1 at box (0, 0, 10, 20) and 2 at (100, 0, 10, 20) px in frames 1-3; the files have no
    world positions (-1), so the boxes are scored. Boxes 10 x 20 px shifted by d px sideways overlap by
    (10 - d) * 20 px^2: IoU 2/3 for d = 2, 1/3 (below 1/2: no match) for d = 5.

    frames 1 and 2: track 1 on person 1's box (IoU 1), track 2 shifted 2 px from person 2's (IoU 2/3);
    frame 3: track 3 on person 1's box (IoU 1, an identity switch from track 1); track 2 shifted 5 px
    (IoU 1/3): person 2 missed and track 2 a false positive.
    Person-frames 6, matches 5, misses 1, false positives 1, switches 1: MOTA = 1 - 3/6 = 1/2;
    MOTP = mean IoU of the matches = (1 + 2/3 + 1 + 2/3 + 1) / 5 = 13/15.
    IDF1: truth positions 3 + 3 = 6, track positions 2 + 3 + 1 = 6; pairing 1-1 (2 frames) and 2-2
    (the 2 frames it matched) gives IDTP = 4: IDF1 = 2 * 4 / (6 + 6) = 2/3.
    """
    people = [(frame, 1, 0, 0, 10, 20) for frame in (1, 2, 3)] + [(frame, 2, 100, 0, 10, 20) for frame in (1, 2, 3)]
    truth = mot_file(tmp_path / "gt.txt", box_rows(people))
    tracks = mot_file(
        tmp_path / "tracks.txt",
        box_rows(
            [(frame, 1, 0, 0, 10, 20) for frame in (1, 2)]
            + [(frame, 2, 102, 0, 10, 20) for frame in (1, 2)]
            + [(3, 3, 0, 0, 10, 20), (3, 2, 105, 0, 10, 20)]
        ),
    )
    scored_json = tmp_path / "scored.json"
    assert main(["score", truth, tracks, "--json", str(scored_json)]) == 0
    printed = capsys.readouterr().out
    assert "matched by boxes overlapping at IoU >= 0.5" in printed
    assert printed_figures(printed)["MOTP [IoU]"] == f"{13 / 15:.1%}"
    scored = json.loads(scored_json.read_text())
    assert scored["coordinates"] == "image" and scored["min_iou"] == 0.5
    assert (scored["objects"], scored["matches"], scored["misses"]) == (6, 5, 1)
    assert (scored["false_positives"], scored["switches"]) == (1, 1)
    assert scored["mota"] == pytest.approx(0.5)
    assert scored["motp_iou"] == pytest.approx(13 / 15)
    assert scored["idf1"] == pytest.approx(2 / 3)
    assert "motp_m" not in scored


GOOD_TRUTH = ground_rows([(1, 1, 0, 0), (2, 1, 0, 0)])
GOOD_TRACKS = ground_rows([(1, 7, 0, 0.1), (2, 7, 0, 0.2)])
BAD_INPUTS = {
    "no such truth file": (None, GOOD_TRACKS, [], ("gt.txt", "no such truth file")),
    "a line of nine fields": (GOOD_TRUTH, "1,7,-1,-1,-1,-1,1,0,0\n", [], ("tracks.txt", "line 1", "expected 10")),
    "a field that is not a number": (
        GOOD_TRUTH,
        "1,7,-1,-1,-1,-1,1,0,0,0\n2,7,-1,-1,-1,-1,1,zero,0,0\n",
        [],
        ("tracks.txt", "line 2", "not a number"),
    ),
    "a tracks file with no rows": (GOOD_TRUTH, "\n", [], ("tracks.txt", "no tracks rows")),
    "frames that do not overlap": (
        GOOD_TRUTH,
        ground_rows([(500, 7, 0, 0), (800, 7, 0, 0)]),
        [],
        ("tracks.txt", "frames 500 to 800", "gt.txt", "frames 1 to 2"),
    ),
    "a frame 0": (GOOD_TRUTH, "0,7,-1,-1,-1,-1,1,0,0,0\n", [], ("tracks.txt", "line 1", "frames are numbered from 1")),
    "a track twice in a frame": (
        GOOD_TRUTH,
        ground_rows([(1, 7, 0, 0), (2, 7, 0, 0), (2, 7, 1, 0)]),
        [],
        ("tracks.txt", "line 3", "2 times in frame 2"),
    ),
    "every truth row not to score": (ground_rows([(1, 1, 0, 0)], conf=0), GOOD_TRACKS, [], ("gt.txt", "conf")),
    "world coordinates without them": (
        box_rows([(1, 1, 0, 0, 10, 20)]),
        box_rows([(1, 7, 0, 0, 10, 20)]),
        ["--coordinates", "world"],
        ("gt.txt", "no world positions", "--coordinates image"),
    ),
    "image coordinates without boxes": (
        GOOD_TRUTH,
        GOOD_TRACKS,
        ["--coordinates", "image"],
        ("gt.txt", "no boxes", "--coordinates world"),
    ),
    "a box without area": (
        box_rows([(1, 1, 0, 0, 10, 20)]),
        box_rows([(1, 7, 0, 0, 10, 20), (2, 7, 0, 0, 0, 20)]),
        [],
        ("tracks.txt", "line 2", "0 px wide"),
    ),
    "a gate for boxes": (
        box_rows([(1, 1, 0, 0, 10, 20)]),
        box_rows([(1, 7, 0, 0, 10, 20)]),
        ["--gate-m", "2"],
        ("--gate-m 2", "world coordinates"),
    ),
}


@pytest.mark.parametrize("name", BAD_INPUTS)
def test_a_bad_input_gets_one_line_and_exit_status_2(tmp_path, capsys, name):
    truth_rows, tracks_rows, options, says = BAD_INPUTS[name]
    paths = []
    for file_name, rows in (("gt.txt", truth_rows), ("tracks.txt", tracks_rows)):
        path = tmp_path / file_name
        if isinstance(rows, str):
            path.write_text(rows)
        elif rows is not None:
            mot_file(path, rows)
        paths.append(str(path))
    scored_json = tmp_path / "scored.json"
    assert main(["score", *paths, *options, "--json", str(scored_json)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith("ptztrack: error: ") and captured.err.count("\n") == 1
    for part in says:
        assert part in captured.err
    assert not scored_json.exists()


def test_a_gate_that_is_not_a_distance_is_refused_by_the_parser(tmp_path, capsys):
    truth = mot_file(tmp_path / "gt.txt", GOOD_TRUTH)
    with pytest.raises(SystemExit) as exited:
        main(["score", truth, truth, "--gate-m", "-1"])
    assert exited.value.code == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "--gate-m" in error
