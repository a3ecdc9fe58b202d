"""The schema of a kit map (motions/drum_kit.toml, or a user's ``[plan] drum_kit``).

Declared once here, below both readers: :func:`virja.plan.config.parse_kit` (the
planner's :class:`~virja.plan.config.DrumKit`) and
:func:`virja.motion.drummer_kit.default_articulations` (the hi-hat's openness).
"""

from __future__ import annotations

from virja.tomlconf import Schema


class KitNoteTable(Schema):
    """``38 = { piece = "snare", name = "Acoustic Snare" }``: where a GM note goes."""

    piece: str
    limb: str | None = None  # "right_foot"/"left_foot" for pedals; absent: a hand
    priority: int | None = None  # absent: the piece's [priority]
    articulation: str | None = None
    name: str = ""


class KitFile(Schema):
    """The whole file: ``[priority]`` per piece and ``[notes]`` per GM note number."""

    priority: dict[str, int] = {}
    notes: dict[str, KitNoteTable] = {}
