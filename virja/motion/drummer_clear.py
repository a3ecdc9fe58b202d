"""The drummer's two sticks kept apart as paths, and off the kit between strokes (issue 15).

:mod:`virja.motion.drummer_hands` builds each hand's track from its own strokes; two
tracks built apart can pass through each other (a left hand leaving the snare as the
right comes down past it, hands crossing over the hi-hat) and a stick on its way can
dip through a cymbal or a head (a left hand off the hi-hat for the snare 85 ms later,
MMA Swing1 at 240 bpm: 22 such runs in 12 s).  Here both tracks are sampled together
and where a stick comes too near the other stick, or a tip goes under a piece's
surface inside its rim, one hand's track is bent away by a *detour*: a smooth offset
of the whole hand (wrist, grip and stick moved together) that is zero at every
impact of that hand, ramps in and out with smoothstep and holds over the conflict.

- **stick against stick**: where the sticks come within ``STICK_TRIGGER_M``, one
  hand moves: across the sticks to ``STICK_CLEAR_M``, or up over the other stick,
  or back along its own, or out along the other stick past its tip (a stick passing
  upright through the other one, the left coming down from the crash to the snare
  through the crossed right stick: no offset across or up fits), as far as it takes
  to bring one stick's tip around the other's (``_END_PAST_M``); the least offset
  that fits between that hand's impacts,
  keeps the sticks ``STICK_APART_M`` apart over its whole window (or, where none
  does, the one keeping them farthest apart, at least ``STICK_NEAR_M``), puts no tip
  into a piece and adds no 30 fps jump over ``JUMP_OK_M`` (:func:`_apart_detour`);
  where no one hand's fits within a ramp of ``RAMP_MAX_S``, both hands move, each
  half of one of those offsets, and only then one hand on a longer ramp;
- **tip against a piece**: the stick turns up about the wrist (a *lift* detour, the
  wrist stays where it is) until the tip is ``SURFACE_CLEAR_M`` over the surface:
  over the rim, not through the cymbal.  (Moving the whole hand up instead added up
  to 2.4 cm to the 30 fps jumps of the fast hi-hat-to-snare moves it fixed.)

A detour never starts before a frame already drawn (``floor``), so a change of plan
never changes a frame shown; one that would have to ramp faster than ``RAMP_SPEED_M_S``
(``LIFT_SPEED_M_S`` for a lift; peak, smoothstep: 1.5 x its amplitude over its ramp)
is not made.

Pure functions over arrays: (n,) times, (n, 3) metres; detours as :class:`Detour`.
"""

from __future__ import annotations

import bisect
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from virja.geometry import Cymbal, Drum, DrumKit

