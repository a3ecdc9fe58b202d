"""HMAC-SHA256 tags of signed RMCP datagrams, and the key file.

The tag is the first 16 bytes of HMAC-SHA256(key, header and body), appended
after the body, with flag SIGNED set.  The key is the key file's bytes with
surrounding whitespace stripped.
"""

from __future__ import annotations

import hashlib
import hmac
import logging
import os
import stat
from dataclasses import replace
from pathlib import Path

from virja.errors import InputFileError
from virja.rmcp.wire import TAG_LEN, Datagram, Flags

log = logging.getLogger(__name__)

MAX_KEY_BYTES = 4096
MIN_KEY_BYTES = 16  # 128 bits


def tag_of(key: bytes, header_and_body: bytes) -> bytes:
    """The 16-byte tag over the header and body bytes."""
    return hmac.new(key, header_and_body, hashlib.sha256).digest()[:TAG_LEN]


def sign(dgram: Datagram, key: bytes) -> Datagram:
    """``dgram`` with SIGNED set and its tag computed."""
    unsigned = replace(dgram, flags=dgram.flags | Flags.SIGNED, tag=b"\0" * TAG_LEN)
    return replace(unsigned, tag=tag_of(key, unsigned.header_and_body()))


def tag_matches(key: bytes, header_and_body: bytes, tag: bytes) -> bool:
    """Whether ``tag`` is the tag of ``header_and_body`` (constant-time compare).  The
    receiver passes the bytes as they arrived (all but the last 16)."""
    return hmac.compare_digest(tag, tag_of(key, header_and_body))


def verify(dgram: Datagram, key: bytes) -> bool:
    """Whether a SIGNED datagram's tag is right (constant-time compare)."""
    return dgram.signed and tag_matches(key, dgram.header_and_body(), dgram.tag)


def load_key(path: str | Path) -> bytes:
    """The key in ``path``, byte for byte as the file holds it (docs/rmcp.md).

    One exception, so that ``echo secret > FILE`` works: a text key (printable
    ASCII only) ends at its line end, which is not part of the key.  A binary key
    (any other byte) is used exactly, whitespace included.  Raises InputFileError
    for a missing, unreadable, empty (or blank), over-long (more than
    ``MAX_KEY_BYTES``) or not regular file (a FIFO or a device is refused before
    it is opened for reading); warns when the key is shorter than
    ``MIN_KEY_BYTES`` or the file is readable by group or others.
    """
    p = Path(path)
    try:
        st = os.stat(p)
    except FileNotFoundError:
        raise InputFileError(path, "key file not found") from None
    except OSError as exc:
        raise InputFileError(path, f"cannot read key file: {exc.strerror or exc}") from None
    if not stat.S_ISREG(st.st_mode):
        raise InputFileError(path, "not a regular file (a folder, FIFO or device): not a key file")
    if st.st_size > MAX_KEY_BYTES:
        raise InputFileError(path, f"key file of {st.st_size} bytes: at most {MAX_KEY_BYTES}")
    try:
        # O_NONBLOCK: a FIFO swapped in after the check cannot hang the open
        fd = os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as fh:
            if not stat.S_ISREG(os.fstat(fh.fileno()).st_mode):
                raise InputFileError(path, "not a regular file: not a key file")
            data = fh.read(MAX_KEY_BYTES + 1)
    except OSError as exc:
        raise InputFileError(path, f"cannot read key file: {exc.strerror or exc}") from None
    if len(data) > MAX_KEY_BYTES:
        raise InputFileError(path, f"key file longer than {MAX_KEY_BYTES} bytes")
    key = key_bytes(data)
    if not key.strip():
        raise InputFileError(path, "key file is empty")
    if len(key) < MIN_KEY_BYTES:
        log.warning(
            "key file %s: a %d-byte key is weak; use at least %d random bytes "
            "(head -c 32 /dev/urandom > FILE)",
            path,
            len(key),
            MIN_KEY_BYTES,
        )
    if st.st_mode & 0o077:
        log.warning(
            "key file %s is readable by others (mode %o); chmod 600 it",
            path,
            stat.S_IMODE(st.st_mode),
        )
    return key


def key_bytes(data: bytes) -> bytes:
    """A key file's bytes to the key: a text key (printable ASCII) loses its one line
    end ("\\n" or "\\r\\n"); any other key is the bytes exactly."""
    for end in (b"\r\n", b"\n"):
        if data.endswith(end):
            text = data[: -len(end)]
            if all(0x20 <= c < 0x7F for c in text):
                return text
    return data
