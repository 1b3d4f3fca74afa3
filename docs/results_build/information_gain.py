"""The information-gain PTZ camera's page (``results/information-gain.md``): its fields and its headline."""

from __future__ import annotations

from collections.abc import Sequence

from . import Load
from .formatting import by_label, dimensions, fixed, paired, pct, pct_pm, points, span, table

PTZ_FIGURES = (
    ("MOTA", "mota"),
    ("MOTP [m]", "motp_m"),
    ("Height [px]", "height_px"),
    ("# Dets", "detections"),
    ("Zoom [x]", "zoom"),
)


def ptz_cell(row: dict, key: str, spread_key: str, paper: dict | None, detection_digits: int) -> str:
    """One cell of a PTZ table: MOTA with its spread over the runs, the other figures plain; the
    paper's value in brackets where ``paper`` gives one."""
    if key == "mota":
        text = pct_pm(row["mota"], row[spread_key]) if row["sequences"] > 1 else pct(row["mota"])
    elif key == "detections":
        text = fixed(row[key], detection_digits)
    else:
        text = fixed(row[key], {"motp_m": 3, "height_px": 1, "zoom": 2}[key])
    if paper is not None:
        text += f" ({paper_figure(paper, key)})"
    return text


def paper_figure(paper: dict, key: str) -> str:
    """A figure of the paper's tables (MOTA in percent) as the paper prints it."""
    return {"mota": "{:.1f}", "motp_m": "{:g}", "height_px": "{:.1f}", "detections": "{:g}", "zoom": "{:.2f}"}[
        key
    ].format(paper[key])


def paper_table(columns: dict[str, dict]) -> str:
    """One of the paper's tables: a column per strategy, a row per figure, MOTA in percent."""
    body = [
        [name] + [paper_figure(figures, key) + (" %" if key == "mota" else "") for figures in columns.values()]
        for name, key in PTZ_FIGURES
    ]
    return table([""] + list(columns), body)


def ptz_table(
    rows: Sequence[dict],
    spread_key: str,
    paper: dict | None = None,
    figures: Sequence[tuple[str, str]] = PTZ_FIGURES,
    folds: bool = False,
    detection_digits: int = 1,
) -> str:
    """The paper's layout: a column per strategy, a row per figure; ``paper`` maps a column's label to
    the paper's figures, shown in brackets; ``folds`` adds each fold's MOTA."""
    body = [
        [name] + [ptz_cell(row, key, spread_key, paper and paper[row["label"]], detection_digits) for row in rows]
        for name, key in figures
    ]
    if folds:
        body.append(["MOTA folds"] + [" / ".join(pct(value) for value in row["mota_folds"]) for row in rows])
    return table([""] + [row["label"] for row in rows], body)


def gaps_over(rows: dict[str, dict], baseline: str, columns: Sequence[str], key: str = "mota") -> list[float]:
    return [rows[column][key] - rows[baseline][key] for column in columns]


def fold_gaps_over(rows: dict[str, dict], baseline: str, columns: Sequence[str]) -> list[float]:
    return [
        fold - base
        for column in columns
        for fold, base in zip(rows[column]["mota_folds"], rows[baseline]["mota_folds"], strict=True)
    ]


INFORMATION_GAIN = ("intg b9", "smpl b9", "intg b1", "smpl b1")


