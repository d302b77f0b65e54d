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
  :class:`CacheWarning` naming it, and the kernel is compiled and cached anew;
- one process compiles a kernel at a time, the others wait for it and load it from the cache
  (:func:`_one_at_a_time`): processes that start together on an empty cache — a sweep's workers,
  the test suite's — compile each kernel once, not once each;
- under :func:`cached_only` a kernel numba would compile raises :class:`NotCompiled` before
  its compilation starts (a kernel in memory or in the disk cache runs): the default evaluator
  (:mod:`projeq.assembly.auto`) evaluates interpreted instead, a closed loop by its numpy path
  (:class:`projeq.constraints.compiled.Deferred`), the integration loop by solve_ivp, until
  :data:`BUDGET` seconds of CPU are spent so over the runs of the same numba cache, then compiles
  (:func:`spend`, :func:`compile_now`).

All four apply to projeq's own functions only (their module's name starts with ``projeq``: the
package and the modules it generates, :func:`projeq.assembly.given.generated_module`).
"""

from __future__ import annotations

import atexit
import contextlib
import functools
import os
import sys
import threading
import time
import warnings
from pathlib import Path

try:
    import fcntl
except ImportError:  # Windows: no compile lock (_one_at_a_time)
    fcntl = None

#: seconds after which a top-level kernel's compilation is reported by name
SLOW = 5.0

#: CPU seconds of interpreted evaluation, while the compiled kernels needed are not in numba's cache,
#: after which they are compiled (counted over the processes of one numba cache). Compiling a model's
#: kernels costs 10–40 s of CPU (README's pendulum: 17 s for ẋ alone, 47 s for the whole example);
#: renting the interpreted evaluator until its cost reaches the price of compiling, then buying, costs
#: at most twice the better of the two choices made knowing the run's length in advance (the
#: ski-rental bound), and a short run (README's example, ``projeq run``) compiles nothing.
BUDGET = 10.0

#: ``PROJEQ_COMPILE=now``: compile on first use, as before the budget (benchmarks of the compiled path)
COMPILE_NOW = "now"


class NotCompiled(Exception):
    """Under :func:`cached_only`, numba was about to compile a projeq kernel (it was not cached)."""


class CacheWarning(UserWarning):
    """A damaged entry of numba's disk cache was discarded; the kernel was compiled anew."""


def _ours(function) -> bool:
    return (getattr(function, "__module__", None) or "").startswith("projeq")


class _Announcer:
    """numba's ``numba:compile`` listener: the first line, then the slow top-level kernels; under
    :func:`cached_only`, :class:`NotCompiled` before a top-level kernel compiles."""

    def __init__(self):
        self.announced, self.depth, self.started, self.cpu = False, 0, None, 0.0
        self.seconds = 0.0  # CPU of the top-level compilations of projeq's kernels in this process
        self.deferring = threading.local()

    def on_start(self, event):
        function = getattr(event.data.get("dispatcher"), "py_func", None)
        self.depth += 1  # the end event follows even where this raises
        if self.depth > 1 or not _ours(function):
            return
        self.started = None
        if getattr(self.deferring, "on", False):
            raise NotCompiled(function.__qualname__)  # before numba compiles anything
        self.started, self.cpu = time.perf_counter(), time.process_time()
        if not self.announced:
            self.announced = True
            print("projeq: compiling the compiled kernels — first use, cached afterwards (up to a minute or two on "
                  "a new machine)", file=sys.stderr, flush=True)

    def on_end(self, event):
        self.depth -= 1
        function = getattr(event.data.get("dispatcher"), "py_func", None)
        compiled = self.started is not None  # not the kernel cached_only stopped
        if self.depth == 0 and _ours(function) and compiled:
            self.seconds += time.process_time() - self.cpu
        if self.depth == 0 and _ours(function) and compiled and time.perf_counter() - self.started > SLOW:
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


def _one_at_a_time(compile):
    """numba's ``Dispatcher.compile``, for a top-level projeq kernel under an exclusive lock on a file
    beside its cache entries (``fcntl.flock``, released by the system if the process dies): a process
    that finds another compiling the same kernel waits, and numba's compile then finds the entry the
    other wrote and loads it (it looks in the disk cache before compiling); under :func:`cached_only` it
    does not wait: :class:`NotCompiled`; a stopped or hung holder is waited for :data:`LOCK_WAIT` seconds
    at most (:func:`_acquired`). Kernels compiled inside another's compilation are not locked (a process
    holding a lock never waits for one: no deadlock); without ``fcntl`` (Windows) or a disk cache,
    unchanged."""

    @functools.wraps(compile)
    def locked_compile(self, sig):
        folder = getattr(self._cache, "_cache_path", None)
        if fcntl is None or folder is None or getattr(_LOCKING, "held", False) or not _ours(self.py_func):
            return compile(self, sig)
        try:
            os.makedirs(folder, exist_ok=True)
            lock = open(os.path.join(folder, f"{self.py_func.__qualname__}.projeq-lock"), "a")  # noqa: SIM115
        except OSError:  # no file can be made in the cache folder: compile as numba does
            return compile(self, sig)
        with lock:
            try:
                if not _acquired(lock, self.py_func.__qualname__):
                    return compile(self, sig)
            except OSError:  # a file system without locks (some network ones): compile as numba does
                return compile(self, sig)
            _LOCKING.held = True
            try:
                return compile(self, sig)
            finally:
                _LOCKING.held = False
                fcntl.flock(lock, fcntl.LOCK_UN)

    locked_compile.projeq_locked = True
    return locked_compile


