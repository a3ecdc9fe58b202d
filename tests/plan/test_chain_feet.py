"""A foot's chain (virja.plan.chain_feet): strokes, bounces, too fast, chicks."""

from __future__ import annotations

from tests.plan.chains import context, drum
from virja.plan.chain_feet import FootChain
from virja.plan.chain_kit import REBOUND_VELOCITY


def foot_with(limb: str, *notes: tuple[float, int, int]) -> FootChain:
    chain = FootChain(context(), "right_foot" if limb == "right_foot" else "left_foot")
    kit = chain.ctx.config.kit
    for i, (t, note, velocity) in enumerate(notes):
        dn = kit.lookup(note)
        assert dn is not None
        chain.take(chain.held(i, drum(t, note, velocity), 0.0, dn))
    return chain


def test_kind_is_the_pedal_timing() -> None:
    chain = foot_with("right_foot", (1.0, 36, 100))
    assert chain.pending[0].kind == "kick"
    assert foot_with("left_foot", (1.0, 44, 100)).pending[0].kind == "hihat_pedal"


def test_strokes_follow_and_the_state_is_the_last_stroke() -> None:
    chain = foot_with("right_foot", (1.0, 36, 100), (1.25, 36, 90))
    chain.fix_all()
    out = chain.ctx.ledger.outbox
    assert [(p.limb, p.piece, p.motion.name) for p in out] == [
        ("right_foot", "kick", "kick_right_foot")
    ] * 2
    assert chain.state == 1.25


def test_a_stroke_sooner_than_the_foot_can_is_the_second_note_of_a_double() -> None:
    # kick: 50 ms between strokes, the grouping window 30 ms; GMD (drummer9 session1
    # take 21, 1.84 s and 1.889 s): a kick pair 49 ms apart, the second the louder, is
    # a slide double: one press, the second note on the beater's rebound
    chain = foot_with(
        "right_foot", (1.0, 36, 38), (1.049, 36, 76), (1.5, 36, 100), (1.54, 36, 10), (1.6, 36, 90)
    )
    chain.fix_all()
    assert not chain.ctx.ledger.dropped
    out = {p.time: p for p in chain.ctx.ledger.outbox}
    assert set(out) == {1.0, 1.049, 1.5, 1.54, 1.6}
    for t in (1.049, 1.54):
        assert out[t].limb == "right_foot" and out[t].cost == 0.0 and out[t].impact == t
    assert chain.ctx.ledger.counts["foot_double"] == 2
    assert chain.state == 1.6  # 100 ms after the stroke at 1.5: a stroke of its own


def test_a_soft_touch_just_before_a_stroke_is_its_bounce_and_a_flam_rides_on_the_stroke() -> None:
    chain = foot_with(
        "right_foot", (1.0, 36, REBOUND_VELOCITY - 1), (1.035, 36, 100), (1.055, 36, 80)
    )
    chain.fix_all()
    out = {p.time: p for p in chain.ctx.ledger.outbox}
    assert set(out) == {1.0, 1.035, 1.055} and not chain.ctx.ledger.dropped
    assert out[1.055].motion == out[1.035].motion and out[1.055].impact == 1.055
    assert chain.state == 1.035  # only the loud note was a stroke of its own


def test_chick_takes_a_hihat_note_when_the_foot_is_free_or_already_there() -> None:
    foot = foot_with("left_foot", (1.0, 44, 100))
    hands_note = drum(2.0, 42)
    dn = foot.ctx.config.kit.lookup(42)
    assert dn is not None
    rec = foot.held(5, hands_note, 1.0, dn)
    assert foot.can_chick(2.0)
    assert foot.chick(rec)
    p = foot.ctx.ledger.outbox[-1]
    assert (p.limb, p.piece, p.motion.name, p.impact) == (
        "left_foot",
        "hihat",
        "hihat_left_foot",
        2.0,
    )
    assert foot.state == 2.0 and foot.ctx.ledger.counts["foot_chick"] == 1
    assert foot.can_chick(1.01)  # with the pending pedal stroke: rides on it
    assert not foot.can_chick(1.05)  # 50 ms after it: sooner than the pedal can


def test_chick_refuses_what_is_no_hihat_or_too_close_to_a_pedal_stroke() -> None:
    foot = foot_with("left_foot", (1.0, 44, 100))
    kit = foot.ctx.config.kit
    snare, hihat = kit.lookup(38), kit.lookup(42)
    assert snare is not None and hihat is not None
    assert not foot.chick(foot.held(5, drum(3.0, 38), 1.0, snare))
    assert not foot.chick(foot.held(6, drum(1.045, 42), 0.5, hihat))
    assert foot.ctx.ledger.outbox == []


def test_out_of_order_a_free_foot_strikes_a_busy_one_drops_it() -> None:
    chain = foot_with("right_foot", (1.0, 36, 100), (2.0, 36, 100))
    chain.fix_all()
    kit = chain.ctx.config.kit
    kick = kit.lookup(36)
    assert kick is not None
    chain.take(chain.held(7, drum(1.5, 36), 1.4, kick))  # free: a stroke
    chain.take(chain.held(8, drum(1.97, 36), 1.9, kick))  # 30 ms before a fixed one
    assert chain.ctx.ledger.outbox[-1].time == 1.5
    assert [d.reason for d in chain.ctx.ledger.dropped] == ["no_free_limb"]
