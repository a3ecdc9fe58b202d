"""A camera for offline renders that follows the music: cuts and moves between the players.

Pure: the notes of the whole performance (known to an offline render) go in,
a list of shots comes out, and :func:`camera_at` gives the camera of any frame.

The rules, in order:

1. **A drum fill** (strokes on snare and toms much denser than the drummer's
   usual) cuts to the drummer for the fill and a beat after it.
2. **A bass feature** (the bassist denser than usual while the drummer is
   sparse) cuts to the bassist.
3. Otherwise the shots take turns: the band from the front, the bassist, the
   band, the drummer, ... each held ``hold_s`` (the close-ups shorter).

No shot is shorter than ``min_shot_s`` (a fill that short joins its
neighbour), and each change is a quick eased move of ``move_s``, not a jump,
so the eye can follow.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from virja.render.camera import PRESETS, Camera
from virja.vocab import Performer

# GM and Roland TD pitches struck in a fill: snare (head, rim, side), toms (head, rim)
FILL_NOTES = frozenset({37, 38, 40, 41, 43, 45, 47, 48, 50, 58})
ROTATION = ("front", "bass", "front", "drums")


@dataclass(frozen=True)
class Shot:
    start_s: float
    end_s: float
    name: str  # a key of render.camera.PRESETS


def _density(times: np.ndarray, grid: np.ndarray, window_s: float) -> np.ndarray:
    """Notes per second in a window centred on each grid time."""
    if times.size == 0:
        return np.zeros_like(grid)
    lo = np.searchsorted(times, grid - window_s / 2)
    hi = np.searchsorted(times, grid + window_s / 2)
    return (hi - lo) / window_s


def plan_shots(
    notes: Sequence[tuple[float, Performer, int]],
    t0_s: float,
    t1_s: float,
    *,
    hold_s: float = 8.0,
    min_shot_s: float = 2.0,
    step_s: float = 0.25,
) -> list[Shot]:
    """Shots covering [t0, t1] from the band's notes: (time, performer, MIDI note)."""
    if t1_s <= t0_s:
        return [Shot(t0_s, t1_s, "front")]
    grid = np.arange(t0_s, t1_s, step_s)
    fills = np.sort([t for t, who, n in notes if who == "drums" and n in FILL_NOTES])
    drums = np.sort([t for t, who, _ in notes if who == "drums"])
    bass = np.sort([t for t, who, _ in notes if who == "bass"])
    fill_d = _density(np.asarray(fills), grid, 1.0)
    drum_d = _density(np.asarray(drums), grid, 2.0)
    bass_d = _density(np.asarray(bass), grid, 2.0)

    def usual(d: np.ndarray) -> float:
        active = d[d > 0]
        return float(np.median(active)) if active.size else math.inf

    want = np.full(grid.shape, "", dtype=object)
    want[(fill_d >= max(4.0, 2.0 * usual(fill_d)))] = "drums"
    bass_feature = (bass_d >= 1.5 * usual(bass_d)) & (drum_d <= 0.5 * usual(drum_d))
    want[(want == "") & bass_feature] = "bass"
    # hold a fill's shot a little after it, so the cut back does not clip its last stroke
    tail = int(1.0 / step_s) + 1
    for k in np.flatnonzero(want == "drums").tolist():
        after = want[k : k + tail]
        after[after == ""] = "drums"

    shots: list[Shot] = []
    turn = 0
    i = 0
    while i < grid.size:
        start = float(grid[i])
        if want[i]:
            j = i
            while j < grid.size and want[j] == want[i]:
                j += 1
            name = str(want[i])
        else:
            name = ROTATION[turn % len(ROTATION)]
            length = hold_s if name == "front" else hold_s * 0.6
            j = i
            while j < grid.size and not want[j] and grid[j] < start + length:
                j += 1
            turn += 1
        end = float(grid[j]) if j < grid.size else t1_s
        if shots and shots[-1].name == name:
            shots[-1] = replace(shots[-1], end_s=end)
        else:
            shots.append(Shot(start, end, name))
        i = j
    return _merge_short(shots, min_shot_s)


def _merge_short(shots: list[Shot], min_shot_s: float) -> list[Shot]:
    """A shot shorter than ``min_shot_s`` is given to the shot before it (or after)."""
    out: list[Shot] = []
    for shot in shots:
        if out and (shot.end_s - shot.start_s < min_shot_s or out[-1].name == shot.name):
            out[-1] = replace(out[-1], end_s=shot.end_s)
        else:
            out.append(shot)
    if len(out) > 1 and out[0].end_s - out[0].start_s < min_shot_s:
        out[1] = replace(out[1], start_s=out[0].start_s)
        out.pop(0)
    return out


def lerp_camera(a: Camera, b: Camera, u: float) -> Camera:
    """The camera ``u`` of the way from ``a`` to ``b`` (yaw the short way round)."""
    u = min(1.0, max(0.0, u))
    dyaw = (b.yaw_deg - a.yaw_deg + 180.0) % 360.0 - 180.0
    ta, tb = np.asarray(a.target), np.asarray(b.target)
    target = ta + (tb - ta) * u
    return replace(
        a,
        target=(float(target[0]), float(target[1]), float(target[2])),
        yaw_deg=a.yaw_deg + dyaw * u,
        pitch_deg=a.pitch_deg + (b.pitch_deg - a.pitch_deg) * u,
        distance_m=a.distance_m + (b.distance_m - a.distance_m) * u,
        fov_deg=a.fov_deg + (b.fov_deg - a.fov_deg) * u,
    )


def camera_at(shots: Sequence[Shot], time_s: float, *, move_s: float = 0.6) -> Camera:
    """The camera at ``time_s``: the shot's preset, eased from the previous one during
    the first ``move_s`` of each shot (smoothstep)."""
    if not shots:
        return PRESETS["front"]
    k = 0
    while k + 1 < len(shots) and shots[k + 1].start_s <= time_s:
        k += 1
    cam = PRESETS[shots[k].name]
    if k == 0 or move_s <= 0:
        return cam
    u = (time_s - shots[k].start_s) / move_s
    if u >= 1.0:
        return cam
    u = max(0.0, u)
    return lerp_camera(PRESETS[shots[k - 1].name], cam, u * u * (3.0 - 2.0 * u))


class FollowCamera:
    """``camera(t)`` for a render: the shots of a performance, planned once."""

    def __init__(self, shots: Sequence[Shot]) -> None:
        self.shots = list(shots)

    def __call__(self, time_s: float) -> Camera:
        return camera_at(self.shots, time_s)
