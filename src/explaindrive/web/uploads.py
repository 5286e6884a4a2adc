"""Uploaded recordings live only as long as they are needed.

A recording is stored when it is accepted and deleted as soon as it has been
transcribed (or the transcription failed): the ride's transcriber is wrapped in
:class:`DeleteAfterUse`. A recording whose transcription never runs (dropped as
late) is deleted by :meth:`UploadTracker.sweep` once its deadline has passed, and
whatever is left when the ride ends by :meth:`UploadTracker.clear`.
"""

from __future__ import annotations

import dataclasses
import logging
import threading
import time
from pathlib import Path

from explaindrive.language.speech.transcriber import SpeechToText, Transcript
from explaindrive.ride.session import RideSession

log = logging.getLogger(__name__)


class DeleteAfterUse:
    """A transcriber that deletes each file of ``upload_dir`` once it has been transcribed.

    Args:
        inner: the transcriber that does the work (Whisper).
        upload_dir: only files in this directory are deleted.
    """

    def __init__(self, inner: SpeechToText, upload_dir: Path) -> None:
        self.inner = inner
        self.upload_dir = upload_dir.resolve()

    def load(self) -> None:
        """Load the inner transcriber's model."""
        self.inner.load()

    def transcribe(self, path: str | Path) -> Transcript:
        """The inner transcription of ``path``; the file is deleted afterwards, even on errors."""
        try:
            return self.inner.transcribe(path)
        finally:
            file = Path(path)
            if file.resolve().parent == self.upload_dir:
                file.unlink(missing_ok=True)


def delete_uploads_after_use(session: RideSession, upload_dir: Path) -> None:
    """Make ``session`` delete each uploaded recording as soon as it has been transcribed."""
    language = session.language
    if not isinstance(language.transcriber, DeleteAfterUse):
        wrapped = DeleteAfterUse(language.transcriber, upload_dir)
        session.language = dataclasses.replace(language, transcriber=wrapped)


class UploadTracker:
    """The recordings of the current ride that may still be on disk.

    Args:
        max_age_s: a recording older than this is past its transcription deadline [s].
    """

    def __init__(self, max_age_s: float) -> None:
        self.max_age_s = max_age_s
        self._lock = threading.Lock()
        self._files: list[tuple[Path, float]] = []

    def add(self, path: Path) -> None:
        """Track a recording handed to the ride now."""
        with self._lock:
            self._files.append((path, time.monotonic()))

    def waiting(self) -> int:
        """Recordings still on disk (not yet transcribed)."""
        with self._lock:
            self._files = [(p, t) for p, t in self._files if p.exists()]
            return len(self._files)

    def sweep(self) -> int:
        """Delete the recordings past their deadline; returns how many were deleted."""
        now = time.monotonic()
        with self._lock:
            old = [p for p, t in self._files if now - t > self.max_age_s]
            self._files = [(p, t) for p, t in self._files if now - t <= self.max_age_s]
        for path in old:
            if path.exists():
                log.debug("deleting %s: its transcription deadline has passed", path.name)
            path.unlink(missing_ok=True)
        return len(old)

    def clear(self) -> None:
        """Delete every tracked recording (the ride ended)."""
        with self._lock:
            files, self._files = self._files, []
        for path, _ in files:
            path.unlink(missing_ok=True)