# two sticks nearer than this (closest points of their axes; virja.motion.
# drummer_report counts them touching under 14 mm, two stick radii) are moved apart
STICK_TRIGGER_M = 0.022
STICK_CLEAR_M = 0.035
# ... and a detour is made only if it keeps them this far apart over its whole window;
# if the least offset does not, one STICK_MORE_M larger is tried
STICK_APART_M = 0.018
# ... or, where no detour does, the one keeping them farthest apart if that is at least
# this: clear of the report's touching (two stick radii, 14 mm) by 2 mm (GMD disco 137
# at 5.8 s: the left coming down from the hi-hat to the snare past the right stick
# landing there, the best pull-back 17.3 mm apart, no detour made: stick-stick 1)
STICK_NEAR_M = 0.016
STICK_MORE_M = 0.02
# ... and where a stick passes through the other one from under to over (or over to
# under: the left rising from the snare to the crash, or coming down from it, through the
# right stick lying crossed over the hi-hat), no offset across or up can hold them apart
# (a bump only moves the crossing in time); one stick is taken around the other's end:
# its hand pulled back along its own stick until its tip is this far behind the
# crossing, or moved along the other stick until that one's tip is (GMD sample from
# offset 8, round 9: all 8 stick-stick runs left were such passes, the tip 12-17 cm
# past the other stick, more than UP_M's largest)
_END_PAST_M = 0.03
# a hand lifted over the other stick, or pulled back along its own stick out of the
# other's way, when across them fails (GMD hiphop 110: stick-stick 4 -> 3 with these);
# the last is about the most a ramp allows (RAMP_SPEED_M_S x RAMP_MAX_S / 1.5 = 16 cm):
# GMD hiphop 110 at 6.27 s, the left stick rising from the snare under the crossed
# right one as it comes down on the hi-hat, the left's tip 14 cm past the right stick:
# pulled back 15.5 cm, its tip passes behind the right stick (14 cm: they still touch)
UP_M = (0.04, 0.07, 0.1, 0.14, 0.155)
# a tip more than SURFACE_TRIGGER_M under a piece's top inside its rim (+ a margin) is
# lifted (the stick turned up about the wrist) to SURFACE_CLEAR_M over it
SURFACE_TRIGGER_M = 0.002
SURFACE_CLEAR_M = 0.012
RIM_MARGIN_M = 0.01
# a detour is zero this long after an impact of its hand and this long before the next
# (the downstroke lands exactly where it was planned)
AFTER_IMPACT_S = 0.006
BEFORE_IMPACT_S = 0.03
# ramps no longer than this (a detour is local), unless its amplitude needs a longer one
# at RAMP_SPEED_M_S (_END_PAST_M, 16-20 cm: 80-100 ms), as local as its speed allows,
# and tried after both hands sharing the offset (_apart_detour)
RAMP_MAX_S = 0.08
# a move detour holds this much longer on either side of its conflict, where it fits
# (the least that keeps the sticks apart over the whole window): the sticks move on,
# and held over the conflict alone the crossing came back just after it (GMD hiphop
# 110 at 6.75 s: a left hand sweeping past the right stick over the hi-hat)
HOLD_PAD_S = (0.025, 0.06, 0.12)
RAMP_SPEED_M_S = 3.0  # the peak speed a detour adds (1.5 amplitude / ramp)
# ... a lift's at the tip: a stick flicks up off a cymbal faster than a hand moves (a
# downstroke's tip comes in at 5-10 m/s); 6 and 8 m/s left 12 and 4 of the 22 hi-hat
# runs of MMA Swing1 at 240 bpm unmade (the tip under the hi-hat 20 ms after its
# impact, 85 ms before the snare), 10 none
LIFT_SPEED_M_S = 10.0
# a lift starts at its hand's impact (the rebound) and ends this long before the next
# (the tip under the snare's head 25 ms before its own stroke on it, coming in low
# from the hi-hat: GMD punk 140 at 2.12 s)
LIFT_BEFORE_S = 0.008
SAMPLE_S = 1.0 / 240.0
# times this near are the same time (sums and differences of seconds are off by ulps)
_TIME_EPS_S = 1e-9
# a detour is made only if the wrist then moves no more between two 30 fps frames than
# it did, or at most JUMP_OK_M, and no faster than it did, or at most SPEED_OK_M_S (a
# detour ramping out into a fast move added up to 2 cm to a 30 fps jump)
FRAME_30_S = 1.0 / 30.0
JUMP_OK_M = 0.135
SPEED_OK_M_S = 7.0


@dataclass(frozen=True)
class Detour:
    """An offset ``vec`` (3,) m of one hand: 0 at ``t0``, smoothstep to full at ``t1``,
    held to ``t2``, smoothstep back to 0 at ``t3``."""

    t0: float
    t1: float
    t2: float
    t3: float
    vec: np.ndarray


Window = tuple[float, float, float, float]  # a detour's (t0, t1, t2, t3)
Stick = tuple[np.ndarray, np.ndarray, np.ndarray]  # wrist, butt, tip: each (n, 3) m
Sticks = Callable[[np.ndarray], Stick]


def offsets(detours: Sequence[Detour], times: np.ndarray) -> np.ndarray:
    """The sum of ``detours`` at ``times`` (n,): (n, 3) m."""
    t = np.asarray(times, dtype=np.float64)
    out = np.zeros(t.shape + (3,))
    for d in detours:
        if t.size and (d.t3 <= t.min() or d.t0 >= t.max()):
            continue
        up = np.clip((t - d.t0) / max(d.t1 - d.t0, 1e-9), 0.0, 1.0)
        down = np.clip((d.t3 - t) / max(d.t3 - d.t2, 1e-9), 0.0, 1.0)
        w = np.minimum(up * up * (3 - 2 * up), down * down * (3 - 2 * down))
        out += w[:, None] * d.vec
    return out


