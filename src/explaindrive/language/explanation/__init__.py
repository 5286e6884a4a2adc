"""Explanations of the car's actions: LLM-2 decides whether a step needs one, LLM-3 gives it.

- :mod:`~explaindrive.language.explanation.summary`: the state record both read, and its
  human-readable summary;
- :mod:`~explaindrive.language.explanation.hazards`: the safety factors of a state and
  how urgent each one is;
- :mod:`~explaindrive.language.explanation.decision`: LLM-2, the grounded rule engine;
- :mod:`~explaindrive.language.explanation.explainer`: LLM-3, the template explanations;
- :mod:`~explaindrive.language.explanation.grounding`: whether a text is true of the state;
- :mod:`~explaindrive.language.explanation.datasets`: the labelled decision file.
"""
