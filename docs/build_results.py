"""Writes the results pages from their templates and the JSON their commands wrote.

    python docs/build_results.py           # writes docs/results/<page>.md
    python docs/build_results.py --check   # exits 1, naming the pages that differ, unless they are up to date

A page ``docs/results/<page>.md`` is its template ``docs/results/templates/<page>.md.in`` with every
``{{ name }}`` replaced: ``{{ command:RUN }}`` by the command of run ``RUN`` in ``data/runs.json`` (a
``bash`` block marked not-run, with its measured wall time), any other name by the page's field of
that name, computed below from ``docs/results/data/*.json`` as the commands wrote them. A template
naming a field its page does not compute, or a page computing a field its template does not use,
is an error: every figure on a page comes from a stored JSON file.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import statistics
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from statistics import mean

RESULTS = Path(__file__).resolve().parent / "results"
TEMPLATES = RESULTS / "templates"
DATA = RESULTS / "data"
PLACEHOLDER = re.compile(r"\{\{\s*([A-Za-z0-9_:.\-]+)\s*\}\}")
GENERATED_NOTE = "<!-- Written by docs/build_results.py from templates/{page}.md.in and data/: edit those. -->\n"


def load(name: str):
    """The JSON file ``data/<name>.json``."""
    return json.loads((DATA / f"{name}.json").read_text())


# Formatting: every figure of a page goes through one of these.


def pct(fraction: float, digits: int = 1) -> str:
    """A fraction as a percentage: 0.7642 -> '76.4 %'."""
    return f"{100 * fraction:.{digits}f} %"


def pct_pm(fraction: float, spread: float, digits: int = 1) -> str:
    """A fraction and its spread as percentages: '76.4 +- 2.6 %'."""
    return f"{100 * fraction:.{digits}f} +- {100 * spread:.{digits}f} %"


def points(fraction_difference: float, spread: float | None = None) -> str:
    """A difference of fractions in percentage points, signed: '+1.3' or '+1.3 +- 2.6'."""
    text = f"{100 * fraction_difference:+.1f}"
    return text if spread is None else f"{text} +- {100 * spread:.1f}"


def fixed(value: float, digits: int) -> str:
    """A number with ``digits`` decimals."""
    return f"{value:.{digits}f}"


def integer(value: float) -> str:
    """A count, rounded, with thousands separated by commas: 12668 -> '12,668'."""
    return f"{round(value):,}"


def table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A Markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def standard_error(values: Sequence[float]) -> float:
    """The standard error of the mean of ``values`` (sample standard deviation over sqrt(n))."""
    return statistics.stdev(values) / math.sqrt(len(values))


def paired(first: Sequence[float], second: Sequence[float]) -> tuple[float, float]:
    """The mean of ``first - second`` run by run and its standard error."""
    differences = [a - b for a, b in zip(first, second, strict=True)]
    return mean(differences), standard_error(differences)


def by_label(rows: Sequence[dict]) -> dict[str, dict]:
    return {row["label"]: row for row in rows}


# The information-gain camera.

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


def span(values: Sequence[float], signed: bool = False) -> str:
    """The smallest and largest of ``values`` (fractions) in points: '6.6 to 21.6' (one figure where
    they round alike; with ``signed``, '-0.2 to +0.1')."""
    low, high = (f"{100 * value:{'+' if signed else ''}.1f}" for value in (min(values), max(values)))
    return low if low == high else f"{low} to {high}"


INFORMATION_GAIN = ("intg b9", "smpl b9", "intg b1", "smpl b1")


def information_gain_fields() -> dict[str, str]:
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
    return fields | detections_fields() | prior_shift_fields() | pets_crowd_fields()


def detections_fields() -> dict[str, str]:
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


def pets_crowd_fields() -> dict[str, str]:
    """The synthetic scene with PETS 2009 S2.L1's annotated people as its walkers."""
    rows = by_label(load("pets-crowd"))
    difference, error = paired(rows["smpl"]["mota_per_sequence"], rows["intg"]["mota_per_sequence"])
    return {
        "pets_crowd_sequences": str(rows["smpl"]["sequences"]),
        "pets_crowd_mota": ", ".join(f"`{label}` {pct_pm(row['mota'], row['mota_se'])}" for label, row in rows.items()),
        "pets_crowd_smpl_minus_intg": points(difference, error),
        "pets_crowd_zoom": ", ".join(f"`{label}` {row['zoom']:.1f}" for label, row in rows.items() if label != "fix"),
    }


