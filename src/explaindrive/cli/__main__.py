"""``python -m explaindrive.cli``: the ``explaindrive`` program."""

from explaindrive.cli.entry import main

main()
