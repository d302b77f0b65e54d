"""Probes of a :class:`~projeq.subsystems.beam.beam.RitzBeam` along a simulated trajectory:
displacement, slopes and section forces at a station x (issue 6, "Beam probes").

Section forces follow Euler–Bernoulli beam theory: bending moments M = EI Φ″ᵀq and shear
forces Q = −(EI Φ″ᵀq)′, the force that the part of the beam beyond x exerts on the part
before x, in the beam's reference frame (a tip load P gives Q = P along the beam).
Ritz section forces converge more slowly than displacements (two and three derivatives).
"""

from __future__ import annotations

import functools

import numpy as np
from numpy.typing import NDArray

from projeq.analysis.differentiation import attempt_complex, complex_step, raised_by, warn_differences

MODERATE_DEFLECTION = 0.1  # deflections and axial displacements up to 10 % of the length
MODERATE_ROTATION = 0.2  # slopes up to 0.2 rad: their square 0.04 is small against 1


class BeamProbes:
    """Mixin of RitzBeam: probes at stations (needs ``station_data``, ``slices`` and the
    column slices of the beam)."""

    def displacement(self, q_e, x) -> NDArray:
        """(u + u₂, v, w) at stations x in the beam's reference frame: for one q_e a
        (len(x), 3) array, for a trajectory of q_e (rows) a (n_t, len(x), 3) array."""
        x = self._stations(x)
        return self._displacement(q_e, x, self.slice_field(x, self.station_data(x)))

    def _displacement(self, q_e, x, field) -> NDArray:
        """:meth:`displacement` at the stations x of the slice ``field``."""
        q_e = np.asarray(q_e, dtype=float)
        rows = [self.slices(q, field)[0] - np.outer(x, (1.0, 0.0, 0.0)) for q in np.atleast_2d(q_e)]
        return np.array(rows) if q_e.ndim == 2 else rows[0]

    def out_of_range(self, q_e) -> str | None:
        """Where the rows of ``q_e`` leave the moderate-deflection range of the beam's
        second-order theory (deflections small against L, rotations whose square is small
        against 1: Bremer, *Elastic Multibody Dynamics*, 2008, §6.2): what was reached and what
        to do, or None. Limits: lateral deflection or axial displacement 10 % of L, a slope
        of the centre line 0.2 rad."""
        x = np.linspace(0.0, self.length, 21)  # the centre line's stations: their field formed once
        d = self._displacement(np.atleast_2d(q_e), x, self._centre_line_field(len(x)))
        lateral = np.hypot(d[..., 1], d[..., 2])
        reached = {"lateral deflection": lateral.max() / self.length,
                   "axial displacement": np.abs(d[..., 0]).max() / self.length}
        rotation = np.abs(np.diff(lateral, axis=1) / np.diff(x)).max()
        if max(reached.values()) <= MODERATE_DEFLECTION and rotation <= MODERATE_ROTATION:
            return None
        sizes = ", ".join(f"{name} {value:.3g} L" for name, value in reached.items())
        return (f"{sizes}, rotation {rotation:.3g} rad: beyond the moderate-deflection range of the beam's "
                f"second-order theory ({MODERATE_DEFLECTION:g} L, {MODERATE_ROTATION:g} rad), where its "
                "results mean nothing; use more Ritz functions, a slower manoeuvre, or a finer model "
                "(several shorter beams in a chain, each deflecting moderately)")

    def _stations(self, x) -> NDArray:
        x = np.atleast_1d(np.asarray(x, dtype=float))
        if not np.all((x >= 0) & (x <= self.length)):  # NaN is on no beam either
            raise ValueError(f"x: stations must lie on the beam, 0 ≤ x ≤ {self.length}, got {x.tolist()}")
        return x

    def centre_line(self, q_e: NDArray, y_dot: NDArray, stations: int = 21) -> tuple[NDArray, NDArray]:
        """Positions r(x) and velocities J(x) ẏ of ``stations`` equally spaced points of the
        centre line, in the beam's reference frame (for drawing and export)."""
        r, Phi_r = self.slices(q_e, self._centre_line_field(int(stations)))
        return r, self.jacobian(r, Phi_r) @ y_dot

    @functools.lru_cache(maxsize=4)  # noqa: B019 -- a handful of beams per run; drawing a series asks the same stations per frame
    def _centre_line_field(self, stations: int) -> tuple:
        """The slice field (``slice_field``) at the equally spaced stations of :meth:`centre_line`
        (formed once per count: most of the centre line's cost in a ParaView series otherwise)."""
        x = np.linspace(0.0, self.length, stations)
        return self.slice_field(x, self.station_data(x))

    def _coordinates(self, result) -> NDArray:
        """This beam's q_e along a trajectory (rows), found in ``result.system`` (a System, or the
        tree of a ConstrainedSystem: the same coordinates q); a plain array of q_e rows is taken
        as is."""
        if isinstance(result, np.ndarray):
            return np.atleast_2d(result)
        if result.system is None:
            raise ValueError("result: has no system (loaded from a file?); probe a Result from simulate()")
        system = getattr(result.system, "tree", result.system)
        places = [n for n, sub in enumerate(system.subsystems) if sub is self]
        if len(places) != 1:
            raise ValueError(f"result: this beam appears {len(places)} times in the system; probe it by q_e")
        return result.q[:, system.e_q_slice[places[0]]]

    def deflection(self, result, x: float) -> NDArray:
        """(u, v, w) at station x in the beam's reference frame along a simulated
        trajectory: one row per time point (u includes the foreshortening u₂)."""
        return self.displacement(self._coordinates(result), [x])[:, 0, :]

    def slope(self, result, x: float) -> NDArray:
        """(v′, w′) at station x, one row per time point."""
        return self._derivative(result, x, 1)

    def twist(self, result, x: float) -> NDArray:
        """Torsion angle β at station x (rad), one value per time point (zeros without
        torsional functions)."""
        q_e = self._coordinates(result)
        Phi, _ = self.station_data(self._stations(x))
        return q_e[:, self._local(self.beta_cols)] @ Phi["beta"][0][:, 0]

    def bending_moment(self, result, x: float) -> NDArray:
        """Bending moments (EI_z v″, EI_y w″) at station x (N m), one row per time point."""
        return self._derivative(result, x, 2) * np.array([self._EI_at(x, "z"), self._EI_at(x, "y")])

    def shear_force(self, result, x: float) -> NDArray:
        """Shear forces (Q_y, Q_z) = −((EI_z v″)′, (EI_y w″)′) = −(EI′ Φ″ᵀq + EI Φ‴ᵀq) at
        station x (N), one row per time point: the force of the part beyond x on the part
        before x. The slope EI′(x) is exact (:meth:`_EI_slope`)."""
        EI = np.array([self._EI_at(x, "z"), self._EI_at(x, "y")])
        EI_slope = np.array([self._EI_slope(x, "z"), self._EI_slope(x, "y")])
        return -(EI_slope * self._derivative(result, x, 2) + EI * self._derivative(result, x, 3))

    def _derivative(self, result, x: float, order: int) -> NDArray:
        """(v, w) derivatives of the given order at station x, one row per time point."""
        q_e = self._coordinates(result)
        Phi, _ = self.station_data(self._stations(x))
        if any(len(Phi[key]) <= order for key in ("v", "w")):
            raise ValueError(
                f"family: derivative {order} of the Ritz functions is needed here; the user family "
                f"gives only {len(Phi['v'])} arrays (Φ, Φ′, Φ″[, Φ‴])"
            )
        v = q_e[:, self._local(self.v_cols)] @ Phi["v"][order][:, 0]
        w = q_e[:, self._local(self.w_cols)] @ Phi["w"][order][:, 0]
        return np.column_stack((v, w))

    def _EI_at(self, x: float, axis: str) -> float:
        EI = self._EI[axis]
        return float(np.ravel(EI(np.array([x])))[0]) if callable(EI) else float(EI)

    def _EI_slope(self, x: float, axis: str) -> float:
        """EI′(x): 0 for a constant EI; for EI a function of x its complex step Im EI(x + i h)/h
        (Squire & Trapp, "Using complex variables to estimate derivatives of real functions",
        SIAM Review 40, 1998; exact to round-off; a function that returns a real constant has
        slope 0); a function that cannot take complex x (it casts to float) falls back, with one
        warning per callable, to the central difference over 2e-6 L inside [0, L]
        (relative error ~1e-10, :class:`~projeq.analysis.differentiation.DifferencesWarning`)."""
        EI = self._EI[axis]
        if not callable(EI):
            return 0.0
        slope, exc = attempt_complex(lambda: float(complex_step(lambda h: np.ravel(EI(np.array([x + h])))[0])))
        if exc is None:
            return slope
        warn_differences(f"EI_{axis} (shear_force's slope EI′(x))", raised_by(exc), f"{type(exc).__name__}: {exc}")
        h = 1e-6 * self.length
        ahead, behind = min(x + h, self.length), max(x - h, 0.0)
        return (self._EI_at(ahead, axis) - self._EI_at(behind, axis)) / (ahead - behind)

    @staticmethod
    def _local(cols: slice) -> slice:
        """Columns of ẏ → positions within q_e."""
        return slice(cols.start - 6, cols.stop - 6)