PRIOR_SHIFTS = (("15", "15"), ("-10", "minus-10"), ("40", "40"), ("80", "80"))


def prior_shift_fields() -> dict[str, str]:
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


# Face capture on the MSG.

MSG_BIN_WIDTH = 5  # N_j/s bins centred on its multiples, as ptztrack experiment msg prints them
MSG_KEY_BIN = 15  # the paper's key bin


def msg_bin(nj_s: float) -> int:
    return int(math.floor(nj_s / MSG_BIN_WIDTH + 0.5)) * MSG_BIN_WIDTH


def population_sd(values: Sequence[float]) -> float:
    centre = mean(values)
    return math.sqrt(sum((value - centre) ** 2 for value in values) / len(values))


def face_capture_fields() -> dict[str, str]:
    rows = load("msg")
    schedulers = list(dict.fromkeys(row["scheduler"] for row in rows))
    m = {(row["scheduler"], row["seed"]): row["m"] for row in rows}
    bin_of = {row["seed"]: msg_bin(row["nj_s"]) for row in rows}
    seeds = sorted(bin_of)
    bins = sorted(set(bin_of.values()))

    def cell(scheduler: str, seeds_in: Sequence[int]) -> str:
        values = [m[scheduler, seed] for seed in seeds_in]
        return fixed(mean(values), 3) if len(values) == 1 else f"{mean(values):.3f} +- {population_sd(values):.3f}"

    body = []
    for centre in bins:
        mine = [seed for seed in seeds if bin_of[seed] == centre]
        body.append([str(centre), str(len(mine))] + [cell(name, mine) for name in schedulers])
    body.append(["all", str(len(seeds))] + [fixed(mean([m[name, seed] for seed in seeds]), 3) for name in schedulers])
    key_seeds = [seed for seed in seeds if bin_of[seed] == MSG_KEY_BIN]

    def difference(first: str, second: str, seeds_in: Sequence[int]) -> tuple[float, float]:
        return paired([m[first, seed] for seed in seeds_in], [m[second, seed] for seed in seeds_in])

    def signed(value: tuple[float, float]) -> str:
        return f"{value[0]:+.3f} +- {value[1]:.3f}"

    pairs = (
        ("msg", "naive"),
        ("msg", "msg-no-untangling"),
        ("leave-first", "naive"),
        ("msg", "leave-first"),
        ("msg", "msg-no-join"),
        ("msg-no-join", "leave-first"),
    )
    differences = table(
        ["difference", f"all {len(seeds)} runs", f"bin N_j/s = {MSG_KEY_BIN} ({len(key_seeds)} runs)"],
        [
            [
                f"{first} - {second}",
                signed(difference(first, second, seeds)),
                signed(difference(first, second, key_seeds)),
            ]
            for first, second in pairs
        ],
    )

    def capture_rate(name: str) -> float:
        mine = [row for row in rows if row["scheduler"] == name]
        return sum(row["captures"] for row in mine) / sum(row["zooms"] for row in mine)

    rates = ", ".join(f"{name} {capture_rate(name):.3f}" for name in schedulers)
    nj_s_of = {row["seed"]: row["nj_s"] for row in rows}
    high = [seed for seed in seeds if nj_s_of[seed] > 30]
    paper = load("paper")["msg"]
    return {
        "paper_key_msg": fixed(paper["key_bin_msg_above"], 2),
        "paper_key_naive": fixed(paper["key_bin_naive"], 2),
        "msg_runs": str(len(seeds)),
        "msg_first_seed": str(seeds[0]),
        "msg_last_seed": str(seeds[-1]),
        "msg_table": table(["N_j/s", "runs"] + schedulers, body),
        "msg_differences_table": differences,
        "msg_capture_rates": rates,
        "msg_key_bin": str(MSG_KEY_BIN),
        "msg_key_msg": fixed(mean([m["msg", seed] for seed in key_seeds]), 3),
        "msg_key_naive": fixed(mean([m["naive", seed] for seed in key_seeds]), 3),
        "msg_high_runs": str(len(high)),
        "msg_high_mean": fixed(mean([m["msg", seed] for seed in high]), 3),
        "msg_high_worst": fixed(min(m["msg", seed] for seed in high), 3),
        "msg_lead": f"{difference('msg', 'naive', seeds)[0]:+.3f}",
        "msg_untangling_lead": f"{difference('leave-first', 'naive', seeds)[0]:+.3f}",
        "msg_equation_5": signed(difference("msg", "leave-first", seeds)),
        "msg_equation_5_key": signed(difference("msg", "leave-first", key_seeds)),
        "msg_no_join": signed(difference("msg-no-join", "msg", seeds)),
        "msg_no_join_key": signed(difference("msg-no-join", "msg", key_seeds)),
        "msg_past_term": signed(difference("msg-no-join", "leave-first", seeds)),
        "msg_past_term_key": signed(difference("msg-no-join", "leave-first", key_seeds)),
    }


