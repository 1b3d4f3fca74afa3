"""The registration page (``results/registration.md``): its fields and its headline."""

from __future__ import annotations

from . import Load
from .formatting import fixed, pct, table


def fields(load: Load) -> dict[str, str]:
    document = load("registration")
    loop = {row["pose_source"]: row for row in document["closed_loop"]}
    body = [
        [
            row["pose_source"],
            pct(row["mota"]),
            fixed(row["motp_m"], 3),
            pct(row["pose_known"]),
            f"{row['tracker_pan_err_deg']:.3f} deg, {row['tracker_tilt_err_deg']:.3f} deg, "
            f"{row['tracker_zoom_err_pct']:.2f} %",
            str(row["matches"]),
            str(row["false_positives"]),
        ]
        for row in document["closed_loop"]
    ]
    return {
        "registration_views": str(document["views"]),
        "registration_registered": str(document["registered"]),
        "registration_focal_median": fixed(document["focal_err_median_pct"], 3),
        "registration_focal_p90": fixed(document["focal_err_p90_pct"], 3),
        "registration_ground_median": fixed(document["ground_err_median_m"], 3),
        "registration_ground_p90": fixed(document["ground_err_p90_m"], 3),
        "registration_oracle_ground_median": fixed(document["oracle_ground_err_median_m"], 3),
        "registration_oracle_ground_p90": fixed(document["oracle_ground_err_p90_m"], 3),
        "registration_lens_ground_median": fixed(document["lens_ground_err_median_m"], 3),
        "registration_lens_ground_p90": fixed(document["lens_ground_err_p90_m"], 3),
        "registration_roll_median": fixed(document["roll_err_median_deg"], 3),
        "registration_ms_median": fixed(document["register_ms_median"], 0),
        "registration_loop_table": table(
            [
                "pose source",
                "MOTA",
                "MOTP [m]",
                "steps with a pose",
                "tracker's pose error (median pan, tilt, zoom)",
                "matches",
                "false positives",
            ],
            body,
        ),
        "registration_loop_commanded": pct(loop["commanded"]["mota"]),
        "registration_loop_registered": pct(loop["registered"]["mota"]),
        "registration_loop_oracle": pct(loop["oracle"]["mota"]),
        "registration_commanded_false_positives": str(loop["commanded"]["false_positives"]),
        "registration_oracle_false_positives": str(loop["oracle"]["false_positives"]),
    }


def headline(load: Load) -> list[str]:
    document = load("registration")
    loop = {row["pose_source"]: row for row in document["closed_loop"]}
    return [
        "[Registration](registration.md)",
        f"{document['registered']} of {document['views']} random live views register, focal length within "
        f"{document['focal_err_median_pct']:.3f} % (median); in the closed loop with the camera landing off its "
        f"commands, MOTA {pct(loop['registered']['mota'])} with the registered pose, "
        f"{pct(loop['commanded']['mota'])} with the commanded one",
    ]
