"""Each reward term against values computed by hand."""

import math

import pytest

from explaindrive.commands import Command
from explaindrive.env import reward as R


def test_constants_match_the_paper():
    assert (R.R_RESPECT, R.R_UNSAFE, R.R_CRITICAL) == (2.0, 10.0, 50.0)
    assert (R.HEADWAY_MU, R.HEADWAY_SIGMA) == (0.4226, 0.4365)
    assert R.TTC_THRESHOLD_S == 2.0


@pytest.mark.parametrize(
    ("ttc", "expected"),
    [
        (1.0, math.log(0.5)),  # -0.693147
        (0.5, math.log(0.25)),  # -1.386294
        (2.0, 0.0),  # log(1)
        (2.5, 0.0),  # above the threshold
        (math.inf, 0.0),
        (0.0, math.log(0.001 / 2.0)),  # floored: -7.600902
    ],
)
def test_f_ttc(ttc, expected):
    assert R.f_ttc(ttc) == pytest.approx(expected, abs=1e-9)


def test_f_headway_is_the_lognormal_density():
    # h = 1: z = (0 - 0.4226) / 0.4365 = -0.968156; exp(-z^2/2) = 0.625839;
    # 1 / (1 * 0.4365 * sqrt(2 pi)) = 0.913957 -> 0.571990
    assert R.f_headway(1.0) == pytest.approx(0.571990, abs=1e-6)
    # h = 2: z = (0.693147 - 0.4226) / 0.4365 = 0.619810; exp(-z^2/2) = 0.825239;
    # 1 / (2 * 0.4365 * sqrt(2 pi)) = 0.456979 -> 0.377116
    assert R.f_headway(2.0) == pytest.approx(0.377116, abs=1e-6)
    assert R.f_headway(math.inf) == 0.0
    assert R.f_headway(0.0) == 0.0


def test_ttc_and_headway_features():
    assert R.time_to_collision(10.0, 5.0) == 2.0
    assert R.time_to_collision(10.0, 0.0) == math.inf  # not closing in
    assert R.time_to_collision(10.0, -2.0) == math.inf
    assert R.time_headway(10.0, 5.0, 5.0) == 3.0  # (10 + 5) / 5
    assert R.time_headway(10.0, 5.0, 0.0) == math.inf
    assert R.jerk(2.0, -1.0) == 3.0


def test_speed_reward():
    assert R.speed_reward(14.0, 13.89, 3.0) == -10.0
    assert R.speed_reward(6.945, 13.89, 3.0) == pytest.approx(1.5)
    assert R.speed_reward(6.945, 13.89, 1.5) == pytest.approx(0.75)
    assert R.speed_reward(0.0, 8.33, 3.0) == 0.0


def test_traffic_rules_reward():
    assert R.traffic_rules_reward(violation=True, stopped=False, stop_reason=None) == -10.0
    assert R.traffic_rules_reward(violation=False, stopped=True, stop_reason="signal") == 2.0
    assert R.traffic_rules_reward(violation=False, stopped=True, stop_reason="queue") == 0.0
    assert R.traffic_rules_reward(violation=False, stopped=True, stop_reason=None) == -10.0
    assert R.traffic_rules_reward(violation=False, stopped=False, stop_reason=None) == 0.0


def test_stop_reward():
    assert R.stop_reward(0.0, -3) == 2.0
    assert R.stop_reward(0.0, 0) == 2.0  # standing still is respecting the stop
    assert R.stop_reward(5.0, 0) == -50.0
    assert R.stop_reward(5.0, 2) == -50.0
    assert R.stop_reward(5.0, -1) == 0.0


def _features(**kw):
    base = dict(
        speed_mps=10.0,
        speed_change_mps=1,
        limit_mps=13.89,
        ttc_s=1.0,
        headway_s=1.0,
        jerk_mps3=2.0,
        violation=False,
        stop_reason=None,
        collided=False,
    )
    base.update(kw)
    return R.StepFeatures(**base)


def test_fast_reward_terms():
    t = R.reward_terms(Command.FAST, _features())
    assert t.ttc == pytest.approx(2 * -0.693147, abs=1e-6)
    assert t.headway == pytest.approx(3 * 0.571990, abs=1e-5)
    assert t.jerk == 0.0
    assert t.speed == pytest.approx(3 * 10 / 13.89)
    # -1.386294 + 1.715970 + 2.159827 = 2.489503
    assert t.total == pytest.approx(2.489503, abs=1e-5)


