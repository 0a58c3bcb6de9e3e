# dmi.identify.estimate: least-squares fits of a model's parameters to measured records.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Records, the weighted residuals and their Jacobian from :func:`sensitivities`, SciPy's
trust-region ``least_squares``, and the :class:`Estimate` with its covariance and the parameter
combinations the data cannot determine."""
from __future__ import annotations

import dataclasses
import html
import math
import sys
import time
import warnings
from collections.abc import Callable, Hashable, Mapping, Sequence
from typing import Any

import numpy as np
from scipy import optimize, stats

from .._cache import Cache
from .._solver import Solver
from . import _grouped
from .sensitivity import MAX_STEPS, Sensitivities, _build, _sensitivities_of, check_steps

#: Singular values of the column-normalised Jacobian below this fraction of the largest one mark
#: a parameter combination as not determined by the data.
RCOND = 1e-6

#: Singular values below this fraction of the largest one mark the near-null directions along
#: which the saddle check probes the cost at the end of a fit.
SADDLE_RCOND = 1e-3

#: The relative sizes of the saddle check's probes (the largest relative change of a parameter).
SADDLE_STEPS = (0.01, 0.1, 0.3, 1.0, 1.5, 3.0)


@dataclasses.dataclass
class Parameter:
    """One parameter of a fit, given by name in a mapping ``p0 = {name: Parameter(...)}``.

    Attributes
    ----------
    value : float
        The starting value (the value kept, where ``fixed``).
    fixed : bool
        True: kept at ``value``, not fitted.
    lower, upper : float
        Bounds (infinite by default); ``value`` must lie within them.
    """

    value: float
    fixed: bool = False
    lower: float = -math.inf
    upper: float = math.inf


@dataclasses.dataclass
class FitOptions:
    """Options of :func:`estimate` about bounds on the work, the noise model and the checks at
    the end.

    Attributes
    ----------
    max_steps : int
        The most steps one record's run may take (default :data:`MAX_STEPS`); a record asking
        for more is refused before any run, with the memory its sensitivities would hold.
    scale_covar : bool
        True: the covariance is multiplied by the reduced chi-square where every record gives
        sigma (as lmfit's ``scale_covar``): the stated sigma is then taken as relative only, and
        Wald intervals use Student's t.  Without sigma the covariance is always scaled.
    chi2_alpha : float
        A reduced chi-square whose chi-square probability (upper tail: too large; lower tail:
        too small) is below this is implausible for the stated sigma: a RuntimeWarning and the
        message say so.
    saddle_check : bool
        True (default): at the end of a converged fit, the cost is probed along the near-null
        directions of the Jacobian (both signs, relative steps :data:`SADDLE_STEPS`); a lower
        cost found there is reported (``success`` False, ``Estimate.lower``).
    progress : bool or None
        A one-line progress display on stderr (start, iteration, cost, model runs, time); None
        (default): shown only where stderr is a terminal.
    group_models : bool
        True (default): the Jacobians' perturbed models are shared by parameters that move
        disjoint parts of the model (learned from one model per parameter at the first Jacobian,
        checked at each: docs/identify-method.md, "Perturbed models in groups"); False: one model
        per parameter at every Jacobian (for a ``make`` in which a parameter moves, at some
        points only, a part that another parameter moves).
    """

    max_steps: int = MAX_STEPS
    scale_covar: bool = False
    chi2_alpha: float = 1e-3
    saddle_check: bool = True
    progress: bool | None = None
    group_models: bool = True


@dataclasses.dataclass
class Record:
    """One measured record.

    Attributes
    ----------
    t : array_like, shape (m,)
        Measurement times, increasing, >= 0 (time units; anywhere in the run: the model's U and S
        are interpolated linearly between steps).
    y : array_like, shape (m,) or (m, k)
        The measurements: one observed quantity, or k of them.
    components : sequence of int, optional
        The state components observed (k of them); default: component 0 for a 1-D y, else the
        first k.  Ignored with ``observe``.
    observe : callable, optional
        ``observe(t, u, a) -> (k,)``: the observed quantities as a function of the time, the state
        u and the element a = (X - U)/h of A(u) the scheme selects (the friction force, the
        contact force); differentiated by directional differences.
    sigma : float or array_like, optional
        Noise level(s) (units of y): a number, (k,) per quantity or (m, k) per value.  Given, the
        covariance is the inverse of J^T J; not given, it is scaled by the residual variance.
    """

    t: Any
    y: Any
    components: Sequence[int] | None = None
    observe: Callable[[float, np.ndarray, np.ndarray], Any] | None = None
    sigma: Any = None


@dataclasses.dataclass
class Estimate:
    """The result of :func:`estimate`.

    Attributes
    ----------
    p : numpy.ndarray, shape (P,)
        All parameters, the fixed ones as given.
    names : list of str
        Their names.
    free : numpy.ndarray of bool, shape (P,)
        Which were fitted.
    cov : numpy.ndarray, shape (P, P)
        Covariance of the fitted parameters (zero rows for fixed ones; inf on the diagonal of a
        parameter in an undetermined combination); with ``success`` False, that of the linearised
        problem at the returned point, which is not a verified minimum.
    stderr : numpy.ndarray, shape (P,)
        Standard errors, sqrt of cov's diagonal (0 for a fixed parameter, inf for an undetermined
        one).
    corr : numpy.ndarray, shape (P, P)
        Correlations (NaN where a standard error is 0 or inf).
    residuals : numpy.ndarray, shape (M,)
        Weighted residuals (model - data) / sigma of all records, in order.
    jacobian : numpy.ndarray, shape (M, F)
        Jacobian of the weighted residuals in the F free parameters.
    cost : float
        0.5 * sum(residuals**2), SciPy's cost.
    aic, bic : float
        Akaike's and Schwarz's criteria (with sigma given: 2 cost + 2F and 2 cost + F log M;
        without: M log(2 cost / M) + 2F and M log(2 cost / M) + F log M).
    success : bool
        Whether the fit converged and decreased the cost (or started at a zero cost).
    message : str
        SciPy's message, or why the fit failed or stopped, with the last cost.
    unidentifiable : list of str
        The parameter combinations the data do not determine, named (e.g. ``"1.00*mu"``, or
        ``"0.71*C0 - 0.71*C1"`` in relative units: coefficient times parameter / |parameter|).
    nfev, njev : int
        Plain runs of the model for residuals, and sensitivity runs (Jacobians; a sensitivity
        run gives the residuals too, where the optimiser asks for both at one point).
    dof : int
        Degrees of freedom M - F.
    sigma_known : bool
        Whether every record gave sigma.
    starts : list of tuple
        (p0, cost) of each start of ``multistart``.
    unplaced : list of tuple
        (record, step) of each friction reversal the sensitivities could not place inside its
        step at the returned point (see :attr:`Sensitivities.unplaced`): the Jacobian is off by
        O(1) from there on, so ``cov``, ``stderr`` and ``corr`` are NaN (a RuntimeWarning and
        ``message`` say so; a smaller h resolves them).  Empty otherwise.
    chisqr : float
        The chi-square 2 cost = sum(residuals**2).
    redchi : float
        The reduced chi-square chisqr / dof (NaN where dof <= 0).
    pvalue : float
        P(chi2_dof >= chisqr), the chi-square probability of so large a misfit where every record
        gives sigma (NaN otherwise: without sigma there is nothing to test).  Near 0: sigma
        understated or the model misses something; near 1: sigma overstated.
    covar_scaled : bool
        Whether ``cov`` was multiplied by ``redchi`` (without sigma, or with
        ``FitOptions.scale_covar``).
    insensitive : list of str
        The parameters that did not move the records at p0 (a zero column of the Jacobian): kept
        at their p0 value, not fitted, named in ``unidentifiable``, with an infinite standard
        error.
    lower : numpy.ndarray or None
        A point of lower cost the saddle check found along a near-null direction (the fit then
        stopped on a saddle: ``success`` is False); None otherwise.
    lower_cost : float
        Its cost (NaN where ``lower`` is None).
    bounds : tuple of numpy.ndarray or None
        The fit's (lower, upper) bounds of every parameter.
    """

    p: np.ndarray
    names: list
    free: np.ndarray
    cov: np.ndarray
    stderr: np.ndarray
    corr: np.ndarray
    residuals: np.ndarray
    jacobian: np.ndarray
    cost: float
    aic: float
    bic: float
    success: bool
    message: str
    unidentifiable: list
    nfev: int
    njev: int
    dof: int
    sigma_known: bool
    starts: list
    unplaced: list = dataclasses.field(default_factory=list)
    chisqr: float = math.nan
    redchi: float = math.nan
    pvalue: float = math.nan
    covar_scaled: bool = False
    insensitive: list = dataclasses.field(default_factory=list)
    lower: np.ndarray | None = None
    lower_cost: float = math.nan
    bounds: tuple | None = None
    _problem: Any = dataclasses.field(default=None, repr=False)

    def _rows(self) -> list[tuple[str, str, str, str, str]]:
        """(name, value, stderr, relative error, status) of each parameter, as text."""
        rows = []
        for j, name in enumerate(self.names):
            value, se = float(self.p[j]), float(self.stderr[j])
            if name in self.insensitive:
                status = "fixed (no effect at p0)"
            elif not self.free[j]:
                status = "fixed"
            else:
                status = "free"
                if self.bounds is not None:
                    lo, hi = float(self.bounds[0][j]), float(self.bounds[1][j])
                    if lo > -math.inf or hi < math.inf:
                        status += f" in [{lo:.6g}, {hi:.6g}]"
                        if value in (lo, hi):
                            status += " (at a bound)"
            if not self.free[j] and name not in self.insensitive:
                err = rel = "-"
            else:
                err = f"{se:.6g}"
                rel = f"{100 * se / abs(value):.3g} %" if value != 0 and math.isfinite(se) else "-"
            rows.append((name, f"{value:.10g}", err, rel, status))
        return rows

    def _correlations(self, threshold: float) -> list[tuple[str, str, float]]:
        """(name, name, corr) of the fitted pairs with |corr| >= threshold, largest first."""
        out = []
        idx = np.flatnonzero(self.free)
        for a in range(len(idx)):
            for b in range(a + 1, len(idx)):
                c = float(self.corr[idx[a], idx[b]])
                if math.isfinite(c) and abs(c) >= threshold:
                    out.append((self.names[idx[a]], self.names[idx[b]], c))
        return sorted(out, key=lambda x: -abs(x[2]))

    def _statistics(self) -> list[tuple[str, str]]:
        M, F = self.jacobian.shape
        return [("data points", str(M)), ("free parameters", str(F)), ("dof", str(self.dof)),
                ("chi-square", f"{self.chisqr:.6g}"), ("reduced chi-square", f"{self.redchi:.6g}"),
                ("p-value", f"{self.pvalue:.4g}" if self.sigma_known else
                 "- (no sigma given: not tested)"),
                ("covariance scaled by reduced chi-square", "yes" if self.covar_scaled else "no"),
                ("AIC", f"{self.aic:.6g}"), ("BIC", f"{self.bic:.6g}"),
                ("success", str(self.success)), ("model runs, iterations", f"{self.nfev}, {self.njev}")]

    def _notes(self) -> list[str]:
        notes = [f"message: {self.message}"]
        if self.unidentifiable:
            notes.append("undetermined combinations: " + "; ".join(self.unidentifiable))
        if self.insensitive:
            notes.append("no effect on the records at p0 (kept there): " + ", ".join(self.insensitive))
        if self.unplaced:
            notes.append("unplaced switches (record, step): "
                         + ", ".join(f"({k}, {q})" for k, q in self.unplaced))
        if self.lower is not None:
            notes.append(f"lower cost {self.lower_cost:.10g} at p = {np.array2string(self.lower)}")
        return notes

    def report(self, min_correl: float = 0.1) -> str:
        """A text report of the fit: each parameter's value, standard error and status (free,
        with its bounds, or fixed), the correlations of at least ``min_correl`` in magnitude,
        chi-square, reduced chi-square and its p-value, AIC and BIC, the message, the
        undetermined combinations, the parameters without effect and the unplaced switches.

        Parameters
        ----------
        min_correl : float, optional
            The least |correlation| listed.

        Returns
        -------
        str
            The report.
        """
        lines = ["[[Fit statistics]]"]
        lines += [f"    {k:<40s} {v}" for k, v in self._statistics()]
        lines.append("[[Parameters]]")
        width = max(len(n) for n in self.names)
        for name, value, err, rel, status in self._rows():
            lines.append(f"    {name:<{width}s}  {value:>17s} +/- {err:<12s} ({rel:>9s})  {status}")
        lines.append(f"[[Correlations]] (|corr| >= {min_correl:g})")
        pairs = self._correlations(min_correl)
        lines += [f"    C({a}, {b}) = {c:+.4f}" for a, b, c in pairs] or ["    none"]
        lines.append("[[Notes]]")
        lines += [f"    {x}" for x in self._notes()]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        """The report as HTML tables (for notebooks)."""
        e = html.escape
        stats_rows = "".join(f"<tr><td>{e(k)}</td><td>{e(v)}</td></tr>" for k, v in self._statistics())
        par_rows = "".join("<tr>" + "".join(f"<td>{e(x)}</td>" for x in row) + "</tr>"
                           for row in self._rows())
        corr_rows = "".join(f"<tr><td>{e(a)}</td><td>{e(b)}</td><td>{c:+.4f}</td></tr>"
                            for a, b, c in self._correlations(0.1))
        notes = "".join(f"<li>{e(x)}</li>" for x in self._notes())
        return ("<h4>Fit statistics</h4><table>" + stats_rows + "</table>"
                "<h4>Parameters</h4><table><tr><th>name</th><th>value</th><th>standard error</th>"
                "<th>relative error</th><th>status</th></tr>" + par_rows + "</table>"
                "<h4>Correlations (|corr| &ge; 0.1)</h4><table><tr><th></th><th></th><th>corr</th></tr>"
                + corr_rows + "</table><h4>Notes</h4><ul>" + notes + "</ul>")

    def wald_interval(self, index: int | str, level: float = 0.95) -> tuple[float, float]:
        """The Wald (covariance) interval of one parameter.

        Parameters
        ----------
        index : int or str
            The parameter, by position or name.
        level : float, optional
            Confidence level in (0, 1).

        Returns
        -------
        tuple of float
            (low, high): p +- q stderr, q the normal quantile with sigma known, else Student's
            with dof degrees of freedom; with a RuntimeWarning where the fit did not converge
            (``success`` False).

        Raises
        ------
        ValueError
            An unknown parameter or a level outside (0, 1).
        """
        i = _index(index, self.names)
        if not 0.0 < level < 1.0:
            raise ValueError(f"level = {level!r}: expected a number in (0, 1)")
        if not self.success:
            warnings.warn(f"the fit did not converge ({self.message}): this Wald interval is taken at "
                          "a point that is not a verified least-squares minimum", RuntimeWarning,
                          stacklevel=2)
        q = _quantile(level, self.dof, self.sigma_known and not self.covar_scaled)
        return self.p[i] - q * self.stderr[i], self.p[i] + q * self.stderr[i]


def _quantile(level: float, dof: int, known: bool) -> float:
    if known:
        return float(stats.norm.ppf(0.5 + level / 2))
    return float(stats.t.ppf(0.5 + level / 2, max(dof, 1)))


def _index(index: int | str, names: list) -> int:
    if isinstance(index, str):
        if index not in names:
            raise ValueError(f"parameter {index!r} is not one of {names}")
        return names.index(index)
    i = int(index)
    if not 0 <= i < len(names):
        raise ValueError(f"parameter index {index!r} outside 0 .. {len(names) - 1}")
    return i


# ---- the records --------------------------------------------------------------------------------

@dataclasses.dataclass
class _Data:
    """A checked record: times, data (m, k), weights 1/sigma (m, k), what is observed."""

    t: np.ndarray
    y: np.ndarray
    w: np.ndarray
    components: list | None
    observe: Callable | None
    sigma_known: bool


def _check_record(r: Any, k_index: int, n: int) -> _Data:
    if not isinstance(r, Record):
        raise TypeError(f"records[{k_index}] is a {type(r).__name__}; expected a dmi.identify.Record")
    where = f"records[{k_index}]"
    t = np.asarray(r.t, dtype=float)
    if t.ndim != 1 or len(t) == 0:
        raise ValueError(f"{where}.t has shape {t.shape}; expected (m,), m >= 1 times")
    if not np.all(np.isfinite(t)):
        raise ValueError(f"{where}.t has NaN or infinite times")
    if t[0] < 0.0:
        raise ValueError(f"{where}.t starts at {t[0]!r} < 0: times outside the run (it starts at "
                         "t = 0; the history is not measured)")
    if np.any(np.diff(t) < 0):
        raise ValueError(f"{where}.t is not increasing")
    y = np.asarray(r.y, dtype=float)
    if y.ndim == 1:
        y = y[:, None]
    if y.ndim != 2 or y.shape[0] != len(t):
        raise ValueError(f"{where}.y has shape {np.shape(r.y)}; expected ({len(t)},) or ({len(t)}, k)")
    if not np.all(np.isfinite(y)):
        bad = np.argwhere(~np.isfinite(y))[0]
        raise ValueError(f"{where}.y has NaN or infinite values (first at row {bad[0]}, column "
                         f"{bad[1]}); drop those rows")
    k = y.shape[1]
    comps = None
    if r.observe is None:
        comps = list(range(k)) if r.components is None else [int(c) for c in r.components]
        if len(comps) != k:
            raise ValueError(f"{where}: {len(comps)} components {comps} for y of {k} columns")
        if any(not 0 <= c < n for c in comps):
            raise ValueError(f"{where}.components {comps}: the state has components 0 .. {n - 1}")
    if r.sigma is None:
        w = np.ones_like(y)
    else:
        sig = np.asarray(r.sigma, dtype=float)
        try:
            sig = np.broadcast_to(sig, y.shape)
        except ValueError:
            raise ValueError(f"{where}.sigma has shape {sig.shape}; expected a number, ({k},) or "
                             f"{y.shape}") from None
        if not np.all(np.isfinite(sig) & (sig > 0)):
            raise ValueError(f"{where}.sigma: noise levels must be finite and > 0")
        w = 1.0 / sig
    return _Data(t, y, w, comps, r.observe, r.sigma is not None)


def _interp(grid_t: np.ndarray, h: float, t: np.ndarray, V: np.ndarray) -> np.ndarray:
    """V (steps + 1, ...) at the times t, linearly between steps."""
    x = t / h
    i = np.minimum(np.floor(x).astype(int), len(grid_t) - 2)
    i = np.maximum(i, 0)
    f = (x - i).reshape((-1,) + (1,) * (V.ndim - 1))
    return (1.0 - f) * V[i] + f * V[i + 1]


def _forces(U: np.ndarray, X: np.ndarray, h: float) -> np.ndarray:
    """a^p = (X^{p-1} - U^p) / h at each step, a^0 = a^1."""
    a = np.empty_like(U)
    a[1:] = (X - U[1:]) / h
    a[0] = a[1]
    return a


def record_steps(s: Solver, d: _Data) -> int:
    """The steps of s that a record reaches: its last time over h, at least 1."""
    return max(1, math.ceil(d.t[-1] / s.h - 1e-9))


class _Problem:
    """The residuals of all records as a function of the free parameters."""

    def __init__(self, makes: list, p0: np.ndarray, free: np.ndarray, data: list, rhs: Any):
        self.makes, self.p0, self.free, self.data, self.rhs = makes, p0, free, data, rhs
        self.nfev = self.njev = 0
        self.jumps = True
        self.bounds = (np.full(len(p0), -np.inf), np.full(len(p0), np.inf))
        self.best: tuple[float, np.ndarray] | None = None
        self.unplaced: list = []        # (record, step) of the last Jacobian's unplaced reversals
        self.max_steps: int | None = None
        # the residuals and Jacobian at the last x, the models of the last Jacobian (the next one
        # at the same p, with or without the saltation, steps the same solvers again) and the
        # residuals at the last two x
        self.cache = Cache(4 + 3 * len(makes))
        self.recent: list = []          # the keys of the residuals kept, oldest first
        # and per record (in the cache): how its perturbed models are grouped, ("plan", k),
        # learned from the last build of all of them (None: one model per parameter), and the
        # model of the last residuals, ("made", k): (p, solver)
        self.grouped = True             # False: one perturbed model per parameter, always
        # True: the residuals come from the Jacobian's run where the last ones' Jacobian was asked
        # for (``asked``: a Jacobian was asked for since the last residuals)
        self.speculate = False
        self.asked = True

    def full(self, x: np.ndarray) -> np.ndarray:
        p = self.p0.copy()
        p[self.free] = x
        return p

    def _predict(self, d: _Data, t_grid: np.ndarray, h: float, U: np.ndarray, X: np.ndarray,
                 S: np.ndarray | None, dX: np.ndarray | None) -> tuple[np.ndarray, np.ndarray | None]:
        """The model's values (m, k) at the record's times and their derivatives (m, k, F)."""
        if d.observe is None:
            val = _interp(t_grid, h, d.t, U[:, d.components])
            der = None if S is None else _interp(t_grid, h, d.t, S[:, d.components, :])
            return val, der
        a = _forces(U, X, h)
        ui, ai = _interp(t_grid, h, d.t, U), _interp(t_grid, h, d.t, a)
        val = np.array([np.asarray(d.observe(tt, uu, aa), dtype=float).reshape(-1)
                        for tt, uu, aa in zip(d.t, ui, ai)])
        if val.shape != d.y.shape:
            raise ValueError(f"observe returned {val.shape[1:]} values per time; the record has "
                             f"{d.y.shape[1]}")
        if S is None:
            return val, None
        dA = np.empty_like(S)
        dA[1:] = (dX - S[1:]) / h
        dA[0] = dA[1]
        Si, dAi = _interp(t_grid, h, d.t, S), _interp(t_grid, h, d.t, dA)
        der = np.empty(val.shape + (S.shape[2],))
        for m in range(len(d.t)):
            scale = max(1.0, float(np.abs(ui[m]).max()), float(np.abs(ai[m]).max()))
            for j in range(S.shape[2]):
                norm = max(1.0, float(np.abs(Si[m, :, j]).max()), float(np.abs(dAi[m, :, j]).max()))
                eps = 2.0 ** -26 * scale / norm
                up = d.observe(d.t[m], ui[m] + eps * Si[m, :, j], ai[m] + eps * dAi[m, :, j])
                der[m, :, j] = (np.asarray(up, dtype=float).reshape(-1) - val[m]) / eps
        return val, der

    def residuals(self, x: np.ndarray, check: bool = False) -> np.ndarray:
        """The weighted residuals at the free parameters x (those of a recent call at the same x
        kept); with ``check``, a ValueError naming the record, the time and the culprit (the
        run's state or ``observe``) where one is not finite."""
        key = ("residuals", x.tobytes())
        if key not in self.recent:
            self.recent.append(key)
            if len(self.recent) > 2:
                self.cache.pop(self.recent.pop(0))
        r = self.cache.cached(key, lambda: self._residuals(x, check))
        if check and not np.all(np.isfinite(r)):
            return self._residuals(x, check)
        return r.copy()

    def seed(self, x: np.ndarray) -> None:
        """Keeps the residuals of the Jacobian's run at x (where one is kept) as the residuals at
        x: the same run (the tangent steps the model as a plain run does, bit for bit)."""
        got = self.cache.pop("linearised")
        if got is None:
            return
        self.cache.cached("linearised", lambda: got)
        if got[0][0] == x.tobytes():
            key = ("residuals", x.tobytes())
            self.cache.pop(key)
            self.recent = [k for k in self.recent if k != key] + [key]
            if len(self.recent) > 2:
                self.cache.pop(self.recent.pop(0))
            self.cache.cached(key, lambda: got[1][0].copy())

    def _residuals(self, x: np.ndarray, check: bool) -> np.ndarray:
        if self.speculate and self.asked and not check:
            # the optimiser asks for the Jacobian where it takes a step: the tangent's run gives
            # the residuals too (bit for bit a plain run's) and keeps the Jacobian for that call;
            # after a step not taken (no Jacobian asked there), a plain run
            try:
                r = self.linearised(x)[0]
            except Exception:
                # (the plain run below raises what fails there, as without the Jacobian; what
                # fails in the Jacobian only is raised where the optimiser asks for it)
                r = None
            self.asked = False
            if r is not None:
                cost = 0.5 * float(r @ r)
                if np.isfinite(cost) and (self.best is None or cost < self.best[0]):
                    self.best = (cost, x.copy())
                return r.copy()
        p = self.full(x)
        out = []
        for k, (make, d) in enumerate(zip(self.makes, self.data)):
            s = make(p.copy())
            s.init()
            self.cache.pop(("made", k))
            self.cache.cached(("made", k), lambda: (p.tobytes(), s))
            t_grid, U, X = s.run_terms(record_steps(s, d))
            val, _ = self._predict(d, t_grid, s.h, U, X, None, None)
            if check and not np.all(np.isfinite(val)):
                self._not_finite(k, d, p, t_grid, s.h, U, X, val)
            out.append(((val - d.y) * d.w).ravel())
        r = np.concatenate(out)
        self.nfev += 1
        cost = 0.5 * float(r @ r)
        if np.isfinite(cost) and (self.best is None or cost < self.best[0]):
            self.best = (cost, x.copy())
        return r

    def _not_finite(self, k: int, d: _Data, p: np.ndarray, t_grid: np.ndarray, h: float,
                    U: np.ndarray, X: np.ndarray, val: np.ndarray) -> None:
        """ValueError for the first value of record k that is not finite, naming its cause."""
        m = int(np.argwhere(~np.all(np.isfinite(val), axis=1))[0, 0])
        where = f"records[{k}] at t = {d.t[m]:.10g} (row {m})"
        ui = _interp(t_grid, h, d.t[m:m + 1], U)[0]
        if not np.all(np.isfinite(ui)):
            raise ValueError(f"the model's state is not finite for {where}, at p = {p.tolist()}: "
                             "the run diverges before the record ends; start from other parameters "
                             "or a smaller h")
        if d.observe is not None:
            ai = _interp(t_grid, h, d.t[m:m + 1], _forces(U, X, h))[0]
            raise ValueError(f"{where}: observe(t, u, a) returned {val[m].tolist()} (not finite) for "
                             f"u = {ui.tolist()}, a = {ai.tolist()}, at p = {p.tolist()}; observe "
                             "must return finite numbers wherever the run goes")
        raise ValueError(f"the model's values are not finite for {where}, at p = {p.tolist()}")

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """The Jacobian of the weighted residuals at the free parameters x (:meth:`linearised`)."""
        return self.linearised(x)[1]

    def linearised(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(r, J): the weighted residuals and their Jacobian at the free parameters x, from the
        sensitivities' runs (kept in the problem's cache for the next call at the same x)."""
        self.asked = True
        return self._slot("linearised", (x.tobytes(), self.jumps),
                          lambda: self._linearise(x))

    def _slot(self, slot: Hashable, key: Hashable, factory: Callable[[], Any]) -> Any:
        """What the cache's ``slot`` holds for ``key``, else factory() there in its place (one
        object a slot: the last one)."""
        got = self.cache.pop(slot)
        if got is None or got[0] != key:
            got = (key, factory())
        self.cache.cached(slot, lambda: got)
        return got[1]

    def _models(self, k: int, make_free: Callable[[np.ndarray], Solver], p: np.ndarray
                ) -> Any:
        """The models of record k at p and at the perturbed free parameters: grouped by the
        record's plan where it has one (and it still holds), else one per parameter (the plan
        learned from them); the model at p that of the last residuals where made at p."""
        q = p[self.free]
        made = self.cache.pop(("made", k))
        base = made[1] if made is not None and made[0] == p.tobytes() else None
        plan = self.cache.pop(("plan", k))
        self.cache.cached(("plan", k), lambda: plan)     # (kept where a make below fails)
        mod = None
        if plan is not None and self.grouped:
            mod = _grouped.build(make_free, q, plan, base)
        if mod is None:
            mod = _build(make_free, q, base)
            plan = _grouped.plan(mod)
            self.cache.pop(("plan", k))
            self.cache.cached(("plan", k), lambda: plan)
        return mod

    def _linearise(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        p = self.full(x)
        idx = np.flatnonzero(self.free)
        rows, res = [], []
        rhs = None
        if self.rhs is not None:
            def rhs(t: float, u: np.ndarray, q: np.ndarray) -> Any:
                pc = self.p0.astype(complex)
                pc[self.free] = q
                return self.rhs(t, u, pc)
        unplaced = []
        for k, (make, d) in enumerate(zip(self.makes, self.data)):
            def make_free(q: np.ndarray, _make: Callable = make) -> Solver:
                return _make(self.full(q))
            # the models at p and p + delta_j e_j: those of the last Jacobian at this p (made by
            # make at the same parameters; each run starts from their init), else made now
            mod = self._slot(("models", k), (p.tobytes(), self.grouped),
                             lambda: self._models(k, make_free, p))
            with warnings.catch_warnings():
                # reversals left unplaced are gathered here and reported once by the estimate
                warnings.filterwarnings("ignore", "sensitivities: .* could not be placed",
                                        RuntimeWarning)
                sens: Sensitivities = _sensitivities_of(
                    mod, p[idx], record_steps(mod.base, d), rhs=rhs, jumps=self.jumps,
                    max_steps=self.max_steps)
            unplaced += [(k, q) for q in sens.unplaced]
            val, der = self._predict(d, sens.t, sens.h, sens.u, sens.x, sens.S, sens.dx)
            res.append(((val - d.y) * d.w).ravel())
            rows.append((der * d.w[:, :, None]).reshape(-1, len(idx)))
        J = np.concatenate(rows)
        self.njev += 1
        self.unplaced = unplaced
        return np.concatenate(res), J


# ---- the fit --------------------------------------------------------------------------------------

def estimate(make: Callable[[np.ndarray], Solver] | Sequence[Callable[[np.ndarray], Solver]],
             p0: Any, records: Record | Sequence[Record], *, names: Sequence[str] | None = None,
             free: Any = None, bounds: tuple[Any, Any] | None = None, x_scale: Any = "jac",
             loss: str = "linear", multistart: int | Sequence[Any] | None = None, seed: int = 0,
             max_nfev: int | None = None, callback: Callable[[dict], Any] | None = None,
             verbose: bool = False, polish: bool = True,
             rhs: Callable[[float, np.ndarray, np.ndarray], np.ndarray] | None = None,
             options: FitOptions | None = None) -> Estimate:
    """Fits the parameters of ``make(p) -> dmi.Solver`` to measured records by SciPy's
    trust-region ``least_squares`` with the Jacobian of :func:`sensitivities`.

    Parameters
    ----------
    make : callable or sequence of callables
        ``make(p) -> dmi.Solver`` for the full parameter vector p; a sequence: one model per record
        (several experiments: each takes the full p and uses its shared and its own parameters,
        e.g. its own initial condition through the history).
    p0 : array_like, shape (P,), or mapping
        The starting point (and the values of the fixed parameters); or a mapping
        ``{name: value or Parameter}`` giving the names, and per parameter whether it is fixed
        and its bounds (``names``, ``free`` and ``bounds`` are then not given).
    records : Record or sequence of Record
        The measurements; times from t = 0, the start of the model's run.
    names : sequence of str, optional
        The parameters' names (default ``p0``, ``p1``, ...).
    free : array_like, optional
        Which parameters are fitted: a boolean mask (P,) or the indices or names of the free ones
        (default: all).
    bounds : tuple of array_like, optional
        (lower, upper), each a number or (P,) (for all parameters; infinite allowed); p0 must lie
        inside.
    x_scale : array_like or "jac", optional
        SciPy's ``x_scale`` for the free parameters (default ``"jac"``).
    loss : str, optional
        SciPy's loss (``"linear"`` default; ``"soft_l1"``, ``"huber"``, ``"cauchy"``,
        ``"arctan"``): the covariance is then that of the linear loss at the solution.
    multistart : int or sequence of array_like, optional
        More starting points: a number M of starts (p0 and M - 1 drawn uniformly within finite
        bounds, or within p0 * (1 +- 0.5) otherwise, with ``seed``), or the starts themselves
        (P each); the lowest cost wins.
    seed : int, optional
        Seed of the drawn starts.
    max_nfev : int, optional
        Most model runs per start (SciPy's default otherwise).
    callback : callable, optional
        ``callback(info)`` after each iteration with ``info = {"iteration", "cost", "p"}``;
        returning True stops the fit at the best point so far (success False).  Ctrl-C
        (KeyboardInterrupt) also stops it there.
    verbose : bool, optional
        Prints the cost per iteration.
    polish : bool, optional
        True (default): after the fit with the equation's sensitivities, a few iterations with the
        scheme's own tangent (jumps=False in :func:`sensitivities`), the exact derivative of the
        scheme's residuals where nothing switches: quadratic convergence to the scheme's least
        squares.  The covariance is that of the equation's sensitivities either way.
    rhs : callable, optional
        ``rhs(t, u, p)``: f as a Python function of complex u and the full p, for complex-step
        derivatives (see :func:`sensitivities`).
    options : FitOptions, optional
        The bound on a record's steps, the noise-model check and covariance scaling, the saddle
        check at the end and the progress display (see :class:`FitOptions`).

    Returns
    -------
    Estimate
        The fit, its uncertainty and what the data leave undetermined.

    Raises
    ------
    ValueError
        Records of the wrong shape, NaN in the data, times before 0, sigma not positive, p0 not
        finite or of another length than names, bounds that exclude p0, no free parameter, make
        raising at p0, a record asking for more steps than ``FitOptions.max_steps`` (before any
        run), residuals not finite at the start (naming the record, the time, and ``observe``
        where it returned them), or a parameter that changes the model's structure (see
        :func:`sensitivities`).

    Warns
    -----
    RuntimeWarning
        Parameters without effect on the records at p0 (kept there, named); a reduced
        chi-square implausible for the stated sigma; a lower cost found along a near-null
        direction at the end (a saddle); reversals the sensitivities could not place.
    TypeError
        A record that is not a :class:`Record`, or make not returning a dmi.Solver.
    """
    options = _options(options)
    p0, names, mask, (lo, hi), records, makes = _parameters(make, p0, records, names, free, bounds)
    data = _records(records, makes, p0, mask, options.max_steps)
    problem = _new_problem(makes, p0, mask, data, rhs, (lo, hi), options, polish)
    starts = _starts(multistart, p0, lo, hi, seed)
    # the parameters that do not move the records at p0: kept there and named, before a fit
    # could walk the others anywhere to make up for them
    insensitive = _insensitive(problem, names)
    if insensitive:
        mask = mask & ~np.isin(names, insensitive)
        problem = _new_problem(makes, p0, mask, data, rhs, (lo, hi), options, polish)
        why = (f"{', '.join(insensitive)} do{'es' if len(insensitive) == 1 else ''} not move the "
               "records at p0 (a zero column of the Jacobian): kept at p0 and not fitted, infinite "
               "standard error; fix it in make, or start from a p0 where it acts")
        warnings.warn(f"estimate: {why}", RuntimeWarning, stacklevel=2)
        if not mask.any():
            return _unmoved(problem, names, insensitive, lo, hi)
    fits = _run_starts(problem, starts, (lo, hi), x_scale, loss, max_nfev, callback, verbose,
                       polish, options.progress)
    best = min(fits, key=lambda f: f[1])
    x, cost, message, stopped, converged = best
    problem.jumps = True                # the covariance's Jacobian: the equation's sensitivities
    problem.grouped = False             # from one model per parameter (no plan trusted there)
    lower = None
    if converged and not stopped and options.saddle_check:
        lower = _saddle(problem, x, cost, names)
    est = _summarise(problem, names, x, cost, message, stopped, converged, options, insensitive)
    est.starts = [(s.copy(), f[1]) for s, f in zip(starts, fits)]
    est.bounds = (lo.copy(), hi.copy())
    if lower is not None:
        est.lower, est.lower_cost = problem.full(lower[0]), lower[1]
        why = (f"the cost falls from {cost:.10g} to {lower[1]:.10g} along a near-null direction of "
               f"the Jacobian ({lower[2]}): the fit stopped on a saddle, not a minimum; refit from "
               "Estimate.lower (or with multistart)")
        est.success = False
        est.message = f"{est.message}; {why}"
        warnings.warn(f"estimate: {why}", RuntimeWarning, stacklevel=2)
    return est


def _options(options: FitOptions | None) -> FitOptions:
    """The fit's options (default ``FitOptions()``), checked."""
    options = FitOptions() if options is None else options
    if not isinstance(options, FitOptions):
        raise TypeError(f"options is a {type(options).__name__}; expected a dmi.identify.FitOptions")
    if not isinstance(options.group_models, (bool, np.bool_)):
        raise TypeError(f"FitOptions.group_models = {options.group_models!r}: expected True or False")
    if not 0.0 < options.chi2_alpha < 0.5:
        raise ValueError(f"FitOptions.chi2_alpha = {options.chi2_alpha!r}: expected a probability "
                         "in (0, 0.5)")
    return options


