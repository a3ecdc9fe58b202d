"""Sequence numbers: u32 arithmetic modulo 2^32 and a duplicate window.

``seq_diff(a, b)`` is ``a - b`` taken in (-2^31, 2^31]: "a is ahead of b" when
positive.  :class:`SeqWindow` remembers which of a sender's last 4096 sequence
numbers were seen (RFC 6479-style bit mask relative to the highest).
"""

from __future__ import annotations

SEQ_MOD = 1 << 32
HALF = 1 << 31
WINDOW = 4096
_WINDOW_MASK = (1 << WINDOW) - 1


def seq_add(seq: int, n: int) -> int:
    """``seq + n`` modulo 2^32."""
    return (seq + n) % SEQ_MOD


def seq_diff(a: int, b: int) -> int:
    """Signed distance ``a - b`` modulo 2^32, in (-2^31, 2^31]."""
    d = (a - b) % SEQ_MOD
    return d - SEQ_MOD if d > HALF else d


def seq_after(a: int, b: int) -> bool:
    """Whether ``a`` comes after ``b`` (over a window of 2^31)."""
    return seq_diff(a, b) > 0


class SeqWindow:
    """Which of the last ``WINDOW`` sequence numbers of one sender were seen.

    Bit ``i`` of ``mask`` is ``highest - i``.  A number more than ``WINDOW``
    behind the highest cannot be told from a restarted sender: it restarts the
    window (the sender's numbering started again).
    """

    __slots__ = ("highest", "mask")

    def __init__(self, first: int) -> None:
        self.highest = first
        self.mask = 1

    def seen(self, seq: int) -> bool:
        """Whether ``seq`` is a repeat within the window."""
        d = seq_diff(self.highest, seq)
        if d < 0 or d >= WINDOW:
            return False
        return bool(self.mask >> d & 1)

    def add(self, seq: int) -> None:
        """Record ``seq`` as seen (after :meth:`seen` said no)."""
        d = seq_diff(seq, self.highest)
        if d > 0:
            self.mask = ((self.mask << d) | 1) & _WINDOW_MASK if d < WINDOW else 1
            self.highest = seq
        elif -d < WINDOW:
            self.mask |= 1 << -d
        else:
            self.highest = seq
            self.mask = 1
