# Models and exact periodic solutions for the periodic-orbit tests, derived here
# from the equations, not from the code under test:
# - Den Hartog's non-stick orbit of x'' + x + F0 sign(x') = F cos(w t) (Den Hartog 1931;
#   Shaw 1986) and its Floquet multipliers by a saltation analysis;
# - the stick-slip orbit of u' + sigma(u) ∋ c sin t, c > 1, slip phases in closed form;
# - the stick onset of Den Hartog's orbit (where the net force at a reversal reaches F0);
# - bifurcations of forced orbits by shooting with scipy's DOP853 (x(P) = x(0) and a condition
#   on the monodromy matrix), the fold of the forced Duffing oscillator's resonance;
# - event-driven flows by DOP853 with events: a forced oscillator with dry friction between its
#   velocity's zeros (reversals, sticks), a forced oscillator held by a face x <= 1.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import scipy.optimize as so
from scipy.integrate import solve_ivp

import dmi


class DenHartog:
    """x'' + 2 zeta x' + x + F0 sign(x') = F cos(w t), as u = (x, v): u' + A(u) + f(t, u) ∋ 0
    with f = (-v, x + 2 zeta v - F cos w t), A = (0, F0 sigma(v)).  ``zeta = 0``: Den Hartog's
    closed form (attributes a, t0, exact(t), multipliers)."""

    def __init__(self, w: float = 0.7, F: float = 1.0, F0: float = 0.3, zeta: float = 0.0):
        self.w, self.F, self.F0, self.zeta = w, F, F0, zeta
        self.T = 2 * np.pi / w
        if zeta == 0.0:
            self._solve()

    def make_for(self, M: int):
        """make(p) with h = T / M (no delay: tau = h, N = 1); p scales the forcing: F p."""
        w, F0, z = self.w, self.F0, self.zeta

        def make(p: float) -> dmi.Solver:
            if not 0 <= p <= 10:
                raise ValueError(f"p = {p}: the forcing scale must be in [0, 10]")
            Fp = self.F * p
            s = dmi.Solver(2, self.T / M, 1)
            s.set_rhs(lambda t, u: np.array([-u[1], u[0] + 2 * z * u[1] - Fp * np.cos(w * t)]))
            s.set_friction([0.0, F0])
            return s
        return make

    # --- Den Hartog's orbit (zeta = 0): on [t0, t0 + T/2] x' > 0 and
    #     x = -F0 + C1 cos(t - t0) + C2 sin(t - t0) + Q cos(w t), Q = F / (1 - w^2);
    #     x(t0) = -a, x'(t0) = 0, x(t0 + T/2) = a, x'(t0 + T/2) = 0; x(t + T/2) = -x(t).
    def _solve(self) -> None:
        w, F0, T = self.w, self.F0, self.T
        Th = T / 2
        z = den_hartog_orbit(w, self.F, F0, guesses=(1.0,))
        self.C1, self.C2, self.a, self.t0 = z[0], z[1], z[2], z[3] % T
        r = np.linspace(0, Th, 4001)[1:-1]  # x' > 0 inside the half [t0, t0 + T/2]
        if np.any(self.exact(self.t0 + r)[1] <= 0):
            raise RuntimeError("x' changes sign inside a half period: not Den Hartog's orbit")
        # non-stick: x' keeps its sign on each half (checked), and at a reversal the net force
        # exceeds F0 (no stick): |F cos(w ts) - a| > F0 at the maximum ts = t0 + T/2
        ts1 = self.t0 + Th
        if abs(self.F * np.cos(w * ts1) - self.a) <= F0:
            raise RuntimeError("the orbit sticks")
        # saltation at a reversal v: + -> - at x = a: S = diag(1, acc_after / acc_before)
        acc_before = -self.a - F0 + self.F * np.cos(w * ts1)
        acc_after = -self.a + F0 + self.F * np.cos(w * ts1)
        R = np.array([[np.cos(Th), np.sin(Th)], [-np.sin(Th), np.cos(Th)]])  # x'' + x = 0, T/2
        S = np.diag([1.0, acc_after / acc_before])
        mu = np.linalg.eigvals(S @ R @ S @ R)  # the reversal at x = -a has the same S (symmetry)
        self.multipliers = mu[np.argsort(-np.abs(mu))]
        self.smooth_multipliers = np.linalg.eigvals(R @ R)  # without the saltation

    def exact(self, t):
        """(x(t), x'(t)) of Den Hartog's orbit."""
        w, Th = self.w, self.T / 2
        Q = self.F / (1 - w * w)
        tt = (np.asarray(t) - self.t0) % self.T
        s = np.where(tt < Th, 1.0, -1.0)
        r = np.where(tt < Th, tt, tt - Th)
        t = np.asarray(t)
        x = s * (-self.F0 + self.C1 * np.cos(r) + self.C2 * np.sin(r)) + Q * np.cos(w * t)
        v = s * (-self.C1 * np.sin(r) + self.C2 * np.cos(r)) - Q * w * np.sin(w * np.asarray(t))
        return x, v