def _parameters(make: Any, p0: Any, records: Any, names: Any, free: Any, bounds: Any
                ) -> tuple[np.ndarray, list, np.ndarray, tuple, list, list]:
    """(p0, names, the free mask, (lo, hi), the records, a model per record) from estimate's
    arguments, checked (ValueError naming the one at fault)."""
    if isinstance(p0, Mapping):
        p0, names, free, bounds = _from_parameters(p0, names, free, bounds)
    p0 = np.array(p0, dtype=float).reshape(-1)
    P = len(p0)
    if P == 0 or not np.all(np.isfinite(p0)):
        raise ValueError("p0: expected a nonempty vector of finite numbers")
    names = [f"p{j}" for j in range(P)] if names is None else [str(n) for n in names]
    if len(names) != P or len(set(names)) != P:
        raise ValueError(f"names {names}: expected {P} distinct names, one per parameter")
    records = [records] if isinstance(records, Record) else list(records)
    if not records:
        raise ValueError("records: expected at least one Record")
    makes = list(make) if isinstance(make, (list, tuple)) else [make] * len(records)
    if len(makes) != len(records):
        raise ValueError(f"{len(makes)} models for {len(records)} records: give one make, or one per "
                         "record")
    mask = _free_mask(free, names)
    if not mask.any():
        raise ValueError("free: no parameter left to fit")
    lo, hi = _bounds(bounds, P)
    outside = np.flatnonzero((p0 < lo) | (p0 > hi))
    if len(outside):
        j = outside[0]
        raise ValueError(f"bounds exclude p0: {names[j]} = {float(p0[j])!r} is outside "
                         f"[{float(lo[j])!r}, {float(hi[j])!r}]; move p0 or widen the bounds")
    return p0, names, mask, (lo, hi), records, makes


