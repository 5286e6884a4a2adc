"""Ride scripts: parsing and the errors a user sees."""

from pathlib import Path

import pytest

from explaindrive.ride.script import ScriptError, default_script_path, load_script


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_yaml_script_is_sorted_and_resolves_audio(tmp_path):
    (tmp_path / "a.wav").write_bytes(b"RIFF")
    path = write(
        tmp_path, "s.yaml", "- {t: 30, audio: a.wav}\n- {t: 0, say: hurry, confirm: yes}\n"
    )
    lines = load_script(path)
    assert [ln.t for ln in lines] == [0.0, 30.0]
    assert lines[0].say == "hurry" and lines[0].confirm == "yes" and lines[0].answer is True
    assert lines[1].confirm is None and lines[1].answer is None
    assert lines[1].audio == tmp_path / "a.wav"


def test_json_script_with_lines_key(tmp_path):
    path = write(tmp_path, "s.json", '{"lines": [{"t": 5, "say": "stop", "confirm": "no"}]}')
    (line,) = load_script(path)
    assert (line.t, line.say, line.confirm, line.answer) == (5.0, "stop", "no", False)


def test_default_script_exercises_fast_why_stop_comfort():
    lines = load_script(default_script_path())
    assert [ln.t for ln in lines] == [0.0, 52.0, 60.0, 80.0]
    # a question is not confirmed
    assert [ln.confirm for ln in lines] == ["yes", None, "yes", "yes"]


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("- {t: 1, say: hi, volume: 3}\n", "line 1: volume: Extra inputs are not permitted"),
        ("- {t: 1}\n", "exactly one of 'say' or 'audio'"),
        ("- {t: -1, say: hi}\n", "line 1: t: Input should be greater than or equal to 0"),
        ("- {t: 1, say: hi, confirm: maybe}\n", "line 1: confirm"),
        ("- {t: 900, say: hi}\n", "t=900 s is after the end of the ride (600 s)"),
        ("{t: 1, say: hi}\n", "must be a list of lines"),
        ("- [unclosed\n", "is not valid YAML/JSON"),
    ],
)
def test_bad_scripts_are_refused_clearly(tmp_path, text, message):
    path = write(tmp_path, "bad.yaml", text)
    with pytest.raises(ScriptError, match=r"bad\.yaml") as err:
        load_script(path, max_time_s=600)
    assert message in str(err.value)


def test_unreadable_script(tmp_path):
    with pytest.raises(ScriptError, match="cannot read ride script"):
        load_script(tmp_path / "missing.yaml")


def test_a_missing_audio_file_is_refused_at_load(tmp_path):
    (tmp_path / "here.wav").write_bytes(b"RIFF")
    path = write(tmp_path, "s.yaml", "- {t: 0, audio: here.wav}\n- {t: 5, audio: gone.wav}\n")
    with pytest.raises(ScriptError) as err:
        load_script(path)
    assert str(err.value) == (
        f"ride script {path}, line 2: audio file not found: {tmp_path / 'gone.wav'}"
    )


def test_a_script_that_is_not_utf8_names_the_file(tmp_path):
    path = tmp_path / "latin1.yaml"
    path.write_bytes('- {t: 0, say: "schneller bitte, ich bin spät"}\n'.encode("latin-1"))
    with pytest.raises(ScriptError) as err:
        load_script(path)
    assert (
        str(err.value)
        == f"ride script {path} is not UTF-8 text (byte 42: invalid continuation byte)"
    )


def test_a_line_is_typed_or_spoken_never_a_prefixed_string(tmp_path: Path) -> None:
    from explaindrive.ride.inputs import SpokenLine, TypedLine

    (tmp_path / "stop.wav").write_bytes(b"RIFF")
    (tmp_path / "s.yaml").write_text(
        "- {t: 0, say: '@audio:stop.wav'}\n- {t: 5, audio: stop.wav}\n"
    )
    typed, spoken = load_script(tmp_path / "s.yaml")
    assert typed.line == TypedLine("@audio:stop.wav")  # text stays text
    assert spoken.line == SpokenLine(tmp_path / "stop.wav")
