"""The decision at yellow: which stop lines are virtual leaders."""

from explaindrive.env.lights import AmberDecision
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