def _records(records: list, makes: list, p0: np.ndarray, mask: np.ndarray,
             max_steps: int | None) -> list:
    """The records checked against their models at p0 (their n, and the steps they reach against
    max_steps, before any run)."""
    data = []
    for k, (r, mk) in enumerate(zip(records, makes)):
        try:
            s = mk(p0.copy())
        except Exception as e:
            raise ValueError(f"make(p0) for records[{k}] raised {type(e).__name__}: {e}") from e
        if not isinstance(s, Solver):
            raise TypeError(f"make(p0) returned {type(s).__name__}; expected a dmi.Solver")
        d = _check_record(r, k, s.n)
        steps = record_steps(s, d)
        check_steps(steps, s.n, s.N, int(mask.sum()), s.h, max_steps,
                    f"records[{k}] (t up to {float(d.t[-1]):.6g})")
        data.append(d)
    return data


def _new_problem(makes: list, p0: np.ndarray, mask: np.ndarray, data: list, rhs: Any,
                 bounds: tuple[np.ndarray, np.ndarray], options: FitOptions,
                 polish: bool = False) -> _Problem:
    """The residuals' problem of a fit of the parameters ``mask`` within ``bounds``, its
    Jacobian (until the fit's end) that of the fit's first phase: the scheme's tangent with the
    polish, else the equation's sensitivities."""
    problem = _Problem(makes, p0, mask, data, rhs)
    problem.jumps = not polish
    problem.grouped = options.group_models
    problem.bounds = bounds
    problem.max_steps = options.max_steps
    return problem


