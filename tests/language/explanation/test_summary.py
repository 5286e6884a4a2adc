"""State record and environment summary."""

from __future__ import annotations

import numpy as np
import pytest

from explaindrive.language.explanation.summary import (
    StateRecord,
    describe_action,
    environment_summary,
)


def _obs(
    cmd: int, v: float, lim: float, lead: float, dv: float, tl: float, tls: int, cross: float
) -> np.ndarray:
    return np.array([cmd, v, lim, lead, dv, tl, tls, cross], dtype=np.float32)


def test_from_observation_maps_sensor_range_to_null() -> None:
    rec = StateRecord.from_observation(_obs(0, 8, 13.9, 200, 0, 200, 0, 200), -2)
    assert rec.request == "fast" and rec.action == -2
    s = rec.state
    assert (s.d_lead, s.dv, s.d_tl, s.tl_state, s.d_cross) == (None, None, None, None, None)
    assert s.v_ego == 8.0 and s.v_lim == pytest.approx(13.9)


def test_from_observation_keeps_objects_and_drops_virtual_leader() -> None:
    rec = StateRecord.from_observation(_obs(1, 9, 13.9, 22, 1.5, 35, 2, 120), 0)
    assert rec.request == "comfort"
    assert rec.state.d_lead == 22.0 and rec.state.dv == 1.5
    assert rec.state.tl_state == "red" and rec.state.d_tl == 35.0 and rec.state.d_cross == 120.0
    # a leader on the red stop line is the env's virtual leader, not a vehicle
    virt = StateRecord.from_observation(_obs(2, 9, 13.9, 35, 9, 35, 2, 200), -3)
    assert virt.state.d_lead is None and virt.state.dv is None and virt.request == "stop"


def test_from_observation_drops_the_leader_on_the_yield_line() -> None:
    # the env's virtual leader at a yield line 14.0 m ahead, seen (with noise) at 14.2 m
    held = _obs(0, 6, 13.9, 14.2, 6, 200, 0, 200)
    rec = StateRecord.from_observation(held, -2, yield_gap_m=14.04)
    assert (rec.state.d_lead, rec.state.dv, rec.state.d_yield) == (None, None, 14.0)
    # without the yield reading the same observation reads as a standing car
    plain = StateRecord.from_observation(held, -2)
    assert (plain.state.d_lead, plain.state.dv, plain.state.d_yield) == (14.2, 6.0, None)
    # the sensor range is no yield line
    assert StateRecord.from_observation(held, -2, yield_gap_m=200.0).state.d_yield is None


def test_a_car_before_the_yield_line_stays_a_car() -> None:
    # |14.2 - 16.3| = 2.1 m > the 2 m tolerance: a real car 2.1 m before the line
    rec = StateRecord.from_observation(_obs(0, 6, 13.9, 14.2, 1, 200, 0, 200), -1, yield_gap_m=16.3)
    assert (rec.state.d_lead, rec.state.dv, rec.state.d_yield) == (14.2, 1.0, 16.3)


def test_json_without_d_yield_still_reads_and_unknown_keys_are_refused() -> None:
    old = '{"request": "fast", "action": 0, "state": {"v_ego": 1, "v_lim": 10, "d_cross": null}}'
    assert StateRecord.from_json(old).state.d_yield is None
    given = '{"request": "fast", "action": -1, "state": {"v_ego": 5, "v_lim": 10, "d_yield": 9}}'
    assert StateRecord.from_json(given).state.d_yield == 9.0
    with pytest.raises(ValueError, match="d_give_way"):
        StateRecord.from_json(
            '{"request": "fast", "action": 0, "state": {"v_ego": 1, "v_lim": 10, "d_give_way": 9}}'
        )
    # beyond the 50 m cut-off a yield line is left out, as any object
    far = '{"request": "fast", "action": -1, "state": {"v_ego": 5, "v_lim": 10, "d_yield": 51}}'
    assert StateRecord.from_json(far).nearby().d_yield is None


def test_from_observation_rejects_bad_action_and_shape() -> None:
    with pytest.raises(ValueError):
        StateRecord.from_observation(_obs(0, 8, 13.9, 200, 0, 200, 0, 200), 5)
    with pytest.raises(ValueError):
        StateRecord.from_observation(np.zeros(7), 0)


