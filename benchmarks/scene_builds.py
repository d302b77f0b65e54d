"""The build time of the scenes whose joints come from ``UserJoint.from_sympy``: the first build in
a fresh process, the median of ``--repeat`` builds after it, a build with another value of a
parameter that enters the joint's expressions (the disc's and the disk's radius, the bicycle's
rear wheel radius: a sweep's next point), and where the time goes — inside
``UserJoint.from_sympy`` (of it: sympy's lambdify with its common subexpressions, and the checks of
the pose against F and K), the rest (the scene's own sympy work, cached by the scene on the first
build, and the System) — and the first ``compiled_values`` of the scene's joints with their numba C
callbacks (compiled, or loaded from numba's disk cache).

With another checkout (before a change: ``git archive``), both trees alternately in fresh
processes, and the ratios before/after of the first and of the repeated build:

    PYTHONPATH=. python benchmarks/scene_builds.py [--repeat 5] [SCENE ...]
    git -C /work/main archive HEAD | tar -x -C /tmp/builds_old
    PYTHONPATH=. python benchmarks/scene_builds.py --base /tmp/builds_old
    PYTHONPATH=. python benchmarks/scene_builds.py --quick   # Barhorst's particle, one build after the first
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

CHILD = """
import json, statistics, sys, time
import sympy
import projeq as pq
from projeq import scenes
from projeq.joints import UserJoint, user_compiler
from projeq.constraints import compiled

name, repeat = sys.argv[1], int(sys.argv[2])
OTHER = {"knife_edge_disc": {"r": 1.1}, "rolling_disk": {"R": 0.016}, "whipple_bicycle": {"params": {"r_R": 0.31}}}
if name.startswith("rigid_slice_chain"):
    from projeq.scenes.elastic import rigid_slice_chain
    build = lambda **other: rigid_slice_chain(int(name.partition(":")[2] or 8), lambda t: (0.0, 0.0, 0.0))[0]
else:
    build = scenes.SCENES[name].build
scenes._symbolic(name) if name in scenes._SYMBOLIC else None  # the scene's module imported beforehand

spent = {"from_sympy": 0.0, "lambdify": 0.0, "checks": 0.0}

def timed(key, function):
    def wrapper(*args, **kwargs):
        started = time.perf_counter()
        try:
            return function(*args, **kwargs)
        finally:
            spent[key] += time.perf_counter() - started
    return wrapper

sympy.lambdify = timed("lambdify", sympy.lambdify)  # user_compiler calls sp.lambdify
user_compiler._check_pose = timed("checks", user_compiler._check_pose)
UserJoint.from_sympy = classmethod(timed("from_sympy", UserJoint.from_sympy.__func__))

def one(**other):
    for key in spent:
        spent[key] = 0.0
    started = time.perf_counter()
    system = build(**other)
    total = time.perf_counter() - started
    return system, dict(spent, total=total)

system, first = one()
repeats = [one()[1] for _ in range(repeat)]
median = {key: statistics.median(r[key] for r in repeats) for key in first}
other = one(**OTHER[name])[1]["total"] if name in OTHER else float("nan")
started = time.perf_counter()
for joint in getattr(system, "tree", system).joints:
    if getattr(joint, "symbols", None) is not None:
        compiled.joint_callback(joint)
callbacks = time.perf_counter() - started
print(json.dumps({"first": first, "repeat": median, "other": other, "callbacks": callbacks}))
"""

SCENES = ("car", "knife_edge_disc", "rolling_disk", "barhorst_particle", "nonholonomic_particle",
          "whipple_bicycle", "rigid_slice_chain:8")


def run(tree: Path, name: str, repeat: int) -> dict:
    """One fresh process of ``tree``: the first and the repeated builds of scene ``name``."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    done = subprocess.run([sys.executable, "-c", CHILD, name, str(repeat)], env=env, cwd=tree,
                          capture_output=True, text=True)
    if done.returncode:
        raise RuntimeError(f"{tree}: {name}: {done.stderr}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def ratio(a: float, b: float) -> str:
    return f"{a / b:.1f}" if b > 0 else "-"


def table(here: Path, names, repeat: int) -> None:
    """This tree alone: the first build, the repeated one, their ratio, and the breakdowns."""
    print(f"{'scene':22s} {'first s':>8s} {'repeat s':>9s} {'first/repeat':>12s} {'other value s':>13s} | "
          f"first: {'from_sympy':>10s} "
          f"{'lambdify':>8s} {'checks':>7s} {'rest':>6s} | repeat: {'from_sympy':>10s} {'lambdify':>8s} "
          f"{'checks':>7s} | {'callbacks s':>11s}")
    for name in names:
        r = run(here, name, repeat)
        f, p = r["first"], r["repeat"]
        print(f"{name:22s} {f['total']:8.3f} {p['total']:9.4f} {ratio(f['total'], p['total']):>12s} "
              f"{r['other']:13.4f} | "
              f"{'':7s}{f['from_sympy']:10.3f} {f['lambdify']:8.3f} {f['checks']:7.3f} "
              f"{f['total'] - f['from_sympy']:6.3f} | {'':8s}{p['from_sympy']:10.4f} {p['lambdify']:8.4f} "
              f"{p['checks']:7.4f} | {r['callbacks']:11.3f}")


def compare(here: Path, base: Path, names, repeat: int) -> None:
    """Both trees alternately: first and repeated builds before/after and their ratios."""
    print(f"{'scene':22s} {'first before':>12s} {'first after':>11s} {'ratio':>6s} | {'repeat before':>13s} "
          f"{'repeat after':>12s} {'ratio':>6s} | {'other value before':>18s} {'after':>7s} {'ratio':>6s}")
    for name in names:
        before, after = run(base, name, repeat), run(here, name, repeat)
        fb, fa = before["first"]["total"], after["first"]["total"]
        rb, ra = before["repeat"], after["repeat"]
        ob, oa = before.get("other", float("nan")), after["other"]
        print(f"{name:22s} {fb:12.3f} {fa:11.3f} {ratio(fb, fa):>6s} | {rb['total']:13.4f} {ra['total']:12.4f} "
              f"{ratio(rb['total'], ra['total']):>6s} | {ob:18.4f} {oa:7.4f} {ratio(ob, oa):>6s}")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scenes", nargs="*", default=list(SCENES),
                        help="scene names (rigid_slice_chain:N: the Cardan-jointed slice chain of N slices)")
    parser.add_argument("--base", type=Path, help="another checkout (before the change) to compare against")
    parser.add_argument("--repeat", type=int, default=5, help="builds after the first (median)")
    parser.add_argument("--quick", action="store_true", help="barhorst_particle, --repeat 1 (a test runs it)")
    args = parser.parse_intermixed_args(argv)
    if args.quick:
        args.scenes, args.repeat = ["barhorst_particle"], 1
    here = Path(__file__).resolve().parent.parent
    if args.base is None:
        table(here, args.scenes, args.repeat)
    else:
        compare(here, args.base, args.scenes, args.repeat)


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()