def _run_starts(problem: _Problem, starts: list, bounds: tuple[np.ndarray, np.ndarray],
                x_scale: Any, loss: str, max_nfev: int | None, callback: Any, verbose: bool,
                polish: bool, progress: bool | None) -> list:
    """The fits from each start (:func:`_fit`), until one is stopped by the user; the progress
    shown on a terminal's stderr (``progress`` None) or as asked."""
    show = sys.stderr.isatty() if progress is None else bool(progress)
    clock = time.monotonic()
    fits = []
    for number, x_start in enumerate(starts):
        def display(iteration: int, cost: float, _number: int = number) -> None:
            sys.stderr.write(f"\restimate: start {_number + 1}/{len(starts)}, iteration {iteration}, "
                             f"cost {cost:.8g}, {problem.nfev} runs, "
                             f"{time.monotonic() - clock:.1f} s   ")
            sys.stderr.flush()
        fits.append(_fit(problem, x_start, bounds[0], bounds[1], x_scale, loss, max_nfev, callback,
                         verbose, polish, display if show else None))
        if fits[-1][3]:                                   # stopped by the user: no more starts
            break
    if show:
        sys.stderr.write("\n")
    return fits

def _from_parameters(params: Mapping, names: Any, free: Any, bounds: Any
                     ) -> tuple[np.ndarray, list, np.ndarray, tuple]:
    """p0, names, the free mask and the bounds from ``{name: value or Parameter}``."""
    if names is not None or free is not None or bounds is not None:
        raise ValueError("p0 is a mapping of Parameters: give names, fixed flags and bounds there, "
                         "not also as names=, free= or bounds=")
    values, lo, hi, mask = [], [], [], []
    for name, v in params.items():
        q = v if isinstance(v, Parameter) else Parameter(float(v))
        values.append(float(q.value))
        lo.append(float(q.lower))
        hi.append(float(q.upper))
        mask.append(not q.fixed)
    return np.array(values), [str(n) for n in params], np.array(mask, bool), (lo, hi)


