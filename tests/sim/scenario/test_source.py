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


def test_a_share_of_the_draws_is_the_papers_road(tmp_path: Path) -> None:
    source = ScenarioSource(tmp_path, "random", every=1, paper_share=0.25)
    # seed 0: 0 * 7919 % 1000 = 0 < 250, paper; seed 1: 919 >= 250, generated;
    # seed 3: 3 * 7919 = 23757 -> 757, generated; seed 9: 71271 -> 271, generated;
    # seed 13: 102947 -> 947; seed 12: 95028 -> 28, paper
    names = [source.for_episode(seed).name for seed in (0, 1, 12)]
    assert names == ["paper", "random-1000001", "paper"]
