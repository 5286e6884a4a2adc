"""The data shipped with the language layer, and where it is installed.

The command files are read by :mod:`explaindrive.language.intent.datasets`, the decision
file by :mod:`explaindrive.language.explanation.datasets`; the classifier weights are
LLM-1's (:mod:`explaindrive.language.intent.classifier`).
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

TRAIN_CSV = "commands_train.csv"
"""Every labelled request a model may be built or selected on; the split column says how."""
TEST_CSV = "commands_test.csv"
"""The blind test requests, never used to build or select a model."""
BLIND_CSV = "commands_blind.csv"
"""A second blind test split, written for the readings the first one missed: negated stops,
complaints that mention lights, stops or arriving, self-corrections, hedges, typos and
speech-recognition errors, polite, terse and rude phrasings, and off-topic remarks that
use driving words. Never used to build or select a model."""
DECISIONS_JSONL = "decisions.jsonl"
"""Labelled state records for the LLM-2 trigger and the LLM-3 explanations."""
CLASSIFIER_NPZ = "intent_classifier.npz"
"""The shipped LLM-1 weights over all-MiniLM-L6-v2."""


def data_path(name: str) -> Path:
    """Path of a file shipped in ``explaindrive/language/data``."""
    return Path(str(resources.files(__name__) / name))