def _insensitive(problem: _Problem, names: list) -> list:
    """The free parameters whose column of the Jacobian at p0 is zero (or below 1e-13 of the
    largest, each scaled by |p_j|)."""
    x0 = problem.p0[problem.free]
    J = problem.jacobian(x0)
    d = np.where(x0 != 0.0, np.abs(x0), 1.0)
    norms = np.linalg.norm(J, axis=0) * d
    top = norms.max() if norms.size else 0.0
    idx = np.flatnonzero(problem.free)
    return [names[idx[j]] for j in range(len(idx)) if norms[j] == 0.0 or norms[j] <= 1e-13 * top]


def _unmoved(problem: _Problem, names: list, insensitive: list, lo: np.ndarray,
             hi: np.ndarray) -> Estimate:
    """The Estimate at p0 where no parameter moves the records: success False, all named."""
    p = problem.p0.copy()
    r = problem.residuals(np.empty(0), check=True)
    cost = 0.5 * float(r @ r)
    P, M = len(p), len(r)
    cov = np.zeros((P, P))
    stderr = np.zeros(P)
    for name in insensitive:
        j = names.index(name)
        cov[j, j] = stderr[j] = np.inf
    known = all(d.sigma_known for d in problem.data)
    chisqr = 2.0 * cost
    message = (f"the fit cannot decrease the cost: no free parameter moves the records at p0 "
               f"({', '.join(insensitive)}); last cost {cost:.10g}")
    return Estimate(p=p, names=list(names), free=problem.free.copy(), cov=cov, stderr=stderr,
                    corr=np.full((P, P), np.nan), residuals=r, jacobian=np.zeros((M, 0)), cost=cost,
                    aic=math.nan, bic=math.nan, success=False, message=message,
                    unidentifiable=[f"1.00*{n}" for n in insensitive], nfev=problem.nfev,
                    njev=problem.njev, dof=M, sigma_known=known, starts=[], chisqr=chisqr,
                    redchi=chisqr / M, pvalue=float(stats.chi2.sf(chisqr, M)) if known else math.nan,
                    covar_scaled=not known, insensitive=list(insensitive),
                    bounds=(lo.copy(), hi.copy()), _problem=problem)


