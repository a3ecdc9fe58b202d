"""Keep a long-running loop alive through one step's failure (docs/reliability.md).

``with survive_tick():`` around one tick of a daemon's loop: an exception in it
(anything but cancellation, KeyboardInterrupt or SystemExit) is logged as a
one-line warning -- once per kind and place, later ones counted -- and the loop
goes on with its next tick.  ``SURVIVED`` counts them all.
:func:`close_at_last_line` closes a text log whose disk failed, whole lines kept.
"""

from __future__ import annotations

import contextlib
import io
import logging
import os
import stat
import traceback
from collections import Counter
from collections.abc import Iterator
from contextlib import contextmanager
from typing import IO

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


def close_at_last_line(stream: IO[str]) -> None:
    """Close a text log whose write failed, cut back to its last whole line (a
    regular file only), so what was written stays readable line by line."""
    fd = None
    with contextlib.suppress(OSError, ValueError, AttributeError, io.UnsupportedOperation):
        fd = os.dup(stream.fileno())
    name = getattr(stream, "name", None)
    with contextlib.suppress(OSError, ValueError):
        stream.close()  # its flush may fail again: the file is closed anyway
    if fd is None:
        return
    try:
        if isinstance(name, str) and stat.S_ISREG(os.fstat(fd).st_mode):
            size = os.lseek(fd, 0, os.SEEK_END)
            start = max(0, size - 65536)
            with open(name, "rb") as reader:  # the log's own descriptor is write-only
                reader.seek(start)
                tail = reader.read(size - start)
            if tail and not tail.endswith(b"\n"):
                os.ftruncate(fd, start + tail.rfind(b"\n") + 1)
    except OSError:
        pass
    finally:
        os.close(fd)
