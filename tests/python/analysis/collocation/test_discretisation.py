# CollocationDiscretisation and equation_hopf_orbit: a branch of the closed-form circles of
# u' = (mu - |u|^2) u + w0 J u - int_0^tau g e^{-s/th} cos(beta s) u(t - s) ds from the Hopf point
# (radius^2 = mu - mu_H, Omega fixed by the kernel's transform), the van der Pol branch against the
# Fourier solve of models/delay_models.py, and a Den Hartog branch whose signature changes (sticks
# appear) mended by adapt, against the scheme's orbits as h shrinks.  The continuation loop here is
# a natural-parameter one written in the test (the driver is not this module's).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import scipy.sparse.linalg as sla

from dmi import analysis as da

from models import delay_models as tc
from models.orbit_models import DenHartog


def corrected(disc, x, p, iters=40):
    """Newton at fixed p on the discretisation's residual and Jacobian, a step halved while it
    raises the residual or leaves the switching times out of order (ValueError)."""
    def size(z):
        try:
            return float(np.max(np.abs(disc.residual(z, p))))
        except ValueError:
            return np.inf
    for _ in range(iters):
        J, Jp = disc.jacobian(x, p)
        assert J.shape == (x.size, x.size) and Jp.shape == (x.size,)
        r0 = size(x)
        dx = sla.splu(J.tocsc()).solve(-disc.residual(x, p))
        if np.max(np.abs(dx)) < 1e-12 * max(1.0, np.max(np.abs(x))):
            return x + dx
        lam = 1.0
        while size(x + lam * dx) >= r0 and lam > 1e-3:
            lam *= 0.5
        x = x + lam * dx
    raise AssertionError("no convergence")


def branch(disc, x, ps):
    points = []
    for p in ps:
        x = corrected(disc, x, p)
        points.append(disc.point(x, p))
        x = disc.adapt(x, p)
    return points


def circle_hopf():
    r, T = tc.circle_reference()
    om = 2 * math.pi / T
    return tc.K_hat(1j * om).real, om, T


def test_hopf_orbit_and_circle_branch_closed_form():
    muH, om, T = circle_hopf()
    e = da.equation_hopf_orbit(tc.rotating, da.HopfPoint(p=muH, omega=om, root=1j * om),
                               [0.0, 0.0], 0.1)
    assert abs(e.p - (muH + 0.01)) < 1e-10 and abs(e.period - T) < 1e-10
    assert np.all(np.abs(e.amplitude - 0.1) < 1e-10)
    disc, x = da.CollocationDiscretisation.of(e)
    ps = [muH + 0.02, muH + 0.05, muH + 0.1, muH + 0.2, 0.6, 1.0]
    pts = branch(disc, x, ps)
    for p, pt in zip(ps, pts):
        assert pt is not None and pt.p == p                 # lands on each p asked
        assert abs(pt.period - T) < 1e-10
        assert np.all(np.abs(pt.amplitude - math.sqrt(p - muH)) < 1e-10)
        assert abs(pt.multipliers[0] - 1) < 1e-8
        assert pt.errors["period"] >= abs(pt.period - T)
    ev = disc.event_functions(x, 1.0, pts[-1])
    assert "segment" not in ev                              # a smooth orbit: no segments


def test_vdp_branch_against_fourier():
    o = tc.vdp_scheme_orbit()
    e = da.collocate(o, intervals=40, multipliers=4)
    disc, x = da.CollocationDiscretisation.of(e, multipliers=4)
    ps = [0.5, 0.65, 0.8]
    pts = branch(disc, x, ps)
    for p, pt in zip(ps, pts):
        tc.AV = p
        try:
            ref_T, _, _ = tc.fourier_orbit(pt.period, lambda t: pt.u_at(t)[:, 0])
        finally:
            tc.AV = 0.5
        assert abs(pt.period - ref_T) < 1e-9
        assert pt.errors["period"] >= abs(pt.period - ref_T)


def test_den_hartog_branch_signature_changes_to_stick_slip():
    # p scales the forcing: at p = 1 the orbit reverses without sticking (two segments); lowering
    # the forcing makes it stick at the reversals (from p = 0.45 on); adapt mends the signature
    # between steps
    d = DenHartog()
    e = da.collocate(tc.forced_orbit(d, 2000, 20), intervals=24, multipliers=2)
    assert e.signature.switches == 2
    disc, x = da.CollocationDiscretisation.of(e, multipliers=2)
    # the events at p = 1: a complex pair (Den Hartog's closed form) inside the unit circle
    ev = disc.event_functions(x, 1.0, disc.point(x, 1.0))
    assert abs(ev["torus"] - (np.max(np.abs(d.multipliers)) - 1)) < 1e-8
    assert "fold" not in ev and "period_doubling" not in ev
    assert abs(ev["segment"] - 0.5) < 1e-10                 # two half periods
    p, pt = 1.0, e
    while p > 0.41:
        p = round(p - 0.05, 10)
        for _ in range(4):                                   # mend until the signature holds
            x = corrected(disc, x, p)
            pt = disc.point(x, p)                            # None (a warning) when broken
            if pt is not None:
                break
            x = disc.adapt(x, p)
        assert pt is not None, f"no orbit at p = {p}"
        x = disc.adapt(x, p)
    stuck = [row for row in pt.signature.describe() if "stuck" in row]
    assert len(stuck) == 2
    ev = disc.event_functions(x, p, pt)
    lengths = np.diff(np.concatenate([pt.switches, [pt.switches[0] + pt.period]]))
    assert abs(ev["segment"] - lengths.min() / pt.period) < 1e-12
    # the scheme's orbit at p approaches the collocated one as h shrinks (O(h))
    gaps = []
    for Ms in (1000, 4000):
        os_ = tc.forced_orbit(d, Ms, 20, p)
        gaps.append(np.max(np.abs(os_.u - pt.u_at(os_.t))))
    assert gaps[1] < 0.4 * gaps[0]



def test_belt_hopf_orbit_vertical_branch():
    # a belt that slips (y = x' - V < 0) is linear: x'' + x - p x' + g int_0^tau e^{-s} x(t - s) ds
    # = alpha; its Hopf point from lambda^2 - p lambda + 1 + g K(lambda) = 0, K(lambda) = (1 -
    # e^{-(1 + lambda) tau}) / (1 + lambda), at lambda = i omega (models/truncated_belt.py); every
    # amplitude below grazing is an orbit at p_H of period 2 pi / omega (a vertical branch)
    from models.truncated_belt import V, belt, hopf
    om, pH, xe = hopf()
    for a in (0.1, 0.3):
        e = da.equation_hopf_orbit(belt, da.HopfPoint(p=pH, omega=om, root=1j * om), [xe, -V], a)
        assert e.signature.describe() == ["(free, slip -)"]
        assert abs(e.p - pH) < 1e-10 and abs(e.period - 2 * math.pi / om) < 1e-10
        assert abs(e.amplitude[1] - a) < 1e-10          # y moves most: a sine of amplitude a
        assert e.stable is None                          # not isolated at fixed p: no verdict
