"""Keep a long-running loop alive through one step's failure (docs/reliability.md).

``with survive_tick():`` around one tick of a daemon's loop: an exception in it
(anything but cancellation, KeyboardInterrupt or SystemExit) is logged as a
one-line warning -- once per kind and place, later ones counted -- and the loop
goes on with its next tick.  ``SURVIVED`` counts them all.
"""

from __future__ import annotations

import logging
import traceback
from collections import Counter
from collections.abc import Iterator
from contextlib import contextmanager

log = logging.getLogger(__name__)

SURVIVED: Counter[str] = Counter()


@contextmanager
def survive_tick() -> Iterator[None]:
    try:
        yield
    except Exception as exc:  # the loop must survive any one step (asyncio's cancel is not one)
        tb = traceback.extract_tb(exc.__traceback__)
        where = f"{tb[-1].filename.rsplit('/', 1)[-1]}:{tb[-1].lineno}" if tb else "?"
        key = f"{type(exc).__name__} at {where}"
        if key not in SURVIVED:
            log.warning("%s: %s (reported once; going on)", key, exc)
            log.debug("the traceback", exc_info=exc)
        SURVIVED[key] += 1
