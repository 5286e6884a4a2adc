"""What the whole-speed action grid costs: SUMO's Krauss driver held to the speeds the
agents can reach.

The agents change their speed by whole m/s (the paper's seven actions) from a standstill,
so the highest speed they can hold under a 50 km/h limit (13.89 m/s) is 13 m/s, and 8 m/s
under 30 km/h (8.33 m/s). Krauss cruises at the limit. This script drives Krauss on the
same episodes twice, once as it is and once with its speed factor at ``--factor`` of the
limit (default 13 / 13.89, so that it cruises at 13.0 m/s at 50 km/h and 7.8 m/s at 30),
and prints the mean speed, travel time and ride figures of both, with the ratio.

    python scripts/krauss_whole_speeds.py --seeds 1000-1009 [--traffic 0.5,0.75,1.0,1.25,1.5]
"""

from __future__ import annotations

import argparse
import statistics
from concurrent.futures import ProcessPoolExecutor

from explaindrive.commands import Command
from explaindrive.env.metrics import EpisodeResult
from explaindrive.env.urban_drive import UrbanDriveEnv
from explaindrive.evaluation.aggregate import aggregate
from explaindrive.evaluation.parsing import SpecError, parse_levels, parse_seeds
from explaindrive.evaluation.runner import run_episode
from explaindrive.evaluation.spec import EpisodeSpec, parse_policy
from explaindrive.sim.scenario.files import EGO_ID
from explaindrive.sim.scenario.layout import TRAFFIC_LEVELS

WHOLE_SHARE_50 = 13.0 / (50.0 / 3.6)  # the highest whole speed under 50 km/h, as a share


def krauss_episode(seed: int, traffic: float, factor: float | None) -> EpisodeResult:
    """One Krauss episode of the paper's road; ``factor`` sets its speed factor."""
    spec = EpisodeSpec(parse_policy("krauss"), seed, traffic, Command.FAST.label, ())

    def hold(env: UrbanDriveEnv) -> None:
        env.sumo.vehicle.setSpeedFactor(EGO_ID, factor)

    return run_episode(spec, None if factor is None else hold).result


def _row(name: str, results: list[EpisodeResult]) -> tuple[float, float]:
    """Print one table row; returns the mean speed and the mean travel time."""
    a = aggregate(results)
    travel = statistics.fmean(r.travel_time_s for r in results)
    print(
        f"| {name} | {a.mean_speed_mps:.3f} | {travel:.1f} | {a.hard_brakes_per_episode:.2f} "
        f"| {100 * (a.slow_free_road_share or 0.0):.1f} % | {a.light_stop_gap_mean_m or 0:.1f} |"
    )
    return a.mean_speed_mps, travel


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", default="1000-1009")
    parser.add_argument("--traffic", default=",".join(f"{t:g}" for t in TRAFFIC_LEVELS))
    parser.add_argument("--factor", type=float, default=WHOLE_SHARE_50)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    if not 0.0 < args.factor <= 2.0:
        parser.error(f"--factor must lie in (0, 2], got {args.factor}")
    try:
        grid = [(s, t) for s in parse_seeds(args.seeds) for t in parse_levels(args.traffic)]
    except SpecError as exc:
        parser.error(str(exc))
    with ProcessPoolExecutor(args.workers) as pool:
        free = list(pool.map(krauss_episode, *zip(*grid, strict=True), [None] * len(grid)))
        held = list(pool.map(krauss_episode, *zip(*grid, strict=True), [args.factor] * len(grid)))
    print(f"{len(grid)} episodes each (seeds {args.seeds}, traffic {args.traffic})\n")
    print("| Krauss | mean speed m/s | travel time s | hard brakes /episode "
          "| free road < 60 % | standstill at lights m |")  # fmt: skip
    print("|---|---|---|---|---|---|")
    v0, t0 = _row("as it is", free)
    v1, t1 = _row(f"speed factor {args.factor:.3f}", held)
    print(f"\nmean speed ratio {v1 / v0:.3f}; travel time +{t1 - t0:.1f} s an episode")


if __name__ == "__main__":
    main()
