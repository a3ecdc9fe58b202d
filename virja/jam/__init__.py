"""Jamming from a MIDI keyboard: ports (python-rtmidi, JACK or ALSA), routing, latency.

- :mod:`virja.jam.keyboard`: raw MIDI -> events -> who plays them (pure);
- :mod:`virja.jam.delay`: the thru output's delay line (pure);
- :mod:`virja.jam.watch`: following a keyboard unplugged and plugged back (pure);
- :mod:`virja.jam.ports`: the rtmidi IO (backend probe, input, thru output);
- :mod:`virja.jam.live`: one message from the port to the band, thru and RMCP.

``virja jam`` (:mod:`virja.cli.cmd_jam`) strings them together with a
``virja.session.Performance``.
"""
