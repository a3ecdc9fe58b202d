"""Following a port that comes and goes (a keyboard unplugged and plugged back).

Pure state, time passed in: the IO owner asks :meth:`PortWatcher.due` at any
rate; when it says yes, it lists the port names and hands them to
:meth:`PortWatcher.update`, which answers what to do (a :class:`PortChange`) or
None.  Listing ports costs a round trip to the MIDI server, so it is done at a
low rate (``poll_interval_s``, default 0.5 s: a replugged keyboard plays again
within half a second, and the server sees two requests a second).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

DEFAULT_POLL_INTERVAL_S = 0.5


def find_port(names: Sequence[str], pattern: str) -> int | None:
    """Index of the first name containing ``pattern`` (case-insensitive); None if none."""
    needle = pattern.casefold()
    for i, name in enumerate(names):
        if needle in name.casefold():
            return i
    return None


@dataclass(frozen=True, slots=True)
class PortChange:
    """What the owner must do: close ``disconnect`` (if any), then open ``connect`` (if any).

    ``connect_index`` is the index of ``connect`` in the listing just given.
    """

    disconnect: str | None
    connect: str | None
    connect_index: int | None = None


class PortWatcher:
    """Keeps one connection to the first port whose name contains ``pattern``."""

    def __init__(
        self,
        pattern: str,
        *,
        connected: str | None = None,
        poll_interval_s: float = DEFAULT_POLL_INTERVAL_S,
    ) -> None:
        if poll_interval_s <= 0:
            raise ValueError(f"poll_interval_s must be > 0, got {poll_interval_s}")
        self.pattern = pattern
        self.connected = connected
        self.poll_interval_s = poll_interval_s
        self._next_poll_s = -math.inf

    def forget(self) -> None:
        """The owner failed to open the port it was told to: try again at the next poll."""
        self.connected = None

    def due(self, now_s: float) -> bool:
        """Whether it is time to list the ports again."""
        return now_s >= self._next_poll_s

    def update(self, names: Sequence[str], now_s: float) -> PortChange | None:
        """Compare a fresh listing with the connection held; None when nothing changes.

        The port held is kept as long as it is listed, even if another matching
        port appears before it; when it is gone, the first matching port (if any)
        replaces it.
        """
        self._next_poll_s = now_s + self.poll_interval_s
        if self.connected is not None and self.connected in names:
            return None
        index = find_port(names, self.pattern)
        wanted = None if index is None else names[index]
        if wanted == self.connected:
            return None
        change = PortChange(disconnect=self.connected, connect=wanted, connect_index=index)
        self.connected = wanted
        return change
