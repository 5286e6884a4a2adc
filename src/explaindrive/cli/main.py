"""``python -m explaindrive.cli.main``: the ``explaindrive`` program, as ``python -m
explaindrive.cli`` and the ``explaindrive`` script run it (:mod:`explaindrive.cli.entry`).

The command group itself is :mod:`explaindrive.cli.app`.
"""

from explaindrive.cli.entry import main

if __name__ == "__main__":  # pragma: no cover
    main()
