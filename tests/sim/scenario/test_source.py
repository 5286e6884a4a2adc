"""Which scenario each episode runs in; domain randomisation draws every K episodes."""

from __future__ import annotations

from pathlib import Path

from explaindrive.sim.scenario.source import ScenarioSource


def test_random_draws_a_new_scenario_every_k_episodes(tmp_path: Path) -> None:
    source = ScenarioSource(tmp_path, "random", every=2)
    names = [source.for_episode(seed).name for seed in (5, 6, 7, 8, 1005)]
    # seeds 5 and 7 start a draw: training seeds 1_000_000 + seed % 1000
    assert names == ["random-1000005", "random-1000005", "random-1000007", "random-1000007",
                     "random-1000005"]  # fmt: skip
    # each drawn network is built once and reused: the first (seed 1_000_000) and two draws
    assert len(list((tmp_path / "scenarios").iterdir())) == 3


def test_without_settings_it_is_the_papers_road(tmp_path: Path) -> None:
    scenario = ScenarioSource(tmp_path).for_episode(0)
    assert scenario.name == "paper" and scenario.route_edges[0] == "W0_J1"
