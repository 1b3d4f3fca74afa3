"""The face-capture (MSG) page (``results/face-capture.md``): its fields and its headline."""

from __future__ import annotations

import math
from collections.abc import Sequence
from statistics import mean

from . import Load
from .formatting import fixed, paired, table

MSG_BIN_WIDTH = 5  # N_j/s bins centred on its multiples, as ptztrack experiment msg prints them
MSG_KEY_BIN = 15  # the paper's key bin


def msg_bin(nj_s: float) -> int:
    return int(math.floor(nj_s / MSG_BIN_WIDTH + 0.5)) * MSG_BIN_WIDTH


def population_sd(values: Sequence[float]) -> float:
    centre = mean(values)
    return math.sqrt(sum((value - centre) ** 2 for value in values) / len(values))


def fields(load: Load) -> dict[str, str]:
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


def headline(load: Load) -> list[str]:
    rows = load("msg")
    m = {(row["scheduler"], row["seed"]): row["m"] for row in rows}
    seeds = sorted({row["seed"] for row in rows})
    return [
        "[Face capture (MSG)](face-capture.md)",
        f"over {len(seeds)} simulations `msg` labels M = {mean([m['msg', seed] for seed in seeds]):.3f} of the "
        f"tracklets, the naive scheduler {mean([m['naive', seed] for seed in seeds]):.3f}",
    ]
