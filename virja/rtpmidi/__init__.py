"""RTP-MIDI (RFC 6295) with Apple's session protocol: network MIDI as a Mac,
an iPad, rtpMIDI on Windows or rtpmidid on Linux send it (docs/rtp-midi.md).

``control`` (AppleMIDI session packets: IN/OK/NO/BY/CK/RS) and ``payload``
(the RTP header and the MIDI command section) are the sans-IO codec;
``host`` the sans-IO session listener (invitations, clock sync, feedback,
timeouts, drops by reason); ``transport`` the thin asyncio layer on PORT
(control) and PORT+1 (data); ``recording`` reads the sessions back out of a
pcap; ``announce`` the optional mDNS/Bonjour announcement.
"""

from __future__ import annotations

DEFAULT_PORT = 5004  # control; data is PORT + 1 (Apple's and rtpmidid's default)
DEFAULT_BIND = "127.0.0.1"
CLOCK_RATE = 10_000  # AppleMIDI timestamps and delta times tick at 10 kHz (100 us)
SERVICE_TYPE = "_apple-midi._udp.local."
