"""Evaluation suite: episode grids, parallel runners, aggregates, tables, figures and the report.

- :mod:`~explaindrive.evaluation.parsing`: the text formats of seeds, traffic levels and schedules;
- :mod:`~explaindrive.evaluation.spec`: policies and the episode grids they run over;
- :mod:`~explaindrive.evaluation.runner`: one episode, and grids on a process pool or Ray;
- :mod:`~explaindrive.evaluation.aggregate`: aggregation maths (pure functions);
- :mod:`~explaindrive.evaluation.schema`: the JSON result file;
- :mod:`~explaindrive.evaluation.tables`: Markdown tables in the paper's layout;
- :mod:`~explaindrive.evaluation.figures`: speed profiles and training curves;
- :mod:`~explaindrive.evaluation.paper`: the paper's reported numbers (the only copy);
- :mod:`~explaindrive.evaluation.report_plan`: the runs of ``docs/results.md``;
- :mod:`~explaindrive.evaluation.report_sections`: its Markdown sections;
- :mod:`~explaindrive.evaluation.report_discussion`: our numbers against the paper's, in words;
- :mod:`~explaindrive.evaluation.report`: ``docs/results.md``: runs the plan, writes the figures.
"""
