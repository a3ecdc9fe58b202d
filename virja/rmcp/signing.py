"""HMAC-SHA256 tags of signed RMCP datagrams, and the key file.

The tag is the first 16 bytes of HMAC-SHA256(key, header and body), appended
after the body, with flag SIGNED set.  The key is the key file's bytes with
surrounding whitespace stripped.
"""

from __future__ import annotations

import hashlib
import hmac
from dataclasses import replace
from pathlib import Path

from virja.errors import InputFileError
from virja.rmcp.wire import TAG_LEN, Datagram, Flags


def tag_of(key: bytes, header_and_body: bytes) -> bytes:
    """The 16-byte tag over the header and body bytes."""
    return hmac.new(key, header_and_body, hashlib.sha256).digest()[:TAG_LEN]


def sign(dgram: Datagram, key: bytes) -> Datagram:
    """``dgram`` with SIGNED set and its tag computed."""
    unsigned = replace(dgram, flags=dgram.flags | Flags.SIGNED, tag=b"\0" * TAG_LEN)
    return replace(unsigned, tag=tag_of(key, unsigned.header_and_body()))


def verify(dgram: Datagram, key: bytes) -> bool:
    """Whether a SIGNED datagram's tag is right (constant-time compare)."""
    return dgram.signed and hmac.compare_digest(dgram.tag, tag_of(key, dgram.header_and_body()))


def load_key(path: str | Path) -> bytes:
    """The key in ``path``: its bytes with surrounding whitespace stripped.

    Raises InputFileError for a missing, unreadable or empty (after stripping) file.
    """
    try:
        data = Path(path).read_bytes()
    except FileNotFoundError:
        raise InputFileError(path, "key file not found") from None
    except OSError as exc:
        raise InputFileError(path, f"cannot read key file: {exc.strerror or exc}") from None
    key = data.strip()
    if not key:
        raise InputFileError(path, "key file is empty")
    return key
