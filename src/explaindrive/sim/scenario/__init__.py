"""The urban scenario: its layout (:mod:`.layout`), how it is built (:mod:`.build`) and its files."""

from explaindrive.sim.scenario.files import ScenarioFiles, default_scenario

__all__ = ["ScenarioFiles", "default_scenario"]