# Long runs.


def long_runs_fields() -> dict[str, str]:
    runs = {"default": load("soak-default"), "long_run": load("soak-long-run")}
    targets = load("targets")["long_runs"]

    def memory(run: dict) -> tuple[float, float]:
        at = {int(step): mb for step, mb in run["rss_mb_at"].items()}
        return at[min(step for step in at if step >= targets["memory_from_step"])], at[max(at)]

    def growth(run: dict) -> str:
        start, end = memory(run)
        return f"{start:.0f} / {end:.0f} MB ({100 * (end / start - 1):+.1f} %)"

    figures = (
        ("MOTA", lambda run: pct(run["mota"]), ""),
        ("IDF1", lambda run: pct(run["idf1"]), f">= {pct(targets['idf1_at_least'], 0)}"),
        (
            "identity switches per 100 steps",
            lambda run: fixed(run["id_switches_per_100_steps"], 1),
            f"<= {targets['switches_per_100_steps_at_most']:g}",
        ),
        (
            f"switches, first / last {targets['window_steps']:,} steps",
            lambda run: f"{run['switches_first_2000']} / {run['switches_last_2000']}",
            "last no higher than first",
        ),
        ("distinct track ids reported", lambda run: str(run["track_ids_reported"]), ""),
        (
            f"resident memory at step {targets['memory_from_step']:,} / the last",
            growth,
            f"within {pct(targets['memory_growth_at_most'], 0)}",
        ),
        ("writing the folder", lambda run: f"{run['write_s']:.1f} s", f"within {targets['write_s_at_most']:g} s"),
        ("running the steps", lambda run: f"{run['run_s']:.1f} s", ""),
    )
    body = [[name, show(runs["default"]), show(runs["long_run"]), asked] for name, show, asked in figures]
    gaps = runs["long_run"]["switch_gaps"]
    return {
        "soak_steps": str(runs["default"]["steps"]),
        "soak_people": str(runs["default"]["people"]),
        "soak_table": table(["figure", "default tracker", "`examples/long_run.yaml`", "asked"], body),
        "soak_person_unmatched": " / ".join(fixed(value, 0) for value in gaps["person_unmatched_steps"]),
        "soak_track_undetected": " / ".join(fixed(value, 0) for value in gaps["track_unseen_steps"]),
    }


