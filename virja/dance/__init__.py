"""Method B: motion from music, taught by example (Aozuka and Yamamoto).

Modules: :mod:`~virja.dance.audio` (read, mono, 8 kHz), :mod:`~virja.dance.beats`
(beat extraction), :mod:`~virja.dance.ar` (AR(3) by exact maximum likelihood),
:mod:`~virja.dance.segment` (cutting a capture at beats), :mod:`~virja.dance.database`
(the {segment, sound parameters, span} store), :mod:`~virja.dance.intervals`
(beat-interval correction), :mod:`~virja.dance.generate` (choosing and joining
segments), :mod:`~virja.dance.evaluate` (objective scores),
:mod:`~virja.dance.synth_capture` / :mod:`~virja.dance.synth_music` (synthetic
teachers and music for tests), :mod:`~virja.dance.band_capture` (our own band
as teacher), :mod:`~virja.dance.stage` (a dance as a figure on stage) and
:mod:`~virja.dance.bench`.  See docs/dance.md.
"""

from __future__ import annotations

from virja.dance.intervals import CorrectedInterval, correct_intervals

__all__ = ["CorrectedInterval", "correct_intervals"]