def den_hartog_orbit(w: float, F: float, F0: float, guesses: tuple[float, ...] = (1.0, 0.5, 2.0)
                     ) -> tuple[float, float, float, float]:
    """(C1, C2, a, t0) of Den Hartog's orbit (zeta = 0, see :class:`DenHartog`): the four
    conditions at the reversals by fsolve from a = g |Q| (g in guesses) and 25 phases t0."""
    T = 2 * np.pi / w
    Q, Th = F / (1 - w * w), T / 2

    def eqs(z):
        C1, C2, a, t0 = z
        s, c = np.sin(w * t0), np.cos(w * t0)
        return [-F0 + C1 + Q * c + a, C2 - Q * w * s,
                -F0 + C1 * np.cos(Th) + C2 * np.sin(Th) - Q * c - a,
                -C1 * np.sin(Th) + C2 * np.cos(Th) + Q * w * s]
    for g in guesses:
        for t0 in np.linspace(0, T, 25, endpoint=False):
            z, _, ier, _ = so.fsolve(eqs, [0, 0, g * abs(Q), t0], full_output=True, xtol=1e-14)
            if ier == 1 and z[2] > 0 and max(map(abs, eqs(z))) < 1e-12:
                return tuple(float(v) for v in z)
    raise RuntimeError(f"no Den Hartog orbit at w = {w}, F = {F}")


def den_hartog_onset(w: float, F0: float, lo: float, hi: float) -> float:
    """The forcing F in [lo, hi] where the net force at Den Hartog's orbit's reversal reaches
    F0, |F cos(w (t0 + T / 2)) - a| = F0 (its stick onset), by brentq."""
    def margin(F: float) -> float:
        _, _, a, t0 = den_hartog_orbit(w, F, F0)
        return abs(F * np.cos(w * t0 + np.pi) - a) - F0
    return so.brentq(margin, lo, hi, xtol=1e-14, rtol=1e-15)


class StickSlip1:
    """u' + sigma(u) ∋ c sin t (c > 1): f = -c sin t, A = sigma.  The 2 pi-periodic orbit:
    stuck at 0 until t1 = asin(1/c), then u = c (cos t1 - cos t) - (t - t1) > 0 until t2, stuck
    again until pi + t1 (c sin t2 >= -1 checked), then the mirror image: u(t + pi) = -u(t)."""

    def __init__(self, c: float = 1.5):
        self.c = c
        self.T = 2 * np.pi
        self.t1 = np.arcsin(1 / c)
        self.t2 = so.brentq(lambda t: self._slip(t), np.pi - self.t1, 2 * np.pi)
        if c * np.sin(self.t2) < -1:
            raise RuntimeError("no stick after the slip")
        self.stick_fraction = 2 * (np.pi + self.t1 - self.t2) / (2 * np.pi)

    def _slip(self, t):
        return self.c * (np.cos(self.t1) - np.cos(t)) - (t - self.t1)

    def exact(self, t):
        s = (np.asarray(t) - self.t1) % (2 * np.pi)  # from the start of the positive slip
        half = s >= np.pi
        r = self.t1 + np.where(half, s - np.pi, s)
        u = np.where(r < self.t2, self._slip(r), 0.0)
        return np.where(half, -u, u)

    def make_for(self, M: int):
        c = self.c

        def make(p: float) -> dmi.Solver:
            s = dmi.Solver(1, self.T / M, 1)
            s.set_rhs(lambda t, u: np.array([-c * np.sin(t)]))
            s.set_friction([1.0])
            return s
        return make


