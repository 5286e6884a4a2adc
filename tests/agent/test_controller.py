"""Policy files and the merged controller."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from explaindrive.agent.checkpoint import CheckpointError, load_policy, save_policy
from explaindrive.agent.controller import MergedController, QPolicy, shipped_policy_path
from explaindrive.agent.network import DuelingQNetwork
from explaindrive.commands import Command
from tests import helpers

OBS = np.array([0, 5.0, 13.9, 200.0, 0.0, 200.0, 0, 200.0], dtype=np.float32)


def constant_policy(tmp_path: Path, name: str, action: int) -> Path:
    """A network whose Q-values ignore the input and peak at ``action``."""
    return helpers.constant_policy(tmp_path / f"{name}.pt", action, {"name": name})


def test_policy_round_trip_and_raw_observations(tmp_path: Path) -> None:
    torch.manual_seed(0)
    net = DuelingQNetwork((8, 8))
    path, card_path = save_policy(tmp_path / "p", net, {"name": "p", "episodes": 3})
    loaded, card = load_policy(path)
    assert card == {"name": "p", "episodes": 3} and card_path.name == "p.json"
    x = torch.from_numpy(OBS[None])
    assert torch.equal(loaded(x), net(x))
    policy = QPolicy(loaded, card)
    assert policy.act(OBS) == int(net(x).argmax())


def test_policy_round_trip_keeps_the_near_range_features(tmp_path: Path) -> None:
    torch.manual_seed(0)
    net = DuelingQNetwork((8,), near_range_m=12.5)
    path, _ = save_policy(tmp_path / "near", net, {})
    loaded, _ = load_policy(path)
    assert loaded.near_range_m == 12.5
    x = torch.from_numpy(OBS[None])
    assert torch.equal(loaded(x), net(x))
    # a file written before the option holds no such entry: the 8 components alone
    payload = torch.load(path, weights_only=False)
    plain = DuelingQNetwork((8,))
    payload.pop("near_range_m")
    payload["state_dict"] = plain.state_dict()
    torch.save(payload, path)
    assert load_policy(path)[0].near_range_m is None


def test_bad_policy_files_name_the_file(tmp_path: Path) -> None:
    path = constant_policy(tmp_path, "fast", 6)
    path.with_suffix(".json").unlink()
    with pytest.raises(CheckpointError, match="policy card not found") as err:
        load_policy(path)
    assert str(path.with_suffix(".json")) in str(err.value)
    path.write_bytes(b"\x00garbage")
    with pytest.raises(CheckpointError, match="is not an explaindrive policy file") as err:
        load_policy(path)
    assert str(path) in str(err.value)
    with pytest.raises(CheckpointError, match="not found"):
        load_policy(tmp_path / "missing.pt")


def test_merged_controller_routes_commands(tmp_path: Path) -> None:
    ctrl = MergedController.from_files(
        constant_policy(tmp_path, "fast", 6), constant_policy(tmp_path, "comfort", 1)
    )
    assert ctrl.act(OBS) == 6
    ctrl.set_command("stop")  # stop keeps the fast agent, fed cmd = 2
    assert ctrl.active_agent is Command.FAST and ctrl.observation(OBS)[0] == 2.0
    assert ctrl.act(OBS) == 6
    ctrl.set_command(Command.COMFORT)
    assert ctrl.act(OBS) == 1 and ctrl.observation(OBS)[0] == 1.0
    ctrl.set_command(2)
    assert (ctrl.active_agent, ctrl.command, ctrl.act(OBS)) == (Command.COMFORT, Command.STOP, 1)
    with pytest.raises(ValueError, match="unknown command"):
        ctrl.set_command("turbo")


def test_the_controller_follows_the_env_s_command(tmp_path: Path) -> None:
    class Env:  # what holds the passenger's command
        command = Command.COMFORT

    ctrl = MergedController.from_files(
        constant_policy(tmp_path, "fast", 6), constant_policy(tmp_path, "comfort", 1)
    )
    env = Env()
    ctrl.follow(env)
    assert (ctrl.command, ctrl.active_agent, ctrl.act(OBS)) == (Command.COMFORT,) * 2 + (1,)
    env.command = Command.STOP  # stop keeps the comfort agent, fed cmd = 2
    ctrl.follow(env)
    assert (ctrl.active_agent, ctrl.observation(OBS)[0]) == (Command.COMFORT, 2.0)


def test_stop_reaches_the_agent_as_cmd_2(tmp_path: Path) -> None:
    """A network that brakes hard only when cmd = 2 (first input) shows the stop routing."""
    net = DuelingQNetwork((1,))
    with torch.no_grad():
        for p in net.parameters():
            p.zero_()
        net.trunk[0].weight[0, 0] = 1.0  # feature = cmd / 2
        net.advantage.weight[0, 0] = 1.0  # action 0 (-3 m/s) grows with cmd
        net.advantage.bias[3] = 0.75  # idle wins for cmd 0 and 1 (0, 0.5), loses for 2 (1.0)
    fast, _ = save_policy(tmp_path / "fast.pt", net, {})
    ctrl = MergedController.from_files(fast, constant_policy(tmp_path, "comfort", 3))
    assert ctrl.act(OBS) == 3
    ctrl.set_command("stop")
    assert ctrl.act(OBS) == 0


def test_the_controller_drives_in_its_networks_yellow_rule(tmp_path: Path) -> None:
    def policy(name: str, rule: str | None) -> Path:
        config = {} if rule is None else {"yellow_leader": rule}
        return helpers.constant_policy(tmp_path / f"{name}.pt", 1, {"config": config})

    # a card written before the field existed: the default rule
    assert MergedController.from_files(policy("a", None), policy("b", "decided")).yellow_leader == (
        "decided"
    )
    paper = MergedController.from_files(policy("c", "always"), policy("d", "always"))
    assert paper.yellow_leader == "always"
    mixed = MergedController.from_files(policy("e", "always"), policy("f", "decided"))
    with pytest.raises(CheckpointError, match="different yellow-light rules"):
        _ = mixed.yellow_leader


def test_a_trained_network_replaces_a_shipped_one(tmp_path: Path) -> None:
    run = tmp_path / "run"  # a training run directory holds its policy.pt
    run.mkdir()
    helpers.constant_policy(run / "policy.pt", 6, {"name": "mine"})
    ctrl = MergedController.from_package(fast=run)
    assert ctrl.policies[Command.FAST].card == {"name": "mine"}
    assert ctrl.act(OBS) == 6
    assert ctrl.policies[Command.COMFORT].card["name"] == "comfort"  # still the shipped one
    with pytest.raises(CheckpointError, match="not found"):
        MergedController.from_package(comfort=tmp_path / "missing.pt")


def test_shipped_policy_paths() -> None:
    assert shipped_policy_path("fast").name == "fast.pt"
    assert shipped_policy_path("comfort").parent.name == "policies"
    with pytest.raises(ValueError, match="no shipped policy"):
        shipped_policy_path("stop")


def test_stop_guard_keeps_the_latency_bound(tmp_path: Path) -> None:
    """A policy that brakes by only 1 m/s under STOP is pushed to stop within ceil(v/3) + 2."""
    gentle = QPolicy.load(constant_policy(tmp_path, "gentle", 2))  # always -1 m/s
    controller = MergedController(gentle, gentle, Command.STOP)
    speed, changes = 6.0, []
    while speed > 0:
        obs = OBS.copy()
        obs[1] = speed
        change = controller.act(obs) - 3
        changes.append(change)
        speed = max(0.0, speed + change)
    # bound ceil(6 / 3) + 2 = 4 steps: -1, -1, -1, then -3 from 3 m/s
    assert changes == [-1, -1, -1, -3]
    bare = MergedController(gentle, gentle, Command.STOP, use_shield=False)
    assert bare.act(OBS) == 2  # without the shield the network decides alone


def test_overrides_are_counted_with_and_without_the_shield(tmp_path: Path) -> None:
    """+3 m/s from 12 m/s would reach 15 > 13.9: the shield replaces it (or would)."""
    eager = QPolicy.load(constant_policy(tmp_path, "eager", 6))
    fast = OBS.copy()
    fast[1] = 12.0
    # shielded: the next-best action; the others tie at 0 and the first of them, -3, is safe
    for use_shield, expected in ((True, 0), (False, 6)):
        ctrl = MergedController(eager, eager, use_shield=use_shield)
        assert ctrl.act(OBS) == 6 and not ctrl.last_override  # 8 m/s: +3 is fine
        assert ctrl.act(fast) == expected and ctrl.last_override
        assert (ctrl.steps, ctrl.overrides, ctrl.last_network_action) == (2, 1, 6)


class _Seen(QPolicy):
    """A constant +1 m/s policy that records the speed it is shown."""

    def __init__(self, inner: QPolicy) -> None:
        super().__init__(inner.network, inner.card)
        self.speeds: list[float] = []

    def q_values(self, obs: np.ndarray) -> np.ndarray:
        self.speeds.append(round(float(obs[1]), 6))
        return super().q_values(obs)


def test_after_begin_a_network_trained_on_the_estimate_sees_it(tmp_path: Path) -> None:
    """Under 0.6 m/s of speed noise the controller drives on its estimate (gain by hand:
    0.0025 / (0.0025 + 0.36) = 0.0068966); before begin() on the readings."""
    card = {"mode": "fast", "config": {"speed_estimate": True}}
    seen = _Seen(QPolicy.load(helpers.constant_policy(tmp_path / "up.pt", 4, card)))  # +1 m/s
    ctrl = MergedController(seen, seen, use_shield=False)
    readings = (0.5, 1.6, 1.4)
    for reading in readings:
        obs = OBS.copy()
        obs[1] = reading
        ctrl.act(obs)
    assert seen.speeds == [0.5, 1.6, 1.4]
    seen.speeds.clear()
    ctrl.begin(0.6)  # a ride starts at rest
    for reading in readings:
        obs = OBS.copy()
        obs[1] = reading
        ctrl.act(obs)
    first = 1.0 + 0.0068966 * 0.6
    assert seen.speeds[0] == 0.0 and seen.speeds[1] == pytest.approx(first, abs=1e-5)
    assert seen.speeds[2] > first + 0.99  # +1 again, pulled down a little by 1.4
    assert ctrl.last_seen is not None and ctrl.last_seen[1] == pytest.approx(seen.speeds[2])
    ctrl.begin(0.0)  # a noise-free sensor: the readings again
    seen.speeds.clear()
    ctrl.act(OBS)
    assert seen.speeds == [5.0]


def _read_under_a_limit(ctrl: MergedController, readings: tuple[float, ...], limit: float) -> None:
    """A ride on a sensor with 0.6 m/s of noise: one step per speed reading, under a posted
    limit of ``limit``."""
    ctrl.begin(0.6)
    for reading in readings:
        obs = OBS.copy()
        obs[1], obs[2] = reading, limit
        ctrl.act(obs)


def test_the_estimate_knows_the_speed_limiter_cut_its_rise(tmp_path: Path) -> None:
    """With the speed limiter, +1 m/s from 1 m/s under a 1.5 m/s limit lands on 1.5: the
    estimate predicts 1.5, not 2.0, and a reading of 1.5 leaves it there."""
    card = {"mode": "fast", "config": {"speed_estimate": True, "speed_limiter": True}}
    seen = _Seen(QPolicy.load(helpers.constant_policy(tmp_path / "up.pt", 4, card)))  # +1 m/s
    ctrl = MergedController(seen, seen, use_shield=False)
    _read_under_a_limit(ctrl, (0.0, 1.0, 1.5, 1.5), limit=1.5)
    # 0 at rest, then 1.0 (the readings agree with the prediction), then the limit twice
    assert seen.speeds == pytest.approx([0.0, 1.0, 1.5, 1.5], abs=1e-6)


def test_a_network_trained_on_the_readings_keeps_them(tmp_path: Path) -> None:
    plain = _Seen(QPolicy.load(constant_policy(tmp_path, "plain", 4)))  # a card without it
    card = {"mode": "comfort", "config": {"speed_estimate": True}}
    estimating = _Seen(QPolicy.load(helpers.constant_policy(tmp_path / "e.pt", 4, card)))
    assert not plain.speed_estimate and estimating.speed_estimate
    ctrl = MergedController(plain, estimating, use_shield=False)
    ctrl.begin(0.6)
    for reading, command in ((0.5, "fast"), (1.6, "fast"), (2.4, "comfort")):
        ctrl.set_command(command)
        obs = OBS.copy()
        obs[1] = reading
        ctrl.act(obs)
    # the estimate runs under both: +1, +1 from rest -> about 2 m/s when comfort takes over
    assert plain.speeds == [0.5, 1.6]
    assert estimating.speeds[0] == pytest.approx(2.0, abs=0.02)


def test_the_car_has_the_limiter_when_either_network_was_trained_with_it(tmp_path: Path) -> None:
    """A fast network trained with the limiter and a comfort one trained without it: the
    car drives with the limiter under both, so the comfort network's estimate, too,
    predicts the rise the limiter lets through (1.5 from 1.0 under a 1.5 m/s limit)."""
    card = {"mode": "fast", "config": {"speed_estimate": True, "speed_limiter": True}}
    fast = QPolicy.load(helpers.constant_policy(tmp_path / "fast.pt", 4, card))
    plain_card = {"mode": "comfort", "config": {"speed_estimate": True}}
    comfort = _Seen(QPolicy.load(helpers.constant_policy(tmp_path / "c.pt", 4, plain_card)))
    assert fast.speed_limiter and not comfort.speed_limiter
    ctrl = MergedController(fast, comfort, command="comfort", use_shield=False)
    assert ctrl.speed_limiter
    assert not MergedController(comfort, comfort).speed_limiter
    _read_under_a_limit(ctrl, (0.0, 1.0, 1.5, 1.5), limit=1.5)
    assert comfort.speeds == pytest.approx([0.0, 1.0, 1.5, 1.5], abs=1e-6)
