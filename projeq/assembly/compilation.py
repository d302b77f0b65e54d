"""What a user sees of numba's compilation: one line when projeq's kernels are first compiled, and
a damaged cache entry rebuilt with one warning instead of a traceback.

numba compiles projeq's kernels on their first use and keeps them in its disk cache
(``cache=True``), so a new machine or a new numba cache pays the compilation once. :func:`prepare`
(called wherever projeq first imports numba) makes that visible and safe:

- the first compilation of a projeq kernel in a process prints one line on standard error
  ("projeq: compiling the compiled kernels — first use, cached afterwards ..."), and each
  top-level kernel that then takes longer than :data:`SLOW` seconds one line with its name and
  time (numba's ``numba:compile`` event fires on a cache miss only, before compiling);
- a cache entry numba cannot read back (a truncated or corrupted index or data file: an
  ``EOFError`` or ``UnpicklingError`` from its loader) is discarded with one
  :class:`CacheWarning` naming it, and the kernel is compiled and cached anew.

Both apply to projeq's own functions only (their module's name starts with ``projeq``: the
package and the modules it generates, :func:`projeq.assembly.given.generated_module`).
"""

from __future__ import annotations

import functools
import sys
import time
import warnings

#: seconds after which a top-level kernel's compilation is reported by name
SLOW = 5.0


class CacheWarning(UserWarning):
    """A damaged entry of numba's disk cache was discarded; the kernel was compiled anew."""


def _ours(function) -> bool:
    return (getattr(function, "__module__", None) or "").startswith("projeq")


class _Announcer:
    """numba's ``numba:compile`` listener: the first line, then the slow top-level kernels."""

    def __init__(self):
        self.announced, self.depth, self.started = False, 0, 0.0

    def on_start(self, event):
        function = getattr(event.data.get("dispatcher"), "py_func", None)
        self.depth += 1
        if self.depth > 1 or not _ours(function):
            return
        self.started = time.perf_counter()
        if not self.announced:
            self.announced = True
            print("projeq: compiling the compiled kernels — first use, cached afterwards (up to a minute or two on "
                  "a new machine)", file=sys.stderr, flush=True)

    def on_end(self, event):
        self.depth -= 1
        function = getattr(event.data.get("dispatcher"), "py_func", None)
        if self.depth == 0 and _ours(function) and time.perf_counter() - self.started > SLOW:
            print(f"projeq:   compiled {function.__qualname__} "
                  f"({time.perf_counter() - self.started:.0f} s)", file=sys.stderr, flush=True)


def _safe_load(load):
    """numba's ``Cache.load_overload``, with an entry it cannot read discarded (:class:`CacheWarning`)."""

    @functools.wraps(load)
    def load_overload(self, sig, target_context):
        try:
            return load(self, sig, target_context)
        except Exception as exc:  # noqa: BLE001 — pickle's and numba's errors of a damaged file have no common base
            if not _ours(getattr(self, "_py_func", None)):
                raise
            name = f"{self._py_func.__module__}.{self._py_func.__qualname__}"
            warnings.warn(f"numba's cache entry of {name} in {self._cache_path} could not be read "
                          f"({type(exc).__name__}: {exc}); discarded, compiling it anew", CacheWarning, stacklevel=2)
            self.flush()  # an empty index: the entry compiled now replaces the damaged one
            return None

    load_overload.projeq_safe = True
    return load_overload


@functools.cache
def prepare() -> None:
    """Install the compilation notice and the safe cache loading (once per process; needs numba)."""
    from numba.core import caching, event

    class Listener(event.Listener):
        def on_start(self, found):
            _ANNOUNCER.on_start(found)

        def on_end(self, found):
            _ANNOUNCER.on_end(found)

    event.register("numba:compile", Listener())
    if not getattr(caching.Cache.load_overload, "projeq_safe", False):
        caching.Cache.load_overload = _safe_load(caching.Cache.load_overload)


_ANNOUNCER = _Announcer()
