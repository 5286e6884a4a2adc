"""The driving environment against a live SUMO (libsumo)."""

from __future__ import annotations

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import explaindrive
from explaindrive.env import state as S
from explaindrive.env.actions import action_index, least_stopping_need
from explaindrive.env.config import EnvConfig
from explaindrive.env.metrics import EpisodeMetrics
from explaindrive.env.ride_quality import is_free_road
from explaindrive.env.scripted import AlwaysAccelerate, CautiousDriver, ConstantSpeed
from explaindrive.sim.connection import SumoConnection


def run_episode(env, driver, seed, options=None, max_steps=2000):
    obs, _ = env.reset(seed=seed, options=options)
    observations, infos, rewards = [obs], [], []
    metrics = EpisodeMetrics()
    for _ in range(max_steps):
        obs, reward, terminated, truncated, info = env.step(driver(obs))
        observations.append(obs)
        infos.append(info)
        rewards.append(reward)
        metrics.update(info, reward)
        if terminated or truncated:
            break
    return np.array(observations), infos, rewards, metrics.result()


def test_check_env_passes(make_env):
    env = make_env()
    check_env(env, skip_render_check=True)


def test_registered_id_builds_the_env():
    import gymnasium as gym

    env = gym.make(explaindrive.ENV_ID, traffic_level=0.5)
    try:
        assert env.unwrapped.config.traffic_level == 0.5
        obs, _ = env.reset(seed=0)
        assert obs.shape == (8,)
    finally:
        env.close()


def test_same_seed_same_episode(make_env):
    env = make_env()
    a, _, ra, _ = run_episode(env, CautiousDriver(), seed=21)
    b, _, rb, _ = run_episode(env, CautiousDriver(), seed=21)
    c, _, _, _ = run_episode(env, CautiousDriver(), seed=22)
    assert a.shape == b.shape
    np.testing.assert_array_equal(a, b)
    assert ra == rb
    assert a.shape != c.shape or not np.array_equal(a, c)


def test_initial_observation(make_env):
    env = make_env()
    obs, info = env.reset(seed=3, options={"command": "comfort", "traffic_level": 0.5})
    assert obs[S.CMD] == 1.0
    assert obs[S.V_EGO] == 0.0
    assert obs[S.V_LIM] == pytest.approx(50 / 3.6, abs=0.01)
    assert info["traffic_level"] == 0.5
    assert env.observation_space.contains(obs)


def test_action_changes_speed_by_its_amount(make_env):
    env = make_env(traffic_level=0.5)
    env.reset(seed=1)
    speeds = []
    for change in (3, 2, -1, -3, -3):
        obs, *_ = env.step(action_index(change))
        speeds.append(float(obs[S.V_EGO]))
    assert speeds == [3.0, 5.0, 4.0, 1.0, 0.0]  # clipped at 0


def test_route_position_moves_by_the_distance_driven(make_env):
    env = make_env(traffic_level=0.5)
    env.reset(seed=1)
    start = env.route_pos_m
    for change in (3, 2):  # 3 then 5 m/s: 8 m in two 1 s steps
        _, _, _, _, info = env.step(action_index(change))
    assert env.route_pos_m - start == pytest.approx(info["distance_m"]) == pytest.approx(8.0)


def test_virtual_leader_on_red_and_for_pedestrians(make_env):
    env = make_env(traffic_level=0.5)
    seen_red = seen_ped = False
    for seed in range(20):
        obs_seq, infos, _, _ = run_episode(env, CautiousDriver(), seed=seed)
        for obs, info in zip(obs_seq[1:], infos, strict=True):
            real_gap = info["real_gap_m"]
            if obs[S.TLS] == 2 and obs[S.D_TL] < min(real_gap, S.SENSOR_RANGE_M):
                seen_red = True
                assert obs[S.D_LEAD] == pytest.approx(obs[S.D_TL], abs=1e-3)
                assert obs[S.DV] == pytest.approx(obs[S.V_EGO], abs=1e-3)  # leader speed 0
            if obs[S.D_CROSS] < min(real_gap, S.SENSOR_RANGE_M):
                seen_ped = True
                stop_line = obs[S.D_CROSS]
                if obs[S.TLS] != 0:
                    stop_line = min(stop_line, obs[S.D_TL])
                assert obs[S.D_LEAD] == pytest.approx(stop_line, abs=1e-3)
        if seen_red and seen_ped:
            break
    assert seen_red and seen_ped


class _IgnoresLights:
    """Follows real leaders like :class:`CautiousDriver` but drives through every light."""

    def __call__(self, obs):
        if abs(obs[S.D_LEAD] - obs[S.D_TL]) <= 0.5:  # the light's virtual leader
            obs = obs.copy()
            obs[S.D_LEAD] = S.SENSOR_RANGE_M
        return CautiousDriver()(obs)


