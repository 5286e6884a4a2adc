"""Command-line interface: one module per command, assembled in :mod:`explaindrive.cli.app`."""
