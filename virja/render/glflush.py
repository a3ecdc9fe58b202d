"""``glFlush`` for moderngl, which has only ``finish`` (flush and wait).

A flush hands the commands issued so far to the driver (on Mesa's llvmpipe:
the rasteriser threads start on the frame) and returns at once, so the
calling thread can do other work (build the next frame's scene) before it
reads the frame back.  Where no GL library can be loaded it does nothing: the
read-back flushes anyway, only later.
"""

from __future__ import annotations

import ctypes
import ctypes.util
from collections.abc import Callable
from functools import cache

_LIBRARIES = ("libOpenGL.so.0", "libGL.so.1", "libOpenGL.so", "libGL.so")


@cache
def _gl_flush() -> Callable[[], None] | None:
    names = list(_LIBRARIES)
    found = ctypes.util.find_library("OpenGL") or ctypes.util.find_library("GL")
    if found:
        names.append(found)
    for name in names:
        try:
            lib = ctypes.CDLL(name)
        except OSError:
            continue
        fn = getattr(lib, "glFlush", None)
        if fn is not None:
            fn.restype = None
            fn.argtypes = []
            flush: Callable[[], None] = fn
            return flush
    return None


def flush() -> bool:
    """Flush the current GL context's commands without waiting; False if unavailable."""
    fn = _gl_flush()
    if fn is None:
        return False
    fn()
    return True
