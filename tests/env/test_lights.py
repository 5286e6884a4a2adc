"""The decision at yellow: which stop lines are virtual leaders."""

import pytest

from explaindrive.env.actions import can_stop_before
from explaindrive.env.lights import AmberDecision, clears, stops_gently
from explaindrive.env.state import LightState

GREEN, YELLOW, RED = LightState.GREEN, LightState.YELLOW, LightState.RED


def test_red_is_a_leader_and_green_is_not() -> None:
    amber = AmberDecision()
    assert amber.is_leader("A", RED, 13.0, 5.0)
    assert not amber.is_leader("A", GREEN, 0.0, 50.0)


def test_a_yellow_seen_where_the_car_can_stop_is_a_leader_while_it_lasts() -> None:
    amber = AmberDecision()
    assert amber.is_leader("A", YELLOW, 12.0, 24.9)  # braking to 9 m/s needs 20 m
    # the car did not brake and is now in the dilemma zone: the decision holds
    assert amber.is_leader("A", YELLOW, 12.0, 12.9)
    assert amber.is_leader("A", RED, 12.0, 0.9)


def test_a_yellow_first_seen_in_the_dilemma_zone_is_driven_through() -> None:
    amber = AmberDecision()
    assert not amber.is_leader("A", YELLOW, 11.0, 13.9)  # braking to 8 m/s needs 17 m
    # slowing down later does not bring the leader back during that yellow
    assert not amber.is_leader("A", YELLOW, 8.0, 5.9)
    # it turned red before the car reached the line: red always holds
    assert amber.is_leader("A", RED, 5.0, 0.9)


def test_each_yellow_is_decided_afresh() -> None:
    amber = AmberDecision()
    assert not amber.is_leader("A", YELLOW, 11.0, 13.9)
    assert amber.is_leader("B", YELLOW, 11.0, 80.0)  # the next light
    amber.is_leader("B", GREEN, 11.0, 40.0)
    assert not amber.is_leader("B", YELLOW, 11.0, 13.9)  # its next yellow
    amber.is_leader(None, GREEN, 11.0, 200.0)  # no light in range
    assert amber.is_leader("B", YELLOW, 11.0, 60.0)


def test_with_the_papers_rule_every_yellow_is_a_leader() -> None:
    amber = AmberDecision(always=True)
    assert amber.is_leader("A", YELLOW, 11.0, 13.9)  # the dilemma zone too
    assert amber.is_leader("A", YELLOW, 8.0, 5.9)
    assert amber.is_leader("A", RED, 5.0, 0.9)
    assert not amber.is_leader("A", GREEN, 5.0, 0.9)


def test_gentle_rule_stops_where_two_m_s_per_step_will_do() -> None:
    # from 5 m/s braking by 2: 3 + 1 m, plus the 2 m margin = 6 m <= 20 m
    amber = AmberDecision.for_rule("gentle")
    assert stops_gently(5.0, 20.0) and amber.is_leader("A", YELLOW, 5.0, 20.0)
    assert amber.shown_colour(YELLOW, True) is YELLOW


def test_gentle_rule_drives_through_a_yellow_it_clears_in_two_steps() -> None:
    # 9 m/s, 16.7 m: braking by 2 needs 7 + 5 + 3 + 1 + 2 = 18 m > 16.7 m, though the
    # hardest braking (6 + 3 + 2 = 11 m) would stop; 2 x 9 = 18 m >= 16.7 + 1 m clears the line
    amber = AmberDecision.for_rule("gentle")
    assert not stops_gently(9.0, 16.7) and can_stop_before(9.0, 16.7) and clears(9.0, 16.7)
    assert not amber.is_leader("A", YELLOW, 9.0, 16.7)
    assert amber.shown_colour(YELLOW, False) is GREEN
    assert not amber.is_leader("A", YELLOW, 9.0, 7.7)  # the decision holds
    # the hardest-braking rule stops there, and shows the yellow as it is
    decided = AmberDecision.for_rule("decided")
    assert decided.is_leader("A", YELLOW, 9.0, 16.7)
    assert decided.shown_colour(YELLOW, False) is YELLOW


def test_gentle_rule_stops_hard_where_it_could_not_clear_the_line_in_time() -> None:
    # 13 m/s, 27 m: braking by 2 needs 11 + 25 + 2 = 38 m, the hardest 10 + 12 + 2 = 24 m;
    # 2 x 13 = 26 m < 27 + 1 m: going on would still be short of the line at red
    amber = AmberDecision.for_rule("gentle")
    assert not stops_gently(13.0, 27.0) and not clears(13.0, 27.0)
    assert amber.is_leader("A", YELLOW, 13.0, 27.0)


def test_gentle_rule_drives_through_the_dilemma_zone_and_red_always_binds() -> None:
    amber = AmberDecision.for_rule("gentle")
    assert not amber.is_leader("A", YELLOW, 13.0, 8.0)  # not even the hardest braking stops
    assert amber.is_leader("A", RED, 13.0, 0.5)
    assert amber.shown_colour(RED, True) is RED


def test_an_unknown_yellow_rule_is_named() -> None:
    with pytest.raises(ValueError, match="unknown yellow rule 'sometimes'"):
        AmberDecision.for_rule("sometimes")


def test_each_stop_line_of_a_joined_cluster_is_decided_when_its_yellow_is_first_seen() -> None:
    # one programme, two stop lines 29 m apart, both turning yellow at 12 m/s: the first is
    # 17.75 m ahead (stopping needs 20 m: through), the second 46.8 m (gently: 10 m this
    # step and 8 + 6 + 4 + 2 m after it, with a 2 m margin, 32 m: stop there)
    amber = AmberDecision(gentle=True)
    assert amber.leaders([("A1", YELLOW, 17.75), ("A2", YELLOW, 46.8)], 12.0) == [False, True]
    assert amber.leaders([("A1", YELLOW, 5.75), ("A2", YELLOW, 34.8)], 12.0) == [False, True]
    # past the first line, the second's decision holds: its yellow is two steps old, and
    # decided afresh (it clears within 2 s, as if its yellow had just begun) it is through
    assert amber.leaders([("A2", YELLOW, 22.8)], 12.0) == [True]
    assert not AmberDecision(gentle=True).is_leader("A2", YELLOW, 12.0, 22.8)
    # a red further on is a leader too; once a line is out of sight, its decision goes
    assert amber.leaders([("A2", YELLOW, 10.8), ("A3", RED, 60.0)], 12.0) == [True, True]
    amber.leaders([("B", GREEN, 150.0)], 12.0)
    assert amber.decided == {}
