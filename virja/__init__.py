"""virja: a real-time animation server for a virtual jazz band.

Time-stamped notes arrive (RMCP/1 over UDP, MIDI files, live MIDI ports,
pcap recordings); a cost-table scheduler picks a basic motion for each; the
motions are blended so every impact lands on its sound; moderngl draws the
bassist and the drummer.  See docs/architecture.md.
"""

__version__ = "0.1.0"
