"""Build the golden RMCP/1 datagrams of tests/data/rmcp (run once; files are kept).

    .venv/bin/python tests/data/rmcp/make_golden.py

Valid: one file per kind (+ a signed and an immediate one).  Invalid: one per
reason of the parser, named ``bad_<reason>_*.bin``.  The key of the signed
ones is ``key.txt`` (stripped: ``virja-test-key``).
"""

from __future__ import annotations

import struct
from pathlib import Path

HERE = Path(__file__).resolve().parent
KEY = b"virja-test-key"
T = 1_700_000_000_123_456  # 2023-11-14T22:13:20.123456Z


def header(
    kind: int,
    body: bytes,
    *,
    flags: int = 0,
    sender: int = 1,
    seq: int = 7,
    time_us: int = T,
    magic: bytes = b"RMCP",
    version: int = 1,
    reserved: int = 0,
    body_len: int | None = None,
) -> bytes:
    n = len(body) if body_len is None else body_len
    return struct.pack(
        "!4sBBBBHHIq", magic, version, kind, flags, reserved, sender, n, seq, time_us
    )


def dgram(kind: int, body: bytes, **kw: object) -> bytes:
    return header(kind, body, **kw) + body  # type: ignore[arg-type]


def signed(kind: int, body: bytes, key: bytes = KEY, **kw: object) -> bytes:
    import hashlib
    import hmac

    data = header(kind, body, flags=2, **kw) + body  # type: ignore[arg-type]
    return data + hmac.new(key, data, hashlib.sha256).digest()[:16]


MIDI_BODY = bytes(
    [0x90, 60, 100, 0x99, 38, 90, 0x80, 60, 0, 0xB0, 64, 127, 0xC0, 33, 0xF0, 0x7E, 0x01, 0xF7]
)
BEAT_BODY = struct.pack("!IBBBBI", 12, 1, 4, 2, 0, 500_000)
CHORD_BODY = bytes([2, 255, 2]) + b"m7"
CLOCK_REQUEST_BODY = struct.pack("!Iq", 0xDEADBEEF, T)
CLOCK_REPLY_BODY = struct.pack("!Iqqq", 0xDEADBEEF, T, T + 1500, T + 1600)

FILES: dict[str, bytes] = {
    "midi.bin": dgram(1, MIDI_BODY),
    "beat.bin": dgram(2, BEAT_BODY, sender=3, seq=0),
    "chord.bin": dgram(3, CHORD_BODY, sender=3, seq=1),
    "chord_slash.bin": dgram(3, bytes([0, 4, 4]) + b"maj7", sender=3, seq=2),
    "clock_request.bin": dgram(16, CLOCK_REQUEST_BODY, flags=1, sender=9, seq=4294967295),
    "clock_reply.bin": dgram(17, CLOCK_REPLY_BODY, flags=1, sender=2, seq=0),
    "midi_immediate.bin": dgram(1, bytes([0x90, 36, 127]), flags=1, sender=2, seq=8),
    "midi_signed.bin": signed(1, bytes([0x99, 42, 80]), sender=2, seq=9),
    "unknown_kind.bin": dgram(200, b"future", sender=5, seq=1),
    # invalid, one per reason
    "bad_too_short.bin": dgram(1, b"")[:23],
    "bad_too_long.bin": dgram(200, bytes(1177)),
    "bad_magic.bin": dgram(1, bytes([0x90, 60, 100]), magic=b"RMCQ"),
    "bad_version.bin": dgram(1, bytes([0x90, 60, 100]), version=2),
    "bad_flags.bin": dgram(1, bytes([0x90, 60, 100]), flags=4),
    "bad_reserved.bin": dgram(1, bytes([0x90, 60, 100]), reserved=1),
    "bad_length_long.bin": dgram(1, bytes([0x90, 60, 100])) + b"\0",
    "bad_length_unsigned_tag.bin": header(1, bytes([0x90, 60, 100]), flags=2)
    + bytes([0x90, 60, 100]),
    "bad_body_midi_empty.bin": dgram(1, b""),
    "bad_body_midi_missing_data.bin": dgram(1, bytes([0x90, 60])),
    "bad_body_midi_data_above_127.bin": dgram(1, bytes([0x90, 60, 200])),
    "bad_body_midi_running_status.bin": dgram(1, bytes([0x90, 60, 100, 62, 100])),
    "bad_body_midi_unterminated_sysex.bin": dgram(1, bytes([0xF0, 0x7E, 0x01])),
    "bad_body_midi_status_f1.bin": dgram(1, bytes([0xF1, 0x10])),
    "bad_body_midi_status_f8.bin": dgram(1, bytes([0xF8])),
    "bad_body_beat_11.bin": dgram(2, BEAT_BODY[:11]),
    "bad_body_chord_n.bin": dgram(3, bytes([2, 255, 3]) + b"m7"),
    "bad_body_clock_request_13.bin": dgram(16, CLOCK_REQUEST_BODY + b"\0", flags=1),
    "bad_body_clock_reply_27.bin": dgram(17, CLOCK_REPLY_BODY[:27], flags=1),
}


def main() -> None:
    for name, data in FILES.items():
        (HERE / name).write_bytes(data)
    (HERE / "key.txt").write_bytes(KEY + b"\n")
    print(f"wrote {len(FILES)} datagrams to {HERE}")


if __name__ == "__main__":
    main()