# The camera network.


def camera_network_fields() -> dict[str, str]:
    return synthetic_network_fields() | pets_network_fields()


def synthetic_network_fields() -> dict[str, str]:
    rows = load("network-synthetic")
    configs = {row["config"]: row for row in rows}
    body = [
        [
            f"`{row['config']}`",
            pct_pm(row["mota"], row["mota_se"]),
            points(row["mota_minus_joint"], row["mota_minus_joint_se"]) if "joint" in row else "",
            fixed(row["motp_m"], 3),
            pct(row["idf1"]),
            fixed(row["detections"], 1),
            fixed(row["zoom"], 2),
        ]
        for row in rows
    ]

    def lead(config: str) -> str:
        row = configs[config]
        return points(-row["mota_minus_joint"], row["mota_minus_joint_se"])

    ptz_over_fixed = [-row["mota_minus_joint"] for row in rows if "fixed" in row["config"] and "joint" in row]
    ring = [configs[f"{count}ptz-independent"] for count in (2, 3, 4)]
    resolved = [-row["mota_minus_joint"] > 2 * row["mota_minus_joint_se"] for row in ring]
    return {
        "network_sequences": str(rows[0]["sequences"]),
        "network_ring_verdict": (
            "ahead of independent ones by more than twice the paired standard error"
            if all(resolved)
            else "not ahead of independent ones by twice the paired standard error at every count"
        ),
        "network_table": table(["config", "MOTA", "- joint [points]", "MOTP [m]", "IDF1", "# Dets", "Zoom [x]"], body),
        "network_joint_over_independent_2": lead("2ptz-independent"),
        "network_joint_over_independent_3": lead("3ptz-independent"),
        "network_joint_over_independent_4": lead("4ptz-independent"),
        "network_joint_over_independent_mast_2": lead("2ptz-independent-mast"),
        "network_joint_over_independent_mast_3": lead("3ptz-independent-mast"),
        "network_joint_over_independent_mast_4": lead("4ptz-independent-mast"),
        "network_ptz_over_fixed": span(ptz_over_fixed),
        "network_ptz_counts": ", ".join(
            pct(configs[config]["mota"]) for config in ("1ptz", "2ptz-joint", "3ptz-joint", "4ptz-joint")
        ),
        "network_wide_alone": pct(configs["wide"]["mota"]),
        "network_wide_adds": ", ".join(
            f"{points(configs[with_wide]['mota'] - configs[alone]['mota'])} ({count})"
            for count, alone, with_wide in (
                ("one", "1ptz", "1ptz+wide"),
                ("two", "2ptz-joint", "2ptz-joint+wide"),
                ("three", "3ptz-joint", "3ptz-joint+wide"),
                ("four", "4ptz-joint", "4ptz-joint+wide"),
            )
        ),
    }


def pets_network_fields() -> dict[str, str]:
    rows = load("network-pets")
    body = [
        [
            f"`{row['config']}`",
            str(row["seeds"]),
            pct_pm(row["mota"], row["mota_sd"]) if row["seeds"] > 1 else pct(row["mota"]),
            fixed(row["motp_m"], 3),
            pct(row["idf1"]),
            fixed(row["false_positives"], 1),
            fixed(row["misses"], 1),
            fixed(row["switches"], 1),
            pct(row["mota_all_tracks"]),
            pct(row["mota_tracking_area"]),
            pct(row["idf1_tracking_area"]),
            fixed(row["detections"], 0),
            fixed(row["zoom"], 2),
        ]
        for row in rows
    ]
    configs = {row["config"]: row for row in rows}

    def paired_lead(other: str, key: str) -> str:
        network = configs["ptz+6fixed"][key]
        if len(configs[other][key]) != len(network):
            return points(mean(network) - mean(configs[other][key]))
        return points(*paired(network, configs[other][key]))

    return {
        "pets_network_table": table(
            [
                "config",
                "seeds",
                "MOTA",
                "MOTP [m]",
                "IDF1",
                "FP",
                "Misses",
                "IDsw",
                "MOTA all",
                "MOTA TA",
                "IDF1 TA",
                "# Dets",
                "Zoom [x]",
            ],
            body,
        ),
        "pets_network_over_ptz": paired_lead("ptz", "mota_per_seed"),
        "pets_network_over_fixed": paired_lead("6fixed", "mota_per_seed"),
        "pets_network_over_ptz_area": paired_lead("ptz", "mota_tracking_area_per_seed"),
        "pets_network_objects": str(rows[0]["objects"]),
    }


