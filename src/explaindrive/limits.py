"""The range of every number a command takes, in one place.

The commands check their options against these bounds before any work starts (a value
outside is one line, exit status 2), so no input makes a run grow without end. The
seed and traffic ranges are the scenario's (:mod:`explaindrive.sim.scenario.limits`);
docs/evaluation.md and docs/ride.md list them all.
"""

from __future__ import annotations

from annotated_types import Le

from explaindrive.sim.scenario.limits import SEED_LIMIT

MAX_STEPS = 7_200
"""[steps of 1 s] The longest episode or ride: two hours of driving."""

STEP_LIMIT = Le(MAX_STEPS)
"""Marks a config field that holds a step limit: ``Annotated[PositiveInt, STEP_LIMIT]``."""

MAX_SEED = SEED_LIMIT - 1
"""The largest simulation seed (seeds are in [0, 2**31))."""

MAX_SEEDS = 1_000
"""The most seeds one ``--seeds`` list may name (after ranges are expanded)."""

MAX_WORKERS = 256
"""The most processes (``--workers``) or parallel environments (``--envs``) of one run."""

MAX_EPISODES = 10_000_000
"""The most training episodes of one run (the paper's agents train 11,000)."""

MAX_REPLAY = 20_000_000
"""Transitions a training run's replay buffer holds at most (about 1.6 GB, allocated when
the run starts; the paper's 5M take about 400 MB)."""

MAX_COOLDOWN_S = 3_600.0
"""[s] The longest explanation cool-down of a ride."""

COOLDOWN_LIMIT = Le(MAX_COOLDOWN_S)
"""Marks a config field that holds a cool-down: ``Annotated[NonNegativeFloat, COOLDOWN_LIMIT]``."""

MAX_FILE_AUDIO_S = 600.0
"""[s] The longest recording ``transcribe`` and a ride script's audio lines decode; a
longer file is refused once this much of it is decoded."""

RAY_CONNECT_TIMEOUT_S = 10.0
"""[s] How long a ``--ray-address`` has to answer before the command gives up."""