def test_comfort_reward_terms():
    t = R.reward_terms(Command.COMFORT, _features(collided=True))
    assert t.headway == pytest.approx(1.5 * 0.571990, abs=1e-5)
    assert t.jerk == -4.0
    assert t.speed == pytest.approx(1.5 * 10 / 13.89)
    assert t.collision == -50.0
    # -1.386294 + 0.857985 - 4 + 1.079914 - 50 = -53.448395
    assert t.total == pytest.approx(-53.448395, abs=1e-5)


def test_stop_reward_terms_only_hold_the_stop_term():
    t = R.reward_terms(Command.STOP, _features(speed_change_mps=1))
    assert t.as_dict() == {
        "ttc": 0.0,
        "headway": 0.0,
        "jerk": 0.0,
        "traffic": 0.0,
        "speed": 0.0,
        "collision": 0.0,
        "stop": -50.0,
        "time": 0.0,
        "brake": 0.0,
        "approach": 0.0,
        "cruise": 0.0,
        "total": -50.0,
    }


def test_hard_brake_penalty_charges_braking_beyond_one_mps2():
    assert R.hard_brake_penalty(-1.0, 0.5) == 0.0
    assert R.hard_brake_penalty(2.0, 0.5) == 0.0
    assert R.hard_brake_penalty(-2.0, 0.5) == -0.5  # 0.5 * 1^2
    assert R.hard_brake_penalty(-3.0, 0.25) == -1.0  # 0.25 * 2^2


def test_passenger_fast_terms():
    # braking at -3 m/s per step while closing in on a stop line (a virtual leader)
    f = _features(
        speed_change_mps=-3, accel_mps2=-3.0, leader_gap_m=10.0, closing_speed_mps=10.0,
        leader_virtual=True,
    )  # fmt: skip
    t = R.reward_terms(Command.FAST, f, R.PASSENGER_RECIPE)
    assert t.ttc == pytest.approx(2 * -0.693147, abs=1e-6)
    assert t.headway == 0.0  # no real leader: a stop line earns no headway reward
    assert t.jerk == pytest.approx(-0.3 * 4)
    assert t.speed == pytest.approx(3 * 10 / 13.89)
    assert t.time == -0.75
    assert t.brake == -8.0  # 2.0 * (3 - 1)^2
    # before a stop line the room keeps no time gap: 10 - 2 = 8 m; stopping 10 m/s in it
    # needs 100 / 16 = 6.25 m/s^2: 0.3 * 4.75^2 = 6.76875
    assert t.approach == pytest.approx(-6.76875)
    assert t.cruise == 0.0  # not a free road
    # -1.386294 - 1.2 + 2.159827 - 0.75 - 8.0 - 6.76875 = -15.945217
    assert t.total == pytest.approx(-15.945217, abs=1e-5)


def test_passenger_approach_keeps_a_time_gap_behind_vehicles_only():
    # 8 m/s towards a standing queue 40 m ahead: the room is 40 - 2 - 8 = 30 m
    f = _features(speed_mps=8.0, leader_gap_m=40.0, closing_speed_mps=8.0)
    t = R.reward_terms(Command.COMFORT, f, R.PASSENGER_RECIPE)
    # 64 / 60 = 1.066667 m/s^2, 0.066667 beyond comfort's free 1.0: 2.0 * 0.066667^2
    assert t.approach == pytest.approx(-0.008889, abs=1e-6)
    assert R.reward_terms(Command.FAST, f, R.PASSENGER_RECIPE).approach == 0.0  # fast: 1.5
    f = _features(speed_mps=12.0, leader_gap_m=40.0, closing_speed_mps=12.0)
    t = R.reward_terms(Command.COMFORT, f, R.PASSENGER_RECIPE)
    # room 40 - 2 - 12 = 26 m; 144 / 52 = 2.769231 m/s^2; 2.0 * 1.769231^2 = 6.260355
    assert t.approach == pytest.approx(-6.260355, abs=1e-6)
    # a stop line 40 m ahead keeps no time gap: 144 / 76 = 1.894737 m/s^2; 2.0 * 0.894737^2
    f = _features(speed_mps=12.0, leader_gap_m=40.0, closing_speed_mps=12.0, leader_virtual=True)
    t = R.reward_terms(Command.COMFORT, f, R.PASSENGER_RECIPE)
    assert t.approach == pytest.approx(-1.601108, abs=1e-6)
    # with the default free 1.5 m/s^2 and weight 1: 0.394737^2
    assert R.approach_penalty(40.0, 12.0, 1.0) == pytest.approx(-0.155817, abs=1e-6)


