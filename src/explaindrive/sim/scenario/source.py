"""Which scenario an environment's episodes run in: the paper's road, a scenario directory,
an own network, or a new generated scenario every few episodes (domain randomisation)."""

from __future__ import annotations

from pathlib import Path

from explaindrive.sim.scenario.choice import RANDOM
from explaindrive.sim.scenario.files import ScenarioFiles, default_scenario


class ScenarioSource:
    """The scenario of each episode.

    Args:
        cache_dir: where built networks, demand and warm-up states are kept.
        scenario: a scenario directory, :data:`RANDOM`, or ``None``.
        net_file: an own network (with ``route``), or the paper's layout on another build
            of its network (without).
        route: ``(from_edge, to_edge)`` of the ego's route on ``net_file``.
        demand_file: background demand on ``net_file`` (else generated trips).
        every: under :data:`RANDOM`, episodes per drawn scenario.
        paper_share: under :data:`RANDOM`, the share of draws that are the paper's road.

    Raises:
        ValueError: (:class:`~explaindrive.sim.network.NetworkError` or
            :class:`~explaindrive.sim.scenario.directory.ScenarioDirError`) naming what
            cannot be used.
    """

    def __init__(
        self,
        cache_dir: Path,
        scenario: str | None = None,
        net_file: Path | None = None,
        route: tuple[str, str] | None = None,
        demand_file: Path | None = None,
        every: int = 1,
        paper_share: float = 0.0,
    ) -> None:
        self._cache = cache_dir
        self._every = every
        self._paper_share = paper_share
        self._episodes = 0
        self.random = scenario == RANDOM
        if self.random:
            from explaindrive.sim.scenario.generator import TRAIN_SEED_START

            self.current = self._draw(TRAIN_SEED_START)
        elif scenario is not None:
            from explaindrive.sim.scenario.directory import load_scenario_dir

            self.current = load_scenario_dir(Path(scenario), cache_dir)
        elif route is not None:
            from explaindrive.sim.network import NetworkError, own_network

            if net_file is None:
                raise NetworkError("a route needs the network it runs on (net_file)")
            self.current = own_network(net_file, route, cache_dir, demand_file)
        elif net_file is not None:
            self.current = ScenarioFiles(net_file=net_file, cache_dir=cache_dir)
        else:
            self.current = default_scenario(cache_dir)
        self.current.check()

    def _draw(self, scenario_seed: int) -> ScenarioFiles:
        from explaindrive.sim.scenario.directory import random_scenario

        return random_scenario(scenario_seed, self._cache)

    def for_episode(self, episode_seed: int) -> ScenarioFiles:
        """The scenario of the next episode: under :data:`RANDOM` a new draw (from the
        episode seed) every ``every`` episodes, the paper's road for a ``paper_share`` of the
        draws; else always the same."""
        if self.random and self._episodes % self._every == 0:
            from explaindrive.sim.scenario.generator import draws_paper_road, training_seed

            if draws_paper_road(episode_seed, self._paper_share):
                self.current = default_scenario(self._cache)
            else:
                self.current = self._draw(training_seed(episode_seed))
        self._episodes += 1
        return self.current
