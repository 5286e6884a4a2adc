"""The kinematic safety shield against hand-computed cases."""

import numpy as np

from explaindrive.agent.shield import (
    is_safe,
    runtime_mask,
    safe_action_mask,
    shield,
    stop_in_time,
    training_mask,
)
from explaindrive.env.actions import action_index


def obs(v=10.0, lim=13.89, d_lead=200.0, dv=0.0, d_tl=200.0, tls=0, d_cross=200.0, cmd=0):
    return np.array([cmd, v, lim, d_lead, dv, d_tl, tls, d_cross], dtype=np.float32)


def test_speed_limit():
    assert is_safe(obs(v=10), action_index(3))  # 13 <= 13.89
    assert not is_safe(obs(v=12), action_index(3))  # 15 > 13.89
    assert is_safe(obs(v=17), action_index(-3))  # above the limit: braking hardest is allowed
    assert not is_safe(obs(v=17), action_index(-2))


def test_red_light_needs_a_stopping_option():
    # v_new = 10: 10 + (7 + 4 + 1) + 2 = 24 <= 30; v_new = 13: 13 + 22 + 2 = 37 > 30
    red = obs(v=10, d_lead=30, dv=10, d_tl=30, tls=2)
    assert is_safe(red, action_index(0))
    assert not is_safe(red, action_index(3))


def test_yellow_inside_the_dilemma_zone_means_go():
    # braking hardest from 13: 10 + (7 + 4 + 1) + 2 = 24 m > 10 m: it cannot stop, so it goes
    yellow = obs(v=13, d_lead=10, dv=13, d_tl=10, tls=1)
    assert is_safe(yellow, action_index(0))
    assert not is_safe(yellow, action_index(-1))  # slowing would strand it at red
    assert not is_safe(obs(v=13, d_lead=10, dv=13, d_tl=10, tls=2), action_index(0))


def test_yellow_it_can_still_stop_for_is_a_stop_line():
    # from 12 braking hardest: 9 + (6 + 3) + 2 = 20 m <= 29.9 m: it must stop
    yellow = obs(v=12, d_lead=29.9, dv=12, d_tl=29.9, tls=1)
    assert not is_safe(yellow, action_index(0))  # 12 + (9 + 6 + 3) + 2 = 32 > 29.9
    assert is_safe(yellow, action_index(-1))  # 11 + (8 + 5 + 2) + 2 = 28 <= 29.9


def test_real_leader_may_brake_at_9():
    # leader at 10 m/s, 12 m ahead: it stops within 1 m; ego at v_new = 10 needs 24 m
    assert not is_safe(obs(v=10, d_lead=12, dv=0), action_index(0))
    # with 23 m: 23 + 1 = 24 >= 10 + 12 + 2 = 24
    assert is_safe(obs(v=10, d_lead=23, dv=0), action_index(0))


def test_shield_keeps_the_best_safe_action():
    q = np.array([0, 1, 2, 3, 4, 5, 6], dtype=float)  # prefers +3
    free = shield(obs(v=5), q)
    assert free.action == action_index(3) and not free.overridden
    red = shield(obs(v=10, d_lead=30, dv=10, d_tl=30, tls=2), q)
    # +1: 11 + (8 + 5 + 2) + 2 = 28 <= 30; +2: 12 + (9 + 6 + 3) + 2 = 32 > 30
    assert red.action == action_index(1) and red.overridden
    wall = shield(obs(v=13, d_lead=1, dv=13, d_cross=1), q)
    assert wall.action == action_index(-3) and wall.overridden


def test_stop_in_time():
    # from 6 m/s with 4 steps left: -1 -> 5, then ceil(5 / 3) = 2 more: 3 <= 4
    assert stop_in_time(6.0, action_index(-1), 4)
    # with 1 step left only a standstill in this step will do
    assert not stop_in_time(3.0, action_index(-1), 1)
    assert stop_in_time(3.0, action_index(-3), 1)


def test_mask_of_a_batch_is_the_mask_of_each_row() -> None:
    rows = np.stack([obs(v=10, d_lead=30, dv=10, d_tl=30, tls=2), obs(v=12), obs(v=17)])
    mask = safe_action_mask(rows)
    assert mask.shape == (3, 7)
    for row, expected in zip(rows, mask, strict=True):
        assert np.array_equal(safe_action_mask(row), expected)
    assert mask[0].tolist() == [True] * 5 + [False] * 2  # +2/+3 cannot stop for the red light
    assert mask[1].tolist() == [True] * 5 + [False] * 2  # 14 and 15 m/s > 13.89
    assert mask[2].tolist() == [True] + [False] * 6  # above the limit: hardest braking only


def test_training_mask_allows_dilemma_braking_and_runtime_mask_does_not() -> None:
    yellow = obs(v=13, d_lead=10, dv=13, d_tl=10, tls=1)
    assert training_mask(yellow)[:3].all()  # -3, -2, -1 allowed in training
    assert not runtime_mask(yellow)[:3].any()  # the shield would override them
    assert training_mask(yellow)[3] and runtime_mask(yellow)[3]  # going on is fine in both


def test_stop_must_bring_the_standstill_closer() -> None:
    # STOP at 10 m/s: ceil(10/3) = 4 steps; v_new must need at most 3: <= 9 m/s
    stopping = obs(v=10, cmd=2)
    assert training_mask(stopping).tolist() == [True, True, True, False, False, False, False]
    # at 9 m/s: 3 steps; only 6 m/s (-3) needs 2
    assert training_mask(obs(v=9, cmd=2)).tolist() == [True] + [False] * 6
    # standing: only staying at 0 (the braking actions keep 0 m/s)
    assert training_mask(obs(v=0, cmd=2)).tolist() == [True] * 4 + [False] * 3
    assert training_mask(obs(v=10, cmd=0))[3:6].all()  # no such rule under FAST
    # STOP in the dilemma zone of a yellow light: keep the speed and clear the junction
    yellow = obs(v=13, d_lead=10, dv=13, d_tl=10, tls=1, cmd=2)
    assert runtime_mask(yellow).tolist() == [False] * 3 + [True] + [False] * 3


def test_where_nothing_is_safe_the_hardest_braking_is_allowed() -> None:
    wall = obs(v=13, d_lead=1, dv=13, d_cross=1)
    assert not safe_action_mask(wall).any()
    assert training_mask(wall).tolist() == [True] + [False] * 6
    assert runtime_mask(wall).tolist() == [True] + [False] * 6


def test_standing_at_the_line_when_it_turns_yellow_is_no_dilemma() -> None:
    # stopped 0.7 m before the line: it can stay; pulling away would cross at red
    standing = obs(v=0, d_lead=0.7, dv=0, d_tl=0.7, tls=1)
    assert runtime_mask(standing).tolist() == [True] * 4 + [False] * 3
    assert training_mask(standing).tolist() == [True] * 4 + [False] * 3


def test_dilemma_braking_is_left_to_the_rewards_unless_configured() -> None:
    # yellow 17.9 m ahead at 13 m/s: braking hardest covers 10 + 7 + 4 + 1 = 22 m > 17.9
    dilemma = obs(v=13, lim=13.9, d_lead=17.9, dv=13, d_tl=17.9, tls=1)
    allowed = [action_index(c) for c in (-3, -2, -1, 0)]  # +1 would exceed the limit
    assert np.flatnonzero(training_mask(dilemma)).tolist() == allowed
    assert np.flatnonzero(training_mask(dilemma, dilemma_braking=False)).tolist() == [
        action_index(0)
    ]
    assert np.flatnonzero(runtime_mask(dilemma)).tolist() == [action_index(0)]
