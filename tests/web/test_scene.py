"""The static scene read from the network file, and signal colours."""

from __future__ import annotations

import pytest

from explaindrive.sim.scenario.files import default_scenario
from explaindrive.web.scene import load_scene, signal_colour


def test_scene_from_the_shipped_network():
    scene = load_scene(default_scenario().net_file)
    assert scene.bounds == [0.0, 0.0, 1550.0, 300.0]
    kinds = {lane["kind"] for lane in scene.lanes}
    assert kinds == {"road", "sidewalk", "internal"}
    assert len(scene.crossings) == 2  # the unsignalised crossing and the one at J2
    # one head per signalised road approach: four at each of the two intersections
    assert sorted(s.tls_id for s in scene.signals) == ["J1"] * 4 + ["J2"] * 4
    for head in scene.signals:
        assert 0 <= head.x <= 1550 and 0 <= head.y <= 300
        assert 0 <= head.link_index < 12
    data = scene.to_json()
    assert set(data["signals"][0]) == {"tls", "x", "y"}


def test_scene_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError, match="not found"):
        load_scene(tmp_path / "none.net.xml")


@pytest.mark.parametrize(
    ("state", "index", "colour"),
    [
        ("rGy", 0, "red"),
        ("rGy", 1, "green"),
        ("rgy", 1, "green"),
        ("rGy", 2, "yellow"),
        ("rGy", 3, "off"),
        ("rGO", 2, "off"),
        ("", 0, "off"),
    ],
)
def test_signal_colour(state, index, colour):
    assert signal_colour(state, index) == colour


def test_scene_from_a_netgenerate_grid(netgen):
    from ..conftest import GRID_WITH_LIGHTS

    scene = load_scene(netgen("grid", *GRID_WITH_LIGHTS))
    # 5 x 5 junctions 200 m apart: 800 m square
    assert scene.bounds[2] - scene.bounds[0] == 800.0
    assert scene.bounds[3] - scene.bounds[1] == 800.0
    assert {lane["kind"] for lane in scene.lanes} >= {"road", "internal"}
    assert len({s.tls_id for s in scene.signals}) == 25  # every junction has a light
