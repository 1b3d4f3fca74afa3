"""The speed page (``results/speed.md``): its fields."""

from __future__ import annotations

from . import Load
from .formatting import dimensions, fixed, table


def decision_speed_fields(load: Load) -> dict[str, str]:
    figures = load("decision-speed")["sizes"]
    body = []
    for size, rates in figures.items():
        tracks, actions = size.split("x")
        ratio = rates["stonesoup_ratio"]
        versus = (
            f"intg {ratio:.0f}x, smpl {ratio * rates['smpl'] / rates['intg']:.0f}x faster" if ratio is not None else ""
        )
        body.append(
            [
                f"{tracks} x {actions}",
                f"{rates['intg']:.0f}",
                f"{rates['smpl']:.0f} (CPU time: {rates['smpl_cpu']:.0f})",
                versus,
            ]
        )
    return {
        "decision_speed_table": table(
            ["tracks x actions", "intg decisions/s", "smpl (M = 100) decisions/s", "per action-track vs Stone Soup"],
            body,
        )
    }


def follow_speed_fields(load: Load) -> dict[str, str]:
    speed = load("follow-speed")
    return {
        "follow_speed_steps": str(speed["steps"]),
        "follow_speed_view": dimensions(speed["view_size_px"]),
        "follow_speed_person": str(speed["person"]),
        "follow_speed_particles": str(speed["particles"]),
        "follow_speed_patches": str(speed["patches"]),
        "follow_speed_pf": f"{speed['pf_steps_per_s']:.0f}",
        "follow_speed_tracking_steps": str(speed["pf_tracking_steps"]),
        "follow_speed_default_patches": str(speed["default_patches"]),
        "follow_speed_pf_default": f"{speed['pf_default_steps_per_s']:.0f}",
        "follow_speed_search_particles": str(speed["search_particles"]),
        "follow_speed_pf_search": f"{speed['pf_search_steps_per_s']:.0f}",
        "follow_speed_csrt": f"{speed['csrt_steps_per_s']:.1f}",
        "follow_speed_mil": f"{speed['mil_steps_per_s']:.1f}",
    }


def msg_speed_fields(load: Load) -> dict[str, str]:
    body = [
        [
            f"{row['vertices']:,}",
            f"{row['aux_ms']:.3f}",
            f"{row['traversal_ms']:,.1f}",
            f"{row['traversal_ms'] / row['aux_ms']:,.0f}x",
        ]
        for row in load("msg-speed")
    ]
    return {"msg_speed_table": table(["vertices", "aux data [ms]", "traversal [ms]", "ratio"], body)}


def registration_speed_fields(load: Load) -> dict[str, str]:
    speed = load("registration-speed")
    return {
        "registration_speed_views": str(speed["views"]),
        "registration_speed_size": dimensions(speed["size_px"]),
        "registration_speed_median": fixed(speed["register_ms_median"], 1),
        "registration_speed_p90": fixed(speed["register_ms_p90"], 1),
        "registration_speed_sift": fixed(speed["sift_ms_median"], 1),
        "registration_speed_matching": fixed(speed["matching_ms_median"], 1),
        "registration_speed_full_sift": fixed(speed["full_size_sift_ms_median"], 1),
    }


def occupancy_speed_fields(load: Load) -> dict[str, str]:
    speed = load("occupancy-speed")
    stages = speed["stages_ms_per_frame"]
    return {
        "occupancy_speed_views": str(speed["views"]),
        "occupancy_speed_size": dimensions(speed["image_size_px"]),
        "occupancy_speed_frames": str(speed["frames"]),
        "occupancy_speed_lpom_fps": fixed(speed["frames_per_s"], 1),
        "occupancy_speed_lpom_ms": fixed(speed["ms_per_frame_median"], 1),
        "occupancy_speed_edges_ms": fixed(stages["edges"], 1),
        "occupancy_speed_loci_ms": fixed(stages["loci"], 1),
        "occupancy_speed_map_ms": fixed(stages["map_and_modes"], 1),
        "occupancy_speed_motion_pixels": f"{speed['motion_pixels_per_view_mean']:.0f}",
        "occupancy_speed_table_mb": f"{speed['table_mb']:.0f}",
        "occupancy_speed_table_s": f"{speed['table_build_s']:.1f}",
        "occupancy_speed_pom_fps": fixed(speed["pom_frames_per_s"], 1),
        "occupancy_speed_pom_ms": fixed(speed["pom_ms_per_frame_median"], 1),
        "occupancy_speed_pom_iterations": f"{speed['pom_iterations_mean']:.0f}",
        "occupancy_speed_pom_cells": str(speed["pom_cells"]),
        "occupancy_speed_pom_working": dimensions(speed["pom_working_px"]),
    }


def step_cost_fields(load: Load) -> dict[str, str]:
    rows = load("step-cost")
    body = [
        [
            row["policy"],
            fixed(row["zoom"], 2),
            fixed(row["read_ms"], 1),
            fixed(row["warp_ms"], 1),
            fixed(row["detect_ms"], 0),
            fixed(row["track_ms"], 1),
            fixed(row["decide_ms"], 2),
            fixed(row["total_ms"], 0),
            fixed(row["steps_per_s"], 1),
            fixed(row["reference_detect_ms"], 0),
            fixed(row["reference_steps_per_s"], 1),
            f"{row['detect_speedup']:.1f}x",
        ]
        for row in rows
    ]
    shares = [row["detect_share"] for row in rows]
    return {
        "step_cost_steps": str(rows[0]["steps"]),
        "step_cost_table": table(
            [
                "policy",
                "zoom",
                "read",
                "warp",
                "detect",
                "track",
                "decide",
                "total",
                "steps/s",
                "every window: detect",
                "steps/s",
                "detect speed-up",
            ],
            body,
        ),
        "step_cost_detect_share": f"{100 * min(shares):.0f}-{100 * max(shares):.0f} %",
    }


SPEED_PARTS = (
    decision_speed_fields,
    follow_speed_fields,
    msg_speed_fields,
    registration_speed_fields,
    occupancy_speed_fields,
    step_cost_fields,
)


def fields(load: Load) -> dict[str, str]:
    fields: dict[str, str] = {}
    for part in SPEED_PARTS:
        fields |= part(load)
    return fields
