"""Tables for notes played at once (a jam's keys, RTP-MIDI): the shortest stroke.

A note that arrives at its own time is compressed by the planner (it starts
on arrival and strikes ``min_anticipation_s`` later).  For live input that
floor is cut to :data:`IMMEDIATE_STROKE_S`, so the impact is drawn within a
frame of the key, and such a note is not marked late: the short stroke is how
a note played at once is played (``Timing.immediate``); only one that lands
later still (a key that arrived after its time) is late.
"""

from __future__ import annotations

import dataclasses

from virja.plan.config import PlanConfig

IMMEDIATE_STROKE_S = 0.012  # a key's stroke lands within a frame


def immediate_strokes(config: PlanConfig) -> PlanConfig:
    """``config`` with every motion kind's shortest stroke at most IMMEDIATE_STROKE_S."""
    kinds = {
        k: dataclasses.replace(
            mt, min_anticipation_s=min(mt.min_anticipation_s, IMMEDIATE_STROKE_S)
        )
        for k, mt in config.timing.kinds.items()
    }
    timing = dataclasses.replace(config.timing, kinds=kinds, immediate=True)
    return dataclasses.replace(config, timing=timing)
