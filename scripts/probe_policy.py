"""Where a network settles on a free road and before a red light, probed without SUMO.

    python scripts/probe_policy.py src/explaindrive/agent/policies/fast.pt \
        src/explaindrive/agent/policies/comfort.pt [--light-m 100]

Both probes follow the network's greedy (bare) choice on made-up states, with the
environment's kinematics: the speed change applies at once and the car covers its new
speed in the 1 s step.

- Free road, per posted limit: from a standstill with nothing in range, the speed where
  the network stops accelerating (for a network trained with the speed limiter, through
  it), its share of the limit, the highest whole speed under the limit, and how far Q(+1)
  lies below the best action at the settled speed. Then, on speeds in steps of 0.1 m/s,
  the lowest speed from which Q(+1) stays below Q(0) up to the limit: +1 becomes illegal
  above the limit less 1 m/s, and how far under that the network gives it up shows how far
  the values pushed down there spread to legal speeds.
- Red light: from that settled speed, with a red light ``--light-m`` ahead as the leader,
  the approach until the car stands: the distance it stands from the line, its hardest
  braking and how far from the line it starts braking.

- Free road under speed noise (``--speed-noise SD``, m/s): the whole speeds as a Markov
  chain, the network choosing on readings with Gaussian noise of that deviation (sampled,
  ``--draws`` per speed). From the settled speed, after 1,000 steps, the mean speed and how
  many steps in 1,000 exceed the limit: a single reading cannot tell the limit's whole speed
  from the one below it, so a network keeps a margin only where its values do. A network
  trained on the controller's speed estimate chooses on the estimate instead, whose error
  settles at a smaller deviation (``agent/estimator.py:settled_sd``: 0.17 m/s under 0.6);
  the probe draws its readings with that deviation (independently, where the estimate's
  errors are correlated from step to step). The chain has whole speeds only, so it is not
  drawn for a network trained with the speed limiter (which lands a rise on the limit and
  cannot speed by rising): its columns read "-".

- Standing before a red line (50 km/h zone): at a standstill 9, 7 and 5 m before it, the value
  of staying, Q(0), and how far Q(+1), creeping a metre closer, lies from it.

These probes show, state by state, where a network settles; the evaluation's averages
(free-road speed share, standstill distance) only show the result.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
import torch

from explaindrive.agent.controller import QPolicy
from explaindrive.agent.estimator import settled_sd
from explaindrive.commands import Command
from explaindrive.env import state as S
from explaindrive.env.actions import SPEED_CHANGES_MPS, action_index, limited_speed, speed_change

LIMITS_KMH = (30, 40, 50, 60, 70)


def _obs(cmd: int, v: float, limit: float, light_m: float | None) -> np.ndarray:
    d = S.SENSOR_RANGE_M if light_m is None else light_m
    tls = S.LightState.GREEN if light_m is None else S.LightState.RED
    dv = 0.0 if light_m is None else v
    return np.asarray([cmd, v, limit, d, dv, d, float(tls), S.SENSOR_RANGE_M], np.float32)


def free_road(
    policy: QPolicy, cmd: int, limit: float, limiter: bool = False
) -> tuple[float, float]:
    """The speed the network settles at from a standstill (through the speed limiter with
    ``limiter``), and Q(+1) - max Q there."""
    v = 0.0
    for _ in range(40):
        q = policy.q_values(_obs(cmd, v, limit, None))
        change = speed_change(int(np.argmax(q)))
        v_new = min(limited_speed(v, change, limit if limiter else None), S.MAX_SPEED_MPS)
        if change <= 0 or v_new == v:
            return v, float(q[action_index(1)] - q.max())
        v = v_new
    return v, math.nan


def gives_up_plus_one(policy: QPolicy, cmd: int, limit: float) -> float:
    """The lowest speed, in steps of 0.1 m/s up to ``limit``, from which Q(+1) < Q(0) on a
    free road all the way to the limit."""
    speeds = np.arange(0.0, limit + 1e-9, 0.1)
    q = np.stack([policy.q_values(_obs(cmd, float(v), limit, None)) for v in speeds])
    above = q[:, action_index(1)] >= q[:, action_index(0)]
    last = np.flatnonzero(above)
    if not len(last):
        return 0.0
    return float(speeds[last[-1] + 1]) if last[-1] + 1 < len(speeds) else math.nan


def red_light(
    policy: QPolicy, cmd: int, limit: float, speed: float, light_m: float, limiter: bool = False
) -> tuple[float, int, float]:
    """From ``speed``, ``light_m`` before a red line: the distance the car stands from it,
    its hardest braking [m/s per step] and how far from the line it first brakes (through
    the speed limiter with ``limiter``)."""
    v, d = speed, light_m
    hardest, first_brake, still = 0, math.nan, 0
    for _ in range(200):
        change = speed_change(int(np.argmax(policy.q_values(_obs(cmd, v, limit, d)))))
        if change < 0 and math.isnan(first_brake):
            first_brake = d
        v_new = limited_speed(v, change, limit if limiter else None)
        hardest = min(hardest, round(v_new - v))
        v = v_new
        d -= v
        still = still + 1 if v == 0.0 else 0
        if still >= 3 or d < 0.0:
            break
    return d, hardest, first_brake


def noisy_cruise(
    policy: QPolicy, cmd: int, limit: float, start: float, sd: float, draws: int, seed: int = 0
) -> tuple[float, float]:
    """On a free road with noise of ``sd`` m/s on the speed reading, from ``start``: the mean
    speed over 1,000 steps and the expected steps above ``limit`` among them."""
    speeds = np.arange(0.0, S.MAX_SPEED_MPS + 1.0)
    rng = np.random.default_rng(seed)
    moves = np.zeros((len(speeds), len(speeds)))
    for i, v in enumerate(speeds):
        obs = np.repeat(_obs(cmd, float(v), limit, None)[None], draws, axis=0)
        obs[:, S.V_EGO] = np.clip(v + sd * rng.standard_normal(draws), 0.0, S.MAX_SPEED_MPS)
        with torch.no_grad():
            actions = policy.network(torch.from_numpy(obs)).argmax(dim=1).numpy()
        changes = np.asarray(SPEED_CHANGES_MPS)[actions]
        after = np.clip(v + changes, 0.0, S.MAX_SPEED_MPS).astype(int)
        moves[i] = np.bincount(after, minlength=len(speeds)) / draws
    share = np.zeros(len(speeds))
    share[int(start)] = 1.0
    mean, over = 0.0, 0.0
    for _ in range(1000):
        share = share @ moves
        mean += float(share @ speeds)
        over += float(share[speeds > limit + 1e-6].sum())
    return mean / 1000, over


STANDSTILL_M = (9.0, 7.0, 5.0)


def standstill(policy: QPolicy, cmd: int, limit: float) -> list[tuple[float, float]]:
    """At a standstill :data:`STANDSTILL_M` before a red line: Q(0) and Q(+1) - Q(0)."""
    out = []
    for d in STANDSTILL_M:
        q = policy.q_values(_obs(cmd, 0.0, limit, d))
        out.append((float(q[action_index(0)]), float(q[action_index(1)] - q[action_index(0)])))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("policies", type=Path, nargs="+", help="policy .pt files")
    parser.add_argument("--light-m", type=float, default=100.0, help="red light ahead [m]")
    parser.add_argument("--speed-noise", type=float, default=0.6, help="[m/s] reading's sd")
    parser.add_argument("--draws", type=int, default=20_000, help="noisy readings per speed")
    args = parser.parse_args()
    sd = args.speed_noise
    print(
        "| policy | limit km/h | settles m/s | share of limit | highest whole speed | "
        "Q(+1) - max | gives up +1 from m/s | brakes from m | hardest brake m/s | "
        f"stands before the line m | noise {sd} m/s: mean m/s | speeding steps /1,000 |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    policies = {path: QPolicy.load(path) for path in args.policies}
    for path, policy in policies.items():
        cmd = int(Command.parse(policy.card["mode"]))
        for kmh in LIMITS_KMH:
            limit = kmh / 3.6
            limiter = policy.speed_limiter
            settled, gap = free_road(policy, cmd, limit, limiter)
            gives_up = gives_up_plus_one(policy, cmd, limit)
            stand, hardest, first = red_light(policy, cmd, limit, settled, args.light_m, limiter)
            noisy = "- | -"
            if not limiter:
                seen_sd = settled_sd(sd) if policy.speed_estimate else sd
                mean, over = noisy_cruise(policy, cmd, limit, settled, seen_sd, args.draws)
                noisy = f"{mean:.2f} | {over:.2f}"
            print(
                f"| {path} | {kmh} | {settled:.4g} | {settled / limit:.2f} | "
                f"{math.floor(limit)} | {gap:.1f} | {gives_up:.1f} | {first:.0f} | {hardest} | "
                f"{stand:.1f} | {noisy} |"
            )
    metres = " / ".join(f"{d:.0f}" for d in STANDSTILL_M)
    print(f"\n| policy | standing {metres} m before a red line: Q(0) | Q(+1) - Q(0) |")
    print("|---|---|---|")
    for path, policy in policies.items():
        values = standstill(policy, int(Command.parse(policy.card["mode"])), 50 / 3.6)
        stay = " / ".join(f"{q:.1f}" for q, _ in values)
        creep = " / ".join(f"{dq:.1f}" for _, dq in values)
        print(f"| {path} | {stay} | {creep} |")


if __name__ == "__main__":
    main()
