"""The drummer's hands (virja.plan.chain_hands): strokes to hands, bounces, rebounds,
a crowded hi-hat to the left foot, notes out of order."""

from __future__ import annotations

import itertools

from tests.plan.chains import context, drum
from virja.plan import drums
from virja.plan.chain_feet import FootChain
from virja.plan.chain_hands import BUZZ_S, HandsChain, hand_group, velocity_priority
from virja.plan.chain_kit import DrumHeld

SEQ = itertools.count()


def hands_with(*notes: tuple[float, int, int]) -> HandsChain:
    ctx = context()
    chain = HandsChain(ctx, FootChain(ctx, "left_foot"))
    for t, note, velocity in notes:
        take(chain, t, note, velocity)
    return chain


def take(chain: HandsChain, t: float, note: int, velocity: int = 100, known_s: float = 0.0) -> None:
    dn = chain.ctx.config.kit.lookup(note)
    assert dn is not None and dn.limb is None
    chain.take(chain.held(next(SEQ), drum(t, note, velocity), known_s, dn))


def test_velocity_priority_lets_ghost_notes_give_way_and_keeps_accents() -> None:
    assert [velocity_priority(1, v) for v in (20, 50, 80, 110)] == [4, 2, 1, 0]
    assert velocity_priority(0, 120) == 0


def test_hand_group_keeps_two_strokes_bounces_a_planned_piece_and_counts_the_rest() -> None:
    chain = hands_with()
    kit = chain.ctx.config.kit

    def rec(seq: int, t: float, note: int, velocity: int = 100) -> DrumHeld:
        dn = kit.lookup(note)
        assert dn is not None
        return chain.held(seq, drum(t, note, velocity), 0.0, dn)

    # snare twice 5 ms apart (one stroke), hi-hat, crash (least important), snare again
    group = [rec(1, 1.0, 38), rec(2, 1.005, 38), rec(3, 1.0, 42), rec(4, 1.0, 49), rec(5, 1.02, 38)]
    hp = hand_group(group, 1.0)
    assert [s.piece for s in hp.group.strokes] == ["snare", "hihat"]
    assert [[r.seq for r in c] for c in hp.kept] == [[1, 2], [3]]
    assert [(i, [r.seq for r in c]) for i, c in hp.bounces] == [(0, [5])]
    assert [r.seq for r in hp.extra] == [4]
    assert [s.dt for s in hp.group.strokes] == [0.0, 0.0]


def test_two_pieces_at_once_get_two_hands_and_the_state_follows() -> None:
    chain = hands_with((1.0, 38, 100), (1.0, 42, 100), (1.5, 38, 100))
    chain.fix_all()
    out = chain.ctx.ledger.outbox
    first = {p.piece: p.limb for p in out if p.time == 1.0}
    assert set(first.values()) == {"left_hand", "right_hand"}
    assert all(p.motion.name == f"{p.piece}_{p.limb}" for p in out)
    assert chain.state != drums.START


def test_a_crowded_hihat_goes_to_the_left_foot() -> None:
    chain = hands_with((1.0, 38, 100), (1.0, 42, 100), (1.0, 49, 100))
    chain.fix_all()
    by_piece = {p.piece: p for p in chain.ctx.ledger.outbox}
    assert by_piece["hihat"].limb == "left_foot"
    assert {by_piece["snare"].limb, by_piece["crash"].limb} == {"left_hand", "right_hand"}
    assert chain.foot.state == 1.0 and chain.ctx.ledger.counts["foot_chick"] == 1
    assert chain.foot.fixed[-1][1] is by_piece["hihat"]


def test_a_ghost_note_right_after_a_stroke_is_its_rebound_on_the_same_hand() -> None:
    chain = hands_with((1.0, 38, 100), (1.0 + BUZZ_S - 0.01, 38, 30))
    chain.fix_all()
    stroke, ghost = chain.ctx.ledger.outbox
    assert ghost.limb == stroke.limb and ghost.cost == 0.0
    assert ghost.impact == 1.0 + BUZZ_S - 0.01
    assert chain.pending_count == 0 and not chain.ctx.ledger.dropped


def test_fixing_in_steps_equals_fixing_at_once() -> None:
    notes = [(1.0 + 0.0625 * i, (38, 42, 45, 51, 49)[i % 5], 40 + (i * 37) % 87) for i in range(40)]
    once = hands_with(*notes)
    once.fix_all()
    steps = hands_with(*notes)
    for now in (1.1, 1.4, 1.45, 2.0, 2.9):
        steps.commit(now)
    steps.fix_all()
    assert steps.ctx.ledger.outbox == once.ctx.ledger.outbox


def test_out_of_order_a_free_hand_strikes_and_none_free_drops() -> None:
    chain = hands_with((1.0, 38, 100), (1.0, 42, 100), (2.0, 38, 100))
    chain.fix_all()
    take(chain, 1.0, 38, 90, known_s=1.1)  # the fixed snare stroke then: shared
    assert chain.ctx.ledger.outbox[-1].limb == chain.ctx.ledger.outbox[0].limb
    take(chain, 1.01, 45, 90, known_s=1.1)  # both hands struck 10 ms before
    assert [d.reason for d in chain.ctx.ledger.dropped] == ["no_free_limb"]
    take(chain, 1.5, 45, 90, known_s=1.4)  # both free
    p = chain.ctx.ledger.outbox[-1]
    assert (p.time, p.piece) == (1.5, "tom_low") and p.limb in ("left_hand", "right_hand")
    costs = chain.ctx.config.costs
    before = chain.ctx.ledger.outbox[3]  # the latest fixed before it: the shared snare
    row = costs.table[costs.motions.index(before.motion.name)]
    assert (
        p.cost
        == row[costs.index("tom_low", p.limb)]
        == min(row[costs.index("tom_low", h)] for h in ("left_hand", "right_hand"))
    )
