"""LLM-1: a passenger's request to a command (fast, comfort, stop) and its confirmation.

- :mod:`~explaindrive.language.intent.interpreter`: the interpreter's interface, its
  results, the confirmation template and yes/no answers;
- the embedded classifier: :mod:`~explaindrive.language.intent.classifier` at run time,
  built by :mod:`~explaindrive.language.intent.training` from the command files
  (:mod:`~explaindrive.language.intent.datasets`), on sentence features
  (:mod:`~explaindrive.language.intent.features`) of the sentence encoder
  (:mod:`~explaindrive.language.intent.encoders`,
  :mod:`~explaindrive.language.intent.onnx_encoder`) and lexical direction cues
  (:mod:`~explaindrive.language.intent.cues`,
  :mod:`~explaindrive.language.intent.cue_lexicon`);
- readings it corrects: negated stops (:mod:`~explaindrive.language.intent.negation`) and
  self-corrections (:mod:`~explaindrive.language.intent.corrections`);
- :mod:`~explaindrive.language.intent.agreement`: when a remote model and the embedded
  interpreter read a line differently.
"""
