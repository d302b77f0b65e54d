"""What a user sees of numba's compilation (projeq/assembly/compilation.py): one line when a
projeq kernel is first compiled, nothing when it loads from the cache, and a damaged cache entry
discarded with one warning and compiled anew instead of a traceback on every later run.

The kernel here is a generated module's function (projeq writes the modules of its joints'
callbacks under the name ``projeq_generated_<digest>``), so that the test compiles in a second,
not the minute of the tree kernels; the mechanism is the same for every projeq kernel."""

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip("numba")

ROOT = Path(__file__).resolve().parents[2]
KERNEL = '''import numba

@numba.njit(cache=True)
def twice(x):
    return 2.0 * x
'''
RUN = "from projeq.assembly import kernels; kernels.numba_module(); import projeq_generated_probe as m; print(m.twice(1.5))"


def _environment(folder: Path) -> dict:
    """numba's cache in ``folder``/cache; the probe module in ``folder`` and this checkout's projeq importable."""
    return dict(os.environ, NUMBA_CACHE_DIR=str(folder / "cache"), PYTHONPATH=os.pathsep.join([str(folder), str(ROOT)]))


def _run(folder: Path, prelude: str = "") -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", prelude + RUN], cwd=folder, env=_environment(folder),
                          capture_output=True, text=True, timeout=120, check=False)


def test_first_compilation_is_announced_and_a_damaged_cache_is_rebuilt(tmp_path):
    (tmp_path / "projeq_generated_probe.py").write_text(KERNEL)
    first = _run(tmp_path)
    assert first.returncode == 0 and first.stdout.strip() == "3.0", first.stderr
    assert first.stderr.count("projeq: compiling the compiled kernels") == 1
    cached = [p for p in (tmp_path / "cache").rglob("*") if p.suffix in (".nbi", ".nbc")]
    assert cached, "numba wrote no cache entry"
    again = _run(tmp_path)
    assert again.returncode == 0 and again.stdout.strip() == "3.0" and "compiling" not in again.stderr
    for path in cached:  # truncated: as a full disk or a killed process leaves them
        path.write_bytes(path.read_bytes()[:10])
    damaged = _run(tmp_path)
    assert damaged.returncode == 0 and damaged.stdout.strip() == "3.0", damaged.stderr
    assert damaged.stderr.count("CacheWarning") == 1 and "discarded, compiling it anew" in damaged.stderr
    assert "Traceback" not in damaged.stderr
    rebuilt = _run(tmp_path)
    assert rebuilt.returncode == 0 and rebuilt.stderr == "", rebuilt.stderr


TOGETHER = '''import os, pathlib, time
from projeq.assembly import kernels; kernels.numba_module()
import projeq_generated_probe as m
pathlib.Path(f"ready-{os.getpid()}").touch()
while not pathlib.Path("go").exists():
    time.sleep(0.002)
print(m.twice(1.5))
'''


def test_processes_that_start_together_compile_a_kernel_once(tmp_path):
    """Two processes on an empty cache call the kernel at the same moment: one compiles it (announced)
    and the other waits for its lock and loads it from the cache (silent). Without the lock both
    compiled, as a sweep's workers or the test suite's processes each compiled every kernel."""
    pytest.importorskip("fcntl")  # POSIX: the lock is fcntl.flock
    (tmp_path / "projeq_generated_probe.py").write_text(KERNEL)
    runs = [subprocess.Popen([sys.executable, "-c", TOGETHER], cwd=tmp_path, env=_environment(tmp_path), stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True) for _ in range(2)]
    deadline = time.monotonic() + 60
    while len(list(tmp_path.glob("ready-*"))) < 2 and time.monotonic() < deadline and all(r.poll() is None for r in runs):
        time.sleep(0.01)
    (tmp_path / "go").touch()
    outputs = [run.communicate(timeout=120) for run in runs]
    assert [out.strip() for out, _ in outputs] == ["3.0", "3.0"], [err for _, err in outputs]
    assert sum(err.count("projeq: compiling the compiled kernels") for _, err in outputs) == 1, outputs


def test_a_process_holding_the_lock_too_long_is_not_waited_for_forever(tmp_path):
    """A process that holds a kernel's compile lock and does not finish (stopped, hung: here this test
    holds it) is waited for LOCK_WAIT seconds (1 s here), saying so, then the kernel is compiled
    without it: the run goes on, it never hangs."""
    fcntl = pytest.importorskip("fcntl")  # POSIX: the lock is fcntl.flock
    (tmp_path / "projeq_generated_probe.py").write_text(KERNEL)
    assert _run(tmp_path).returncode == 0  # compiled once: the lock file exists beside the cache entries
    (lock_file,) = (tmp_path / "cache").rglob("*.projeq-lock")
    for path in (tmp_path / "cache").rglob("*"):
        if path.suffix in (".nbi", ".nbc"):
            path.unlink()  # not cached any more: the next process must compile
    with open(lock_file, "a") as held:
        fcntl.flock(held, fcntl.LOCK_EX)
        found = _run(tmp_path, "from projeq.assembly import compilation; compilation.LOCK_WAIT = 1.0; ")
    assert found.returncode == 0 and found.stdout.strip() == "3.0", found.stderr
    assert "projeq: another process is compiling twice; waiting for it" in found.stderr
    assert "projeq: waited 1 s for another process compiling twice; compiling it here" in found.stderr
    assert "projeq: compiling the compiled kernels" in found.stderr