def fields(load: Load) -> dict[str, str]:
    paper = load("paper")["ptz"]
    fields: dict[str, str] = {}
    scene = load("scene-statistics")
    fields |= {
        "scene_detected": fixed(scene["detected"], 1),
        "scene_instances": fixed(scene["instances"], 0),
        "scene_detected_pct": pct(scene["detected_fraction"]),
        "scene_height_px": fixed(scene["height_px"], 1),
        "scene_hidden_pct": pct(scene["hidden_fraction"]),
        "scene_out_of_view_pct": pct(scene["out_of_view_fraction"]),
        "paper_scene_detected": fixed(paper["table_1"]["fix"]["detections"], 1),
        "paper_scene_height_px": fixed(paper["table_1"]["fix"]["height_px"], 1),
    }
    resolved = []
    for name, paper_columns in (
        ("synthetic-ideal", "table_1"),
        ("synthetic-realistic-true", "table_2"),
        ("synthetic-realistic-online", None),
    ):
        rows = load(name)
        key = name.replace("-", "_")
        fields[f"{key}_table"] = ptz_table(rows, "mota_se", paper[paper_columns] if paper_columns else None)
        columns = by_label(rows)
        difference, error = paired(columns["smpl"]["mota_per_sequence"], columns["intg"]["mota_per_sequence"])
        fields[f"{key}_smpl_minus_intg"] = points(difference, error)
        resolved.append(abs(difference) > 2 * error)
    fields["synthetic_smpl_intg_verdict"] = (
        "is within twice its paired standard error in every table"
        if not any(resolved)
        else "exceeds twice its paired standard error in at least one table"
    )
    ideal = by_label(load("synthetic-ideal"))
    fields["synthetic_sequences"] = str(ideal["smpl"]["sequences"])
    fields["pets_seeds"] = str(max(row["seeds"] for row in load("pets-hog-a-priori")))
    realistic = by_label(load("synthetic-realistic-true"))
    fields["synthetic_fix_ideal"] = pct(ideal["fix"]["mota"])
    fields["synthetic_fix_realistic"] = pct(realistic["fix"]["mota"])
    zooms = [
        row["zoom"]
        for table_rows in (ideal, realistic)
        for label, row in table_rows.items()
        if label in ("intg", "smpl")
    ]
    fields["synthetic_information_gain_zoom"] = f"{min(zooms):.1f}-{max(zooms):.1f}"
    ratios = [
        table_rows[label]["height_px"] / table_rows["fix"]["height_px"]
        for table_rows in (ideal, realistic)
        for label in ("intg", "smpl")
    ]
    fields["synthetic_height_ratio"] = f"{min(ratios):.1f}-{max(ratios):.1f}"
    fields["synthetic_patrol_realistic"] = pct(realistic["patrol"]["mota"])
    fields["synthetic_patrol_detections"] = fixed(realistic["patrol"]["detections"], 1)
    fields["paper_patrol_realistic"] = paper_figure(paper["table_2"]["patrol"], "mota")
    fields["paper_patrol_detections"] = paper_figure(paper["table_2"]["patrol"], "detections")

    for detector in ("ideal", "hog"):
        for protocol in ("a-priori", "two-fold"):
            name = f"pets-{detector}-{protocol}"
            rows = load(name)
            key = name.replace("-", "_")
            fields[f"{key}_table"] = ptz_table(rows, "mota_sd", folds=protocol == "two-fold", detection_digits=0)
    fields["pets_ideal_paper_table"] = paper_table(paper["table_3"])
    fields["pets_hog_paper_table"] = paper_table(paper["table_4"])
    for detector in ("ideal", "hog"):
        fitted = load(f"pets-{detector}-two-fold")[0]["fitted"]
        fields[f"pets_{detector}_fitted_noise_px"] = " / ".join(fixed(fold["pixel_noise_px"], 2) for fold in fitted)
        fields[f"pets_{detector}_fitted_width_m"] = " / ".join(fixed(fold["width_m"], 3) for fold in fitted)
    hog_fitted = load("pets-hog-two-fold")[0]["fitted"]
    fields["pets_hog_fitted_recall"] = "; ".join(
        f"Kd {fold['recall_kd']:.3g}, r0 {fold['recall_r0_px']:.3g} px" for fold in hog_fitted
    )

    hog_a_priori = by_label(load("pets-hog-a-priori"))
    hog_two_fold = by_label(load("pets-hog-two-fold"))
    a_priori_gaps = gaps_over(hog_a_priori, "fix", INFORMATION_GAIN)
    fold_gaps = fold_gaps_over(hog_two_fold, "fix", INFORMATION_GAIN)
    fields["pets_hog_who_leads"] = (
        "every information-gain strategy beats `fix`"
        if min(a_priori_gaps + fold_gaps) > 0
        else "the information-gain strategies are not all ahead of `fix`"
    )
    fields["pets_hog_gap_a_priori"] = span(a_priori_gaps)
    fields["pets_hog_gap_folds"] = span(fold_gaps)
    fields["pets_hog_gap_all"] = span(a_priori_gaps + fold_gaps)
    fields["pets_hog_least_ahead"] = min(
        INFORMATION_GAIN, key=lambda column: min(fold_gaps_over(hog_two_fold, "fix", [column]))
    )
    smpl_over_intg_b1 = gaps_over(hog_a_priori, "intg b1", ["smpl b1"]) + fold_gaps_over(
        hog_two_fold, "intg b1", ["smpl b1"]
    )
    fields["pets_hog_smpl_b1_over_intg_b1"] = " / ".join(points(gap) for gap in smpl_over_intg_b1)
    fields["pets_hog_fix"] = pct(hog_a_priori["fix"]["mota"])
    fields["pets_hog_best"] = max(INFORMATION_GAIN, key=lambda column: hog_a_priori[column]["mota"])
    fields["pets_hog_best_mota"] = pct_pm(
        hog_a_priori[fields["pets_hog_best"]]["mota"], hog_a_priori[fields["pets_hog_best"]]["mota_sd"]
    )
    ideal_a_priori = by_label(load("pets-ideal-a-priori"))
    fields["pets_ideal_gap_b9"] = span(gaps_over(ideal_a_priori, "fix", ("intg b9", "smpl b9")))
    fields["pets_ideal_gap_b1"] = span(gaps_over(ideal_a_priori, "fix", ("intg b1", "smpl b1")), signed=True)
    return (
        fields
        | detections_fields(load)
        | prior_shift_fields(load)
        | pets_crowd_fields(load)
        | any_recording_fields(load)
        | detector_model_fields(load)
        | patrol_gap_fields(load)
        | rendered_people_fields(load)
        | smpl_against_intg_fields(load)
    )


