"""The bass's chain (virja.plan.chain_bass): the left hand over strings and frets."""

from __future__ import annotations

from tests.plan.chains import bass, context
from virja.plan import bass as bass_mod
from virja.plan.chain_bass import BassChain
from virja.plan.types import PlannedNote

OPEN = {"E": 28, "A": 33, "D": 38, "G": 43}


def chain_with(*notes: tuple[float, int], known_s: float = 0.0) -> BassChain:
    chain = BassChain(context())
    for i, (t, pitch) in enumerate(notes):
        chain.take(chain.held(i, bass(t, pitch), known_s))
    return chain


def sounds(p: PlannedNote) -> int:
    assert p.string is not None and p.fret is not None
    return OPEN[p.string] + p.fret


def test_held_folds_a_note_into_range_and_reports_it_moved() -> None:
    chain = BassChain(context())
    rec = chain.held(1, bass(1.0, 16), 0.0)
    assert rec.played == 28 and rec.kind == "pluck"
    assert [(m.note.note, m.played_note) for m in chain.ctx.ledger.moved] == [(16, 28)]
    assert chain.held(2, bass(1.0, 40), 0.0).played == 40
    assert len(chain.ctx.ledger.moved) == 1


def test_a_line_is_fingered_where_it_sounds_and_the_hand_state_follows() -> None:
    chain = chain_with((1.0, 40), (1.5, 43), (2.0, 45), (2.5, 47))
    chain.fix_all()
    out = chain.ctx.ledger.outbox
    assert [sounds(p) for p in out] == [40, 43, 45, 47]
    assert all(p.limb == "right_hand" and p.piece is None for p in out)
    assert chain.state is not None  # fretted: the hand is somewhere
    last = out[-1]
    assert last.motion == bass_mod.motion_key(last.string or "", last.fret or 0, chain.state)
    assert chain.pending_count == 0 and chain.last_fixed_t == 2.5


def test_fixing_in_steps_equals_fixing_at_once() -> None:
    notes = [(1.0 + 0.25 * i, 28 + (i * 5) % 19) for i in range(20)]
    once = chain_with(*notes)
    once.fix_all()
    steps = chain_with(*notes)
    for now in (1.2, 1.9, 2.3, 3.0, 4.0):
        steps.commit(now)
    steps.fix_all()
    assert steps.ctx.ledger.outbox == once.ctx.ledger.outbox


def test_a_double_stop_is_one_group_and_pays_its_cost_once() -> None:
    chain = chain_with((1.0, 40), (1.0, 45))
    chain.fix_all()
    out = chain.ctx.ledger.outbox
    assert sorted(sounds(p) for p in out) == [40, 45]
    assert len({p.string for p in out}) == 2
    assert out[1].cost == 0.0


def test_out_of_order_notes_share_a_twin_drop_a_late_double_stop_or_take_a_free_spot() -> None:
    chain = chain_with((1.0, 40), (2.0, 43))
    chain.fix_all()
    state = chain.state
    chain.take(chain.held(10, bass(1.0, 40), 0.9))  # same pitch as a fixed note: shared
    twin = chain.ctx.ledger.outbox[0]
    shared = chain.ctx.ledger.outbox[-1]
    assert (shared.string, shared.fret, shared.motion, shared.cost) == (
        twin.string,
        twin.fret,
        twin.motion,
        0.0,
    )
    chain.take(chain.held(11, bass(1.0, 47), 0.9))  # another pitch then: too late to stop both
    assert [d.reason for d in chain.ctx.ledger.dropped] == ["no_double_stop"]
    n = len(chain.ctx.ledger.outbox)
    chain.take(chain.held(12, bass(1.5, 45), 1.4))  # between fixed notes: placed, no re-plan
    assert len(chain.ctx.ledger.outbox) == n + 1
    assert sounds(chain.ctx.ledger.outbox[-1]) == 45
    assert chain.state == state and chain.pending_count == 0