def segment_closest(
    p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Closest points (n, 3) on segments p0-p1 and q0-q1, vectorised over the first axis."""
    d1, d2, r = p1 - p0, q1 - q0, p0 - q0
    a = np.einsum("ij,ij->i", d1, d1)
    e = np.einsum("ij,ij->i", d2, d2)
    f = np.einsum("ij,ij->i", d2, r)
    c = np.einsum("ij,ij->i", d1, r)
    b = np.einsum("ij,ij->i", d1, d2)
    denom = a * e - b * b
    s = np.where(denom > 1e-12, np.clip((b * f - c * e) / np.maximum(denom, 1e-12), 0, 1), 0.0)
    t = np.clip((b * s + f) / np.maximum(e, 1e-12), 0, 1)
    s = np.clip((b * t - c) / np.maximum(a, 1e-12), 0, 1)
    return p0 + d1 * s[:, None], q0 + d2 * t[:, None]


def _apart(a: Stick, b: Stick, gap: np.ndarray, i: int, j: int) -> np.ndarray:
    """The one direction (3,) to hold the left stick ``a`` from the right one ``b`` over
    samples ``i..j``, pointing to the side the left stick comes from: across both
    sticks (their common normal) where they pass through each other, else along the
    closest points' line.  (The closest points' line flips as one stick passes
    through the other: a detour along it at the nearest sample only moved the
    crossing a few ms on.)"""
    k = i + int(np.argmin(np.linalg.norm(gap[i : j + 1], axis=1)))
    n = np.cross(a[2][k] - a[1][k], b[2][k] - b[1][k])
    norm = float(np.linalg.norm(n))
    g = gap[k] / max(float(np.linalg.norm(gap[k])), 1e-9)
    if norm > 1e-9 and abs(float(g @ (n / norm))) > 0.5:
        g = n / norm  # the closest points lie across both sticks: they cross
    first = gap[max(i - 1, 0)]
    return g if float(first @ g) >= 0.0 else -g


def _apart_over(
    t: np.ndarray,
    a: Stick,
    b: Stick,
    moved: Sequence[tuple[int, Window, np.ndarray]],
    run: tuple[int, int],
) -> float:
    """How far apart (m) the hands moved by detours ``moved`` (hand, window, offset) keep
    the two sticks (``a`` left, ``b`` right, sampled at ``t``) at least, over
    the whole window and the conflict's samples ``run`` (a detour found on the nearest
    sample alone could push the crossing a few ms on, or push the stick through the
    other one; one squeezed before its hand's impact could end before the conflict
    begins and leave it as it was: GMD hiphop 110 at 6.27 s, a right-hand detour over
    6.14-6.25 s for sticks crossing at 6.26-6.27 s, 10 ms before its hi-hat stroke)."""
    i = min([int(np.searchsorted(t, w[0])) for _h, w, _v in moved] + [run[0]])
    j = max([int(np.searchsorted(t, w[3], side="right")) for _h, w, _v in moved] + [run[1] + 1])
    if j <= i:
        return True
    sides = [[p[i:j] for p in s[1:]] for s in (a, b)]
    for h, w, vec in moved:
        off = offsets([Detour(w[0], w[1], w[2], w[3], vec)], t[i:j])
        sides[h] = [p + off for p in sides[h]]
    (a0, a1), (b0, b1) = sides
    pa, pb = segment_closest(a0, a1, b0, b1)
    return float(np.linalg.norm(pa - pb, axis=1).min())


def _runs(flags: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) index of each run of True."""
    f = np.concatenate([[0], flags.astype(np.int8), [0]])
    edges = np.flatnonzero(np.diff(f))
    return [(int(a), int(b) - 1) for a, b in zip(edges[::2], edges[1::2], strict=True)]


