"""Output paths checked before a command starts its work.

A run that ends by failing to write its result loses the run; so every ``--out``,
``--json`` and ``--figures`` is checked first: a file must not name a folder, a folder
must not name a file, and the nearest folder that exists on the way must be a folder
this user can write into. Nothing is created here.
"""

from __future__ import annotations

import os
from pathlib import Path


class OutputPathError(ValueError):
    """An output path that cannot take what the command writes."""


def check_out_file(path: Path | None, flag: str) -> None:
    """Check that the file ``path`` (given with option ``flag``) can be written.

    Raises:
        OutputPathError: naming the option and the problem.
    """
    if path is None:
        return
    if path.is_dir():
        raise OutputPathError(f"{flag} {path} is a folder; name a file")
    _check_parents(path, flag)
    if path.exists() and not os.access(path, os.W_OK):
        raise OutputPathError(f"{flag} {path} cannot be written (permission denied)")


def check_out_dir(path: Path | None, flag: str) -> None:
    """Check that the folder ``path`` (given with option ``flag``) can be made or written.

    Raises:
        OutputPathError: naming the option and the problem.
    """
    if path is None:
        return
    if path.exists() and not path.is_dir():
        raise OutputPathError(f"{flag} {path} is a file, not a folder; name a folder")
    if path.is_dir():
        if not os.access(path, os.W_OK | os.X_OK):
            raise OutputPathError(f"{flag} {path} cannot be written (permission denied)")
        return
    _check_parents(path, flag)


def _check_parents(path: Path, flag: str) -> None:
    """The nearest existing parent of ``path`` is a folder this user can write into."""
    for parent in path.parents:
        if not parent.exists():
            continue
        if not parent.is_dir():
            raise OutputPathError(f"{flag} {path}: {parent} is a file, not a folder")
        if not os.access(parent, os.W_OK | os.X_OK):
            raise OutputPathError(f"{flag} {path} cannot be written in {parent}")
        return


def refuse_bad_outputs(
    files: tuple[tuple[Path | None, str], ...] = (),
    folders: tuple[tuple[Path | None, str], ...] = (),
) -> None:
    """Check each ``(path, flag)`` of ``files`` and ``folders``; the first problem ends the
    command with one line on stderr and exit status 2."""
    import typer

    from explaindrive.cli._errors import print_error

    try:
        for path, flag in files:
            check_out_file(path, flag)
        for path, flag in folders:
            check_out_dir(path, flag)
    except OutputPathError as exc:
        print_error(exc)
        raise typer.Exit(2) from None
