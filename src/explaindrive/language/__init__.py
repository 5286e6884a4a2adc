"""The language layer: speech, command interpretation (LLM-1), explanation trigger
(LLM-2) and explanation generator (LLM-3), with an offline and an OpenAI backend.

- :mod:`~explaindrive.language.speech`: speech to text (Whisper);
- :mod:`~explaindrive.language.intent`: LLM-1, a passenger's request to a command;
- :mod:`~explaindrive.language.explanation`: the state summary, LLM-2 (whether a step
  needs an explanation) and LLM-3 (the explanation), checked against the state;
- :mod:`~explaindrive.language.backends`: the registry of backends that build the three
  modules (``embedded``, ``openai``) and the reading of a remote model's replies;
- :mod:`~explaindrive.language.stack` assembles them for a backend,
  :mod:`~explaindrive.language.config` configures them, :mod:`~explaindrive.language.data`
  holds the shipped data and :mod:`~explaindrive.language.evaluation` scores them.
"""
