"""The urban scenario: its layout, how it is built, and its files."""

from explaindrive.sim.scenario.files import ScenarioFiles, default_scenario

__all__ = ["ScenarioFiles", "default_scenario"]
