"""The synthetic crowd's and the assumed person's parameters and their defaults, plain data that the
configuration maps onto (:mod:`ptztrack.config` takes its defaults from here)."""

from dataclasses import dataclass


@dataclass(frozen=True)
class PersonParameters:
    """The standing person the policies, the baselines and the occupancy maps assume when they do not
    know who stands there.

    height_m : their height (m), the middle of the synthetic crowd's heights (1.6-1.9 m).
    """

    height_m: float = 1.75


@dataclass(frozen=True)
class CrowdParameters:
    """Who walks in the synthetic scene (:func:`ptztrack.scene.synthetic.walk_people`).

    count : people; speed_m_s, height_m : [low, high] of the uniform draws per person;
    width_m : everybody's width; turn_rate_sigma_deg_s : stationary spread of the turn rate;
    enter_leave : people enter through the border and leave after a stay drawn from ``stay_s``;
    else they are there from the first frame to the last. stay_s : [low, high] seconds of the uniform
    draw of how long each person stays before walking out, with ``enter_leave``.
    paired_fraction : the share of the people who walk in pairs (:attr:`pairs`), the second of a pair
    ``pair_spacing_m`` to the left of the first, who leads. pair_spacing_m : metres between the two people
    of a pair, side by side.
    """

    count: int = 7
    speed_m_s: tuple[float, float] = (1.0, 1.5)
    height_m: tuple[float, float] = (1.6, 1.9)
    width_m: float = 0.62
    turn_rate_sigma_deg_s: float = 40.0
    enter_leave: bool = False
    stay_s: tuple[float, float] = (8.0, 20.0)
    paired_fraction: float = 0.85
    pair_spacing_m: float = 0.75

    @property
    def pairs(self) -> int:
        """How many pairs walk side by side (persons 0 and 1, 2 and 3, ...): the fraction of count / 2,
        rounded, never more than there are people for."""
        return min(round(self.paired_fraction * self.count / 2), self.count // 2)
