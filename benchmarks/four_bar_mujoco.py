"""The four-bar of ``scenes.four_bar()`` in projeq and in MuJoCo, side by side in one run: the CPU
of a 5 s simulation at equal accuracy (issue 34, "the four-bar against MuJoCo").

The mechanism: crank a = 0.3 m (1 kg) about the origin, coupler b = 1 m (2 kg) at the crank pin,
rocker c = 0.8 m (1.5 kg) about D = (1, 0); uniform slender rods (centroidal moment m L²/12),
gravity 9.81 m/s² along −y; the crank at 0.5 rad turning at 3 rad/s, the loop closed.

MuJoCo: three hinge bodies about z (the crank with the coupler as its child, the rocker), a
``connect`` equality between sites at the coupler's and the rocker's tips (solref = (2·dt, 1):
the stiffest the step resolves; solimp 0.9999 so that the constraint's impedance stays near 1
at every violation), contacts off, the fixed-step RK4 integrator; the initial hinge rates are
projeq's tree velocities. Its output is read every 0.05 s (``mj_step(..., nstep)`` between
outputs: no Python per step).

Error of a run = the largest crank-angle difference at the 101 output times 0, 0.05, …, 5 s from
projeq's RK45 run at rtol 1e-11, atol 1e-13. Each projeq setting is matched to MuJoCo's RK4 at
the largest step dt = 0.05 s / k (k whole, so the output times are steps) whose error is at
most projeq's; the ratio is projeq's CPU over that MuJoCo run's CPU (time.process_time, warm:
projeq's kernels compiled or loaded before, the minimum of ``--repeat`` alternating runs). One
``mj_forward`` and one projeq ẋ (closure included) are timed alongside.

    pip install 'projeq[bench]'                    # mujoco
    python benchmarks/four_bar_mujoco.py           # 5 s; the settings default, rtol 1e-6 and 1e-10
    python benchmarks/four_bar_mujoco.py --quick   # 0.5 s, rtol 1e-6 only, one repeat (a test)
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # single-threaded CPU times, comparable between codes
import argparse
import importlib.util
import time
import warnings

import numpy as np

import projeq as pq
from projeq.studies.table import Table
from projeq.studies.timing import time_per_call

A, B, C, D = 0.3, 1.0, 0.8, 1.0  # m: crank, coupler, rocker, ground link
MASSES = (1.0, 2.0, 1.5)  # kg: crank, coupler, rocker
G = 9.81  # m/s²
OUTPUT_STEP = 0.05  # s between output times
#: projeq settings compared: name → simulate's keyword arguments
SETTINGS = {"default": {}, "rtol=1e-6": {"rtol": 1e-6, "atol": 1e-8},
            "rtol=1e-10": {"rtol": 1e-10, "atol": 1e-12}}
REFERENCE = {"method": "RK45", "rtol": 1e-11, "atol": 1e-13}


def scene():
    return pq.scenes.four_bar(a=A, b=B, c=C, d=D, m=MASSES, g=G)


def mujoco_xml(dt: float) -> str:
    """The four-bar as MJCF at step ``dt``: rods along each body's x from its hinge."""

    def rod(name: str, m: float, L: float, pos: str, child: str = "", site: str = "") -> str:
        I_c = m * L * L / 12  # about the rod's centre, across it (about its axis: nearly 0)
        inertial = f'<inertial pos="{L / 2} 0 0" mass="{m}" diaginertia="1e-10 {I_c} {I_c}"/>'
        tip = f'<site name="{site}" pos="{L} 0 0"/>' if site else ""
        return f'<body name="{name}" pos="{pos}"><joint name="{name}" type="hinge" axis="0 0 1"/>' \
               f"{inertial}{tip}{child}</body>"

    coupler = rod("coupler", MASSES[1], B, f"{A} 0 0", site="coupler_tip")
    return (f'<mujoco><option timestep="{dt!r}" integrator="RK4" gravity="0 {-G} 0"><flag contact="disable"/>'
            f"</option><worldbody>{rod('crank', MASSES[0], A, '0 0 0', child=coupler)}"
            f"{rod('rocker', MASSES[2], C, f'{D} 0 0', site='rocker_tip')}</worldbody>"
            f'<equality><connect site1="coupler_tip" site2="rocker_tip" solref="{2 * dt!r} 1" '
            f'solimp="0.9999 0.9999 0.001 0.5 2"/></equality></mujoco>')


def mujoco_crank(k: int, times: np.ndarray) -> tuple[np.ndarray, float]:
    """Crank angle at ``times`` by MuJoCo's RK4 at dt = OUTPUT_STEP / k, and the CPU of the stepping."""
    import mujoco

    system = scene()
    model = mujoco.MjModel.from_xml_string(mujoco_xml(OUTPUT_STEP / k))
    data = mujoco.MjData(model)
    # projeq's tree orders q = (crank, rocker, coupler), the coupler's angle relative to the crank's
    # (as MuJoCo's hinge in the crank's body)
    tree_rates = system.tree_velocities(system.q0, system.s_dot0)
    for i, name in enumerate(system.tree.names):
        joint = model.joint(name)
        data.qpos[joint.qposadr[0]], data.qvel[joint.dofadr[0]] = system.q0[i], tree_rates[i]
    crank = model.joint("crank").qposadr[0]
    angles = np.empty(len(times))
    started = time.process_time()
    mujoco.mj_forward(model, data)
    angles[0] = data.qpos[crank]
    for i in range(1, len(times)):
        mujoco.mj_step(model, data, nstep=k)
        angles[i] = data.qpos[crank]
    return angles, time.process_time() - started


