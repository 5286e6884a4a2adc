"""LLM-1: a passenger's line to a command (fast, comfort, stop), or to what else it is.

- :mod:`~explaindrive.language.intent.interpreter`: the interpreter's interface, its
  results and the confirmation template;
- the embedded model: all-MiniLM-L6-v2 fine-tuned through low-rank adapters
  (:mod:`~explaindrive.language.intent.adapter`) with a reading head that may abstain
  (:mod:`~explaindrive.language.intent.model`), run by
  :mod:`~explaindrive.language.intent.reader` on the sentence encoder
  (:mod:`~explaindrive.language.intent.encoders`,
  :mod:`~explaindrive.language.intent.onnx_encoder`), with STOP's explicit path
  (:mod:`~explaindrive.language.intent.stop_path`);
- its training: :mod:`~explaindrive.language.intent.finetune` on the pools of
  :mod:`~explaindrive.language.intent.corpus`, thresholds from
  :mod:`~explaindrive.language.intent.calibration`; the command files' readers for
  scoring: :mod:`~explaindrive.language.intent.datasets`;
- :mod:`~explaindrive.language.intent.agreement`: when a remote model and the embedded
  interpreter read a line differently.
"""