def _saddle(problem: _Problem, x: np.ndarray, cost: float, names: list
            ) -> tuple[np.ndarray, float, str] | None:
    """A point of lower cost than the fit's along the near-null directions of the Jacobian at x
    (:func:`_probe`), walking one level on along the directions where the cost stays flat (a
    valley of equal cost may lead to a saddle); None where none is found.  Ctrl-C ends the
    probes (None)."""
    zero_cost = 0.5 * sum(float(np.sum((dd.y * dd.w) ** 2)) for dd in problem.data)
    tol = 1e-6 * cost + 1e-14 * zero_cost        # rounding of the cost
    try:
        return _probe(problem, x, cost, names, tol, walk=True)
    except KeyboardInterrupt:
        return None


def _probe(problem: _Problem, x: np.ndarray, cost: float, names: list, tol: float, walk: bool
           ) -> tuple[np.ndarray, float, str] | None:
    """The near-null directions of the Jacobian at x (singular values below SADDLE_RCOND of the
    largest, columns scaled by |x| and normalised; at most 3), the cost's Hessian in their
    subspace by central differences, and each of its eigenvectors probed in both signs at the
    relative steps SADDLE_STEPS within the bounds: the first point whose cost is below ``cost``
    by more than ``tol``, as (y, cost, the step), else None.  With ``walk``, a probe point of
    the same cost (to ``tol``) along a null direction, at a relative step of 0.3 or more, is
    probed the same way (without walking on)."""
    J = problem.jacobian(x)
    F = J.shape[1]
    if F == 0:
        return None
    d = np.where(x != 0.0, np.abs(x), 1.0)
    norms = np.linalg.norm(J * d, axis=0)
    safe = np.where(norms > 0, norms, 1.0)
    # all F right singular vectors: the thin SVD has them where M >= F (not the M x M U)
    _, sv, Vt = np.linalg.svd(J * d / safe, full_matrices=J.shape[0] < F)
    sv = np.concatenate([sv, np.zeros(F - len(sv))])
    top = sv.max() if sv.size and sv.max() > 0 else 1.0
    near = np.flatnonzero(sv <= SADDLE_RCOND * top)[:3]
    if len(near) == 0:
        return None
    # the subspace in relative changes of the parameters, each direction's largest change 1
    U = (Vt[near] / safe).T                                       # (F, k)
    U = U / np.abs(U).max(axis=0)
    lo, hi = (b[problem.free] for b in problem.bounds)

    def at(z: np.ndarray) -> tuple[float, np.ndarray]:
        """The point x + d (U z) and its cost (inf outside the bounds or where make refuses)."""
        y = x + d * (U @ z)
        if np.any((y < lo) | (y > hi)):
            return math.inf, y
        try:
            ry = problem.residuals(y)
        except Exception:
            return math.inf, y
        c = 0.5 * float(ry @ ry)
        return (c if np.isfinite(c) else math.inf), y

    def found(c: float, y: np.ndarray) -> tuple[np.ndarray, float, str]:
        moved = ", ".join(f"{names[j]} {v:+.4g}" for j, v in zip(np.flatnonzero(problem.free), y - x)
                          if abs(v) >= 0.05 * np.abs(y - x).max())
        return y.copy(), c, moved

    k = len(near)
    eps = 1e-2
    e = np.eye(k) * eps
    H = np.zeros((k, k))
    for i in range(k):
        for z in (e[i], -e[i]):
            c, y = at(z)
            if c < cost - tol:
                return found(c, y)
            H[i, i] += c / eps ** 2
        H[i, i] -= 2.0 * cost / eps ** 2
        for j in range(i):
            corners = [at(z) for z in (e[i] + e[j], e[i] - e[j], e[j] - e[i], -e[i] - e[j])]
            for c, y in corners:
                if c < cost - tol:
                    return found(c, y)
            H[i, j] = H[j, i] = (corners[0][0] - corners[1][0] - corners[2][0]
                                 + corners[3][0]) / (4.0 * eps ** 2)
    # the Hessian's eigenvectors (a negative curvature: a saddle), then the null directions
    # themselves, walked on where the cost stays flat
    directions = [(z, False) for z in (np.linalg.eigh(H)[1].T if np.all(np.isfinite(H)) else [])]
    directions += [(z, walk) for z in np.eye(k)]
    for z, walking in directions:
        z = z / np.abs(U @ z).max()
        for sign in (1.0, -1.0):
            for step in SADDLE_STEPS:
                c, y = at(sign * step * z)
                if c < cost - tol:
                    return found(c, y)
                if not math.isfinite(c):
                    break
                if walking and step >= 0.3 and abs(c - cost) <= tol:
                    deeper = _probe(problem, y, cost, names, tol, walk=False)
                    if deeper is not None:
                        return deeper[0], deeper[1], found(deeper[1], deeper[0])[2]
    return None


