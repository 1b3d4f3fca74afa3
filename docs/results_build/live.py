"""The live-loop page (``results/live.md``): its fields and its headline."""

from __future__ import annotations

from . import Load
from .formatting import fixed, integer, pct, pct_pm, points, table


def pace_and_score(run: dict) -> tuple[list[list[str]], list[list[str]]]:
    """A live-loop run's pace and its scores, each a table's rows."""
    pace = [
        ["pictures used", str(run["pictures_used"])],
        ["decisions a second", fixed(run["decisions_per_s"], 2)],
        ["pictures used a second", fixed(run["frames_used_per_s"], 2)],
        ["95 % of the decisions on a picture at most", f"{run['frame_age_s_p95']:.3f} s"],
        [
            "first decision with tracks / median decision",
            f"{1e3 * run['first_decision_s']:.1f} / {1e3 * run['median_decision_s']:.1f} ms",
        ],
        ["new targets sent a second", fixed(run["new_targets_per_s"], 2)],
        ["the virtual camera's share of one core", fixed(run["camera_cpu_share"], 2)],
    ]
    score = [
        ["MOTA live", pct(run["mota_live"])],
        ["the live run's pictures rendered exactly", pct(run["mota_replay_rendered"])],
        ["one such picture a recording step", pct(run["mota_replay_per_step"])],
        ["the offline run of the same steps, seed 0", pct(run["mota_offline"])],
        [
            f"the offline run over {len(run['mota_offline_per_seed'])} seeds",
            pct_pm(run["mota_offline_seeds_mean"], run["mota_offline_seeds_sd"]),
        ],
        ["IDF1 live / offline", f"{pct(run['idf1_live'])} / {pct(run['idf1_offline'])}"],
        ["zoom live / offline", f"{run['zoom_live']:.2f} / {run['zoom_offline']:.2f}"],
        ["pan error of pictures taken while moving, p95", f"{run['pan_error_deg_moving_p95']:.2f} deg"],
    ]
    return pace, score


def fields(load: Load) -> dict[str, str]:
    run = load("live-loop")
    pace, score = pace_and_score(run)
    stages = [[stage, fixed(1e3 * value, 1)] for stage, value in run["stages_s"].items()]
    by_zoom = [
        [band, fixed(figures["ms"], 1), fixed(figures["people_height_px"], 1), fixed(figures["recall"], 2)]
        for band, figures in run["detection_by_zoom"].items()
    ]
    busy = load("live-loop-busy")["busy"]
    busy_pace, busy_score = pace_and_score(busy)
    return (
        camera_from_the_box_fields(load)
        | service_fields(load)
        | {
            "live_busy_cores": str(busy["busy_cores"]),
            "live_busy_pace_table": table(["pace", ""], busy_pace),
            "live_busy_score_table": table(["score", ""], busy_score),
            "live_busy_gap_offline": points(busy["mota_live"] - busy["mota_offline"]),
            "live_machine": f"{run['cpu_model']}, {run['cores']} cores",
            "live_pace_table": table(["pace", ""], pace),
            "live_score_table": table(["score", ""], score),
            "live_stages_table": table(["where a decision's picture ages (medians)", "ms"], stages),
            "live_zoom_table": table(
                ["the picture's zoom", "detection [ms]", "people found [px tall]", "the learned recall there"], by_zoom
            ),
            "live_gap_offline": points(run["mota_live"] - run["mota_offline"]),
        }
    )


def camera_from_the_box_fields(load: Load) -> dict[str, str]:
    """``camera calibrate --geometry`` against virtual cameras of hidden geometries: the file's errors."""
    document = load("camera-from-the-box")
    body = [
        [
            str(run["geometry_seed"]),
            f"{run['focal_err_max_pct']:.2f} %",
            f"{run['pan_tilt_err_max_deg']:.2f} deg ({run['pan_tilt_err_scene_max_deg']:.2f})",
            f"{run['position_err_m']:.3f} m",
            f"{run['bearing_err_deg']:.3f} deg",
            f"{run['calibrate_s']:.0f} s",
        ]
        for run in document["runs"]
    ]
    body.append(
        [
            "largest",
            f"{document['focal_err_max_pct']:.2f} %",
            f"{document['pan_tilt_err_max_deg']:.2f} deg ({document['pan_tilt_err_scene_max_deg']:.2f})",
            f"{document['position_err_m']:.3f} m",
            f"{document['bearing_err_deg']:.3f} deg",
            "",
        ]
    )
    return {
        "box_table": table(
            [
                "geometry seed",
                "focal length, largest error over the zoom steps",
                "pan/tilt mapping over the whole range (over the scene's)",
                "position",
                "bearing",
                "calibration",
            ],
            body,
        )
    }


def service_fields(load: Load) -> dict[str, str]:
    """``ptztrack serve`` soaked: what its subscriber got, its stops, its memory and its files."""
    soak = load("soak-serve")
    growth = soak["rss_mb_end"] / soak["rss_mb_start"] - 1
    rows = [
        ["run", f"{soak['minutes']:g} minutes, the recording at {soak['time_scale']:g} times its pace"],
        ["steps used (both cameras)", integer(soak["steps"])],
        ["steps lost outside the cameras' outages", str(soak["steps_lost_outside_outages"])],
        ["camera outages", str(soak["outages"])],
        [
            "events written / MQTT messages delivered",
            f"{integer(soak['events_written'])} / {integer(soak['mqtt_messages'])}",
        ],
        ["tracebacks", str(soak["tracebacks"])],
        ["SIGTERM to exit, the longest", f"{soak['stop_s']:.1f} s"],
        [
            "resident memory, a minute after the second start to the end",
            f"{soak['rss_mb_start']:.1f} -> {soak['rss_mb_end']:.1f} MB ({100 * growth:+.1f} %)",
        ],
        [
            "rotated files",
            f"{soak['rotated_files']}, {'every one' if soak['rotated_files_whole'] else 'not every one'} whole",
        ],
        [
            "detector models' trials before / after the restart",
            f"{integer(soak['model_trials_before_restart'])} / {integer(soak['model_trials_after_restart'])}",
        ],
    ]
    return {"service_table": table(["the service", ""], rows)}


def headline(load: Load) -> list[str]:
    run = load("live-loop")
    return [
        "[The live loop](live.md)",
        f"against the virtual ONVIF camera at the recording's pace: MOTA {pct(run['mota_live'])} live against "
        f"{pct(run['mota_offline'])} for the offline run of the same steps, {run['decisions_per_s']:.1f} decisions "
        f"a second, 95 % of them on a picture at most {run['frame_age_s_p95']:.3f} s old",
    ]
