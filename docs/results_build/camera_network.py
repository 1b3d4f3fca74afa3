"""The camera-network page (``results/camera-network.md``): its fields and its headline."""

from __future__ import annotations

from statistics import mean

from . import Load
from .formatting import fixed, paired, pct, pct_pm, points, span, table


def fields(load: Load) -> dict[str, str]:
    return synthetic_network_fields(load) | pets_network_fields(load) | twin_fields(load) | scale_fields(load)


def synthetic_network_fields(load: Load) -> dict[str, str]:
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


def pets_network_fields(load: Load) -> dict[str, str]:
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


def twin_fields(load: Load) -> dict[str, str]:
    """The PETS network's synthetic twin: MOTA per configuration and calibration error."""
    document = load("pets-network-twin")
    rows = document["rows"]
    sigmas = list(dict.fromkeys(row["sigma_deg"] for row in rows))
    configs = list(dict.fromkeys(row["config"] for row in rows))
    cell = {(row["sigma_deg"], row["config"]): row for row in rows}
    body = [
        [f"{sigma:g} deg"]
        + [pct(cell[sigma, config]["mota"]) for config in configs]
        + [
            fixed(cell[sigma, "ptz+6fixed"]["false_positives"], 1),
            fixed(cell[sigma, "6fixed"]["false_positives"], 1),
            points(*paired(cell[sigma, "ptz+6fixed"]["mota_per_seed"], cell[sigma, "6fixed"]["mota_per_seed"])),
            points(*paired(cell[sigma, "ptz+6fixed"]["mota_per_seed"], cell[sigma, "ptz"]["mota_per_seed"])),
        ]
        for sigma in sigmas
    ]
    seeds = document["seeds"]
    return {
        "twin_seeds": str(len(seeds)),
        "twin_first_seed": str(seeds[0]),
        "twin_table": table(
            ["sigma"]
            + [f"`{config}`" for config in configs]
            + ["FP `ptz+6fixed`", "FP `6fixed`", "`ptz+6fixed` - `6fixed`", "`ptz+6fixed` - `ptz`"],
            body,
        ),
    }


def scale_fields(load: Load) -> dict[str, str]:
    """The network's closed loop timed at 1 to 64 cameras and two crowds: this machine's figures."""
    document = load("network-scale")
    body = [
        [
            str(row["cameras"]),
            str(row["people"]),
            f"{row['tracks']:.0f}",
            f"{row['decisions_per_s']:.1f}",
            f"{row['decisions_per_s_before']:.1f}",
            f"{row['decisions_per_s_replayed']:.1f}",
            fixed(row["belief_update_ms"], 1),
            f"{row['step_ms']:.0f}",
            "-" if row["cameras_per_actor"] is None else str(row["cameras_per_actor"]),
        ]
        for row in document["rows"]
    ]
    before, after = document["load_average"]
    cameras = [row["cameras"] for row in document["rows"]]
    return {
        "scale_cameras": f"{min(cameras)} to {max(cameras)}",
        "scale_executor": "in Ray actors" if document["executor"] == "ray" else "in the driver's process",
        "scale_cpus": str(document["cpus"]),
        "scale_steps": str(document["steps"]),
        "scale_warmup": str(document["warmup"]),
        "scale_load": f"{before:.2f} / {after:.2f}",
        "scale_table": table(
            [
                "cameras",
                "people",
                "tracks",
                "decisions/s",
                "before",
                "replayed",
                "update [ms]",
                "step [ms]",
                "cameras per actor",
            ],
            body,
        ),
    }


def headline(load: Load) -> list[str]:
    configs = {row["config"]: row for row in load("network-synthetic")}
    joint, independent, fixed_two = (configs[name] for name in ("2ptz-joint", "2ptz-independent", "2fixed"))
    return [
        "[The camera network](camera-network.md)",
        f"two PTZ cameras deciding jointly: MOTA {pct_pm(joint['mota'], joint['mota_se'])}, independently "
        f"{pct_pm(independent['mota'], independent['mota_se'])}, the same two fixed "
        f"{pct_pm(fixed_two['mota'], fixed_two['mota_se'])}",
    ]
