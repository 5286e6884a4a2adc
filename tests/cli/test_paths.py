"""Output paths are checked before a command starts: files, folders, the way to them."""

from __future__ import annotations

from pathlib import Path

import pytest

from explaindrive.cli._paths import OutputPathError, check_out_dir, check_out_file


def test_good_output_paths_pass_and_nothing_is_made(tmp_path: Path) -> None:
    (tmp_path / "runs").mkdir()
    check_out_file(tmp_path / "r.json", "--json")
    check_out_file(tmp_path / "new" / "deeper" / "r.json", "--json")  # made later
    check_out_dir(tmp_path / "runs", "--out")
    check_out_dir(tmp_path / "runs" / "fast", "--out")
    check_out_file(None, "--json")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["runs"]


@pytest.mark.parametrize(
    ("check", "name", "message"),
    [
        (check_out_file, "adir", "--x {root}/adir is a folder; name a file"),
        (
            check_out_file,
            "afile/r.json",
            "--x {root}/afile/r.json: {root}/afile is a file, not a folder",
        ),
        (check_out_dir, "afile", "--x {root}/afile is a file, not a folder; name a folder"),
        (check_out_dir, "afile/a/b", "--x {root}/afile/a/b: {root}/afile is a file, not a folder"),
    ],
)
def test_bad_output_paths_name_the_option_and_the_problem(
    tmp_path: Path, check: object, name: str, message: str
) -> None:
    (tmp_path / "adir").mkdir()
    (tmp_path / "afile").write_text("x")
    with pytest.raises(OutputPathError) as err:
        check(tmp_path / name, "--x")  # type: ignore[operator]
    assert str(err.value) == message.format(root=tmp_path)
