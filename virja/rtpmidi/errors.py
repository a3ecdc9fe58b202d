"""Typed errors of the RTP-MIDI codec.

Every error carries a short machine ``reason`` (the key of the session host's
drop counter) and a message naming what is wrong; all are ``ValueError`` too.
"""

from __future__ import annotations

from typing import ClassVar

from virja.errors import VirjaError


class RtpMidiError(VirjaError, ValueError):
    """A datagram that is not valid AppleMIDI control or RTP-MIDI."""

    reason: ClassVar[str] = "invalid"


class TruncatedError(RtpMidiError):
    """Shorter than its fixed part or than a length it declares."""

    reason = "truncated"


class BadSignatureError(RtpMidiError):
    """A control packet not starting with 0xFFFF."""

    reason = "bad_signature"


class UnknownCommandError(RtpMidiError):
    """A control command this host does not know."""

    reason = "unknown_command"


class BadVersionError(RtpMidiError):
    """An AppleMIDI protocol version other than 2, or an RTP version other than 2."""

    reason = "bad_version"


class BadCommandSectionError(RtpMidiError):
    """A MIDI command section that cannot be read (a data byte with no status, a
    delta time longer than 4 bytes, a status byte inside a command)."""

    reason = "bad_midi"
