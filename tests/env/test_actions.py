"""Action-space physics against hand-computed cases."""

import numpy as np
import pytest

from explaindrive.env.actions import (
    braking_distance,
    braking_distances,
    can_stop_before,
    least_stopping_need,
    stopping_need,
)


@pytest.mark.parametrize(
    ("v", "brake", "expected"),
    [(13, 3, 22.0), (6, 3, 3.0), (3, 3, 0.0), (0, 3, 0.0), (10, 9, 1.0), (10, 4.5, 6.5)],
)
def test_braking_distance(v, brake, expected):
    # 13 -> 10 + 7 + 4 + 1; 6 -> 3; 10 at 9 -> 1; 10 at 4.5 -> 5.5 + 1
    assert braking_distance(v, brake) == pytest.approx(expected)


def test_braking_distances_of_a_batch_match_the_step_sum() -> None:
    speeds = np.array([13.0, 6.0, 3.0, 0.0, 9.5, 1.0])
    # 10+7+4+1, 3, 0, 0, 6.5+3.5+0.5, 0
    assert braking_distances(speeds).tolist() == pytest.approx([22, 3, 0, 0, 10.5, 0])


@pytest.mark.parametrize(
    ("v_new", "expected"),
    [
        (0.0, 0.0),  # standing still after the step: it moves no further
        (3.0, 3.0 + 0.0 + 2.0),  # one step at 3 m/s, then at rest
        (8.0, 8.0 + 7.0 + 2.0),  # 8 m, then 5 + 2 m, then the margin
        (9.0, 9.0 + 9.0 + 2.0),  # 9 m, then 6 + 3 m
    ],
)
def test_stopping_need(v_new: float, expected: float) -> None:
    assert stopping_need(v_new) == pytest.approx(expected)


@pytest.mark.parametrize(
    ("v", "expected"),
    [
        (3.0, 0.0),  # braking hardest stands still at once
        (11.0, 8.0 + 7.0 + 2.0),  # the step to 8 m/s, then as stopping_need(8)
        (12.0, 9.0 + 9.0 + 2.0),  # to 9 m/s
    ],
)
def test_least_stopping_need(v: float, expected: float) -> None:
    assert least_stopping_need(v) == pytest.approx(expected)


@pytest.mark.parametrize(
    ("v", "d", "expected"),
    [
        (11.0, 13.9, False),  # hardest braking to 8 m/s still needs 17 m
        (11.0, 17.0, True),
        (12.0, 15.7, False),  # to 9 m/s: 20 m
        (12.0, 24.9, True),
        (3.0, 0.0, True),  # braking hardest stands still at once
    ],
)
def test_can_stop_before(v: float, d: float, expected: bool) -> None:
    assert can_stop_before(v, d) is expected
