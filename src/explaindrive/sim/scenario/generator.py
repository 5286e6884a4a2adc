"""Seeded generator of urban scenarios: each parameter drawn uniformly from its range here.

The ranges lie inside the limits :class:`~explaindrive.sim.scenario.params.ScenarioParams`
accepts. Seeds below :data:`TRAIN_SEED_START` are held out for evaluation
(``explaindrive evaluate --scenarios random:100-119``); training with ``--scenario random``
draws its scenarios from seeds at or above it, so the two never share a scenario.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np

from explaindrive.sim.scenario.limits import validate_seed
from explaindrive.sim.scenario.params import (
    MIN_TAPER_GAP_M,
    SIGNAL_FIXED_S,
    ScenarioParams,
    min_yellow_s,
)

TRAIN_SEED_START = 1_000_000
"""Scenario seeds of training draws start here; evaluation seeds lie below."""
TRAIN_SEED_POOL = 1_000
PAPER_DRAW_MULTIPLIER = 7_919  # a prime: spreads consecutive episode seeds over [0, 1000)
"""Training draws come from this many seeds, so built networks are reused (cached)."""

# (low, high, step) of each drawn value; block lengths [m], limits [km/h], times [s],
# rates [1/h].
RANGES: dict[str, tuple[float, float, float]] = {
    "approach_m": (150, 600, 10),
    "j1_to_zone_m": (60, 300, 10),
    "zone_to_crossing_m": (60, 300, 10),
    "crossing_to_zone_end_m": (60, 300, 10),
    "zone_end_to_j2_m": (60, 300, 10),
    "exit_m": (150, 500, 10),
    "limit_kmh": (30, 70, 10),
    "zone_limit_kmh": (20, 40, 10),  # and at most limit_kmh
    "side_limit_kmh": (30, 60, 10),
    "cycle_s": (50, 100, 5),
    "main_share": (0.5, 0.75, 0.05),  # of the green time a cycle leaves, to the main road
    "yellow_s": (3, 4, 1),  # and at least min_yellow_s of limit_kmh
    "all_red_s": (1, 2, 1),
    "zebra_peds_per_hour": (0, 200, 10),
    "j2_peds_per_hour": (0, 200, 10),
    "main_east": (600, 1100, 50),
    "main_west": (200, 700, 50),
    "j1_cross": (50, 250, 25),
    "j2_turn_south": (50, 250, 25),
    "j2_turn_north": (50, 250, 25),
    "j2_cross": (20, 120, 10),
    "priority_junction": (0, 1, 1),  # 0: no, 1: Z1 is a priority junction the ego yields at
    "z1_cross": (20, 120, 10),  # the main road yields to it: more jams it at high levels
    # each of the three below is on at 2 (a third of the draws), off at 0 and 1
    "turn_lanes": (0, 2, 1),  # J2's approach widens to a left-turn and a straight lane
    "turn_lane_m": (60, 100, 10),  # and at most zone_end_to_j2_m - 20
    "j2_left": (20, 120, 10),  # from the left-turn lane, only with turn_lanes
    "left_turn": (0, 2, 1),  # the ego turns left at J2 on a permissive green
    "joined_signals": (0, 2, 1),  # a junction K1 after J1 runs on J1's programme
    "joined_junction_m": (20, 40, 5),
}
FEATURE_ON = 2
"""The draw of ``turn_lanes``, ``left_turn`` and ``joined_signals`` that turns them on."""
_SIGNAL_KEYS = ("cycle_s", "main_share", "yellow_s", "all_red_s")
_DEMAND_KEYS = ("main_east", "main_west", "j1_cross", "j2_turn_south", "j2_turn_north",
                "j2_cross")  # fmt: skip


def _params(pick: Any) -> ScenarioParams:
    """Parameters from ``pick(name) -> value``, one call per drawn value in a fixed order."""
    data: dict[str, Any] = {}
    for key in ("approach_m", "j1_to_zone_m", "zone_to_crossing_m", "crossing_to_zone_end_m",
                "zone_end_to_j2_m", "exit_m", "limit_kmh", "zone_limit_kmh", "side_limit_kmh",
                "zebra_peds_per_hour", "j2_peds_per_hour"):  # fmt: skip
        data[key] = float(pick(key))
    data["zone_limit_kmh"] = min(data["zone_limit_kmh"], data["limit_kmh"])
    offset_j2 = None
    for light in ("j1", "j2"):
        cycle, share, yellow, all_red = (pick(k) for k in _SIGNAL_KEYS)
        cycle, all_red = int(cycle), int(all_red)
        yellow = max(int(yellow), min_yellow_s(data["limit_kmh"]))
        green = cycle - 2 * (yellow + all_red) - SIGNAL_FIXED_S[light.upper()]
        offset = 0 if light == "j1" else int(pick("offset") * cycle) % cycle
        offset_j2 = offset if light == "j2" else offset_j2
        data[light] = {"cycle_s": cycle, "main_green_s": round(share * green),
                       "yellow_s": yellow, "all_red_s": all_red, "offset_s": offset}  # fmt: skip
    data["demand"] = {key: float(pick(key)) for key in _DEMAND_KEYS}
    # drawn last, so that every value drawn before keeps its draw of earlier versions
    data["priority_junction"] = bool(pick("priority_junction"))
    data["demand"]["z1_cross"] = float(pick("z1_cross"))
    _junction_features(pick, data)
    return ScenarioParams.from_dict(data)


def _junction_features(pick: Any, data: dict[str, Any]) -> None:
    """Draw the turn lane, the ego's left turn and the joined signals into ``data``, after
    every other value (each value is drawn whether its feature is on or not)."""
    lanes_on, lane_m = pick("turn_lanes") == FEATURE_ON, float(pick("turn_lane_m"))
    lane_m = min(lane_m, data["zone_end_to_j2_m"] - MIN_TAPER_GAP_M)
    data["turn_lane_m"] = lane_m if lanes_on else None
    data["demand"]["j2_left"] = float(pick("j2_left"))
    data["left_turn"] = bool(pick("left_turn") == FEATURE_ON)
    joined_on, joined_m = pick("joined_signals") == FEATURE_ON, float(pick("joined_junction_m"))
    data["joined_junction_m"] = joined_m if joined_on else None


def random_params(seed: int) -> ScenarioParams:
    """The scenario of generator seed ``seed`` (the same seed gives the same scenario).

    Raises:
        ValueError: if ``seed`` is not an integer in [0, 2**31).
    """
    rng = np.random.default_rng([validate_seed(seed), 27])

    def pick(key: str) -> float:
        if key == "offset":
            return float(rng.random())
        lo, hi, step = RANGES[key]
        n = round((hi - lo) / step)
        return lo + step * int(rng.integers(0, n + 1))

    return _params(pick)


def extreme_params(end: Literal["low", "high"]) -> ScenarioParams:
    """The scenario with every drawn value at the low or the high end of its range."""

    def pick(key: str) -> float:
        if key == "offset":
            return 0.0 if end == "low" else 0.99
        lo, hi, _step = RANGES[key]
        return lo if end == "low" else hi

    return _params(pick)


def draws_paper_road(episode_seed: int, share: float) -> bool:
    """Whether a training draw for ``episode_seed`` is the paper's road, for a ``share`` of
    the episode seeds (a fixed function of the seed, so a run is reproducible)."""
    return share > 0.0 and (episode_seed * PAPER_DRAW_MULTIPLIER) % 1000 < share * 1000


def training_seed(episode_seed: int) -> int:
    """The generator seed a training draw uses for an episode seed (never held out)."""
    return TRAIN_SEED_START + episode_seed % TRAIN_SEED_POOL