class SlipOnly1:
    """u' + a u + sigma(u) ∋ c sin t (c = 3 > 1 + ...: u crosses 0 transversally twice a period,
    never sticks): f = a u - c sin t, A = sigma.  Without saltation its multiplier would be
    exp(-2 pi a); the crossings make it much smaller."""

    def __init__(self, a: float = 0.1, c: float = 3.0):
        self.a, self.c, self.T = a, c, 2 * np.pi

    def make_for(self, M: int):
        a, c = self.a, self.c

        def make(p: float) -> dmi.Solver:
            s = dmi.Solver(1, self.T / M, 1)
            s.set_rhs(lambda t, u: np.array([a * u[0] - c * np.sin(t)]))
            s.set_friction([1.0])
            return s
        return make


class Fold:
    """u' = p - u^2 (f = u^2 - p, h = 0.1, M = 10 steps a period): the scheme's fixed points
    u = +-sqrt(p) fold at p = 0; multiplier (1 - 2 h u)^M."""
    h, M = 0.1, 10

    def make(self, p: float) -> dmi.Solver:
        s = dmi.Solver(1, self.h, 1)
        s.set_rhs(lambda t, u: np.array([u[0] ** 2 - p]))
        return s


class Logistic:
    """The scheme with h = 1 on u' = p u (1 - u): U+ = U + p U (1 - U), the logistic map
    x -> r x (1 - x) with r = 1 + p, u = r x / p.  Fixed point u = 1, multiplier 1 - p:
    period doubling at p = 2 (r = 3), the 2-cycle x = ((r + 1) +- sqrt((r + 1)(r - 3))) / (2 r)
    with multiplier 4 + 2 r - r^2, doubling again at r = 1 + sqrt(6)."""

    def make(self, p: float) -> dmi.Solver:
        s = dmi.Solver(1, 1.0, 1)
        s.set_rhs(lambda t, u: np.array([-p * u[0] * (1 - u[0])]))
        return s

    @staticmethod
    def cycle(p: float) -> np.ndarray:
        r = 1 + p
        x = ((r + 1) + np.array([1, -1]) * np.sqrt((r + 1) * (r - 3))) / (2 * r)
        return x * r / p


class Belt:
    """A mass on a moving belt with negative viscous damping, autonomous:
    x'' - 2 d x' + x + alpha sigma(x' - v) ∋ 0, as u = (x, y), y = x' - v: f = (-(y + v),
    x - 2 d (y + v)), A = (0, alpha sigma(y)).  Stick (y = 0) while |x - 2 d v| <= alpha; the slip
    starts at x_e = alpha + 2 d v with x' = v and, x'' - 2 d x' + x = alpha (y < 0), grows until x'
    is v again at x_r; the stick then carries x back to x_e at speed v.  Period and stick time
    from the closed-form slip (one root of x'(t) = v)."""

    def __init__(self, alpha: float = 1.0, v: float = 0.5, d: float = 0.05):
        self.alpha, self.v, self.d = alpha, v, d
        w = np.sqrt(1 - d * d)
        z0, dz0 = 2 * d * v, v  # z = x - alpha

        def z(t):
            return np.exp(d * t) * (z0 * np.cos(w * t) + (dz0 - d * z0) / w * np.sin(w * t))

        def dz(t):
            e = np.exp(d * t)
            a, b = z0, (dz0 - d * z0) / w
            return e * ((d * a + w * b) * np.cos(w * t) + (d * b - w * a) * np.sin(w * t))
        ts = np.linspace(1e-6, 2 * np.pi / w, 20001)
        k = np.nonzero(dz(ts) - v >= 0)[0]
        k = k[k > 10][0]  # the first return of x' to v
        self.t_slip = so.brentq(lambda t: dz(t) - v, ts[k - 1], ts[k])
        self.x_r = alpha + z(self.t_slip)
        self.x_e = alpha + 2 * d * v
        if abs(self.x_r - 2 * d * v) > alpha:
            raise RuntimeError("no stick after the slip")
        self.t_stick = (self.x_e - self.x_r) / v
        self.T = self.t_slip + self.t_stick

    def make(self, p: float, h: float = 0.01) -> dmi.Solver:
        a, v, d = self.alpha, self.v, self.d
        s = dmi.Solver(2, h, h=h)
        s.set_rhs(lambda t, u: np.array([-(u[1] + v), u[0] - 2 * d * (u[1] + v)]))
        s.set_friction([0.0, a])
        return s