def detections_fields(load: Load) -> dict[str, str]:
    """View_001's shipped boxes as the detector, under both protocols."""
    a_priori, two_fold = load("pets-detections-a-priori"), load("pets-detections-two-fold")
    labels = [row["label"] for row in a_priori]
    first, second = by_label(a_priori), by_label(two_fold)
    body = [
        ["a priori MOTA"] + [pct_pm(first[label]["mota"], first[label]["mota_sd"]) for label in labels],
        ["MOTP [m]"] + [fixed(first[label]["motp_m"], 3) for label in labels],
        ["# Dets"] + [fixed(first[label]["detections"], 0) for label in labels],
        ["Zoom [x]"] + [fixed(first[label]["zoom"], 2) for label in labels],
        ["two-fold MOTA"] + [pct_pm(second[label]["mota"], second[label]["mota_sd"]) for label in labels],
        ["MOTA folds"] + [" / ".join(pct(value) for value in second[label]["mota_folds"]) for label in labels],
    ]
    fitted = two_fold[0]["fitted"]
    zooms = [first[label]["zoom"] for label in labels if label != "fix"]
    return {
        "detections_best": max(labels, key=lambda label: first[label]["mota"]),
        "detections_table": table(["`detections`"] + labels, body),
        "detections_fitted_recall": "; ".join(
            f"Kd {fold['recall_kd']:.3g}, r0 {fold['recall_r0_px']:.3g} px" for fold in fitted
        ),
        "detections_zoom": f"{min(zooms):.1f}-{max(zooms):.1f}",
    }


def pets_crowd_fields(load: Load) -> dict[str, str]:
    """The synthetic scene with PETS 2009 S2.L1's annotated people as its walkers."""
    rows = by_label(load("pets-crowd"))
    difference, error = paired(rows["smpl"]["mota_per_sequence"], rows["intg"]["mota_per_sequence"])
    return {
        "pets_crowd_sequences": str(rows["smpl"]["sequences"]),
        "pets_crowd_mota": ", ".join(f"`{label}` {pct_pm(row['mota'], row['mota_se'])}" for label, row in rows.items()),
        "pets_crowd_smpl_minus_intg": points(difference, error),
        "pets_crowd_zoom": ", ".join(f"`{label}` {row['zoom']:.1f}" for label, row in rows.items() if label != "fix"),
    }


