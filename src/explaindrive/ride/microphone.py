"""Recording a spoken request from a microphone, when the machine has one."""

from __future__ import annotations

import tempfile
from pathlib import Path


class MicrophoneUnavailableError(RuntimeError):
    """No microphone can be used on this machine."""


def record(seconds: float = 4.0, samplerate: int = 16_000) -> Path:
    """Record ``seconds`` of speech to a temporary WAV file.

    Raises:
        MicrophoneUnavailableError: when ``sounddevice`` is missing or no input device exists.
    """
    try:
        import sounddevice as sd
        import soundfile as sf
    except (ImportError, OSError) as exc:
        raise MicrophoneUnavailableError(
            "voice input needs the `sounddevice` package and PortAudio "
            "(`pip install sounddevice`, `apt-get install libportaudio2`)"
        ) from exc
    try:
        device = sd.query_devices(kind="input")
    except Exception as exc:  # PortAudio raises its own error type
        raise MicrophoneUnavailableError(f"no microphone found on this machine: {exc}") from exc
    if not device:
        raise MicrophoneUnavailableError("no microphone found on this machine")
    audio = sd.rec(int(seconds * samplerate), samplerate=samplerate, channels=1, dtype="float32")
    sd.wait()
    fd, name = tempfile.mkstemp(suffix=".wav", prefix="explaindrive-voice-")
    path = Path(name)
    with open(fd, "wb") as fh:
        sf.write(fh, audio, samplerate, format="WAV")
    return path
