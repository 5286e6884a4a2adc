"""Train a Stable-Baselines3 baseline (MaskablePPO) on the env and evaluate it like the D3QN.

The learner sees the trainer's curriculum through the env's wrappers
(:mod:`explaindrive.env.wrappers`) with a preset's settings (command, traffic levels, stop
injections, seed pool, reward, yellow-light rule, scenarios) and acts through the env's
safety mask (``action_masks()``, the run-time shield's rule). Training stops after the
preset's episode budget (passenger: 1,200 episodes). The preset's observation noise is not
applied (no wrapper draws it).

The model is saved as ``maskable_ppo.zip`` with ``sb3_baseline.json`` (its settings). The
evaluation plays the grid ``explaindrive evaluate`` plays (the paper's seeds 0-4, the five
traffic levels, the same episode specs) with the model acting through the mask, and prints
the same tables. Examples::

    python scripts/train_sb3_baseline.py train runs/sb3            # 1,200 episodes
    python scripts/train_sb3_baseline.py evaluate runs/sb3 --json runs/sb3/eval.json
    explaindrive report --external runs/sb3/eval.json    # beside the D3QN in docs/results.md
    python scripts/train_sb3_baseline.py train /tmp/sb3 --episodes 3 --max-steps 50
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

from explaindrive.agent.config import DEFAULT_PRESET, PRESETS, TrainConfig
from explaindrive.env.config import EnvConfig
from explaindrive.evaluation.paper import PAPER_SEEDS
from explaindrive.sim.scenario.layout import TRAFFIC_LEVELS

MODEL_FILE = "maskable_ppo.zip"
SETTINGS_FILE = "sb3_baseline.json"


def env_config(config: TrainConfig, max_steps: int | None = None) -> EnvConfig:
    """The env a preset trains in, with normalised observations (PPO's MLP input)."""
    fields: dict[str, Any] = {
        "normalize_obs": True,
        "reward": config.reward,
        "yellow_leader": config.yellow_leader,
        **config.scenario_fields(),
    }
    steps = max_steps or config.max_episode_steps
    if steps is not None:
        fields["max_steps"] = steps
    return EnvConfig.from_mapping(fields)


def make_training_env(config: TrainConfig, max_steps: int | None = None) -> Any:
    """The env with the preset's curriculum as wrappers."""
    import gymnasium as gym

    import explaindrive
    from explaindrive.env.wrappers import CommandSchedule, RandomTraffic, SeedPool, StopInjection

    env: Any = gym.make(explaindrive.ENV_ID, config=env_config(config, max_steps))
    if config.seed_pool is not None:
        env = SeedPool(env, config.seed_pool)
    env = RandomTraffic(env, config.traffic_levels)
    env = StopInjection(env, config.stop_gap_s, config.stop_duration_s, config.schedule_horizon_s)
    return CommandSchedule(env, (config.command,))


def train(out: Path, preset: str, episodes: int | None, max_steps: int | None, seed: int) -> Path:
    """Train MaskablePPO for the preset's episode budget (or ``episodes``); returns the model
    file."""
    from sb3_contrib import MaskablePPO
    from stable_baselines3.common.callbacks import StopTrainingOnMaxEpisodes

    config = PRESETS[preset]
    budget = episodes or config.episodes
    env = make_training_env(config, max_steps)
    out.mkdir(parents=True, exist_ok=True)
    try:
        model = MaskablePPO("MlpPolicy", env, seed=seed, verbose=0)  # seeds the env's resets
        model.learn(total_timesteps=10**9, callback=StopTrainingOnMaxEpisodes(budget))
    finally:
        env.close()
    path = out / MODEL_FILE
    model.save(path)
    settings = {
        "learner": "sb3_contrib.MaskablePPO (MlpPolicy, default hyperparameters)",
        "preset": preset,
        "episodes": budget,
        "timesteps": int(model.num_timesteps),
        "seed": seed,
        "env": env_config(config, max_steps).model_dump(mode="json"),
    }
    (out / SETTINGS_FILE).write_text(json.dumps(settings, indent=2) + "\n", encoding="utf-8")
    print(f"trained {budget} episodes ({model.num_timesteps} steps); wrote {path}")
    return path


def evaluate(
    out: Path, seeds: tuple[int, ...], levels: tuple[float, ...], max_steps: int,
    json_file: Path | None,
) -> list[Any]:  # fmt: skip
    """Play ``explaindrive evaluate``'s grid with the saved model and print its tables."""
    from sb3_contrib import MaskablePPO

    from explaindrive.env.metrics import EpisodeMetrics
    from explaindrive.env.urban_drive import UrbanDriveEnv
    from explaindrive.evaluation.runner import EpisodeRecord
    from explaindrive.evaluation.spec import PolicySpec, plan_run

    settings = json.loads((out / SETTINGS_FILE).read_text(encoding="utf-8"))
    model = MaskablePPO.load(out / MODEL_FILE, device="cpu")
    # the driver's view and judgement as trained; the road and traffic are the grid's
    env_fields = {k: settings["env"][k] for k in ("normalize_obs", "reward", "yellow_leader")}
    policy = PolicySpec("maskable_ppo", "agent", (str(out / MODEL_FILE),), "agent", "fast",
                        shield=False)  # fmt: skip
    plan = plan_run(policy, seeds, levels, max_steps=max_steps)
    records = []
    for spec in plan.episodes:
        config = EnvConfig.from_mapping({**env_fields, "traffic_level": spec.traffic_level,
                                         "max_steps": spec.max_steps})  # fmt: skip
        env = UrbanDriveEnv(config=config)
        metrics, speeds, commands = EpisodeMetrics(), [], []
        try:
            obs, info = env.reset(seed=spec.seed, options={
                "command": spec.command, "traffic_level": spec.traffic_level,
                "command_schedule": [list(s) for s in spec.schedule],
            })  # fmt: skip
            done = False
            while not done:
                action, _ = model.predict(obs, action_masks=env.action_masks(), deterministic=True)
                obs, reward, terminated, truncated, info = env.step(int(action))
                metrics.update(info, float(reward))
                speeds.append(float(info["speed_mps"]))
                commands.append(str(info["command"]))
                done = terminated or truncated
        finally:
            env.close()
        records.append(EpisodeRecord(spec, metrics.result(), tuple(speeds), tuple(commands), 0))
    print_tables(plan.name, records)
    if json_file is not None:
        from explaindrive.evaluation.schema import run_document, write_json

        write_json(json_file, [run_document(plan.name, records)])
        print(f"wrote {json_file}")
    return records


def print_tables(name: str, records: list[Any]) -> None:
    """The tables ``explaindrive evaluate`` prints for a policy."""
    from explaindrive.evaluation import tables
    from explaindrive.evaluation.aggregate import summarize

    summary = summarize(name, [(r.spec.traffic_level, r.result) for r in records])
    print(f"## {name} (MaskablePPO through the env's safety mask)\n")
    for table in (tables.paper_table, tables.level_table, tables.safety_table, tables.ride_table):
        print(table([summary]) + "\n")


def _numbers(text: str, kind: type) -> tuple[Any, ...]:
    try:
        return tuple(kind(x) for x in text.split(","))
    except ValueError:
        raise SystemExit(f"error: {text!r} is not a comma-separated list of numbers") from None


def main(argv: list[str] | None = None) -> int:
    """Command line: ``train OUT`` or ``evaluate OUT``."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="what", required=True)
    t = sub.add_parser("train", help="train MaskablePPO and save it in OUT")
    t.add_argument("out", type=Path)
    t.add_argument("--preset", default=DEFAULT_PRESET, choices=sorted(PRESETS))
    t.add_argument("--episodes", type=int, default=None, help="default: the preset's budget")
    t.add_argument("--max-steps", type=int, default=None, help="env step limit per episode")
    t.add_argument("--seed", type=int, default=0)
    e = sub.add_parser("evaluate", help="evaluate the model saved in OUT")
    e.add_argument("out", type=Path)
    e.add_argument("--seeds", default=",".join(str(s) for s in PAPER_SEEDS))
    e.add_argument("--traffic", default=",".join(f"{x:g}" for x in TRAFFIC_LEVELS))
    e.add_argument("--max-steps", type=int, default=1000)
    e.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    if args.what == "train":
        if args.episodes is not None and args.episodes < 1:
            parser.error("--episodes must be >= 1")
        train(args.out, args.preset, args.episodes, args.max_steps, args.seed)
        return 0
    if not (args.out / MODEL_FILE).is_file():
        parser.error(f"no {MODEL_FILE} in {args.out}; train first")
    seeds, levels = _numbers(args.seeds, int), _numbers(args.traffic, float)
    records = evaluate(args.out, seeds, levels, args.max_steps, args.json)
    return 0 if records else 1


if __name__ == "__main__":
    np.set_printoptions(precision=3)
    sys.exit(main())