def projeq_crank(options: dict, times: np.ndarray) -> tuple[np.ndarray, float, object]:
    """Crank angle at ``times`` by ``simulate``, its CPU and the Result."""
    system = scene()
    started = time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the reference's tight RK45 is slow: known
        result = pq.simulate(system, float(times[-1]), t_eval=times, **options)
    return result.q[:, 0], time.process_time() - started, result


class MujocoSteps:
    """MuJoCo's runs by steps per output interval k, each made once; :meth:`fewest` finds the
    smallest k (largest step) whose crank error is at most a target."""

    def __init__(self, reference: np.ndarray, times: np.ndarray):
        self.reference, self.times, self.runs = reference, times, {}

    def error(self, k: int) -> float:
        if k not in self.runs:
            self.runs[k] = mujoco_crank(k, self.times)
        error = np.abs(self.runs[k][0] - self.reference).max()
        return float(error) if np.isfinite(error) else np.inf

    def fewest(self, target: float, k_max: int = 4096) -> int | None:
        """Smallest k ≤ k_max with error(k) ≤ target (the error falls with k: doubling, then bisection)."""
        k = 1
        while self.error(k) > target:
            if k >= k_max:
                return None
            k *= 2
        low, high = k // 2, k  # error(low) > target ≥ error(high), or low = 0
        while high - low > 1:
            middle = (low + high) // 2
            low, high = (low, middle) if self.error(middle) <= target else (middle, high)
        return high


def one_evaluation(budget: float) -> tuple[float, float]:
    """µs of CPU of one projeq ẋ (the evaluator's s̈ with its closure) and of one ``mj_forward``,
    timed alternately."""
    import mujoco

    system = scene()
    model = mujoco.MjModel.from_xml_string(mujoco_xml(1e-3))
    data = mujoco.MjData(model)
    evaluator = system.evaluator()
    q, s_dot = np.asarray(system.q0, float), np.asarray(system.s_dot0, float)
    best = time_per_call({"projeq": lambda q_, s_: evaluator.accelerations(q_, s_, 0.0),
                          "mujoco": lambda q_, s_: mujoco.mj_forward(model, data)}, q, s_dot, budget)
    return best["projeq"] * 1e6, best["mujoco"] * 1e6


def main(argv=None) -> Table:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--t-end", type=float, default=5.0, help="simulated seconds (default 5)")
    parser.add_argument("--repeat", type=int, default=3,
                        help="timed runs of each, alternating; the minimum counts")
    parser.add_argument("--quick", action="store_true", help="0.5 s, rtol 1e-6 only, one repeat")
    args = parser.parse_args(argv)
    settings = SETTINGS
    if args.quick:
        args.t_end, args.repeat, settings = 0.5, 1, {"rtol=1e-6": SETTINGS["rtol=1e-6"]}
    times = np.linspace(0.0, args.t_end, round(args.t_end / OUTPUT_STEP) + 1)
    projeq_crank({}, times[:2])  # compile or load the kernels outside the timings
    reference, reference_cpu, _ = projeq_crank(REFERENCE, times)
    have_mujoco = importlib.util.find_spec("mujoco") is not None
    if not have_mujoco:
        print("mujoco is not installed (pip install 'projeq[bench]'): its runs left out, the ratios are nan")
    steps = MujocoSteps(reference, times) if have_mujoco else None
    rows = []
    for name, options in settings.items():
        runs = [projeq_crank(options, times) for _ in range(args.repeat)]
        error, result = float(np.abs(runs[0][0] - reference).max()), runs[0][2]
        cpu = min(run[1] for run in runs)
        k = steps.fewest(error) if steps else None
        if k is None:
            rows.append((name, str(result.method), int(result.nfev), error, cpu, *(None,) * 4, float("nan")))
            continue
        mujoco_cpu = min([steps.runs[k][1]] + [mujoco_crank(k, times)[1] for _ in range(args.repeat - 1)])
        rows.append((name, str(result.method), int(result.nfev), error, cpu, OUTPUT_STEP / k,
                     round(args.t_end / OUTPUT_STEP) * k, steps.error(k), mujoco_cpu, cpu / mujoco_cpu))
    table = Table(("projeq", "method", "nfev", "crank error", "CPU", "MuJoCo RK4 dt", "steps", "MuJoCo error",
                   "MuJoCo CPU", "projeq/MuJoCo"), rows,
                  units={"crank error": "rad", "CPU": "s", "MuJoCo RK4 dt": "s", "MuJoCo error": "rad",
                         "MuJoCo CPU": "s"},
                  formats={"crank error": ".2e", "CPU": ".3f", "MuJoCo RK4 dt": ".3e", "MuJoCo error": ".2e",
                           "MuJoCo CPU": ".3f", "projeq/MuJoCo": ".2f"},
                  title=(f"four-bar over {args.t_end:g} s: projeq's CPU / MuJoCo RK4's at the largest step "
                         f"reaching projeq's crank error (against RK45 rtol 1e-11, "
                         f"{reference_cpu:.2f} s CPU)"))
    print(table.to_text())
    if have_mujoco:
        projeq_us, mujoco_us = one_evaluation(0.05 if args.quick else 1.0)
        print(f"one evaluation: projeq ẋ {projeq_us:.1f} µs, mj_forward {mujoco_us:.1f} µs, "
              f"ratio {projeq_us / mujoco_us:.2f}")
    return table


# compiled from the first call: this measures the compiled path
os.environ.setdefault("PROJEQ_COMPILE", "now")


if __name__ == "__main__":
    main()