@pytest.mark.parametrize(
    ("speed_mps", "free", "fast", "comfort"),
    [
        (5.0, True, -3 * (0.9 - 0.5), -5 * (0.9 - 0.5)),  # half the 10 m/s limit
        (8.0, True, -3 * 0.1, -5 * 0.1),  # at 80 %
        (9.0, True, 0.0, 0.0),  # at 90 %
        (10.0, True, 0.0, 0.0),
        (5.0, False, 0.0, 0.0),  # a leader or a light near: slow is no fault
    ],
)
def test_passenger_cruise_charges_a_slow_free_road(speed_mps, free, fast, comfort):
    f = _features(speed_mps=speed_mps, limit_mps=10.0, free_road=free)
    assert R.reward_terms(Command.FAST, f, R.PASSENGER_RECIPE).cruise == pytest.approx(fast)
    assert R.reward_terms(Command.COMFORT, f, R.PASSENGER_RECIPE).cruise == pytest.approx(comfort)
    assert R.reward_terms(Command.FAST, f).cruise == 0.0  # the paper's reward has no such term


def test_needed_deceleration():
    assert R.needed_deceleration(27.0, 10.0) == 2.0  # 100 / (2 * 25)
    assert R.needed_deceleration(2.0, 3.0) == 9.0  # the room is floored at 0.5 m
    assert R.needed_deceleration(50.0, -2.0) == 0.0  # opening the gap
    assert R.needed_deceleration(math.inf, 5.0) == 0.0  # nothing ahead
    assert R.approach_penalty(27.0, 10.0, 1.0) == -0.25  # (2 - 1.5)^2
    assert R.approach_penalty(100.0, 10.0, 1.0) == 0.0  # 0.51 m/s^2: gentle enough


def test_passenger_headway_pays_for_a_real_leader():
    f = _features(real_headway_s=1.0)
    t = R.reward_terms(Command.COMFORT, f, R.PASSENGER_RECIPE)
    assert t.headway == pytest.approx(1.5 * 0.571990, abs=1e-5)
    assert t.speed == pytest.approx(3 * 10 / 13.89)  # comfort's progress weighs as fast's
    assert t.jerk == -4.0


@pytest.mark.parametrize(
    ("gap_m", "paper", "passenger"),
    [(3.0, 2.0, 2.0), (1.0, 2.0, 2.0), (5.0, 2.0, 2.0), (8.0, 2.0, 0.0), (0.5, 2.0, 0.0)],
)
def test_standing_for_a_signal_pays_only_near_the_line(gap_m, paper, passenger):
    f = _features(
        speed_mps=0.0, speed_change_mps=-1, ttc_s=math.inf, headway_s=math.inf, jerk_mps3=0.0,
        stop_reason="signal", leader_gap_m=gap_m,
    )  # fmt: skip
    assert R.reward_terms(Command.COMFORT, f).traffic == paper
    t = R.reward_terms(Command.COMFORT, f, R.PASSENGER_RECIPE)
    assert t.traffic == passenger
    assert t.total == pytest.approx(passenger - 0.5)  # and the charge for time


@pytest.mark.parametrize(("gap_m", "paid"), [(4.5, 0.0), (4.0, 2.0), (1.0, 2.0), (0.9, 0.0)])
def test_a_stop_window_replaces_the_recipes_under_both_commands(gap_m, paid):
    recipe = R.PASSENGER_RECIPE.with_stop_window((1, 4))
    assert recipe.fast.stop_window_m == recipe.comfort.stop_window_m == (1.0, 4.0)
    assert recipe.comfort.cruise == R.PASSENGER_RECIPE.comfort.cruise  # nothing else moves
    f = _features(
        speed_mps=0.0, speed_change_mps=-1, ttc_s=math.inf, headway_s=math.inf, jerk_mps3=0.0,
        stop_reason="signal", leader_gap_m=gap_m,
    )  # fmt: skip
    for command in (Command.FAST, Command.COMFORT):
        assert R.reward_terms(command, f, recipe).traffic == paid


@pytest.mark.parametrize("window", [(4.0, 1.0), (2.0, 2.0), (-1.0, 3.0), (1.0, math.inf)])
def test_a_stop_window_must_be_ordered_and_finite(window):
    with pytest.raises(ValueError, match="0 <= min < max"):
        R.PASSENGER_RECIPE.with_stop_window(window)


def test_a_stop_pays_less_than_driving_at_the_limit():
    for w in (R.PASSENGER_RECIPE.fast, R.PASSENGER_RECIPE.comfort):
        assert w.signal_stop - w.time < w.speed - w.time


def test_recipes_are_named_and_stop_has_no_weights():
    assert R.REWARD_NAMES == ("paper", "passenger")
    assert R.RECIPES["paper"].fast.headway == 3.0
    with pytest.raises(ValueError, match="R2"):
        R.PAPER_RECIPE.weights(Command.STOP)
