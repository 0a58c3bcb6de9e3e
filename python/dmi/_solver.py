# dmi.Solver: one libdmi solver (include/dmi.h), method for function.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The class dmi.Solver."""
from __future__ import annotations

import ctypes
import math
import operator
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

from . import _callbacks as cb
from . import _lib
from ._errors import Error, InvalidArgument, from_code

_L = _lib.lib
_DP = ctypes.POINTER(ctypes.c_double)

# A Python function, or a C function: numba cfunc, ctypes function pointer, scipy.LowLevelCallable.
Callback = Any


def _count(value: Any, name: str, minimum: int) -> int:
    try:
        v = operator.index(value)
    except TypeError:
        raise InvalidArgument(_lib.EINVAL, f"{name} = {value!r} is not an integer") from None
    if v < minimum:
        raise InvalidArgument(_lib.EINVAL, f"{name} = {v}: must be >= {minimum}")
    return v


def _positive(value: Any, name: str) -> float:
    """value as a finite float > 0, or InvalidArgument."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InvalidArgument(_lib.EINVAL, f"{name} = {value!r} is not a number") from None
    if not (math.isfinite(v) and v > 0):
        raise InvalidArgument(_lib.EINVAL, f"{name} = {v}: must be finite and > 0")
    return v


def _array(value: Any, shape: tuple[int, ...], name: str) -> np.ndarray:
    """value as a C-contiguous float64 array of the given shape, or InvalidArgument."""
    try:
        a = np.ascontiguousarray(value, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise InvalidArgument(_lib.EINVAL, f"{name}: not an array of floats ({e})") from None
    if a.shape != shape:
        raise InvalidArgument(_lib.EINVAL, f"{name} has shape {a.shape}; expected {shape}")
    return a


def _choice(table: dict[str, int], value: Any, what: str) -> int:
    """libdmi's code of a named choice (a convolution method, a quadrature rule); InvalidArgument
    naming the choices otherwise."""
    code = table.get(value) if isinstance(value, str) else None
    if code is None:
        raise InvalidArgument(_lib.EINVAL, f"{what} {value!r}: expected one of "
                              f"{', '.join(map(repr, table))}")
    return code


def _ptr(a: np.ndarray | None) -> Any:
    return None if a is None else a.ctypes.data_as(_DP)


class Solver:
    """The implicit Euler scheme (3.12)-(3.13) for u' + A(u) + f(t, u) + int_0^tau H(s) u(t-s) ds ∋ 0,
    u = z on [-tau, 0], in R^n, with h = tau / N (``Solver(n, tau, N)``, ``dmi_create``) or with a
    step h that need not divide tau (``Solver(n, tau, h=h)``, ``dmi_create_h``: the delay sum's
    last cell is partial, weighted theta h, see :meth:`__init__`).

    Nothing is set at first: f = 0, A = 0, H = 0, z = 0.  Set the model with the ``set_*``
    methods, then :meth:`init`, then :meth:`step`, :meth:`advance` or :meth:`run`.
    Every failure raises :class:`dmi.Error` (:class:`dmi.InvalidArgument` for a bad argument or
    call, also a ``ValueError``) and leaves the solver as it was.

    Callbacks may be Python functions (``f(t, u) -> (n,)``, ``r(lam, x) -> (n,)``,
    ``H(s) -> (n, n)``, ``z(t) -> (n,)``, float64 NumPy arrays in and out) or C functions with
    libdmi's signature, called by the library with no Python in between: a numba ``cfunc``
    (signatures ``dmi.RHS_SIGNATURE`` etc.), a ctypes function pointer or a
    ``scipy.LowLevelCallable``; or, with ``jit=True``, Python functions compiled by numba into
    such C functions (closure values passed at each call).  A solver may be used by one thread at a
    time; distinct solvers run in parallel in distinct threads (the GIL is released in every call
    into libdmi and taken only by Python callbacks).
    """

    def __init__(self, n: int, tau: float, N: int | None = None, *, h: float | None = None):
        """A solver for R^n with delay tau > 0 (finite) and either N >= 1 steps per tau
        (h = tau / N, ``dmi_create``) or the step h > 0 itself (``dmi_create_h``, libdmi 1.2):
        give exactly one of them.  With h, tau / h need not be an integer: the delay sum has
        N = ceil(tau / h) cells, the last one weighted theta h = tau - (N - 1) h (0 < theta <= 1);
        h = tau / N as ``Solver(n, tau, N)`` computes it gives that solver, bitwise; h > tau
        gives N = 1.  :attr:`N` and :attr:`h` tell what the solver uses."""
        self._handle = None
        n = _count(n, "n", 1)
        if (N is None) == (h is None):
            raise InvalidArgument(_lib.EINVAL, f"Solver(n, tau, N=..., h=...): give exactly one of "
                                  f"N and h (got N = {N!r}, h = {h!r})")
        tau = _positive(tau, "tau")
        handle = ctypes.c_void_p()
        if h is None:
            N = _count(N, "N", 1)
            rc = _L.dmi_create(ctypes.byref(handle), n, tau, N)
            call = f"dmi_create(n = {n}, tau = {tau!r}, N = {N})"
        else:
            h = _positive(h, "h")
            rc = _L.dmi_create_h(ctypes.byref(handle), n, tau, h)
            call = f"dmi_create_h(n = {n}, tau = {tau!r}, h = {h!r})"
        if rc != _lib.OK:
            raise from_code(rc, f"{call}: {_L.dmi_strerror(rc).decode()}")
        self._handle = handle
        self._n, self._tau, self._N = n, tau, int(_L.dmi_get_N(handle))
        self._h_given = h  # (for repr)
        self._keep: dict[str, cb.Bound] = {}   # callbacks and data libdmi points to
        self._resolvent: tuple = ()             # the built-in resolvent and its data (dmi.analysis)
        self._failure: list = [None]           # an exception raised in a Python callback
        self._busy = threading.Lock()

    # ---- helpers -----------------------------------------------------------------------------

    @contextmanager
    def _using(self) -> Iterator[ctypes.c_void_p]:
        """The handle, for one call at a time (libdmi: one solver, one thread)."""
        if self._handle is None:
            raise InvalidArgument(_lib.ESTATE, "the solver is closed")
        if not self._busy.acquire(blocking=False):
            raise InvalidArgument(_lib.ESTATE, "the solver is in use (by another thread, or by a "
                                  "callback of this solver calling it)")
        try:
            yield self._handle
        finally:
            self._busy.release()

    def _check(self, rc: int) -> None:
        """Raises the exception for libdmi's return code rc: a Python callback's own exception
        first (the library then returned DMI_ECALLBACK)."""
        failure, self._failure[0] = self._failure[0], None
        if rc == _lib.OK:
            return
        if failure is not None:
            raise failure
        message = _L.dmi_last_error(self._handle).decode()
        if rc == _lib.ECALLBACK and "callback returned 2 " in message:
            message += (" (a jit=True callback returns 2 when its result does not have libdmi's "
                        "shape: (n,), or (n, n) for the kernel)")
        raise from_code(rc, message)

    def _set_callback(self, slot: str, kind: cb.Kind, setter: Any, f: Any, user: Any,
                      jit: bool = False) -> None:
        if jit and f is not None:
            from . import _jit  # (numba is imported only for jit=True)
            bound = _jit.bind(kind, f, user, self._n)
        else:
            bound = cb.bind(kind, f, user, self._n, self._failure)
        with self._using() as s:
            self._check(setter(s, bound.address, bound.user))
        self._keep[slot] = bound  # only now: a refused call keeps the former callback alive

    # ---- sizes ---------------------------------------------------------------------------------

    @property
    def n(self) -> int:
        """Dimension n of the state."""
        return self._n

    @property
    def tau(self) -> float:
        """Delay tau (time units)."""
        return self._tau

    @property
    def N(self) -> int:
        """Cells of the delay sum, ``dmi_get_N``: steps per delay (h = tau / N) for
        ``Solver(n, tau, N)``; ceil(tau / h) for ``Solver(n, tau, h=h)``.  The window has N + 1
        rows."""
        return self._N

    @property
    def h(self) -> float:
        """Step size h (time units), ``dmi_get_h``: tau / N, or the h given."""
        with self._using() as s:
            return _L.dmi_get_h(s)

    # ---- setup -------------------------------------------------------------------------------

    def set_rhs(self, f: Callback | None, user: Any = None, *, jit: bool = False) -> None:
        """Right-hand side f: ``f(t, u) -> array (n)``, or a C function
        ``int f(double t, const double *u, double *out, void *user)`` (``dmi.RHS_SIGNATURE``).
        None restores f = 0.  ``user``: the C function's user pointer: a NumPy array or ctypes
        object (its data; the solver keeps the object alive), a ctypes pointer or an int address
        (the memory is yours to keep alive); a LowLevelCallable's own user_data otherwise.  Takes
        effect from the next step; may be called at any time.  ``jit=True``: ``f(t, u)`` is a plain
        Python function (def or lambda), compiled by numba into the C function; numbers and NumPy
        arrays of its closure are passed at each call (docs/python.md, "jit=True"); the same
        holds for the other ``set_*`` callbacks."""
        self._set_callback("rhs", cb.RHS, _L.dmi_set_rhs, f, user, jit)

    def set_resolvent(self, r: Callback | None, user: Any = None, *, jit: bool = False) -> None:
        """A through its resolvent: ``r(lam, x) -> (I + lam A)^{-1} x``, array (n), lam = h; or a
        C function ``int r(double lam, const double *x, double *out, void *user)``
        (``dmi.RESOLVENT_SIGNATURE``).  None restores A = 0.  Replaces an earlier resolvent,
        friction or box."""
        self._set_callback("resolvent", cb.RESOLVENT, _L.dmi_set_resolvent, r, user, jit)
        self._resolvent = ()

    def set_friction(self, alpha: Any) -> None:
        """Built-in dry friction A(u)_i = alpha_i sigma(u_i): alpha has n finite values >= 0
        (``dmi_set_friction``).  Replaces an earlier resolvent, friction or box."""
        a = _array(alpha, (self._n,), "alpha")
        with self._using() as s:
            self._check(_L.dmi_set_friction(s, _ptr(a)))
        self._keep["resolvent"] = cb.Bound(None, None, ())
        self._resolvent = ("friction", a.copy())

    def set_box(self, lo: Any, hi: Any) -> None:
        """Built-in normal cone of the box prod_i [lo_i, hi_i] (the resolvent is the projection):
        n values each, no NaN, lo_i <= hi_i, infinite bounds allowed (``dmi_set_box``).  Replaces
        an earlier resolvent, friction or box."""
        lo_a, hi_a = _array(lo, (self._n,), "lo"), _array(hi, (self._n,), "hi")
        with self._using() as s:
            self._check(_L.dmi_set_box(s, _ptr(lo_a), _ptr(hi_a)))
        self._keep["resolvent"] = cb.Bound(None, None, ())
        self._resolvent = ("box", lo_a.copy(), hi_a.copy())

    def set_kernel(self, H: Callback | None, user: Any = None, *, jit: bool = False) -> None:
        """Kernel: ``H(s) -> array (n, n)`` for 0 <= s < tau, or a C function
        ``int H(double s, double *out, void *user)`` writing n*n values row-major
        (``dmi.KERNEL_SIGNATURE``).  None: H = 0.  Sampled by :meth:`init`, so refused after it."""
        self._set_callback("kernel", cb.KERNEL, _L.dmi_set_kernel, H, user, jit)

    def set_kernel_exp(self, a: Any, b: Any, C: Any, D: Any = None) -> None:
        """Kernel as K exponential terms H(s) = sum_k exp(a_k s) (C_k cos(b_k s) + D_k sin(b_k s)):
        a and b of shape (K,) (1 / time unit), C and D of shape (K, n, n) (D None: zero)
        (``dmi_set_kernel_exp``).  Refused after :meth:`init`."""
        if np.ndim(a) != 1 or len(a) == 0:
            raise InvalidArgument(_lib.EINVAL, f"set_kernel_exp: a has shape {np.shape(a)}; expected "
                                  "(K,), K >= 1 terms (set_kernel(None) removes the kernel)")
        K = len(a)
        a_a = _array(a, (K,), "a")
        n = self._n
        b_a = _array(b, (K,), "b")
        C_a = _array(C, (K, n, n), "C")
        D_a = None if D is None else _array(D, (K, n, n), "D")
        with self._using() as s:
            self._check(_L.dmi_set_kernel_exp(s, K, _ptr(a_a), _ptr(b_a), _ptr(C_a), _ptr(D_a)))
        # no callback; the terms kept for dmi.analysis (the equation's characteristic matrix)
        self._keep["kernel"] = cb.Bound(None, None, (a_a, b_a, C_a, D_a))

    def set_history(self, z: Callback | None, user: Any = None, *, jit: bool = False) -> None:
        """History: ``z(t) -> array (n)`` for -tau <= t <= 0, or a C function
        ``int z(double t, double *out, void *user)`` (``dmi.HISTORY_SIGNATURE``).  None: z = 0.
        Sampled by :meth:`init`, so refused after it."""
        self._set_callback("history", cb.HISTORY, _L.dmi_set_history, z, user, jit)

    def set_convolution(self, method: str) -> None:
        """Method of the delay sum: ``"auto"`` (default), ``"direct"``, ``"fft"`` or
        ``"recursive"`` (exponential kernels, see ``dmi_set_convolution``).  Any time, also
        between steps; the methods differ by rounding only."""
        code = _choice(_lib.CONV, method, "set_convolution: method")
        with self._using() as s:
            self._check(_L.dmi_set_convolution(s, code))

    # ---- time stepping -------------------------------------------------------------------------

    def init(self) -> None:
        """Samples the kernel and the history and sets t = 0 (p = 0); again: restarts from t = 0."""
        with self._using() as s:
            self._check(_L.dmi_init(s))

    def step(self) -> None:
        """One step t_p -> t_{p+1}.  On failure the solver is bitwise where it was, and a retry
        gives a clean run's result; an exception raised by a Python callback comes out as it is."""
        with self._using() as s:
            self._check(_L.dmi_step(s))

    def advance(self, steps: int) -> None:
        """``steps`` steps in C.  Stops at the first failing step (the steps before it are kept,
        :attr:`step_index` tells how many) and raises its error."""
        steps = _count(steps, "steps", 0)
        with self._using() as s:
            self._check(_L.dmi_advance(s, steps))

    def run(self, steps: int, stride: int = 1) -> tuple[np.ndarray, np.ndarray]:
        """``steps`` steps in C, recording the states there: returns ``t`` (rows,) and ``U``
        (rows, n) at p0, p0 + stride, ..., p0 + k stride <= p0 + steps, and at p0 + steps (the
        last row), p0 the step index at the call.  On a failing step the steps before it are
        kept, and the exception has the rows recorded until then as ``partial = (t, U)``."""
        t, U, _ = self._run(steps, stride, False)
        return t, U

    def run_terms(self, steps: int, stride: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`run` that also records the resolvent's argument: returns ``t``, ``U`` (rows,
        n) and ``X`` (rows - 1, n), X[k] the argument X^{q-1} of the step into U[k + 1] (at
        step q; :meth:`step_terms` after that step), still in one call to C."""
        return self._run(steps, stride, True)  # type: ignore[return-value]

    def _run(self, steps: int, stride: int, terms: bool
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        steps = _count(steps, "steps", 0)
        stride = _count(stride, "stride", 1)
        cap = steps // stride + 2
        t = np.empty(cap)
        U = np.empty((cap, self._n))
        X = np.empty((cap - 1, self._n)) if terms else None
        rows = ctypes.c_size_t(0)
        with self._using() as s:
            rc = _lib.pylib.dmi_py_run(s, self._n, steps, stride, _ptr(t), _ptr(U),
                                       None if X is None else _ptr(X), ctypes.byref(rows))
            try:
                self._check(rc)
            except BaseException as e:
                e.partial = (t[:rows.value].copy(), U[:rows.value].copy())
                raise
        r = rows.value
        return t[:r].copy(), U[:r].copy(), None if X is None else X[:r - 1].copy()

    # ---- queries ---------------------------------------------------------------------------------

    @property
    def time(self) -> float:
        """t_p = p h (time units); 0 before :meth:`init`."""
        with self._using() as s:
            return _L.dmi_time(s)

    @property
    def step_index(self) -> int:
        """The step counter p (steps since :meth:`init`); InvalidArgument before it."""
        p = ctypes.c_uint64()
        with self._using() as s:
            self._check(_L.dmi_get_step_index(s, ctypes.byref(p)))
        return p.value

    @property
    def state(self) -> np.ndarray:
        """U^p, a new array (n,)."""
        u = np.empty(self._n)
        with self._using() as s:
            self._check(_L.dmi_get_state(s, _ptr(u)))
        return u

    def past(self, lag: int) -> np.ndarray:
        """U^{p - lag}, 0 <= lag <= N (history values for p - lag <= 0), a new array (n,)."""
        lag = _count(lag, "lag", 0)
        if lag > self._N:
            raise InvalidArgument(_lib.EINVAL, f"past: lag = {lag} > N = {self._N}")
        u = np.empty(self._n)
        with self._using() as s:
            self._check(_L.dmi_get_past(s, lag, _ptr(u)))
        return u

    def get_window(self) -> np.ndarray:
        """The window of stored states U^{p-N}, ..., U^p, oldest first, as a new array (N + 1, n)
        (``dmi_get_window``, since libdmi 1.2): with the step counter, the whole state of the
        scheme's step map."""
        U = np.empty((self._N + 1, self._n))
        with self._using() as s:
            self._check(_L.dmi_get_window(s, _ptr(U)))
        return U

    def set_window(self, U: Any) -> None:
        """Replaces the stored states by ``U``, shape (N + 1, n), oldest first (row N is the new
        U^p), keeping the step counter (``dmi_set_window``, since libdmi 1.2); the delay sum's
        engine is recomputed from them.  Non-finite values: InvalidArgument, solver unchanged."""
        a = _array(U, (self._N + 1, self._n), "U")
        with self._using() as s:
            self._check(_L.dmi_set_window(s, _ptr(a)))

    def step_terms(self) -> tuple[np.ndarray, np.ndarray]:
        """Terms of the last step (t_{p-1} -> t_p): ``W`` = W^{p-1} (the delay sum) and ``X`` =
        X^{p-1} (the resolvent's argument; (X - U^p) / h is the element of A(U^p) selected, the
        friction force for friction).  InvalidArgument before the first step."""
        W, X = np.empty(self._n), np.empty(self._n)
        with self._using() as s:
            self._check(_L.dmi_get_step_terms(s, _ptr(W), _ptr(X)))
        return W, X

    # ---- saving and restoring ------------------------------------------------------------------

    def save_state(self) -> bytes:
        """The time-stepping state (step counter, the N + 1 stored states, the last terms, an
        exponential kernel's sums) as bytes (``dmi_state_save``); not the callbacks, resolvent,
        method or kernel."""
        with self._using() as s:
            size = _L.dmi_state_size(s)
            buf = ctypes.create_string_buffer(size)
            self._check(_L.dmi_state_save(s, buf, size))
        return buf.raw

    def load_state(self, data: bytes) -> None:
        """Restores bytes of :meth:`save_state` from a solver with the same n, N, tau, h (and
        exponential kernel); needs :meth:`init` first.  Bad bytes: InvalidArgument, solver
        unchanged.  Stepping on is bitwise the saving solver's."""
        try:
            raw = bytes(data)
        except TypeError:
            raise InvalidArgument(_lib.EINVAL, "load_state: data is not bytes-like") from None
        with self._using() as s:
            self._check(_L.dmi_state_load(s, raw, len(raw)))

    # ---- life cycle ------------------------------------------------------------------------------

    def close(self) -> None:
        """Frees the C solver (``dmi_free``); the object is unusable afterwards.  Also done when
        the object is collected."""
        if self._handle is not None:
            with self._using() as s:
                _L.dmi_free(ctypes.byref(s))
                self._handle = None
            self._keep.clear()

    def __enter__(self) -> Solver:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:
        if getattr(self, "_handle", None) is not None:
            _L.dmi_free(ctypes.byref(self._handle))
            self._handle = None

    def set_quadrature(self, rule: str) -> None:
        """Quadrature rule of the delay integral, before :meth:`init` (``dmi_set_quadrature``):
        ``"left"`` (default) the paper's rectangle rule h H(l h) per cell; ``"cell"`` exact cell
        weights, the integral of H over each cell (closed form for :meth:`set_kernel_exp`, tanh-sinh
        quadrature for a callback, which is then called inside the cells, never at s = 0: kernels
        singular at 0 such as s^-1/2 run).  Every convolution method computes the same sum."""
        code = _choice(_lib.QUAD, rule, "set_quadrature: rule")
        with self._using() as s:
            self._check(_L.dmi_set_quadrature(s, code))

    def set_kernel_near(self, H: Callback | None, delta: float, user: Any = None) -> None:
        """The exact kernel ``H(s) -> array (n, n)`` (or a C kernel function) on the cells below
        ``delta``, whose weights become H's exact cell integrals, while the kernel of
        :meth:`set_kernel_exp` (a fit on [delta, tau]) gives the other cells: a kernel singular at 0 in
        O(1) per step (``dmi_set_kernel_near``).  None removes it.  Before :meth:`init`."""
        def setter(s: Any, address: Any, u: Any) -> int:
            return _L.dmi_set_kernel_near(s, address, u, float(delta))
        self._set_callback("kernel_near", cb.KERNEL, setter, H, user, False)

    def set_kernel_fit(self, fit: Any, entry: tuple[int, int] | None = None, near: Callback | None = None,
                       ) -> None:
        """The kernel of a :class:`dmi.kernels.KernelFit`: an n x n fit fills the whole kernel; a scalar
        fit goes to ``entry=(i, j)`` (the other entries zero), or fills the kernel of an n = 1 solver.
        A fit with ``delta > 0`` (a kernel singular at 0) gets its near cells from ``near``, the exact
        scalar or n x n kernel (default: the fit's own ``kernel`` when it carries one, a
        :class:`dmi.kernels.PowerKernel`); use :meth:`set_quadrature` ``("cell")`` with it.
        Before :meth:`init`."""
        n = self._n
        C, D = np.asarray(fit.C, float), np.asarray(fit.D, float)
        K = len(fit.a)
        if C.ndim == 3:
            if entry is not None or C.shape[1:] != (n, n):
                raise InvalidArgument(_lib.EINVAL, f"set_kernel_fit: a {C.shape[1]} x {C.shape[2]} fit "
                                      f"fills the whole kernel of this n = {n} solver (entry=None)")
            i = j = None
        else:
            if entry is None and n != 1:
                raise InvalidArgument(_lib.EINVAL, f"set_kernel_fit: a scalar fit needs entry=(i, j) "
                                      f"for this n = {n} solver")
            i, j = (0, 0) if entry is None else (int(entry[0]), int(entry[1]))
            if not (0 <= i < n and 0 <= j < n):
                raise InvalidArgument(_lib.EINVAL, f"set_kernel_fit: entry {entry} is outside {n} x {n}")
            Cm, Dm = np.zeros((K, n, n)), np.zeros((K, n, n))
            Cm[:, i, j], Dm[:, i, j] = C, D
            C, D = Cm, Dm
        exact = near if near is not None else getattr(fit, "kernel", None)
        if fit.delta > 0 and exact is None:
            raise InvalidArgument(_lib.EINVAL, "set_kernel_fit: the fit starts at delta = "
                                  f"{fit.delta!r}: give the exact kernel of the near cells (near=...)")
        self.set_kernel_exp(fit.a, fit.b, C, D)
        if fit.delta > 0:
            if i is not None and callable(exact) and not isinstance(exact, ctypes._CFuncPtr) \
                    and not hasattr(exact, "address"):  # a Python scalar kernel: as an n x n one
                scalar = exact

                def exact(s: float, _i: int = i, _j: int = j) -> np.ndarray:
                    out = np.zeros((n, n))
                    out[_i, _j] = scalar(s)
                    return out
            self.set_kernel_near(exact, fit.delta)
        else:
            self.set_kernel_near(None, 0.0)

    def __repr__(self) -> str:
        if self._h_given is not None:
            return f"dmi.Solver(n={self._n}, tau={self._tau!r}, h={self._h_given!r})"
        return f"dmi.Solver(n={self._n}, tau={self._tau!r}, N={self._N})"