def _free_mask(free: Any, names: list) -> np.ndarray:
    P = len(names)
    if free is None:
        return np.ones(P, bool)
    f = np.asarray(free)
    if f.dtype == bool:
        if f.shape != (P,):
            raise ValueError(f"free: a mask of shape {f.shape}; expected ({P},)")
        return f.copy()
    mask = np.zeros(P, bool)
    for item in np.atleast_1d(f).tolist():
        mask[_index(item, names)] = True
    return mask


def _bounds(bounds: Any, P: int) -> tuple[np.ndarray, np.ndarray]:
    if bounds is None:
        return np.full(P, -np.inf), np.full(P, np.inf)
    try:
        lo, hi = bounds
        lo = np.broadcast_to(np.asarray(lo, dtype=float), (P,)).copy()
        hi = np.broadcast_to(np.asarray(hi, dtype=float), (P,)).copy()
    except (TypeError, ValueError):
        raise ValueError(f"bounds: expected (lower, upper), each a number or {P} numbers") from None
    if np.any(np.isnan(lo) | np.isnan(hi)) or np.any(lo >= hi):
        raise ValueError("bounds: need lower < upper for every parameter, no NaN")
    return lo, hi


def _starts(multistart: Any, p0: np.ndarray, lo: np.ndarray, hi: np.ndarray, seed: int) -> list:
    if multistart is None:
        return [p0.copy()]
    if isinstance(multistart, (int, np.integer)):
        if multistart < 1:
            raise ValueError(f"multistart = {multistart}: expected a number of starts >= 1")
        rng = np.random.default_rng(seed)
        out = [p0.copy()]
        for _ in range(int(multistart) - 1):
            a = np.where(np.isfinite(lo), lo, p0 - 0.5 * np.abs(p0))
            b = np.where(np.isfinite(hi), hi, p0 + 0.5 * np.abs(p0))
            a, b = np.maximum(a, lo), np.minimum(b, hi)
            out.append(rng.uniform(a, b))
        return out
    out = [p0.copy()]
    for s in multistart:
        q = np.array(s, dtype=float).reshape(-1)
        if q.shape != p0.shape or not np.all(np.isfinite(q)) or np.any((q < lo) | (q > hi)):
            raise ValueError(f"multistart: a start {q.tolist()} is not {len(p0)} finite numbers "
                             "within the bounds")
        out.append(q)
    return out


def _fit(problem: _Problem, start: np.ndarray, lo: np.ndarray, hi: np.ndarray, x_scale: Any,
         loss: str, max_nfev: int | None, callback: Callable | None, verbose: bool, polish: bool,
         display: Callable[[int, float], None] | None = None
         ) -> tuple[np.ndarray, float, str, bool, bool]:
    """One least_squares run: (x, cost, message, stopped, converged)."""
    free = problem.free
    x0 = start[free].copy()
    problem.best = None
    iteration = [0]

    def progress(intermediate_result: Any) -> None:
        iteration[0] += 1
        cost = float(intermediate_result.cost)
        if verbose:
            print(f"iteration {iteration[0]}: cost {cost:.10g}")
        if display is not None:
            display(iteration[0], cost)
        if callback is not None and callback({"iteration": iteration[0], "cost": cost,
                                              "p": problem.full(intermediate_result.x)}):
            raise StopIteration
    xs = x_scale if isinstance(x_scale, str) else np.broadcast_to(np.asarray(x_scale, float),
                                                                  (free.sum(),))
    problem.seed(x0)
    r0 = problem.residuals(x0, check=True)
    cost0 = 0.5 * float(r0 @ r0)
    def solve(x_start: np.ndarray, jumps: bool, tol: float) -> Any:
        before, problem.jumps, problem.speculate = problem.jumps, jumps, True
        try:
            return optimize.least_squares(problem.residuals, x_start, jac=problem.jacobian,
                                          bounds=(lo[free], hi[free]), method="trf", x_scale=xs,
                                          loss=loss, max_nfev=max_nfev, callback=progress,
                                          ftol=tol, xtol=tol)
        finally:
            problem.jumps, problem.speculate = before, False
    try:
        # with the polish, the scheme's own tangent throughout (the polish then starts where the
        # fit ends, at its last Jacobian); without, the equation's sensitivities
        res = solve(x0, not polish, 1e-5 if polish else 1e-8)
        if res.status > 0 and polish:
            # the scheme's own tangent, exact where nothing switches: quadratic convergence to
            # the scheme's least squares from a point the equation's sensitivities found
            fine = None
            if loss == "linear" and max_nfev is None:
                fine = _gauss_newton(problem, res.x, float(res.cost), lo[free], hi[free], 1e-8,
                                     progress)
            if fine is None:        # a step that did not decrease the cost: least_squares's
                fine = solve(res.x, False, 1e-8)
            if fine.status > 0 and fine.cost <= res.cost:
                res = fine
    except KeyboardInterrupt:
        cost, x = problem.best
        return x, cost, f"stopped (KeyboardInterrupt) at the best point so far, cost {cost:.10g}", \
            True, False
    if res.status == -2:
        return res.x, float(res.cost), f"stopped by the callback at cost {res.cost:.10g}", True, False
    x = res.x
    cost = 0.5 * float(res.fun @ res.fun)
    converged = bool(res.success) and res.status > 0
    if cost >= cost0 and cost0 > 0.0:
        J = problem.jacobian(x)
        rank = np.linalg.matrix_rank(J) if J.size else 0
        if rank < J.shape[1] or not np.any(J):
            return x, cost, (f"the fit cannot decrease the cost (the Jacobian has rank {rank} of "
                             f"{J.shape[1]}): last cost {cost:.10g}"), False, False
    msg = f"{res.message} (cost {cost:.10g} after {problem.njev} iterations)"
    return x, cost, msg, False, converged


def _gauss_newton(problem: _Problem, x: np.ndarray, cost: float, lo: np.ndarray, hi: np.ndarray,
                  tol: float, progress: Callable[[Any], None]) -> Any:
    """The polish: full Gauss-Newton steps with the scheme's own tangent from x (its Jacobian the
    exact derivative of the residuals where nothing switches, so the steps converge fast), each
    taken where it lowers the cost, until the next step is below ``tol`` (as least_squares's
    xtol: |dx| <= tol (tol + |x|)) or would lower the cost by less than ``tol`` of it (ftol, by
    the linear model), and is then not taken (its change is within the tolerance), or a step
    taken lowered it by less than that, or the last two drops of the cost say that the steps
    still to come would lower it by less than that together (:func:`_converged`: no Jacobian is
    computed at the last point then).  A result as least_squares's (x, cost, fun, status,
    success, message; status -2 where ``progress`` stopped it); None where a step leaves the
    bounds or does not lower the cost (or after 20 steps): least_squares then polishes."""
    before, problem.jumps = problem.jumps, False
    drop = math.inf
    try:
        r, J = problem.linearised(x)
        for _ in range(20):
            dx = np.linalg.lstsq(J, -r, rcond=None)[0]
            if not np.all(np.isfinite(dx)):
                return None
            if np.linalg.norm(dx) <= tol * (tol + np.linalg.norm(x)):
                return _result(x, r, 3, "`xtol` termination condition is satisfied.")
            fitted = r + J @ dx
            if cost - 0.5 * float(fitted @ fitted) < tol * cost:
                # the step would lower the cost by less than the tolerance (the linear model's
                # prediction, exact to second order at a Gauss-Newton step)
                return _result(x, r, 2, "`ftol` termination condition is satisfied.")
            y = x + dx
            if np.any(y < lo) or np.any(y > hi):
                return None
            ry = problem.residuals(y)
            cy = 0.5 * float(ry @ ry)
            if not cy <= cost:
                return None
            x, r, drop, last, cost = y, ry, cost - cy, drop, cy
            try:
                progress(optimize.OptimizeResult(x=x, cost=cost))
            except StopIteration:
                return _result(x, r, -2, "stopped by the callback")
            if drop < tol * cost:
                return _result(x, r, 2, "`ftol` termination condition is satisfied.")
            if _converged(drop, last, tol * cost):
                return _result(x, r, 2, "`ftol` termination condition is satisfied (the drops "
                                        "still to come, predicted from the last two, are below "
                                        "it).")
            r, J = problem.linearised(x)
        return None
    finally:
        problem.jumps = before


