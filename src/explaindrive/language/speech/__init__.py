"""Speech to text: the passenger's recordings transcribed by Whisper
(:mod:`~explaindrive.language.speech.transcriber`)."""