def _window(
    impacts: Sequence[float],
    t_in: float,
    t_out: float,
    floor: float,
    amp: float,
    speed: float = RAMP_SPEED_M_S,
    pad: float = 0.0,
    after: float = AFTER_IMPACT_S,
    before: float = BEFORE_IMPACT_S,
) -> Window | None:
    """(t0, t1, t2, t3) of a detour of amplitude ``amp`` held over [t_in, t_out],
    between the hand's impacts (``impacts`` sorted) and after ``floor``; None when no
    impact-free span holds it or its ramps would be too fast."""
    k = bisect.bisect_right(impacts, t_in)
    lo = max((impacts[k - 1] + after) if k else -np.inf, floor)
    hi = impacts[k] - before if k < len(impacts) else np.inf
    if k < len(impacts) and impacts[k] <= t_out:
        return None  # an impact inside the conflict: nothing to bend
    need = 1.5 * amp / speed
    t1, t2 = max(t_in - pad, lo + need), min(t_out + pad, hi - need)
    if t1 > t2:  # a conflict too near an impact: hold what fits, centred
        mid = 0.5 * (t_in + t_out)
        t1 = t2 = min(max(mid, lo + need), hi - need)
        if lo + need > hi - need:
            return None
    longest = max(RAMP_MAX_S, need)  # see RAMP_MAX_S
    ramp_in = min(longest, t1 - lo)
    ramp_out = min(longest, hi - t2)
    # a ramp clamped to the least it may be (t1 = lo + need) comes back from the
    # subtraction an ulp short of ``need``: compared exactly, such a detour was never
    # made (as live, MMA Swing1 at 240 bpm at 10.68 s: the left tip 66 mm under the
    # hi-hat 10 ms after its stroke there; the frame drawn moves the samples' grid,
    # whole input the run began later and the lift was made)
    if min(ramp_in, ramp_out) < need - _TIME_EPS_S:
        return None
    return t1 - ramp_in, t1, t2, t2 + ramp_out


def _free(impacts: Sequence[float], t_in: float, t_out: float) -> float:
    """How much free time ``impacts`` leave around [t_in, t_out] (the shorter side)."""
    k = bisect.bisect_right(impacts, t_in)
    before = t_in - impacts[k - 1] if k else 1.0
    after = impacts[k] - t_out if k < len(impacts) else 1.0
    return min(before, after)