_LOCKING = threading.local()  # .held: this thread compiles a top-level kernel under its lock

#: seconds a process waits for another that compiles the same kernel, then compiles it itself (the other
#: may be stopped or hung; the longest of projeq's compilations takes about 3 minutes on a slow machine)
LOCK_WAIT = 600.0
_WAITED = threading.Event()  # set once this process has said that it waits for another's compilation


def _acquired(lock, name: str) -> bool:
    """Whether this process holds ``lock`` (the compile lock of kernel ``name``): at once, or after waiting
    for the process that holds it (said once per process on standard error) up to :data:`LOCK_WAIT`
    seconds (False: compile without it, said). Under :func:`cached_only`, a held lock is
    :class:`NotCompiled` (being compiled elsewhere is not cached yet)."""
    deadline = None  # of the wait, once it has begun
    while True:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return True
        except BlockingIOError:
            pass
        if getattr(_ANNOUNCER.deferring, "on", False):
            raise NotCompiled(name)
        if deadline is None:
            deadline = time.monotonic() + LOCK_WAIT
            if not _WAITED.is_set():
                _WAITED.set()
                print(f"projeq: another process is compiling {name}; waiting for it, then loading it from numba's "
                      "cache", file=sys.stderr, flush=True)
        elif time.monotonic() > deadline:
            print(f"projeq: waited {LOCK_WAIT:.0f} s for another process compiling {name}; compiling it here",
                  file=sys.stderr, flush=True)
            return False
        time.sleep(0.05)


@contextlib.contextmanager
def cached_only():
    """Within: projeq's kernels run where numba has them compiled (in this process or in its disk
    cache); one it would compile raises :class:`NotCompiled` instead (the calling thread only)."""
    prepare()
    _ANNOUNCER.deferring.on = True
    try:
        yield
    finally:
        _ANNOUNCER.deferring.on = False


class _Budget:
    """The CPU seconds spent interpreted while kernels were not cached, by this process and the
    earlier ones of the same numba cache: kept in a file beside the cache's entries of projeq's
    kernels (:func:`_ledger`), so that the budget is spent once per cache, not once per process (an
    emptied cache starts a new one)."""

    def __init__(self):
        self.spent, self.told, self.before = 0.0, False, None

    def total(self) -> float:
        if self.before is None:
            self.before = _read_ledger()
            atexit.register(self.save)
        return self.before + self.spent

    def exhausted(self) -> bool:
        return os.environ.get("PROJEQ_COMPILE", "").strip().lower() == COMPILE_NOW or self.total() >= BUDGET

    def save(self) -> None:
        if self.spent:
            with contextlib.suppress(OSError):
                ledger = _ledger()
                ledger.parent.mkdir(parents=True, exist_ok=True)
                ledger.write_text(f"{self.total():.3f}\n")


def _ledger() -> Path:
    """The file of the interpreted seconds: in the folder where numba caches this module's kernels
    (``NUMBA_CACHE_DIR``, the ``__pycache__`` beside it, or numba's user-wide folder where that is
    not writable), as numba's own locator finds it."""
    from numba.core.caching import FunctionCache

    return Path(FunctionCache(_ledger)._cache_path) / "projeq-interpreted-seconds"


def _read_ledger() -> float:
    try:
        return max(0.0, float(_ledger().read_text()))
    except (OSError, ValueError):  # none yet, unreadable or damaged: a new budget
        return 0.0


_BUDGET = _Budget()


def compile_now() -> bool:
    """Whether kernels compile at their next use: :data:`BUDGET` is spent, or ``PROJEQ_COMPILE=now``."""
    return _BUDGET.exhausted()


def compiling_seconds() -> float:
    """CPU seconds this process has spent compiling projeq's kernels (top-level compilations)."""
    return _ANNOUNCER.seconds


def spend(seconds: float, what: str) -> None:
    """Add ``seconds`` of interpreted evaluation to the budget; the first time, one line on standard
    error says so, naming ``what`` runs interpreted and how to compile at once."""
    _BUDGET.spent += seconds
    if not _BUDGET.told:
        _BUDGET.told = True
        print(f"projeq: {what}'s compiled kernels are not in numba's cache: evaluating it interpreted until "
              f"{BUDGET:.0f} s of CPU are spent so (now {_BUDGET.total():.1f} s, counted over the runs of this "
              "cache), then compiling them, once (PROJEQ_COMPILE=now compiles at first use)",
              file=sys.stderr, flush=True)


@functools.cache
def prepare() -> None:
    """Install the compilation notice, the safe cache loading and the compile lock (once per process;
    needs numba)."""
    from numba.core import caching, dispatcher, event

    class Listener(event.Listener):
        def on_start(self, found):
            _ANNOUNCER.on_start(found)

        def on_end(self, found):
            _ANNOUNCER.on_end(found)

    event.register("numba:compile", Listener())
    if not getattr(caching.Cache.load_overload, "projeq_safe", False):
        caching.Cache.load_overload = _safe_load(caching.Cache.load_overload)
    if not getattr(dispatcher.Dispatcher.compile, "projeq_locked", False):
        dispatcher.Dispatcher.compile = _one_at_a_time(dispatcher.Dispatcher.compile)


_ANNOUNCER = _Announcer()