def any_recording_fields(load: Load) -> dict[str, str]:
    """The PETS table's strategies on a recording of a geometry drawn at random."""
    document = load("any-recording")
    recording = document["recording"]
    return {
        "any_recording_seed": str(recording["seed"]),
        "any_recording_size": dimensions(recording["image_size_px"]),
        "any_recording_fps": f"{recording['frame_rate_hz']:g}",
        "any_recording_area": dimensions(recording["area_m"]),
        "any_recording_camera": ", ".join(f"{coordinate:g}" for coordinate in recording["camera_position_m"]),
        "any_recording_f": f"{recording['f_px']:g}",
        "any_recording_people": str(recording["people"]),
        "any_recording_frames": str(recording["frames"]),
        "any_recording_steps": str(recording["steps"]),
        "any_recording_step_rate": f"{recording['step_rate_hz']:g}",
        "any_recording_detector": recording["detector"],
        "any_recording_table": ptz_table(document["rows"], "mota_sd", detection_digits=0),
    }


def detector_model_fields(load: Load) -> dict[str, str]:
    """The recall the online model learned in a PETS HOG run, bin by bin, beside the annotated one."""
    document = load("detector-model")
    compared = [row for row in document["bins"] if row["annotated_people"] >= document["min_people"]]
    body = [
        [
            fixed(row["height_px"], 1),
            str(row["annotated_people"]),
            fixed(row["recall_annotated"], 2),
            f"{row['recall_learned']:.2f} +- {row['recall_learned_sd']:.2f}",
            fixed(row["trials"], 1),
        ]
        for row in compared
    ]
    curve = document["curve"]
    return {
        "detector_model_min_people": str(document["min_people"]),
        "detector_model_table": table(
            ["height [px]", "annotated people", "annotated recall", "learned recall", "trials"], body
        ),
        "detector_model_worst": fixed(document["max_abs_error"], 3),
        "detector_model_curve": f"Kd {curve['kd_per_px']:.3g} per px, r0 {curve['r0_px']:.3g} px, "
        f"plateau {curve['plateau']:.2f}",
    }


def patrol_gap_fields(load: Load) -> dict[str, str]:
    """The synthetic strategies' MOTA counting every person and only the people in view, in four scenes."""
    rows = load("patrol-gap")
    scenes = list(dict.fromkeys(row["scene"] for row in rows))
    strategies = list(dict.fromkeys(row["strategy"] for row in rows))
    cell = {(row["scene"], row["strategy"]): row for row in rows}
    body = [
        [scene]
        + [
            f"{100 * cell[scene, strategy]['mota']:.1f} / {100 * cell[scene, strategy]['mota_in_view']:.1f}"
            for strategy in strategies
        ]
        for scene in scenes
    ]
    patrol = [cell[scene, "patrol"] for scene in scenes]
    default = cell["default", "patrol"]
    return {
        "patrol_gap_table": table(["scene"] + [f"`{strategy}`" for strategy in strategies], body),
        "patrol_gap_in_view_lift": points(default["mota_in_view"] - default["mota"]),
        "patrol_gap_best_in_view": pct(max(row["mota_in_view"] for row in patrol)),
    }


def rendered_people_fields(load: Load) -> dict[str, str]:
    """HOG's recall per apparent height on rendered people (cone bodies, PETS cut-outs) and on PETS."""
    cones, cutouts = load("rendered-people-cones"), load("rendered-people-pets-cutouts")
    cutout_recall = {row["height_px"]: row["rendered_recall"] for row in cutouts["bins"]}

    def recall(value: float | None) -> str:
        return "-" if value is None else fixed(value, 2)

    shown = [row for row in cones["bins"] if row["rendered_people"] and row["pets_people"]]
    body = [
        [
            fixed(row["height_px"], 1),
            f"{recall(row['rendered_recall'])} ({row['rendered_people']})",
            recall(cutout_recall[row["height_px"]]),
            f"{recall(row['pets_recall'])} ({row['pets_people']})",
        ]
        for row in shown
    ]
    compared = [row for row in cones["bins"] if row["difference"] is not None]
    close = [row for row in compared if row["height_px"] not in cones["bins_apart_px"]]
    below = [row["rendered_recall"] - cutout_recall[row["height_px"]] for row in compared]
    return {
        "rendered_people_min_people": str(cones["min_people"]),
        "rendered_people_table": table(
            ["height [px]", "cones (people)", "PETS cut-outs", "PETS 2009 View_001 (people)"], body
        ),
        "rendered_people_cones_close": fixed(max(abs(row["difference"]) for row in close), 2),
        "rendered_people_cones_close_from": fixed(min(row["height_px"] for row in close), 1),
        "rendered_people_cones_close_to": fixed(max(row["height_px"] for row in close), 1),
        "rendered_people_cones_apart": ", ".join(f"{height:.1f} px" for height in cones["bins_apart_px"]),
        "rendered_people_cones_apart_by": ", ".join(
            fixed(abs(row["difference"]), 2) for row in compared if row["height_px"] in cones["bins_apart_px"]
        ),
        "rendered_people_cutouts_below": f"{min(below):.2f}-{max(below):.2f}",
    }