def test_a_yellow_is_a_leader_only_where_the_car_could_stop_for_it(make_env):
    # Traffic 0.5, a driver that holds its speed through lights: on seed 16 the light turns
    # yellow 24.9 m ahead at 12 m/s (braking to 9 m/s and on needs 9 + 9 + 2 = 20 m, so the
    # car stops for it); on seed 33, 6.7 m ahead at 10 m/s (it needs 7 + 5 + 2 = 14 m > 6.7
    # m: the dilemma zone, driven through without a leader at the line).
    env = make_env(traffic_level=0.5)
    firsts = {}
    for seed in (16, 33):
        obs_seq, _, _, _ = run_episode(env, _IgnoresLights(), seed=seed)
        yellow = [i for i, o in enumerate(obs_seq) if o[S.TLS] == 1 and o[S.D_TL] < 200]
        first = obs_seq[yellow[0]]
        firsts[seed] = (float(first[S.V_EGO]), float(first[S.D_TL]), float(first[S.D_LEAD]))
        for i in yellow:  # the decision holds while the light stays yellow
            leads = obs_seq[i][S.D_LEAD] == pytest.approx(obs_seq[i][S.D_TL], abs=1e-3)
            assert leads == (seed == 16)
    assert firsts[16] == pytest.approx((12.0, 24.9, 24.9), abs=0.05)
    v, d_tl, d_lead = firsts[33]
    assert (v, d_tl) == pytest.approx((10.0, 6.7), abs=0.05) and d_lead > d_tl


def test_the_papers_rule_makes_the_dilemma_zone_yellow_a_leader(make_env):
    # The yellow of seed 33 above, 6.7 m ahead at 10 m/s, with yellow_leader="always".
    env = make_env(traffic_level=0.5, yellow_leader="always")
    obs_seq, _, _, _ = run_episode(env, _IgnoresLights(), seed=33)
    yellow = [i for i, o in enumerate(obs_seq) if o[S.TLS] == 1 and o[S.D_TL] < 200]
    first = obs_seq[yellow[0]]
    assert (first[S.V_EGO], first[S.D_TL]) == pytest.approx((10.0, 6.7), abs=0.05)
    for i in yellow:
        assert obs_seq[i][S.D_LEAD] == pytest.approx(obs_seq[i][S.D_TL], abs=1e-3)


def test_cautious_driver_breaks_no_rule(make_env):
    env = make_env()
    for seed in range(4):
        _, infos, _, res = run_episode(env, CautiousDriver(), seed=seed)
        assert infos[-1]["arrived"], f"seed {seed} did not finish"
        assert res.violations == 0, (seed, res)
        assert res.distance_m >= env.geometry.length_m - 10.0  # drove the whole route


def test_reckless_drivers_are_caught(make_env):
    env = make_env()
    _, infos, rewards, res = run_episode(env, AlwaysAccelerate(), seed=0)
    assert res.collisions + res.red_light_runs >= 1
    assert res.speeding_steps >= 1
    assert infos[-1]["collision"] and rewards[-1] <= -50.0
    caught = 0
    for seed in range(4):
        _, _, _, res = run_episode(env, ConstantSpeed(8), seed=seed)
        caught += res.collisions + res.red_light_runs + res.ped_violations
    assert caught >= 1


def test_command_schedule_and_set_command(make_env):
    env = make_env(traffic_level=0.5)
    obs, _ = env.reset(seed=4, options={"command_schedule": [(3, "stop"), (5, "comfort")]})
    cmds = [obs[S.CMD]]
    for _ in range(6):
        obs, reward, *_, info = env.step(action_index(1))
        cmds.append(obs[S.CMD])
    assert cmds == [0, 0, 0, 2, 2, 1, 1]
    env.unwrapped.set_command("stop")
    obs, reward, *_, info = env.step(action_index(1))
    assert info["command"] == "stop" and reward == -50.0  # R2: speeding up under STOP


def test_normalised_observations(make_env):
    env = make_env(normalize_obs=True)
    obs, _ = env.reset(seed=2)
    assert np.all(np.abs(obs) <= 1.0)
    assert env.observation_space.contains(obs)
    np.testing.assert_allclose(S.denormalize(obs)[S.V_LIM], 50 / 3.6, atol=0.01)


def test_info_carries_the_reward_terms(make_env):
    env = make_env()
    env.reset(seed=5)
    _, reward, _, _, info = env.step(action_index(2))
    terms = info["reward_terms"]
    assert set(terms) == {
        "ttc",
        "headway",
        "jerk",
        "traffic",
        "speed",
        "collision",
        "stop",
        "time",
        "brake",
        "approach",
        "cruise",
        "total",
    }
    assert terms["total"] == pytest.approx(reward)
    assert terms["speed"] == pytest.approx(3 * 2 / (50 / 3.6), abs=1e-3)