def _height(piece: Drum | Cymbal, tip: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(height (n,) m of ``tip`` (n, 3) over ``piece``'s struck surface, whether it is
    within the piece's rim (+ RIM_MARGIN_M) and not below its body), as
    virja.motion.drummer_report counts a stick in a piece."""
    if isinstance(piece, Cymbal):
        top, depth = piece.centre + piece.thickness / 2 * piece.normal, piece.thickness
    else:
        top, depth = piece.centre, piece.depth
    rel = tip - top
    hgt = rel @ piece.normal
    radial = np.linalg.norm(rel - hgt[:, None] * piece.normal, axis=1)
    return hgt, (hgt > -depth - 0.05) & (radial < piece.radius + RIM_MARGIN_M)


def _under(kit: DrumKit, tip: np.ndarray) -> np.ndarray:
    """(n,) how far (m) ``tip`` (n, 3) is under the deepest piece it is inside the rim
    of (>= 0; 0 where it is under none)."""
    out = np.zeros(len(tip))
    for piece in kit.pieces.values():
        hgt, inside = _height(piece, tip)
        out = np.maximum(out, np.where(inside, -hgt, 0.0))
    return out


def _harmless(
    t: np.ndarray,
    stick: Stick,
    w: Window,
    vec: np.ndarray,
    kit: DrumKit,
) -> bool:
    """Whether a detour (window ``w``, offset ``vec``) of a hand (wrist, butt, tip
    sampled at ``t`` every SAMPLE_S) keeps the wrist within its 30 fps jump and speed
    (see JUMP_OK_M) and the tip out of the kit where it was out."""
    lag = int(round(FRAME_30_S / SAMPLE_S))
    i = max(int(np.searchsorted(t, w[0])) - lag, 0)
    j = min(int(np.searchsorted(t, w[3])) + lag + 1, t.size)
    if j - i <= lag:
        return True
    seg = t[i:j]
    off = offsets([Detour(w[0], w[1], w[2], w[3], vec)], seg)
    was = _under(kit, stick[2][i:j])
    now = _under(kit, stick[2][i:j] + off)
    if np.any((now > SURFACE_TRIGGER_M) & (now > was + 1e-4)):
        return False
    old = stick[0][i:j]
    new = old + off

    def figures(p: np.ndarray) -> tuple[float, float]:
        jump = float(np.linalg.norm(p[lag:] - p[:-lag], axis=1).max())
        return jump, float(np.linalg.norm(np.diff(p, axis=0), axis=1).max()) / SAMPLE_S

    jo, so = figures(old)
    jn, sn = figures(new)
    return jn <= max(jo, JUMP_OK_M) and sn <= max(so, SPEED_OK_M_S)


def _to_tip(point: np.ndarray, tip: np.ndarray, back: np.ndarray) -> float:
    """How far (m) ``tip`` (3,) lies ahead of ``point`` (3,) against the horizontal
    direction ``back`` (unit, (3,)): the stick's length to pull back past a crossing."""
    return max(float((point - tip) @ back), 0.0)


def _apart_detour(
    t: np.ndarray,
    both: tuple[Stick, Stick],
    gap: np.ndarray,
    run: tuple[int, int],
    impacts: Sequence[Sequence[float]],
    kit: DrumKit,
    floor: float,
) -> list[tuple[int, Detour]] | None:
    """[(hand, detour)] keeping the two sticks apart over the samples ``run`` where they
    come near (``gap``: left minus right closest points), or None.

    Tried in order of the offset's size, the higher first, then the hand with more
    free time: either hand to either side across the sticks (the left kept on the
    side it comes from, or on the side it goes to), then one hand up, over the other
    stick, pulled back along its own stick, or moved out along the other stick, past
    its tip (GMD hip-hop 92 at 3.16-3.19 s: the left stick coming down to the snare
    through the crossed right one, 65 ms before its stroke; the right moves), by the
    amounts of UP_M and by as far as takes one tip around the other stick
    (_END_PAST_M); each held longer (HOLD_PAD_S) if it must.  The first that fits
    between the hand's impacts, keeps the sticks apart over its whole window and harms
    nothing (:func:`_harmless`) is made, first among those one ramp of RAMP_MAX_S
    takes (16 cm); if none, the same offsets (between the sticks) shared, half by each
    hand (two detours); then one hand alone on a longer ramp."""
    a, b = both
    i, j = run
    n = _apart(a, b, gap, i, j)
    sep = gap[i : j + 1] @ n  # signed, from the right stick to the left one
    t_in, t_out = float(t[i]), float(t[j])
    free = [-_free(impacts[h], t_in, t_out) for h in (0, 1)]
    tries = []
    for side in (1.0, -1.0):
        least = STICK_CLEAR_M - float((side * sep).min())
        for amp in (least, least + STICK_MORE_M):
            for h in (0, 1):
                vec = (amp if h == 0 else -amp) * side * n
                tries.append((amp, -vec[1], free[h], h, vec))
    k = i + int(np.argmin(np.linalg.norm(gap[i : j + 1], axis=1)))
    near = segment_closest(a[1][k : k + 1], a[2][k : k + 1], b[1][k : k + 1], b[2][k : k + 1])
    for h, stick in enumerate(both):
        back = stick[1][k] - stick[2][k]
        back[1] = 0.0
        back = back / max(float(np.linalg.norm(back)), 1e-9)
        past = both[1 - h][2][k] - both[1 - h][1][k]
        past[1] = 0.0
        past = past / max(float(np.linalg.norm(past)), 1e-9)
        for amp in UP_M:
            tries.append((amp, -amp, free[h], h, np.array([0.0, amp, 0.0])))
            tries.append((amp, 0.0, free[h], h, amp * back))
            tries.append((amp, 0.0, free[h], h, amp * past))
        # around the end: pulled back until its own tip, or moved along the other
        # stick until that one's tip, is behind the crossing (a stick passing through
        # the other one from under to over: no offset across or up fits)
        own = _to_tip(near[h][0], stick[2][k], back)
        other = _to_tip(near[1 - h][0], both[1 - h][2][k], -past)
        for amp in (own + _END_PAST_M, own + _END_PAST_M + STICK_MORE_M):
            tries.append((amp, 0.0, free[h], h, amp * back))
        for amp in (other + _END_PAST_M, other + _END_PAST_M + STICK_MORE_M):
            tries.append((amp, 0.0, free[h], h, amp * past))
    tries.sort(key=lambda x: x[:3])

    # a longer hold (HOLD_PAD_S) often gives the same window (held up to an impact):
    # such a try is not checked again (its checks are pure; it failed)
    seen: set[tuple[tuple[int, Window, bytes], ...]] = set()
    # the harmless try keeping the sticks farthest apart, at least STICK_NEAR_M (for
    # when none keeps them STICK_APART_M apart)
    nearest: list[tuple[float, list[tuple[int, Window, np.ndarray]]]] = []

    def fits(moved: list[tuple[int, Window, np.ndarray]]) -> bool:
        key = tuple((h, w, v.tobytes()) for h, w, v in moved)
        if key in seen:
            return False
        seen.add(key)
        apart = _apart_over(t, a, b, moved, run)
        if apart < STICK_NEAR_M or (nearest and apart <= nearest[0][0] and apart < STICK_APART_M):
            return False
        if not all(_harmless(t, both[h], w, v, kit) for h, w, v in moved):
            return False
        if apart >= STICK_APART_M:
            return True
        nearest[:] = [(apart, moved)]
        return False

    def alone(longer: bool) -> list[tuple[int, Detour]] | None:
        for pad in HOLD_PAD_S:
            for amp, _up, _free_s, h, vec in tries:
                if (1.5 * amp / RAMP_SPEED_M_S > RAMP_MAX_S + _TIME_EPS_S) != longer:
                    continue
                w = _window(impacts[h], t_in, t_out, floor, amp, pad=pad)
                if w is not None and fits([(h, w, vec)]):
                    return [(h, Detour(w[0], w[1], w[2], w[3], vec))]
        return None

    def shared() -> list[tuple[int, Detour]] | None:
        for pad in HOLD_PAD_S:
            for amp, _up, _free_s, h, vec in tries:
                half = 0.5 * (vec if h == 0 else -vec)
                moved = []
                for g, v in ((0, half), (1, -half)):
                    w = _window(impacts[g], t_in, t_out, floor, 0.5 * amp, pad=pad)
                    if w is None:
                        break
                    moved.append((g, w, v))
                else:
                    if fits(moved):
                        return [(g, Detour(w[0], w[1], w[2], w[3], v)) for g, w, v in moved]
        return None

    # one hand alone as far as a ramp of RAMP_MAX_S takes it (16 cm); then both hands
    # give way, each half the offset between the sticks (the left's minus the
    # right's), each ramp half as long (GMD rock half-time 140 fill at 0.43 and 0.61 s:
    # a left tom stroke from under the right stick crossed over the hi-hat, the right
    # landing inside the first crossing, the left's stroke 26 ms after the second); and
    # only then one hand alone on a longer ramp (a 16-20 cm pull-back alone, where both
    # could, doubled the fill's wrist p99 as live: 1.7 -> 3.2 m/s, its jump 6 -> 13 cm)
    # ... and where none keeps the sticks STICK_APART_M apart, the one that keeps them
    # farthest apart, if that is at least STICK_NEAR_M
    found = alone(False) or shared() or alone(True)
    if found is None and nearest:
        found = [(h, Detour(w[0], w[1], w[2], w[3], v)) for h, w, v in nearest[0][1]]
    return found


class Sampled:
    """Both hands' wrists and sticks sampled every SAMPLE_S over a span, and each tip's
    height over every piece (:func:`_height`): what :func:`detours_in` looks at.

    ``sticks[h](times)`` gives hand ``h``'s wrist and stick (wrist, butt, tip), each
    (n, 3), with the detours it has then.  After new detours of a hand,
    :meth:`redo` samples that hand again only inside their windows: a detour is zero
    outside (t0, t3), and a sample depends on its own time alone, so the samples kept
    are those a fresh sampling gives, to the bit (tests/motion/test_drummer_clear.py).
    The second and third passes of :meth:`virja.motion.drummer_hands.DrummerHands._clear`
    cost a few ms less each (docs/performance.md, "Pose and scene, eighth round")."""

    def __init__(self, sticks: Sequence[Sticks | None], kit: DrumKit, span: tuple[float, float]):
        self.t = np.arange(span[0], span[1], SAMPLE_S)
        self.pieces = list(kit.pieces.values())
        self.kit = kit
        self.sticks: list[Stick | None] = [None] * len(sticks)
        self.heights: list[list[tuple[np.ndarray, np.ndarray]]] = [[] for _ in sticks]
        if self.t.size < 2:
            return
        for h, f in enumerate(sticks):
            if f is not None:
                got = self.sticks[h] = f(self.t)
                self.heights[h] = [_height(p, got[2]) for p in self.pieces]

    def redo(self, h: int, stick: Sticks, changed: Sequence[Detour]) -> None:
        """Hand ``h`` sampled again (``stick``, with its detours now) wherever one of
        the detours ``changed`` is not zero."""
        have = self.sticks[h]
        if have is None or not changed or self.t.size < 2:
            return
        keep = np.zeros(self.t.size + 1, dtype=np.int32)
        for d in changed:
            keep[np.searchsorted(self.t, d.t0)] += 1
            keep[np.searchsorted(self.t, d.t3, side="right")] -= 1
        idx = np.flatnonzero(np.cumsum(keep[:-1]) > 0)
        if idx.size == 0:
            return
        new = stick(self.t[idx])
        for old, part in zip(have, new, strict=True):
            old[idx] = part
        for (hgt, inside), piece in zip(self.heights[h], self.pieces, strict=True):
            hgt[idx], inside[idx] = _height(piece, new[2])


def detours(
    sticks: Sequence[Sticks | None],
    impacts: Sequence[Sequence[float]],
    kit: DrumKit,
    span: tuple[float, float],
    floor: float,
) -> tuple[list[list[Detour]], list[list[Detour]]]:
    """New detours of both hands over ``span`` (s), each starting after ``floor``:
    (moves, lifts), each a list per hand; a move's ``vec`` offsets the whole hand, a
    lift's ``vec[1]`` raises the tip, the stick turned up about the wrist.

    ``sticks[h](times)`` gives hand ``h``'s wrist and stick (wrist, butt, tip), each
    (n, 3), with the detours it already has; ``impacts[h]`` its impact times, sorted."""
    return detours_in(Sampled(sticks, kit, span), impacts, floor)


def detours_in(
    sampled: Sampled, impacts: Sequence[Sequence[float]], floor: float
) -> tuple[list[list[Detour]], list[list[Detour]]]:
    """:func:`detours` over sticks already sampled (:class:`Sampled`)."""
    out: list[list[Detour]] = [[], []]
    lifts: list[list[Detour]] = [[], []]
    t = sampled.t
    if t.size < 2:
        return out, lifts
    left, right = sampled.sticks
    if left is not None and right is not None:
        pa, pb = segment_closest(left[1], left[2], right[1], right[2])
        gap = pa - pb
        d = np.linalg.norm(gap, axis=1)
        # each detour is found on the samples as they were before this pass: one whose
        # window overlaps another of the same hand made in this pass is left to the next
        # pass, which sees that one (two pull-backs of 15 cm for two runs 60 ms apart
        # added up to 30 cm, ramped out in 75 ms: a 16 cm jump at 30 fps, GMD rock 140
        # at 26.5 s).  The other hand's may overlap: a run whose detour reaches only
        # STICK_APART_M stays under STICK_TRIGGER_M and is found again each pass, and
        # deferred behind it, the left's pull-back for the crossing 80 ms on was never
        # made (GMD rock 135 at 16.34 s)
        busy: list[list[tuple[float, float]]] = [[], []]
        for i, j in _runs(d < STICK_CLEAR_M):
            if d[i : j + 1].min() < STICK_TRIGGER_M:
                found = _apart_detour(t, (left, right), gap, (i, j), impacts, sampled.kit, floor)
                if not found or any(
                    a <= made.t3 and made.t0 <= b for h, made in found for a, b in busy[h]
                ):
                    continue
                for h, made in found:
                    out[h].append(made)
                    busy[h].append((made.t0, made.t3))
    for h, heights in enumerate(sampled.heights):
        for hgt, inside in heights:
            for i, j in _runs(inside & (hgt < -SURFACE_TRIGGER_M)):
                amp = SURFACE_CLEAR_M - float(hgt[i : j + 1].min())
                w = _window(
                    impacts[h],
                    float(t[i]),
                    float(t[j]),
                    floor,
                    amp,
                    LIFT_SPEED_M_S,
                    0.0,
                    0.0,
                    LIFT_BEFORE_S,
                )
                if w is not None:  # the wrist stays: no jump, no speed added
                    lifts[h].append(Detour(w[0], w[1], w[2], w[3], np.array([0.0, amp, 0.0])))
    return out, lifts


__all__ = ["Detour", "Sampled", "detours", "detours_in", "offsets"]
