"""The follow experiment's summary and tables, on rows made by hand."""

from ptztrack.experiments.follow import FOLLOW_FIGURES, format_follow_people, format_follow_table, summarise_follow


def test_the_summary_is_a_mean_per_tracker_over_the_people_where_a_figure_is_defined():
    rows = [
        {
            "tracker": "a",
            "target_id": 1,
            "steps": 5,
            **dict.fromkeys(FOLLOW_FIGURES, 1.0),
            "losses": 1,
            "recoveries": 0,
        },
        {
            "tracker": "a",
            "target_id": 2,
            "steps": 7,
            **dict.fromkeys(FOLLOW_FIGURES, 3.0),
            "losses": 2,
            "recoveries": 2,
        },
        {
            "tracker": "b",
            "target_id": 1,
            "steps": 5,
            **dict.fromkeys(FOLLOW_FIGURES, 0.5),
            "losses": 0,
            "recoveries": 0,
        },
    ]
    rows[1]["ground_error_m"] = float("nan")
    summary = summarise_follow(rows, FOLLOW_FIGURES)
    assert [row["tracker"] for row in summary] == ["a", "b"] and summary[0]["people"] == 2
    assert summary[0]["in_view_fraction"] == 2.0 and summary[0]["ground_error_m"] == 1.0
    assert "in_view_fraction" in format_follow_table(summary, FOLLOW_FIGURES)
    assert len(format_follow_people(rows).splitlines()) == 3  # a header and two people