class ParametricDuffing:
    """x'' + d x' + (1 + b cos w t) x + x^3 = 0 (Mathieu with a hardening cubic), as u = (x, v):
    f = (-v, d v + (1 + b cos w t) x + x^3), no friction, no delay (tau = h, N = 1), M steps a
    forcing period 2 pi / w.  The rest u = 0 is an orbit for every w; its multipliers cross -1
    at the lower edge w* of the principal parametric resonance tongue (w near 2), where a stable
    orbit of twice the forcing period is born (x -> -x half a period later).  With f explicit
    the scheme is U+ = U - h f(t_k, U), t_k = k h: its period map and exact derivative (the
    product of I - h Df) are computed here in numpy, independent of dmi.analysis."""

    def __init__(self, d: float = 0.1, b: float = 0.4, M: int = 100):
        self.d, self.b, self.M = d, b, M

    def make(self, w: float, h: float | None = None) -> dmi.Solver:
        """The model at frequency w, step h (default 2 pi / (w M))."""
        h = 2 * np.pi / (w * self.M) if h is None else h
        d, b = self.d, self.b
        s = dmi.Solver(2, h, h=h)
        s.set_rhs(lambda t, u: np.array([-u[1], d * u[1] + (1 + b * np.cos(w * t)) * u[0]
                                         + u[0] ** 3]))
        return s

    def run(self, x, w: float, periods: int = 1) -> tuple[np.ndarray, np.ndarray]:
        """(U after periods M steps from U^0 = x at t = 0, its derivative in x) by numpy."""
        h = 2 * np.pi / (w * self.M)
        u, D = np.array(x, dtype=float), np.eye(2)
        for k in range(periods * self.M):
            c = 1 + self.b * np.cos(w * (k * h))
            D = (np.eye(2) - h * np.array([[0.0, -1.0], [c + 3 * u[0] ** 2, self.d]])) @ D
            u = u - h * np.array([-u[1], self.d * u[1] + c * u[0] + u[0] ** 3])
        return u, D

    def rest_multipliers(self, w: float) -> np.ndarray:
        return np.linalg.eigvals(self.run([0.0, 0.0], w)[1])

    def doubling(self, lo: float = 1.79, hi: float = 1.85) -> float:
        """w* in [lo, hi]: the rest's real multiplier through -1 (brentq)."""
        def g(w):
            mu = self.rest_multipliers(w)
            return float(np.min(mu[np.abs(mu.imag) < 1e-12].real, initial=0.0)) + 1
        return so.brentq(g, lo, hi, xtol=1e-14)

    def two_cycle(self, w: float, guess) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(U at t = 0, U one forcing period later, multipliers) of the orbit of period
        2 (2 pi / w) near guess (U at t = 0): Newton on the two-period map in numpy."""
        x = np.array(guess, dtype=float)
        for _ in range(50):
            u, D = self.run(x, w, 2)
            if np.max(np.abs(u - x)) < 1e-14:
                break
            x = x - np.linalg.solve(D - np.eye(2), u - x)
        else:
            raise RuntimeError(f"no two-cycle near {guess} at w = {w}")
        u, D = self.run(x, w, 2)
        return x, self.run(x, w)[0], np.linalg.eigvals(D)


class BumpStick:
    """u' + sigma(u) ∋ F_p(t) = a + c sin t - p sin 3t (friction alpha = 1; f = -F_p, no delay:
    tau = h, N = 1; M steps a period 2 pi).  Around t = 3 pi / 2, F_p(3 pi / 2 + s) =
    a - c cos s - p cos 3s >= a - c - p (c, p > 0): the minimum a - c - p sits at s = 0.
    With a = 0.2, c = 1 the orbit slips once a period (F > 1 around pi / 2) and sticks in one
    phase around 3 pi / 2 while F >= -1 there, i.e. p <= p* = 1 + a - c; above p* the bump of
    -F reaches the friction, a short negative slip splits the stick phase in two (a grazing).
    For the scheme the same p* holds exactly: a stuck step stays stuck while |F_p(t_k)| <= 1,
    and t_k = 3 pi / 2 is a step when 4 divides M.  Slips in closed form (brentq on the
    antiderivative of F): :meth:`stick_time`."""

    def __init__(self, a: float = 0.2, c: float = 1.0):
        self.a, self.c = a, c
        self.p_star = 1.0 + a - c

    def F(self, t, p: float):
        return self.a + self.c * np.sin(t) - p * np.sin(3 * t)

    def _G(self, t, p: float):   # an antiderivative of F
        return self.a * t - self.c * np.cos(t) + p / 3 * np.cos(3 * t)

    def make_for(self, M: int):
        a, c = self.a, self.c

        def make(p: float) -> dmi.Solver:
            s = dmi.Solver(1, 2 * np.pi / M, 1)
            s.set_rhs(lambda t, u: np.array([-(a + c * np.sin(t) - p * np.sin(3 * t))]))
            s.set_friction([1.0])
            return s
        return make

    def stick_time(self, p: float) -> tuple[float, int]:
        """(stuck time per period, stick phases) of the continuous orbit at p: the positive slip
        from t_a (F = 1, rising) until u = int_ta^t (F - 1) is 0 again, the negative one (p > p*)
        from t_b (F = -1, falling, before 3 pi / 2) until int_tb^t (F + 1) is 0; checked: one
        interval each where |F| > 1, and |F| <= 1 on the rest of the period (the sticks)."""
        t = np.linspace(0, 2 * np.pi, 200001)
        Ft = self.F(t, p)
        up, down = Ft > 1, Ft < -1
        ta = so.brentq(lambda s: self.F(s, p) - 1, 0, np.pi / 2)
        tpk = so.brentq(lambda s: self.F(s, p) - 1, np.pi / 2, np.pi)  # F back to 1
        if np.any(up & ((t < ta - 1e-4) | (t > tpk + 1e-4))):
            raise RuntimeError("F > 1 outside one interval")
        te = so.brentq(lambda s: self._G(s, p) - self._G(ta, p) - (s - ta), tpk, 3 * np.pi / 2)
        slip = te - ta
        phases = 1
        if p > self.p_star + 1e-12:
            tb = so.brentq(lambda s: self.F(s, p) + 1, np.pi, 3 * np.pi / 2)
            tb2 = 3 * np.pi - tb   # F is even about 3 pi / 2
            if np.any(down & ((t < tb - 1e-4) | (t > tb2 + 1e-4))):
                raise RuntimeError("F < -1 outside one interval")
            tc = so.brentq(lambda s: self._G(s, p) - self._G(tb, p) + (s - tb), tb2,
                           ta + 2 * np.pi)
            if tc >= ta + 2 * np.pi:
                raise RuntimeError("the negative slip does not end before the positive one")
            slip += tc - tb
            phases = 2
        elif np.any(down):
            raise RuntimeError("F < -1 at p <= p*")
        stuck = (t > te) & (t < 2 * np.pi + ta) | (t < ta)
        if np.any(np.abs(Ft[stuck & ~down]) > 1 + 1e-12):
            raise RuntimeError("|F| > 1 in a stick phase")
        return 2 * np.pi - slip, phases


def flow(rhs, n: int, P: float, x0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(x(P), M) of x' = f(t, x) from x0 at t = 0 and its monodromy M, by scipy's DOP853 on the
    variational equation; rhs(t, x) -> (f, f_x)."""
    def both(t, z):
        f, A = rhs(t, z[:n])
        return np.concatenate([f, (np.asarray(A) @ z[n:].reshape(n, n)).ravel()])
    s = solve_ivp(both, (0, P), np.concatenate([x0, np.eye(n).ravel()]), method="DOP853",
                  rtol=1e-13, atol=1e-13)
    return s.y[:n, -1], s.y[n:, -1].reshape(n, n)


