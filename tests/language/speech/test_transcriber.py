"""Whisper on real (espeak-ng synthesised) audio, and unusable audio."""

from __future__ import annotations

import numpy as np
import pytest
import soundfile as sf

from explaindrive.language.speech.transcriber import AudioError


def test_transcribes_synthesised_speech(transcriber, speak, interpreter) -> None:  # type: ignore[no-untyped-def]
    wav = speak("Please stop the car here.", "stop")
    t = transcriber.transcribe(wav)
    assert "stop the car" in t.text.lower()
    assert t.duration_s > 0.5 and t.language == "en"
    assert interpreter.interpret(t.text).intent is not None
    flac = wav.with_suffix(".flac")
    data, rate = sf.read(wav)
    sf.write(flac, data, rate)
    assert "stop" in transcriber.transcribe(flac).text.lower()


@pytest.mark.parametrize(
    ("kind", "message"),
    [
        ("missing", "not found"),
        ("empty", "empty"),
        ("silent", "silent"),
        ("corrupt", "cannot decode"),
        ("text", "unsupported audio type"),
    ],
)
def test_bad_audio(transcriber, tmp_path, kind: str, message: str) -> None:  # type: ignore[no-untyped-def]
    path = tmp_path / ("x.txt" if kind == "text" else "x.wav")
    if kind == "empty":
        path.write_bytes(b"")
    elif kind == "silent":
        sf.write(path, np.zeros(16000, dtype=np.float32), 16000)
    elif kind in ("corrupt", "text"):
        path.write_bytes(b"RIFF\x00\x00garbage" * 50)
    with pytest.raises(AudioError, match=message):
        transcriber.transcribe(path)
