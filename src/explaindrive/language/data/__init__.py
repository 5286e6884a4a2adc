"""The data shipped with the language layer, and where it is installed.

The command files are read by :mod:`explaindrive.language.intent.datasets` (scoring) and
:mod:`explaindrive.language.intent.corpus` (fine-tuning), the decision file by
:mod:`explaindrive.language.explanation.datasets`; the intent model is LLM-1's
(:mod:`explaindrive.language.intent.model`).
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

TRAIN_CSV = "commands_train.csv"
"""Labelled passenger requests LLM-1 is fine-tuned on; its ``reserve`` split is kept for the
calibration of the thresholds."""
WRITTEN_CSV = "commands_written.csv"
"""In-car chatter and phone talk with pace and stopping words in other senses, questions
about the car's behaviour, answers to a confirmation and negated requests, written for
LLM-1's training; one line in seven is kept for calibration."""
EVERYDAY_TRAIN = "everyday_train.csv.gz"
"""Everyday language from corpora public packages ship (``scripts/build_everyday_corpus.py``):
LLM-1's negatives (split ``train``) and part of its calibration pool (``calibration``)."""
EVERYDAY_WORDS_CSV = "everyday_driving_words.csv"
"""The lines of the same everyday corpora that use words of pace, stopping or driving
(which ``scripts/build_everyday_corpus.py`` leaves out of ``everyday_train.csv.gz``),
labelled by a reader outside the project as if each were said in the taxi (column
``label``; most ask for nothing); one line in seven is kept for calibration."""
EVERYDAY_CHECK = "everyday_check.csv.gz"
"""The external check: chat messages of a public dialogue corpus no model is trained or
selected on."""
HELDOUT_CSV = "commands_heldout10.csv"
"""The test split: written by an author who saw neither the data nor the models, committed
before any model was run on it, scored once. Its column ``split`` says whether a line had a
near-copy among the lines a model learns or is calibrated from when it was committed
(``near``) or not (``unseen``)."""
NEXT_HELDOUT_CSV = "commands_heldout11.csv"
"""The next test split: written by an author who saw neither the data nor the models and
committed before any model was run on it, in the layout of :data:`HELDOUT_CSV`. No model is
trained, calibrated or selected on it; the next fine-tuned model is scored on it once, and it
then takes the place of :data:`HELDOUT_CSV`."""
FORMER_HELDOUT_CSVS = (
    "commands_heldout.csv",
    "commands_heldout2.csv",
    "commands_heldout3.csv",
    "commands_heldout4.csv",
    "commands_heldout5.csv",
    "commands_heldout6.csv",
    "commands_heldout7.csv",
    "commands_heldout8.csv",
    "commands_heldout9.csv",
)
"""Development splits: the previous test splits (each scored once, its errors read since),
trained on."""
TEST_CSV = "commands_test.csv"
"""A development split (scored as a test split once, read since): calibration only."""
BLIND_CSV = "commands_blind.csv"
"""A development split of negated stops, complaints, self-corrections, hedges, typos,
speech-recognition errors and off-topic remarks with driving words (scored as a test split
once, read since): calibration only."""
DEVELOPMENT_CSVS = (TEST_CSV, BLIND_CSV)
"""The development splits LLM-1 is calibrated on, never trained on."""
LABELLED_CSVS = (
    TRAIN_CSV,
    WRITTEN_CSV,
    EVERYDAY_WORDS_CSV,
    *FORMER_HELDOUT_CSVS,
    *DEVELOPMENT_CSVS,
    HELDOUT_CSV,
)
"""Every file of labelled lines (the test split last)."""
DECISIONS_JSONL = "decisions.jsonl"
"""Labelled state records for the LLM-2 trigger and the LLM-3 explanations."""
INTENT_MODEL = "intent_model.npz"
"""The shipped LLM-1: adapters of all-MiniLM-L6-v2, reading head and thresholds."""


def data_path(name: str) -> Path:
    """Path of a file shipped in ``explaindrive/language/data``."""
    return Path(str(resources.files(__name__) / name))