def forced_bifurcation(rhs_at, P: float, guess: np.ndarray, condition, xtol: float = 1e-13
                       ) -> tuple[np.ndarray, float]:
    """(x0, p) of the P-periodic orbit x(P) = x0 with condition(M) = 0 (M its monodromy), by
    fsolve on :func:`flow` from guess = (x0, p); rhs_at(p) is flow's rhs at p."""
    n = guess.size - 1

    def eqs(z):
        xe, M = flow(rhs_at(z[n]), n, P, z[:n])
        return np.concatenate([xe - z[:n], [condition(M)]])
    z = so.fsolve(eqs, guess, xtol=xtol)
    assert np.max(np.abs(eqs(z))) < 1e-11
    return z[:n], float(z[n])


def duffing_fold(c: float, w: float, guess: np.ndarray) -> float:
    """F at the fold of x'' + c x' + x + x^3 = F cos(w t): (x(0), F) with x(P) = x(0) and
    det(M - I) = 0 (M the monodromy, P = 2 pi / w), by scipy's DOP853 and fsolve from guess."""
    def rhs_at(F):
        return lambda t, x: ([x[1], -c * x[1] - x[0] - x[0] ** 3 + F * math.cos(w * t)],
                             [[0.0, 1.0], [-1 - 3 * x[0] ** 2, -c]])
    return forced_bifurcation(rhs_at, 2 * math.pi / w, guess,
                              lambda M: np.linalg.det(M - np.eye(2)), xtol=1e-12)[1]