# The occupancy map.

OCCUPANCY_FIGURES = (
    ("MODA", "moda", pct),
    ("MODP", "modp", pct),
    ("precision", "precision", pct),
    ("recall", "recall", pct),
    ("error [m]", "error_m", lambda value: fixed(value, 3)),
    ("MOTA", "mota", pct),
    ("MOTP [m]", "motp_m", lambda value: fixed(value, 3)),
    ("IDF1", "idf1", pct),
)


def occupancy_table(rows: Sequence[dict]) -> str:
    """A row per people count and method; the clustering baseline feeds no tracker (blank MOTA to IDF1)."""
    body = [
        [str(row["people"]), row["method"]]
        + [show(row[key]) if row.get(key) is not None else "" for _, key, show in OCCUPANCY_FIGURES]
        for row in rows
    ]
    return table(["people", "method"] + [name for name, _, _ in OCCUPANCY_FIGURES], body)


def occupancy_map_fields() -> dict[str, str]:
    room = load("occupancy-synthetic-room")
    cell = {(row["people"], row["method"]): row for row in room}
    people = sorted({row["people"] for row in room})
    lpom_errors = [cell[count, "lpom"]["error_m"] for count in people]
    clustering_errors = [cell[count, "clustering"]["error_m"] for count in people]
    return {
        "room_table": occupancy_table(room),
        "room_lpom_error": f"{min(lpom_errors):.3f}-{max(lpom_errors):.3f}",
        "room_clustering_error": f"{min(clustering_errors):.3f}-{max(clustering_errors):.3f}",
        "room_lpom_moda_crowd": pct(cell[people[-1], "lpom"]["moda"]),
        "room_clustering_moda_crowd": pct(cell[people[-1], "clustering"]["moda"]),
        "room_crowd": str(people[-1]),
        "room_fitted": "; ".join(
            f"{count} {'person' if count == 1 else 'people'}: LPOM's strength "
            + " and ".join(f"{value:g}" for value in cell[count, "lpom"]["fitted_min_strength"])
            + ", POM's person width "
            + " and ".join(f"{value:g} m" for value in cell[count, "pom"]["fitted_width_m"])
            + ", the baseline's views "
            + " and ".join(str(value) for value in cell[count, "clustering"]["fitted_min_views"])
            for count in people
        ),
    }


# The follow camera.

FOLLOW_ROWS = (
    ("in-view fraction", "in_view_fraction", 3),
    ("target point error", "target_point_error", 3),
    ("losses declared", "losses", 2),
    ("recoveries", "recoveries", 2),
    ("steps lost", "lost_steps", 2),
    ("jitter [deg/step^2]", "jitter_deg", 3),
    ("height sd / mean", "height_sd_ratio", 3),
    ("ground error while tracking [m]", "ground_error_m", 2),
    ("zoom", "zoom", 2),
)
OTB_ROWS = (
    ("success AUC", "success_auc", 3),
    ("precision at 20 px", "precision_20px", 3),
    ("frames per second", "fps", 0),
)


def finite_mean(values: Sequence[float]) -> float:
    finite = [value for value in values if value is not None and math.isfinite(value)]
    return mean(finite) if finite else float("nan")


