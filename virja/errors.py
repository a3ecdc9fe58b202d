"""The project's exception hierarchy.

Every error also inherits the matching builtin, so callers may catch either
(``except ValueError`` still works for a bad datagram).
"""

from __future__ import annotations


class VirjaError(Exception):
    """Base of every error virja raises on purpose."""


class InputFileError(VirjaError, ValueError):
    """A file given by the user cannot be read or is malformed; names the file."""

    def __init__(self, path: object, reason: str) -> None:
        self.path = str(path)
        self.reason = reason
        super().__init__(f"{self.path}: {reason}")


class ConfigError(VirjaError, ValueError):
    """A configuration value (TOML file or CLI flag) is invalid."""


class NotAvailableError(VirjaError, RuntimeError):
    """A backend the command needs (EGL, a MIDI API, ffmpeg, a soundfont) is missing."""
