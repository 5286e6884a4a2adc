"""Action-space physics against hand-computed cases."""

import numpy as np
import pytest

from explaindrive.env.actions import braking_distance, braking_distances


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