def follow_camera_fields() -> dict[str, str]:
    summary = load("follow")
    trackers = [row["tracker"] for row in summary["closed_loop"]]
    people = summary["people"]

    def of(tracker: str, parity: int | None = None) -> list[dict]:
        return [
            row for row in people if row["tracker"] == tracker and (parity is None or row["target_id"] % 2 == parity)
        ]

    def split(tracker: str, key: str, digits: int) -> str:
        return " / ".join(fixed(finite_mean([row[key] for row in of(tracker, parity)]), digits) for parity in (0, 1))

    closed = {row["tracker"]: row for row in summary["closed_loop"]}
    body = []
    for name, key, digits in FOLLOW_ROWS:
        body.append([name] + [fixed(closed[tracker][key], digits) for tracker in trackers])
        if key in ("in_view_fraction", "target_point_error"):
            body.append([f"{name}, even / odd people"] + [split(tracker, key, digits) for tracker in trackers])
    otb = {row["tracker"]: row for row in summary["otb"]}
    otb_body = [[name] + [fixed(otb[tracker][key], digits) for tracker in trackers] for name, key, digits in OTB_ROWS]
    particle = sorted(of("particle"), key=lambda row: row["in_view_fraction"])
    kept = [row for row in particle if row["in_view_fraction"] >= 0.98]
    otb_people = sorted({row["target_id"] for row in summary["otb_people"]})
    return {
        "follow_people": str(closed[trackers[0]]["people"]),
        "follow_steps": integer(sum(row["steps"] for row in of(trackers[0]))),
        "follow_table": table([""] + trackers, body),
        "follow_otb_people": ", ".join(str(person) for person in otb_people),
        "follow_otb_table": table([""] + trackers, otb_body),
        "follow_particle_in_view": fixed(closed["particle"]["in_view_fraction"], 3),
        "follow_particle_in_view_odd": fixed(finite_mean([row["in_view_fraction"] for row in of("particle", 1)]), 3),
        "follow_csrt_in_view": fixed(closed["csrt"]["in_view_fraction"], 3),
        "follow_mil_in_view": fixed(closed["mil"]["in_view_fraction"], 3),
        "follow_kept_count": str(len(kept)),
        "follow_lost_people": ", ".join(
            f"person {row['target_id']} ({row['in_view_fraction']:.2f})"
            for row in particle
            if row["in_view_fraction"] < 0.98
        ),
    }


# Registration.


def registration_fields() -> dict[str, str]:
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


# The live loop.


def live_fields() -> dict[str, str]:
    run = load("live-loop")
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
    stages = [[stage, fixed(1e3 * value, 1)] for stage, value in run["stages_s"].items()]
    by_zoom = [
        [band, fixed(figures["ms"], 1), fixed(figures["people_height_px"], 1), fixed(figures["recall"], 2)]
        for band, figures in run["detection_by_zoom"].items()
    ]
    return {
        "live_machine": f"{run['cpu_model']}, {run['cores']} cores",
        "live_pace_table": table(["pace", ""], pace),
        "live_score_table": table(["score", ""], score),
        "live_stages_table": table(["where a decision's picture ages (medians)", "ms"], stages),
        "live_zoom_table": table(
            ["the picture's zoom", "detection [ms]", "people found [px tall]", "the learned recall there"], by_zoom
        ),
        "live_gap_offline": points(run["mota_live"] - run["mota_offline"]),
    }


# Speed.


def decision_speed_fields() -> dict[str, str]:
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