def stick_event(make, p0: float, period: float, steps: int, intervals: int, p_end: float,
                step: float):
    """(branch, its one stick-onset event): the scheme's orbit of make(p0) after ``steps`` steps
    from make's history, made periodic (period ``period``), collocated on ``intervals`` and
    continued to ``p_end`` (2 multipliers a point)."""
    from dmi import analysis as da
    s = make(p0)
    s.init()
    s.advance(steps)
    o = da.periodic_orbit(make, p0, period, s, multipliers=0)
    e = da.collocate(o, intervals=intervals, multipliers=2)
    br = da.continue_orbit(e, p_end, step=step, multipliers=2)
    (ev,) = [x for x in br.events if x.kind == "stick-onset"]
    return br, ev


def map_fixed_point(P, x: np.ndarray, dx: float, tol: float = 1e-12, max_iter: int = 20
                    ) -> tuple[np.ndarray, np.ndarray]:
    """(x, M): the fixed point of the map P near x by Newton and P's Jacobian M there, the
    Jacobian by central differences of step dx (an event-driven period map: see the plane's
    tests with switches)."""
    def jac(z: np.ndarray) -> np.ndarray:
        return np.column_stack([(P(z + dx * e) - P(z - dx * e)) / (2 * dx)
                                for e in np.eye(z.size)])
    x = np.asarray(x, dtype=float)
    for _ in range(max_iter):
        d = np.linalg.solve(jac(x) - np.eye(x.size), -(P(x) - x))
        x = x + d
        if np.max(np.abs(d)) < tol:
            return x, jac(x)
    raise AssertionError(f"Newton on the map did not converge from x = {x!r}")


def _stick_end(accel, level: float, t: float, w: float, t_end: float) -> float:
    """The time the stick at position w from t ends (|accel(t, w, 0)| reaches level), or t_end:
    the first sign change on a grid of 2001 points, then Brent's method."""
    def excess(s: float) -> float:
        return abs(accel(s, w, 0.0)) - level
    grid = np.linspace(t, t_end, 2001)
    k = np.flatnonzero(np.array([excess(s) for s in grid])[1:] >= 0)
    if k.size == 0:
        return t_end
    j = int(k[0]) + 1
    return so.brentq(excess, grid[j - 1], grid[j], xtol=1e-15)


def reversal_flow(accel, level: float, x0, t_end: float, sticks: bool = False
                  ) -> tuple[np.ndarray, list[tuple[float, str]]]:
    """(state at t_end, transitions) of x'' + level sign(x') = accel(t, x, x') (dry friction
    of the given level) from x0 = (x, x') at t = 0 (x' != 0), event-driven: DOP853 (rtol 1e-13)
    between the velocity's zeros, located by its event finder.  At a zero the net force
    accel(t, x, 0) decides: beyond level a reversal, else a stick (x held, x' = 0) until
    |accel(t, x, 0)| reaches level (Brent's method); without ``sticks`` a stick raises an
    AssertionError (not the caller's orbit).  The transitions are (t, kind), kind one of
    "reversal", "stick", "stick end"."""
    t, x = 0.0, np.array(x0, dtype=float)
    mode = 1.0 if x[1] > 0 else -1.0
    seen: list[tuple[float, str]] = []
    while t < t_end:
        if mode == 0.0:                                     # stuck: x held, x' = 0
            t = _stick_end(accel, level, t, x[0], t_end)
            mode = math.copysign(1.0, accel(t, x[0], 0.0))
            seen.append((t, "stick end"))
            continue

        def rhs(s, y, mode=mode):
            return [y[1], accel(s, y[0], y[1]) - level * mode]

        def zero(s, y):
            return y[1]
        zero.terminal, zero.direction = True, -mode
        sol = solve_ivp(rhs, (t, t_end), x, method="DOP853", rtol=1e-13, atol=1e-14,
                        events=zero)
        t, x = float(sol.t[-1]), sol.y[:, -1].copy()
        if sol.status == 1:                 # x' = 0: the net force decides a new slip or a stick
            x[1] = 0.0
            F = accel(t, x[0], 0.0)
            assert sticks or abs(F) > level, f"a stick at t = {t} (net force {F}): not this orbit"
            mode = math.copysign(1.0, F) if abs(F) > level else 0.0
            seen.append((t, "reversal" if mode else "stick"))
    return x, seen


