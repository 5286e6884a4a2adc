"""Print the steps that led to each violation of one episode of a network, bare (or with
``--shield``, through the run-time shield).

    python scripts/trace_violations.py src/explaindrive/agent/policies/fast.pt \
        --seed 44 --traffic 0.75 [--obs-noise 3,0.9] [--scenario DIR] [--shield]

For every collision, red-light run or pedestrian-yield violation it prints the last
``--before`` steps: the time and the ego's route position, the observation, the
network's speed change, and the actions that the learning mask (the shipped recipe's)
and the run-time shield allow (one digit per action, -3 ... +3 m/s; for a network trained
with the speed limiter the episode and both masks run through it). With ``--obs-noise``
the network sees a noisy observation, as ``explaindrive evaluate --obs-noise`` has it (a
network trained on the speed estimate sees the estimate in place of the speed reading, and
the row shows it); each step then shows the true state on a second line. With
``--scenario`` the episode runs on a scenario directory (``explaindrive scenario random
--seed S --out DIR``), with ``--net NET --route FROM,TO [--demand FILE]`` on a network of
your own. A collision also prints SUMO's record of it (who hit whom, on which
lane).
"""

from __future__ import annotations

import argparse
from collections import deque
from pathlib import Path

from explaindrive.agent.controller import MergedController, QPolicy
from explaindrive.agent.shield import runtime_mask, training_mask
from explaindrive.commands import Command
from explaindrive.env.actions import speed_change
from explaindrive.env.config import EnvConfig
from explaindrive.env.noise import parse_noise
from explaindrive.env.state import STATE_NAMES, V_EGO
from explaindrive.env.urban_drive import UrbanDriveEnv
from explaindrive.evaluation.parsing import parse_stop_schedule, stops_to_schedule

VIOLATIONS = ("collision", "red_light_run", "ped_violation")


def _bits(mask: object) -> str:
    return "".join("1" if allowed else "0" for allowed in mask)  # type: ignore[attr-defined]


def _print_collisions(env: UrbanDriveEnv) -> None:
    """SUMO's record of this step's collisions: collider, victim, their kind and lane."""
    api = env.sumo
    for c in api.simulation.getCollisions():
        print(f"   SUMO: {c.collider} ({c.colliderType}, {c.colliderSpeed:.1f} m/s) hit "
              f"{c.victim} ({c.victimType}, {c.victimSpeed:.1f} m/s) on {c.lane} at "
              f"{c.pos:.1f} m: {c.type}")  # fmt: skip


def _own_network(args: argparse.Namespace) -> dict[str, object]:
    """The env's fields for ``--net``, ``--route`` and ``--demand``, if given."""
    if args.net is None:
        return {}
    if args.route is None:
        raise SystemExit("--net needs --route FROM_EDGE,TO_EDGE")
    fields: dict[str, object] = {"net_file": args.net, "route": tuple(args.route.split(","))}
    return fields | ({"demand_file": args.demand} if args.demand else {})


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("policy", type=Path, help="a policy .pt file")
    parser.add_argument("--seed", type=int, required=True)
    parser.add_argument("--traffic", type=float, default=1.0)
    parser.add_argument("--command", default=None, help="fast or comfort (default: the card's)")
    parser.add_argument("--stop-schedule", default=None, help="e.g. 60-75,150-165 [s]")
    parser.add_argument("--before", type=int, default=6, help="steps shown before each event")
    parser.add_argument("--obs-noise", default="0,0", help="SD_M,SD_MPS on what the network sees")
    parser.add_argument("--scenario", default=None, help="a scenario directory (default: paper)")
    parser.add_argument("--net", default=None, help="a network of your own (needs --route)")
    parser.add_argument("--route", default=None, help="FROM_EDGE,TO_EDGE on --net")
    parser.add_argument("--demand", default=None, help="background traffic on --net (.rou.xml)")
    parser.add_argument("--shield", action="store_true", help="act through the run-time shield")
    args = parser.parse_args()

    noise = parse_noise(args.obs_noise)
    agent = QPolicy.load(args.policy)
    command = Command.parse(args.command or agent.card.get("mode", "fast"))
    driver = MergedController(agent, agent, command, use_shield=args.shield)
    schedule = (
        stops_to_schedule(command.label, parse_stop_schedule(args.stop_schedule))
        if args.stop_schedule
        else ()
    )
    env = UrbanDriveEnv(
        config=EnvConfig(
            traffic_level=args.traffic,
            yellow_leader=agent.yellow_leader,
            speed_limiter=agent.speed_limiter,
            obs_noise=(noise.sd_m, noise.sd_mps),
            **({"scenario": args.scenario} if args.scenario else {}),
            **_own_network(args),
        )
    )
    obs, info = env.reset(
        seed=args.seed,
        options={"command": command.label, "traffic_level": args.traffic,
                 "command_schedule": [list(item) for item in schedule]},
    )  # fmt: skip
    driver.begin(noise.sd_mps)  # the speed estimate, as in `evaluate`
    print("time pos_m", *STATE_NAMES, "change", "learning", "shield", sep="\t")
    recent: deque[str] = deque(maxlen=args.before)
    done, events, steps = False, 0, 0
    try:
        while not done:
            driver.set_command(env.command)
            action = int(driver.act(obs))
            seen = driver.observation(obs)
            if driver.estimator is not None and agent.speed_estimate:
                seen[V_EGO] = driver.estimator.speed_mps or 0.0  # the estimate it acted on
            cells = [f"{env.time_s:.0f}s {env.route_pos_m:.1f}"]
            cells += [f"{x:.1f}" for x in seen]
            limiter = agent.speed_limiter
            cells += [f"{speed_change(action):+d}",
                      _bits(training_mask(seen, speed_limiter=limiter)),
                      _bits(runtime_mask(seen, limiter))]  # fmt: skip
            if "true_obs" in info:
                cells += ["\n  true\t", *(f"{x:.1f}" for x in info["true_obs"])]
            recent.append("\t".join(cells))
            obs, _, terminated, truncated, info = env.step(action)
            steps += 1
            done = terminated or truncated
            happened = [name for name in VIOLATIONS if info.get(name)]
            if happened:
                events += 1
                print(f"-- {', '.join(happened)} at {info['time_s']:.0f} s")
                print(*recent, sep="\n")
                if info.get("collision"):
                    _print_collisions(env)
    finally:
        env.close()
    print(f"{events} violation step(s) in {steps} steps")


if __name__ == "__main__":
    main()