def follow_speed_fields() -> dict[str, str]:
    speed = load("follow-speed")
    return {
        "follow_speed_steps": str(speed["steps"]),
        "follow_speed_view": " x ".join(str(size) for size in speed["view_size_px"]),
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


def msg_speed_fields() -> dict[str, str]:
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


def registration_speed_fields() -> dict[str, str]:
    speed = load("registration-speed")
    return {
        "registration_speed_views": str(speed["views"]),
        "registration_speed_size": " x ".join(str(size) for size in speed["size_px"]),
        "registration_speed_median": fixed(speed["register_ms_median"], 1),
        "registration_speed_p90": fixed(speed["register_ms_p90"], 1),
        "registration_speed_sift": fixed(speed["sift_ms_median"], 1),
        "registration_speed_matching": fixed(speed["matching_ms_median"], 1),
        "registration_speed_full_sift": fixed(speed["full_size_sift_ms_median"], 1),
    }


def occupancy_speed_fields() -> dict[str, str]:
    speed = load("occupancy-speed")
    stages = speed["stages_ms_per_frame"]
    return {
        "occupancy_speed_views": str(speed["views"]),
        "occupancy_speed_size": " x ".join(str(size) for size in speed["image_size_px"]),
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
        "occupancy_speed_pom_working": " x ".join(str(size) for size in speed["pom_working_px"]),
    }


def step_cost_fields() -> dict[str, str]:
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


SPEED_PARTS = {
    "decision-speed": decision_speed_fields,
    "follow-speed": follow_speed_fields,
    "msg-speed": msg_speed_fields,
    "registration-speed": registration_speed_fields,
    "occupancy-speed": occupancy_speed_fields,
    "step-cost": step_cost_fields,
}


def speed_fields() -> dict[str, str]:
    fields: dict[str, str] = {}
    for part in SPEED_PARTS.values():
        fields |= part()
    return fields


# The index: a headline figure per system, each from its page's JSON.


def headline_information_gain() -> list[str]:
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


def headline_face_capture() -> list[str]:
    rows = load("msg")
    m = {(row["scheduler"], row["seed"]): row["m"] for row in rows}
    seeds = sorted({row["seed"] for row in rows})
    return [
        "[Face capture (MSG)](face-capture.md)",
        f"over {len(seeds)} simulations `msg` labels M = {mean([m['msg', seed] for seed in seeds]):.3f} of the "
        f"tracklets, the naive scheduler {mean([m['naive', seed] for seed in seeds]):.3f}",
    ]


def headline_registration() -> list[str]:
    document = load("registration")
    loop = {row["pose_source"]: row for row in document["closed_loop"]}
    return [
        "[Registration](registration.md)",
        f"{document['registered']} of {document['views']} random live views register, focal length within "
        f"{document['focal_err_median_pct']:.3f} % (median); in the closed loop with the camera landing off its "
        f"commands, MOTA {pct(loop['registered']['mota'])} with the registered pose, "
        f"{pct(loop['commanded']['mota'])} with the commanded one",
    ]


def headline_follow() -> list[str]:
    closed = {row["tracker"]: row for row in load("follow")["closed_loop"]}
    return [
        "[The follow camera](follow-camera.md)",
        f"the particle filter keeps its person in view {closed['particle']['in_view_fraction']:.3f} of the time "
        f"over all PETS people, CSRT {closed['csrt']['in_view_fraction']:.3f}, "
        f"MIL {closed['mil']['in_view_fraction']:.3f}",
    ]


def headline_occupancy() -> list[str]:
    cell = {(row["people"], row["method"]): row for row in load("occupancy-synthetic-room")}
    people = sorted({count for count, _ in cell})
    return [
        "[The occupancy map (LPOM)](occupancy-map.md)",
        "in the rendered room, LPOM's MODA "
        + " and ".join(
            f"{pct(cell[count, 'lpom']['moda'])} ({count} {'person' if count == 1 else 'people'})" for count in people
        )
        + ", error "
        + " and ".join(f"{cell[count, 'lpom']['error_m']:.3f} m" for count in people),
    ]


def headline_long_runs() -> list[str]:
    default, long_run = load("soak-default"), load("soak-long-run")
    return [
        "[Long runs](long-runs.md)",
        f"{default['steps']:,} steps of the synthetic scene: with the long-run options MOTA {pct(long_run['mota'])}, "
        f"IDF1 {pct(long_run['idf1'])}, {long_run['id_switches_per_100_steps']:.1f} identity switches per 100 steps; "
        f"the default tracker {pct(default['mota'])}, {pct(default['idf1'])}, "
        f"{default['id_switches_per_100_steps']:.1f}",
    ]


def headline_network() -> list[str]:
    configs = {row["config"]: row for row in load("network-synthetic")}
    joint, independent, fixed_two = (configs[name] for name in ("2ptz-joint", "2ptz-independent", "2fixed"))
    return [
        "[The camera network](camera-network.md)",
        f"two PTZ cameras deciding jointly: MOTA {pct_pm(joint['mota'], joint['mota_se'])}, independently "
        f"{pct_pm(independent['mota'], independent['mota_se'])}, the same two fixed "
        f"{pct_pm(fixed_two['mota'], fixed_two['mota_se'])}",
    ]


def headline_live() -> list[str]:
    run = load("live-loop")
    return [
        "[The live loop](live.md)",
        f"against the virtual ONVIF camera at the recording's pace: MOTA {pct(run['mota_live'])} live against "
        f"{pct(run['mota_offline'])} for the offline run of the same steps, {run['decisions_per_s']:.1f} decisions "
        f"a second, 95 % of them on a picture at most {run['frame_age_s_p95']:.3f} s old",
    ]


HEADLINES = (
    headline_information_gain,
    headline_face_capture,
    headline_registration,
    headline_follow,
    headline_occupancy,
    headline_network,
    headline_live,
    headline_long_runs,
)


def index_fields() -> dict[str, str]:
    return {"headline_table": table(["system", "headline"], [headline() for headline in HEADLINES])}


PAGES: dict[str, Callable[[], dict[str, str]]] = {
    "index": index_fields,
    "information-gain": information_gain_fields,
    "face-capture": face_capture_fields,
    "long-runs": long_runs_fields,
    "camera-network": camera_network_fields,
    "occupancy-map": occupancy_map_fields,
    "follow-camera": follow_camera_fields,
    "registration": registration_fields,
    "live": live_fields,
    "speed": speed_fields,
}


def command_block(run: str, runs: dict) -> str:
    """The command of ``run`` as a ``bash`` block, marked not-run with its measured time."""
    entry = runs[run]
    seconds = entry["wall_s"]
    took = f"{round(seconds / 10) * 10:.0f} seconds" if seconds < 90 else f"{round(seconds / 60):.0f} minutes"
    return f"<!-- not-run: reproduces this table, about {took} on 2 cores -->\n```bash\n{entry['command']}\n```"


def render(page: str) -> str:
    """Page ``page`` as the build writes it."""
    template = (TEMPLATES / f"{page}.md.in").read_text()
    fields = PAGES[page]()
    runs = load("runs")
    used = set()

    def replace(match: re.Match) -> str:
        name = match.group(1)
        if name.startswith("command:"):
            return command_block(name.removeprefix("command:"), runs)
        if name not in fields:
            raise KeyError(f"templates/{page}.md.in names {{{{ {name} }}}}, which the page does not compute")
        used.add(name)
        return fields[name]

    text = PLACEHOLDER.sub(replace, template)
    unused = sorted(set(fields) - used)
    if unused:
        raise KeyError(f"templates/{page}.md.in does not use the page's fields {', '.join(unused)}")
    return GENERATED_NOTE.format(page=page) + text


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true", help="write nothing; exit 1 if a page differs")
    args = parser.parse_args(argv)
    differing = []
    for page in PAGES:
        text = render(page)
        path = RESULTS / f"{page}.md"
        if args.check:
            if not path.exists() or path.read_text() != text:
                differing.append(path)
        elif not path.exists() or path.read_text() != text:
            path.write_text(text)
            print(f"wrote {path}")
    if differing:
        names = ", ".join(str(path.relative_to(RESULTS.parent.parent)) for path in differing)
        print(f"not what docs/build_results.py writes: {names}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
