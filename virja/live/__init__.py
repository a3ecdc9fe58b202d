"""The live pipeline's two sides: planning (receive, plan; never blocked by a frame)
and drawing (the window in its own process, paced to the display).

- :mod:`virja.live.sinks`: where committed motions go (the plan side's hook point)
- :mod:`virja.live.viewer`: the window's process, seen from the plan side as a sink
- :mod:`virja.live.frames`: the viewer's frame loop (the frame side's hook point)
- :mod:`virja.live.pacing`: when to draw, for which moment; missed frames skipped
- :mod:`virja.live.timer`: the planning side's timer, which sleeps to the next deadline
"""
