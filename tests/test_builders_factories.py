import math
from dataclasses import replace

from ptztrack.builders.factories import tracker_parameters
from ptztrack.config import scenario_from_dict
from ptztrack.track.parameters import TrackerParameters


def test_the_tracker_section_maps_onto_the_trackers_parameters_and_their_defaults():
    leaving = {"people": {"enter_leave": True}}
    assert tracker_parameters(scenario_from_dict(leaving)) == TrackerParameters()
    tuned = scenario_from_dict({**leaving, "tracker": {"gate_probability": 0.95, "acceleration_sigma_m_s2": 0.5}})
    assert tracker_parameters(tuned) == replace(TrackerParameters(), gate_probability=0.95, acceleration_sigma_m_s2=0.5)


def test_uncertainty_deletes_tracks_only_where_people_can_leave():
    bound = {"tracker": {"max_position_sigma_m": 1.0}}
    assert tracker_parameters(scenario_from_dict(bound)).max_position_sigma_m == math.inf
    leaving = scenario_from_dict({**bound, "people": {"enter_leave": True}})
    assert tracker_parameters(leaving).max_position_sigma_m == 1.0