def test_route_geometry_matches_sumo(make_env):
    env = make_env()
    env.reset(seed=0)
    api = env.sumo
    ego_pos = env.geometry.edge_start_m[0] + api.vehicle.getLanePosition("ego")
    for light in env.geometry.lights:
        tls = {t[0]: t[2] for t in api.vehicle.getNextTLS("ego")}
        assert light.stop_line_m - ego_pos == pytest.approx(tls[light.tls_id], abs=0.05)
    last = env.geometry.edges[-1]
    lane_len = api.lane.getLength(f"{last}_1")
    assert env.geometry.length_m - ego_pos == pytest.approx(
        api.vehicle.getDrivingDistance("ego", last, lane_len), abs=0.05
    )


@pytest.mark.parametrize("bad_action", [7, -1, 2.5])
def test_bad_action_is_refused(make_env, bad_action):
    env = make_env()
    env.reset(seed=0)
    with pytest.raises(ValueError, match="outside the action space"):
        env.step(bad_action)


def test_bad_inputs_give_clear_errors(make_env, tmp_path):
    env = make_env()
    with pytest.raises(ValueError, match="unknown command 'turbo'"):
        env.reset(seed=0, options={"command": "turbo"})
    with pytest.raises(ValueError, match="unknown reset option"):
        env.reset(seed=0, options={"trafic_level": 1.0})
    with pytest.raises(ValueError, match="traffic level must be > 0"):
        env.reset(seed=0, options={"traffic_level": 0})
    with pytest.raises(ValueError, match="traffic level must be > 0"):
        EnvConfig(traffic_level=-1.0)
    with pytest.raises(ValueError, match="unknown env config key"):
        make_env(config={"max_step": 10})
    with pytest.raises(FileNotFoundError, match="network file not found"):
        make_env(net_file=tmp_path / "missing.net.xml")
    assert SumoConnection._libsumo_owner is None  # no SUMO left running
    env = make_env()
    env.reset(seed=0)  # and a new simulation starts fine
    with pytest.raises(RuntimeError, match="reset"):
        type(env)().step(0)


def test_truncation_is_distinct_from_termination(make_env):
    env = make_env(max_steps=5)
    env.reset(seed=0)
    for _ in range(5):
        _, _, terminated, truncated, _ = env.step(action_index(0))
    assert truncated and not terminated
    with pytest.raises(RuntimeError, match="episode is over"):
        env.step(action_index(0))


def test_pedestrians_do_not_step_in_front_of_the_ego_at_the_zebra(make_env):
    """While the ego is on the zebra, or could not stop before it any more, nobody steps on."""
    env = make_env()
    zebra = next(c for c in env.geometry.crossings if not c.signalized)
    length = env._ego_length_m
    held_steps = 0
    for seed in (0, 1, 14, 15):  # on 14 and 15 a pedestrian is held for the ego
        obs, _ = env.reset(seed=seed, options={"traffic_level": 1.25})
        api, driver = env.sumo, CautiousDriver()
        on_crossing = set(api.edge.getLastStepPersonIDs(zebra.crossing_edge))
        was_held: set[str] = set()
        for _ in range(400):
            front = env._episode().pos_m
            obs, _, terminated, truncated, info = env.step(driver(obs))
            assert not info["collision"], seed
            now = set(api.edge.getLastStepPersonIDs(zebra.crossing_edge))
            if zebra.stop_line_m <= front and front - length < zebra.end_m:
                assert now <= on_crossing, (seed, front, now - on_crossing)
            held = {p for p in api.person.getIDList() if env._episode().kerb.holds(p)}
            held_steps += len(held)
            # held through the step: they stood still (those held after it stop next step)
            assert all(api.person.getSpeed(p) == 0.0 for p in held & was_held)
            on_crossing, was_held = now, held
            if terminated or truncated or front > zebra.end_m + 50.0:
                break
    assert held_steps > 0  # the rule was exercised


@pytest.mark.parametrize(("speed", "seed"), [(6, 5), (7, 7)])
def test_a_pedestrian_reaching_the_kerb_waits_for_a_car_that_cannot_stop(make_env, speed, seed):
    """On these episodes a pedestrian reaches the zebra's kerb during the step that leaves
    the car unable to stop before it; they are held at once, not seen stepping out."""
    env = make_env(traffic_level=0.5, max_steps=400)
    zebra = next(c for c in env.geometry.crossings if not c.signalized)
    obs, _ = env.reset(seed=seed)
    api, driver, checked = env.sumo, ConstantSpeed(speed), 0
    while True:
        obs, _, terminated, truncated, _ = env.step(driver(obs))
        ep = env._episode()
        reach = least_stopping_need(ep.speed_mps)
        if 0.0 < zebra.stop_line_m - ep.pos_m < reach:
            at_kerb = [p for wa in zebra.walkingareas for p in api.edge.getLastStepPersonIDs(wa)
                       if api.person.getNextEdge(p) == zebra.crossing_edge]  # fmt: skip
            assert all(ep.kerb.holds(p) for p in at_kerb), (ep.pos_m, at_kerb)
            checked += len(at_kerb)
        if terminated or truncated or ep.pos_m > zebra.end_m:
            break
    assert checked > 0  # someone did reach the kerb then