PRIOR_SHIFTS = (("15", "15"), ("-10", "minus-10"), ("40", "40"), ("80", "80"))


def prior_shift_fields(load: Load) -> dict[str, str]:
    """The online detector model against the a-priori one when the prior curve is shifted."""
    truth = by_label(load("synthetic-realistic-true"))["smpl"]
    body = []
    for shift, name in PRIOR_SHIFTS:
        online, a_priori = (load(f"prior-shift-{name}-{model}")[0] for model in ("online", "a-priori"))
        body.append(
            [f"{shift} px", pct_pm(online["mota"], online["mota_se"]), pct_pm(a_priori["mota"], a_priori["mota_se"])]
        )
    return {
        "prior_shift_true": pct_pm(truth["mota"], truth["mota_se"]),
        "prior_shift_table": table(["prior shifted by D", "online", "a-priori"], body),
    }


def headline(load: Load) -> list[str]:
    synthetic = by_label(load("synthetic-realistic-true"))
    pets = by_label(load("pets-hog-a-priori"))
    best = max(INFORMATION_GAIN, key=lambda column: pets[column]["mota"])
    smpl, intg, fix = (
        pct_pm(synthetic[label]["mota"], synthetic[label]["mota_se"]) for label in ("smpl", "intg", "fix")
    )
    return [
        "[The information-gain PTZ camera](information-gain.md)",
        f"synthetic, realistic detector: MOTA `smpl` {smpl}, `intg` {intg}, `fix` {fix}; PETS 2009 with HOG, a priori: "
        f"`{best}` {pct_pm(pets[best]['mota'], pets[best]['mota_sd'])}, `fix` {pct(pets['fix']['mota'])}",
    ]


# Each run of the section on smpl against intg: its JSON, and what it changes from the synthetic protocol.
SMPL_AGAINST_INTG_RUNS = (
    ("smpl-intg-48-realistic", "realistic, the curve known", "7"),
    ("smpl-intg-48-ideal", "ideal", "7"),
    ("smpl-intg-192-realistic", "realistic, the curve known", "7"),
    ("crowd-14-realistic", "realistic, the curve known", "14"),
    ("crowd-14-ideal", "ideal", "14"),
    ("samples-400-realistic", "realistic, the curve known", "7, `smpl` drawing 400 samples"),
)


def smpl_against_intg_fields(load: Load) -> dict[str, str]:
    """`smpl` against `intg` over more sequences, a denser crowd and more samples: MOTA of each and the
    paired difference."""
    body, resolved = [], []
    for run, detector, people in SMPL_AGAINST_INTG_RUNS:
        rows = by_label(load(run))
        difference, error = paired(rows["smpl"]["mota_per_sequence"], rows["intg"]["mota_per_sequence"])
        if abs(difference) > 2 * error:
            resolved.append(f"{people} people, {detector} ({points(difference, error)})")
        body.append(
            [
                str(rows["smpl"]["sequences"]),
                people,
                detector,
                pct_pm(rows["intg"]["mota"], rows["intg"]["mota_se"]),
                pct_pm(rows["smpl"]["mota"], rows["smpl"]["mota_se"]),
                points(difference, error),
            ]
        )
    paper = load("paper")["ptz"]
    return {
        "smpl_against_intg_table": table(
            ["sequences", "people", "detector", "`intg`", "`smpl`", "`smpl` - `intg`"], body
        ),
        "smpl_against_intg_resolved": "; ".join(resolved) if resolved else "none",
        "paper_smpl_minus_intg_ideal": points(
            (paper["table_1"]["smpl"]["mota"] - paper["table_1"]["intg"]["mota"]) / 100
        ),
        "paper_smpl_minus_intg_realistic": points(
            (paper["table_2"]["smpl"]["mota"] - paper["table_2"]["intg"]["mota"]) / 100
        ),
    }