_BOX_TOL = dict(method="DOP853", rtol=1e-13, atol=1e-15)


def box_shoot(force, c: float, w: float, s0: float, z0, s_end: float | None = None
              ) -> tuple[float, float, object]:
    """(s_a, s_e, the stretch's solve_ivp solution) of the oscillator w^2 x'' + c w x' + x =
    force(s) held by the face x <= 1 in the forcing phase s (x_s + N(x) ∋ y, y = dx/ds):
    from z0 = (x, y) at s0 its free flight until it arrives on the face (x rising through 1) at
    s_a, then its stretch on the face (x = 1, y_s = (force(s) - 1 - c w y) / w^2) from y(s_a)
    until y falls to 0 at s_e (it leaves; within 4 pi) or, given s_end, until s_e = s_end; by
    DOP853 (rtol 1e-13) with events, the stretch's solution with its dense output."""
    def free(s, z):
        return [z[1], (force(s) - z[0] - c * w * z[1]) / w ** 2]

    def held(s, z):
        return [(force(s) - 1.0 - c * w * z[0]) / w ** 2]

    def arrive(s, z):
        return z[0] - 1.0
    arrive.terminal, arrive.direction = True, 1

    def leave(s, z):
        return z[0]
    leave.terminal, leave.direction = True, -1
    a = solve_ivp(free, (s0, s0 + 4 * math.pi), list(z0), events=arrive, **_BOX_TOL)
    if a.t_events[0].size == 0:
        raise AssertionError(f"no arrival on the face within 4 pi of s = {s0}")
    sa = float(a.t_events[0][0])
    ya = [float(a.y_events[0][0][1])]
    if s_end is not None:
        b = solve_ivp(held, (sa, s_end), ya, dense_output=True, **_BOX_TOL)
        return sa, s_end, b
    b = solve_ivp(held, (sa, sa + 4 * math.pi), ya, events=leave, dense_output=True,
                  **_BOX_TOL)
    if b.t_events[0].size == 0:
        raise AssertionError(f"no lift-off within 4 pi of s = {sa}")
    return sa, float(b.t_events[0][0]), b


def limit_cycle(ode, jacobian, start, n: int) -> tuple[float, np.ndarray]:
    """(period, multipliers largest first) of the limit cycle of the autonomous ODE y' = ode(t, y)
    (n states, its Jacobian ``jacobian(y)``) reached from ``start`` by DOP853 over t in [0, 400]:
    the period between two upward crossings of y_0 = 0, the multipliers from the variational
    equations over it."""
    run = solve_ivp(ode, (0, 400), start, method="DOP853", rtol=1e-12, atol=1e-12)

    def up(t: float, y: np.ndarray) -> float:
        return y[0]
    up.direction = 1
    cross = solve_ivp(ode, (0, 30), run.y[:, -1], method="DOP853", rtol=1e-12, atol=1e-13,
                      events=up)
    t, y = cross.t_events[0], cross.y_events[0]
    T = float(t[2] - t[1])

    def variational(t: float, Y: np.ndarray) -> np.ndarray:
        return np.concatenate([ode(t, Y[:n]), (jacobian(Y[:n]) @ Y[n:].reshape(n, n)).ravel()])
    var = solve_ivp(variational, (0, T), np.concatenate([y[1], np.eye(n).ravel()]),
                    method="DOP853", rtol=1e-12, atol=1e-13)
    mu = np.linalg.eigvals(var.y[n:, -1].reshape(n, n))
    return T, mu[np.argsort(-np.abs(mu))]