def test_summary_cuts_off_at_50_m() -> None:
    rec = StateRecord.from_observation(_obs(0, 8, 13.9, 22, 1.5, 35, 2, 120), -2)
    # the red light (slack (35 - 16) / 8 = 2.4 s) leads; the leader (headway 2.75 s,
    # TTC 14.7 s) is no hazard and follows; the absent crossing comes last
    assert environment_summary(rec) == (
        "Ego speed 8.0 m/s (29 km/h); speed limit 13.9 m/s (50 km/h); urban area. "
        "Red traffic light in 35 m. Vehicle ahead at 22 m, closing at 1.5 m/s. "
        "No pedestrian crossing within 50 m. "
        "Most urgent: the red traffic light 35 m ahead (a comfortable stop needs 16 m)."
    )
    far = StateRecord.from_observation(_obs(1, 5, 8.3, 60, 0, 55, 1, 51), 0)
    text = environment_summary(far)
    assert "residential area" in text and "No vehicle ahead within 50 m." in text
    assert "No traffic light within 50 m." in text


def test_json_errors_are_clear(tmp_path) -> None:  # type: ignore[no-untyped-def]
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(ValueError, match="not valid JSON"):
        StateRecord.load(bad)
    bad.write_text('{"request": "fast", "action": 9, "state": {"v_ego": 1, "v_lim": 10}}')
    with pytest.raises(ValueError, match="action"):
        StateRecord.load(bad)
    bad.write_text(
        '{"request": "fast", "action": 0, "speed": 3, "state": {"v_ego": 1, "v_lim": 10}}'
    )
    with pytest.raises(ValueError, match="speed"):
        StateRecord.load(bad)
    with pytest.raises(FileNotFoundError):
        StateRecord.load(tmp_path / "missing.json")


def test_describe_action() -> None:
    assert describe_action(-3) == "braking hard (-3 m/s)"
    assert describe_action(0) == "keeping its speed"
    with pytest.raises(ValueError):
        describe_action(4)


def test_summary_lists_the_hazard_that_forces_the_action_first() -> None:
    # red light 15 m at 10 m/s (inside the 25 m stopping distance) before a crossing 30 m
    rec = StateRecord.model_validate(
        {
            "request": "fast",
            "action": -2,
            "state": {"v_ego": 10, "v_lim": 13.9, "d_tl": 15, "tl_state": "red", "d_cross": 30},
        }
    )
    text = environment_summary(rec)
    assert text.index("Red traffic light in 15 m") < text.index("Pedestrian crossing")
    assert text.endswith(
        "Most urgent: the red traffic light 15 m ahead (a comfortable stop needs 25 m)."
    )
    standing = StateRecord.model_validate(
        {"request": "fast", "action": 0, "state": {"v_ego": 0, "v_lim": 13.9}}
    )
    assert "Most urgent" not in environment_summary(standing)


def test_summary_names_the_junction_where_the_car_gives_way() -> None:
    rec = StateRecord.model_validate(
        {"request": "fast", "action": -2, "state": {"v_ego": 8, "v_lim": 13.9, "d_yield": 20}}
    )
    # the line 20 m ahead is the only hazard; a comfortable stop from 8 m/s needs 8^2 / 4 = 16 m
    assert environment_summary(rec) == (
        "Ego speed 8.0 m/s (29 km/h); speed limit 13.9 m/s (50 km/h); urban area. "
        "Junction in 20 m where we must give way: a car with priority is coming. "
        "No vehicle ahead within 50 m. No traffic light within 50 m. "
        "No pedestrian crossing within 50 m. "
        "Most urgent: giving way at the junction 20 m ahead (a comfortable stop needs 16 m)."
    )


def test_history_summary_in_words() -> None:
    from explaindrive.language.explanation.summary import history_summary

    def with_history(**h: float) -> StateRecord:
        return StateRecord.model_validate(
            {"request": "fast", "action": 0, "state": {"v_ego": 5.0, "v_lim": 13.9}, "history": h}
        )

    # SLOW_MARGIN_MPS = 3 m/s = 10.8 -> 11 km/h
    assert history_summary(with_history(slow_s=8.0, drop_mps=4.0)) == (
        "8 s at least 11 km/h under the limit; 4.0 m/s of speed lost in the last 3 s."
    )
    assert history_summary(with_history(slow_s=9.0, stopped_s=6.0)) == "standing for 6 s."
    assert history_summary(with_history()) == ""
