"""Five- and six-string basses and drop tunings: planned, animated and drawn."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.motion.helpers import bass
from virja.events import NoteOn
from virja.geometry import GEOMETRY
from virja.motion.band import BandAnimator
from virja.motion.clip import MotionLibrary, UnknownMotionError
from virja.motion.metrics import contact_distance
from virja.plan.config import load_plan_config
from virja.plan.planner import OnlinePlanner
from virja.render.scene import band_scene
from virja.routing import Router
from virja.session import Performance
from virja.vocab import ALL_BASS_STRINGS

TOL = 0.01


def _config(tmp_path: Path, tuning: str):  # type: ignore[no-untyped-def]
    path = tmp_path / "c.toml"
    path.write_text(f'[plan]\nbass_tuning = "{tuning}"\n')
    return load_plan_config(path)


def test_the_neck_has_room_for_six_strings_and_the_four_keep_their_place() -> None:
    b = GEOMETRY.bass
    assert b.strings == ALL_BASS_STRINGS
    lateral = [float((b.nut[s] - b.nut["D"]) @ (b.nut["G"] - b.nut["D"])) for s in b.strings]
    assert lateral == sorted(lateral)  # B on the E side, C beyond the G
    assert b.note_of("B", 0) == 23 and b.note_of("C", 5) == 53


@pytest.mark.parametrize("string", ["B", "C"])
def test_low_b_and_high_c_are_fretted_and_plucked_within_1cm(
    library: MotionLibrary, string: str
) -> None:
    for fret in (0, 1, 5, 12, 20):
        a = BandAnimator(library)
        a.use_bass_strings(ALL_BASS_STRINGS)
        p = bass(string, fret, 1.0, 1.2)
        a.add_planned(p)
        pluck, fretting = contact_distance(a, p, p.impact)
        assert pluck < TOL, (string, fret)
        if fret:
            assert fretting is not None and fretting < TOL, (string, fret)


def test_a_four_string_bass_refuses_a_b_string_note_with_a_clear_error(
    library: MotionLibrary,
) -> None:
    a = BandAnimator(library)
    with pytest.raises(UnknownMotionError, match="this bass has E A D G"):
        a.add_planned(bass("B", 3, 1.0, 1.2))
    with pytest.raises(UnknownMotionError, match="clips cover"):
        a.use_bass_strings(("E", "F"))


@pytest.mark.parametrize(
    "tuning, strings, low",
    [
        ("five", ("B", "E", "A", "D", "G"), 23),
        ("six", ALL_BASS_STRINGS, 23),
        ("drop_d", ("E", "A", "D", "G"), 26),
        ("five_drop_a", ("B", "E", "A", "D", "G"), 21),
    ],
)
def test_tunings_plan_and_animate_through_a_performance(
    tmp_path: Path, tuning: str, strings: tuple[str, ...], low: int
) -> None:
    cfg = _config(tmp_path, tuning)
    animator = BandAnimator()
    perf = Performance(router=Router(), planner=OnlinePlanner(cfg), animator=animator)
    assert animator.bass_strings == strings
    line = [low, low + 2, low + 4, 40, 45, 52, 60]
    for i, n in enumerate(line):
        perf.feed_routed("bass", NoteOn(0.5 * (i + 1), 0, n, 96), now_s=0.0)
    planned = perf.planner.flush()
    assert [p.note for p in sorted(planned, key=lambda p: p.time)] == line
    assert planned[0].string == strings[0] and planned[0].fret == 0  # the lowest open string
    for p in planned:
        animator.add_planned(p)
    for p in planned:
        pluck, fretting = contact_distance(animator, p, p.impact)
        assert pluck < TOL and (fretting is None or fretting < TOL), p
    pose = animator.pose(planned[-1].impact)
    assert tuple(pose.string_vibration) == strings
    # the scene draws one string per string of the tuning (more cylinders for more strings)
    four = BandAnimator()
    base = band_scene(four.pose(0.0))
    n_extra = len(strings) - 4
    drawn = band_scene(animator.pose(50.0))  # everything rung out: one segment per string
    assert _cylinders(drawn) - _cylinders(base) == n_extra


def _cylinders(dl) -> int:  # type: ignore[no-untyped-def]
    return sum(len(m) for m in dl.models.get("cylinder", []))
