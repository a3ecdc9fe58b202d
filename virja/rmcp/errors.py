"""Typed errors of the RMCP codec.

Every error carries a short machine ``reason`` (the key of the receiver's drop
counter) and a human message naming what is wrong.  All of them are
``ValueError`` too, so ``except ValueError`` catches a bad datagram.
"""

from __future__ import annotations

from typing import ClassVar

from virja.errors import VirjaError


class RmcpError(VirjaError, ValueError):
    """A datagram that is not valid RMCP/1."""

    reason: ClassVar[str] = "invalid"


class TooShortError(RmcpError):
    """Shorter than the 24-byte header."""

    reason = "too_short"


class TooLongError(RmcpError):
    """Longer than 1200 bytes."""

    reason = "too_long"


class BadMagicError(RmcpError):
    """The first four bytes are not ``RMCP``."""

    reason = "bad_magic"


class BadVersionError(RmcpError):
    """A version other than 1."""

    reason = "bad_version"


class BadFlagsError(RmcpError):
    """A flag bit 2-7 is set."""

    reason = "bad_flags"


class BadReservedError(RmcpError):
    """The reserved header byte is not 0."""

    reason = "bad_reserved"


class BadLengthError(RmcpError):
    """The datagram length is not 24 + body_len (+ 16 when SIGNED)."""

    reason = "bad_length"


class BadBodyError(RmcpError):
    """A body its kind does not allow."""

    reason = "bad_body"


REASONS: tuple[str, ...] = (
    TooShortError.reason,
    TooLongError.reason,
    BadMagicError.reason,
    BadVersionError.reason,
    BadFlagsError.reason,
    BadReservedError.reason,
    BadLengthError.reason,
    BadBodyError.reason,
)