def _converged(drop: float, last: float, tol: float) -> bool:
    """Whether the polish's steps still to come lower the cost by less than ``tol`` together,
    judged from the last two drops: where they shrink at least by half (rate q = drop / last),
    the rest of a sequence converging at that rate (or faster, as Gauss-Newton's near a
    minimum) is at most drop q / (1 - q)."""
    if not (math.isfinite(last) and 0.0 < drop < 0.5 * last):
        return False
    q = drop / last
    return drop * q / (1.0 - q) < tol


def _result(x: np.ndarray, r: np.ndarray, status: int, message: str) -> Any:
    """A least_squares result of the polish."""
    return optimize.OptimizeResult(x=x, fun=r, cost=0.5 * float(r @ r), status=status,
                                   success=status > 0, message=message)


def _summarise(problem: _Problem, names: list, x: np.ndarray, cost: float, message: str,
               stopped: bool, converged: bool, options: FitOptions | None = None,
               insensitive: Sequence[str] = ()) -> Estimate:
    options = FitOptions() if options is None else options
    free = problem.free
    p = problem.full(x)
    r, J = problem.linearised(x)
    M, F = J.shape
    P = len(p)
    dof = M - F
    known = all(d.sigma_known for d in problem.data)
    chisqr = 2.0 * cost
    redchi = chisqr / dof if dof > 0 else math.nan
    pvalue = float(stats.chi2.sf(chisqr, dof)) if known and dof > 0 else math.nan
    scaled = not known or options.scale_covar
    s2 = (redchi if dof > 0 else np.inf) if scaled else 1.0
    if known and dof > 0 and not stopped:
        low = float(stats.chi2.cdf(chisqr, dof))
        if pvalue < options.chi2_alpha or low < options.chi2_alpha:
            big = pvalue < options.chi2_alpha
            why = (f"the reduced chi-square {redchi:.4g} ({dof} degrees of freedom) is implausible "
                   f"for the stated sigma (chi-square probability {pvalue if big else low:.3g} "
                   f"of so {'large' if big else 'small'} a value): sigma is "
                   f"{'understated' if big else 'overstated'} about "
                   f"{math.sqrt(redchi) if big else 1.0 / math.sqrt(redchi):.3g} times"
                   f"{', or the model misses something' if big else ''}; the covariance "
                   + ("is scaled by it (scale_covar)" if options.scale_covar else
                      "takes sigma as stated, so the standard errors are off by that factor: "
                      "FitOptions(scale_covar=True) scales them by the reduced chi-square"))
            message = f"{message}; {why}"
            warnings.warn(f"estimate: {why}", RuntimeWarning, stacklevel=3)
    covf, bad, combos = _covariance(J, x, [names[j] for j in np.flatnonzero(free)])
    cov = np.zeros((P, P))
    idx = np.flatnonzero(free)
    cov[np.ix_(idx, idx)] = covf * s2
    stderr = np.sqrt(np.maximum(np.diag(cov), 0.0))
    for b in bad:
        cov[idx[b], idx[b]] = np.inf
        stderr[idx[b]] = np.inf
    for name in insensitive:
        j = names.index(name)
        cov[j, j] = stderr[j] = np.inf
    combos = [f"1.00*{name}" for name in insensitive] + combos
    if insensitive:
        message = (f"{message}; not fitted, as they do not move the records at p0: "
                   f"{', '.join(insensitive)}")
    with np.errstate(invalid="ignore", divide="ignore"):
        outer = np.outer(stderr, stderr)
        corr = cov / outer
    corr[~np.isfinite(corr) | (outer == 0) | ~np.isfinite(outer)] = np.nan
    if problem.unplaced:
        # the Jacobian is off by O(1) after a reversal it could not place: no covariance from it
        cov[np.ix_(idx, idx)] = np.nan
        stderr[idx] = np.nan
        corr[np.ix_(idx, idx)] = np.nan
        shown = ", ".join(f"step {q} of record {k}" for k, q in problem.unplaced[:5])
        more = ", ..." if len(problem.unplaced) > 5 else ""
        why = (f"the sensitivities could not place {len(problem.unplaced)} friction reversal(s) inside "
               f"their step ({shown}{more}), so the Jacobian is off by O(1) from there on and the "
               "covariance, standard errors and correlations are not reported (NaN); take a smaller h")
        message = f"{message}; {why}"
        warnings.warn(f"estimate: {why}", RuntimeWarning, stacklevel=3)
    rss = 2.0 * cost
    if known:
        aic, bic = rss + 2 * F, rss + F * math.log(M)
    else:
        base = M * math.log(rss / M) if rss > 0 else -np.inf
        aic, bic = base + 2 * F, base + F * math.log(M)
    return Estimate(p=p, names=list(names), free=free.copy(), cov=cov, stderr=stderr, corr=corr,
                    residuals=r, jacobian=J, cost=cost, aic=aic, bic=bic,
                    success=converged and not stopped, message=message, unidentifiable=combos,
                    nfev=problem.nfev, njev=problem.njev, dof=dof, sigma_known=known, starts=[],
                    unplaced=list(problem.unplaced), chisqr=chisqr, redchi=redchi, pvalue=pvalue,
                    covar_scaled=scaled, insensitive=list(insensitive), _problem=problem)


def _covariance(J: np.ndarray, x: np.ndarray, names: list) -> tuple[np.ndarray, list, list]:
    """(J^T J)^-1 on the determined subspace, the parameters in undetermined combinations, and
    those combinations named, from the SVD of J with columns scaled by |x| (1 where x = 0) and
    then normalised."""
    F = J.shape[1]
    d = np.where(x != 0.0, np.abs(x), 1.0)
    Js = J * d
    norms = np.linalg.norm(Js, axis=0)
    safe = np.where(norms > 0, norms, 1.0)
    Jn = Js / safe
    _, sv, Vt = np.linalg.svd(Jn, full_matrices=Jn.shape[0] < F)   # (all F rows of Vt either way)
    sv = np.concatenate([sv, np.zeros(F - len(sv))])
    top = sv.max() if sv.size and sv.max() > 0 else 1.0
    weak = sv <= RCOND * top
    combos, bad = [], set()
    for k in np.flatnonzero(weak):
        v = Vt[k].copy()
        v /= np.abs(v).max()
        v = np.where(np.abs(v) >= 0.05, v, 0.0)
        v /= np.linalg.norm(v)
        terms = [f"{'-' if c < 0 else '+'} {abs(c):.2f}*{names[j]}" for j, c in enumerate(v) if c != 0]
        text = " ".join(terms)
        combos.append(text[2:] if text.startswith("+ ") else "-" + text[2:])
        bad.update(np.flatnonzero(v != 0).tolist())
    keep = ~weak
    V = Vt.T
    inv = (V[:, keep] / sv[keep] ** 2) @ V[:, keep].T           # (Jn^T Jn)^+ on the kept subspace
    scale = d / safe
    cov = inv * np.outer(scale, scale)
    return cov, sorted(bad), combos
