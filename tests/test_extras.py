"""A package of a missing extra is named on one line, with the command that installs it."""

from __future__ import annotations

import re
import subprocess
import sys

from explaindrive.extras import MissingExtraError, missing_extra


def test_a_missing_language_package_names_the_language_extra() -> None:
    exc = missing_extra(ModuleNotFoundError("no", name="faster_whisper.audio"), "explaindrive ride")
    assert isinstance(exc, MissingExtraError)
    assert str(exc) == (
        "explaindrive ride needs the language extra (faster_whisper is not installed): "
        "pip install 'explaindrive[language]'"
    )


def test_other_import_errors_are_not_an_extra() -> None:
    assert missing_extra(ModuleNotFoundError("no", name="numpyy")) is None
    assert missing_extra(ImportError("no", name="fastapi")) is None
    assert missing_extra(ValueError("fastapi")) is None


def test_the_cli_names_the_extra_on_one_line() -> None:
    # the language extra's packages hidden, as in a core install
    hidden = ["sklearn", "faster_whisper", "sentence_transformers", "onnxruntime", "openai"]
    code = (
        f"import sys; sys.modules.update(dict.fromkeys({hidden!r}))\n"
        "sys.argv = ['explaindrive', 'interpret', 'go faster']\n"
        "from explaindrive.cli.entry import main; main()"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 1
    (line,) = done.stderr.splitlines()
    assert re.fullmatch(
        r"error: explaindrive interpret needs the language extra \((\w+) is not installed\): "
        r"pip install 'explaindrive\[language\]'",
        line,
    )