def test_noise_reaches_the_observation_and_not_the_judgement(make_env):
    def drive(env):
        obs, info = env.reset(seed=4)
        seen, true, rewards = [obs], [info.get("true_obs", obs)], []
        for _ in range(5):
            obs, reward, _, _, info = env.step(action_index(2))
            seen.append(obs)
            true.append(info.get("true_obs", obs))
            rewards.append(reward)
        return seen, true, rewards

    clean_seen, _, clean_rewards = drive(make_env(traffic_level=0.5))
    noisy_seen, noisy_true, noisy_rewards = drive(make_env(traffic_level=0.5, obs_noise=(2.0, 0.6)))
    np.testing.assert_array_equal(np.array(noisy_true), np.array(clean_seen))
    assert noisy_rewards == pytest.approx(clean_rewards)  # rewards come from the true state
    assert [o[S.V_LIM] for o in noisy_seen] == [o[S.V_LIM] for o in clean_seen]
    assert noisy_seen[-1][S.V_EGO] != clean_seen[-1][S.V_EGO]


def test_reset_option_sets_the_episode_noise(make_env):
    env = make_env(traffic_level=0.5)
    obs_a, info = env.reset(seed=4, options={"obs_noise": [1.0, 0.3]})
    assert "true_obs" in info
    obs_b, _ = env.reset(seed=4, options={"obs_noise": [1.0, 0.3]})
    np.testing.assert_array_equal(obs_a, obs_b)  # the same seed, the same noise
    _, info = env.reset(seed=4)
    assert "true_obs" not in info


def test_the_ego_enters_the_busiest_road(make_env) -> None:
    # level 2.0: 1800 veh/h towards J1, whose main green passes about 1100; when the entry
    # is cleared after 10 s, the cars waiting to enter there are dropped too, so the ego
    # enters in the step after that clear: 11 steps of waiting, then 1 (seed 7 stayed
    # blocked for 60 s without that rule)
    env = make_env(traffic_level=2.0, max_steps=5)
    env.reset(seed=7)
    assert env.sumo.simulation.getTime() == 180 + 12


def test_a_blocked_entry_at_175_drops_the_queue_after_30_s(tmp_path) -> None:
    from explaindrive.env.urban_drive import UrbanDriveEnv
    from explaindrive.evaluation.scenarios import random_case

    # generated scenario 108 at 1.75 keeps its first road blocked: clearing its first 30 m
    # every 10 s is not enough, so at 30 s the cars queued to enter go too and the ego
    # enters in the next step, 32 s after the 180 s warm-up (it stayed out for 60 s before)
    env = UrbanDriveEnv(dict(random_case(108, tmp_path).fields) | {"cache_dir": tmp_path})
    try:
        env.reset(seed=0, options={"traffic_level": 1.75})
        assert env.sumo.simulation.getTime() == 180 + 32
    finally:
        env.close()


def test_the_cruise_term_charges_exactly_the_slow_free_road_steps(make_env):
    env = make_env(reward="passenger", traffic_level=0.5, max_steps=120)
    obs, _ = env.reset(seed=3, options={"command": "comfort"})
    driver, charged, slow_free = CautiousDriver(), 0, 0
    for _ in range(120):
        obs, _r, terminated, truncated, info = env.step(driver(obs))
        share = info["speed_mps"] / info["posted_limit_mps"]
        cruise = info["reward_terms"]["cruise"]
        if is_free_road(info) and share < 0.9:
            slow_free += 1
            assert cruise == pytest.approx(-5.0 * (0.9 - share))  # comfort's weight
        else:
            assert cruise == 0.0
        charged += cruise < 0
        if terminated or truncated:
            break
    assert charged == slow_free > 0  # the start from standstill is slow on a free road


def test_the_env_reads_its_network_once(monkeypatch):
    import explaindrive.env.urban_drive as urban_drive

    calls = []
    real = urban_drive.read_net
    monkeypatch.setattr(urban_drive, "read_net", lambda f: calls.append(f) or real(f))
    env = urban_drive.UrbanDriveEnv()
    try:
        assert len(calls) == 1
        assert env.geometry.crossings  # the route geometry and the crossing lanes from it
        assert set(env._crossing_lanes) == {c.crossing_edge for c in env.geometry.crossings}
    finally:
        env.close()
