"""The top-down ``rgb_array`` view: the canvas's shapes by hand, and the live env's image."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import explaindrive
from explaindrive.env.render import COLOURS, Canvas
from explaindrive.env.scripted import CautiousDriver

RED, BLUE = (255, 0, 0), (0, 0, 255)


def test_a_band_covers_the_pixels_within_half_its_width() -> None:
    canvas = Canvas((0.0, 0.0), size_px=20, radius_m=10.0)  # 1 m per pixel, y up
    canvas.segment((-5.0, 0.0), (5.0, 0.0), 2.0, RED)
    drawn = np.all(canvas.image == RED, axis=2)
    # pixel centres at y = +-0.5 m are within 1 m of the line: rows 9 and 10
    assert drawn.sum(axis=1).nonzero()[0].tolist() == [9, 10]
    # x from -5 to 5 m, plus round ends reaching 1 m past them but only for |y| <= 0.87 m
    assert drawn[9].nonzero()[0].tolist() == list(range(4, 16))


def test_a_vehicle_lies_behind_its_front_bumper_along_its_heading() -> None:
    canvas = Canvas((0.0, 0.0), size_px=20, radius_m=10.0)
    canvas.box((0.0, 0.0), 90.0, length_m=4.0, width_m=2.0, colour=BLUE)  # heading east
    rows, cols = np.nonzero(np.all(canvas.image == BLUE, axis=2))
    assert sorted(set(cols.tolist())) == [6, 7, 8, 9]  # x from -4 m to 0 m
    assert sorted(set(rows.tolist())) == [9, 10]  # y from -1 m to 1 m


def test_the_registered_env_renders_the_ego_and_the_lights(make_env: Any) -> None:
    env = gym.make(explaindrive.ENV_ID, render_mode="rgb_array")
    try:
        obs, _ = env.reset(seed=3)
        driver = CautiousDriver()
        for _ in range(40):
            obs, *_ = env.step(driver(obs))
        image = env.render()
        assert image.shape == (400, 400, 3) and image.dtype == np.uint8
        ego = np.all(image == COLOURS["ego"], axis=2)
        rows, cols = np.nonzero(ego)
        assert 20 <= ego.sum() <= 200  # 5 m x 1.8 m at 3.33 px/m: about 100 px
        assert abs(rows.mean() - 200) < 12 and abs(cols.mean() - 200) < 12  # centred
        lights = sum(np.all(image == COLOURS[c], axis=2).sum() for c in ("red", "green"))
        assert lights > 0  # the ego stands 2.7 m before a red light (obs d_tl, tls)
    finally:
        env.close()


def test_render_modes_are_the_ones_that_exist(make_env: Any) -> None:
    assert explaindrive.env.urban_drive.UrbanDriveEnv.metadata["render_modes"] == [
        "human",
        "rgb_array",
    ]
    with pytest.raises(ValueError, match="render_mode must be None, 'human' or 'rgb_array'"):
        make_env(render_mode="rgb")
    env = make_env(render_mode="rgb_array")
    with pytest.raises(RuntimeError, match="call reset"):
        env.render()
    assert make_env().render() is None  # no render mode: nothing drawn


def test_check_env_with_rendering(make_env: Any) -> None:
    check_env(make_env(render_mode="rgb_array", max_steps=20))
