# dmi.Solver: one libdmi solver (include/dmi.h), method for function.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The class dmi.Solver."""
from __future__ import annotations

import ctypes
import math
import operator
import re
import threading
import types
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

from . import _callbacks as cb
from . import _lib
from ._errors import Error, InvalidArgument, from_code

_L = _lib.lib
_DP = ctypes.POINTER(ctypes.c_double)
# what a jit=True callback's return code 2 means (libdmi and eval_* name only the code)
_JIT_SHAPE = (" (a jit=True callback returns 2 when its result does not have libdmi's shape: (n,), "
              "or (n, n) for the kernel)")

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


def _unwatched() -> bool:
    return True


def _python_calls(message: str) -> str:
    """libdmi's message with the C call that declares the singularity exponent named as the
    Python call that makes it (``set_quadrature("cell", singularity=...)``)."""
    if "dmi_set_kernel_singularity(s, " not in message:
        return message
    message = re.sub(r"dmi_set_kernel_singularity\(s, ([^)]*)\)",
                     r"set_quadrature('cell', singularity=\1)", message)
    return message.replace("or NAN to have it estimated", "or singularity=None to have it "
                           "estimated").replace("use DMI_QUAD_LEFT", "use set_quadrature('left')")


def _same_value(x: Any, y: Any, depth: int) -> bool:
    """x and y the same object, equal numbers of one type (bit for bit), equal arrays, or Python
    functions of the same code and values (to a depth of 4)."""
    if x is y:
        return True
    if type(x) is not type(y):
        return False
    if isinstance(x, (bool, int, np.integer)):
        return bool(x == y)
    if isinstance(x, (float, np.floating)):
        return np.asarray(x).tobytes() == np.asarray(y).tobytes()
    if isinstance(x, np.ndarray):
        return x.dtype == y.dtype and x.shape == y.shape and x.tobytes() == y.tobytes()
    if isinstance(x, tuple):
        return len(x) == len(y) and all(_same_value(u, v, depth) for u, v in zip(x, y))
    return _same_function(x, y, depth + 1)


def _same_function(f: Any, g: Any, depth: int) -> bool:
    """f and g the same object, or Python functions of the same code and globals whose closure
    values and defaults are the same (:func:`_same_value`)."""
    if f is g:
        return True
    if not isinstance(f, types.FunctionType) or type(g) is not type(f) or depth > 4:
        return False
    if f.__code__ is not g.__code__ or f.__globals__ is not g.__globals__:
        return False
    cf = tuple(c.cell_contents for c in f.__closure__ or ())
    cg = tuple(c.cell_contents for c in g.__closure__ or ())
    return (_same_value(cf, cg, depth) and _same_value(f.__defaults__, g.__defaults__, depth)
            and f.__kwdefaults__ is None and g.__kwdefaults__ is None)


def _same_jit(a: Any, b: Any) -> bool:
    """Two jit=True callbacks (_jit.JitBound) of the same compiled code whose user data hold the
    same values: numbers bit for bit, arrays element by element (their addresses may differ)."""
    if a.address != b.address or a.keys != b.keys or a.n != b.n:
        return False
    if len(a.data) != len(b.data):
        return False
    slot, arrays = 4, 1     # (the head's 4 slots, the scratch array first)
    for key in a.keys:
        if key[0] == "k":   # (a constant of the compiled code: part of its address)
            continue
        if key[0] == "a":
            x, y = a.keep[2][arrays], b.keep[2][arrays]
            if x.shape != y.shape or x.tobytes() != y.tobytes():
                return False
            arrays += 1
            slot += 1 + x.ndim
        else:
            if a.data[slot] != b.data[slot]:
                return False
            slot += 1
    return True


def _ptr(a: np.ndarray | None) -> Any:
    return None if a is None else a.ctypes.data_as(_DP)


class Solver:
    """The implicit Euler scheme (3.12)-(3.13) for u' + A(u) + f(t, u) + int_0^tau H(s) u(t-s) ds ∋ 0,
    u = z on [-tau, 0], in R^n, with h = tau / N (``Solver(n, tau, N)``, ``dmi_create``) or with a
    step h that need not divide tau (``Solver(n, tau, h=h)``, ``dmi_create_h``: the delay sum's
    last cell is partial, weighted theta h, see the parameter ``h``).

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
    into libdmi and taken only by Python callbacks).  A call on a closed solver, or on one in use
    (by another thread, or by a callback of this solver calling it), raises
    :class:`dmi.InvalidArgument` with code ``dmi.ESTATE``.

    Parameters
    ----------
    n : int
        Dimension of the state, >= 1.
    tau : float
        Delay tau > 0, finite (time units).
    N : int, optional
        Steps per delay, >= 1: h = tau / N (``dmi_create``).  Give exactly one of N and h.
    h : float, optional
        The step itself, finite and > 0 (time units; ``dmi_create_h``, libdmi 1.2).  tau / h
        need not be an integer: the delay sum has N = ceil(tau / h) cells, the last one weighted
        theta h = tau - (N - 1) h (0 < theta <= 1); h = tau / N as ``Solver(n, tau, N)`` computes
        it gives that solver, bitwise; h > tau gives N = 1.  :attr:`N` and :attr:`h` tell what
        the solver uses.

    Raises
    ------
    dmi.InvalidArgument
        Code ``dmi.EINVAL``: n or N not an integer >= 1, tau or h not finite and > 0, both or
        neither of N and h given, or h = tau / N not a positive normal number.
    dmi.Error
        Code ``dmi.ENOMEM``: the (N + 1) n stored values cannot be allocated (or tau / h >= 2^50
        cells).
    """

    def __init__(self, n: int, tau: float, N: int | None = None, *, h: float | None = None):
        """A solver for R^n with delay tau and N steps per tau or step h: see :class:`Solver`."""
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
        self._watched: tuple = ()               # the jit=True callbacks the steps call
        self._same: Callable[[], bool] = _unwatched  # (their variables unchanged; see _watch)
        self._resolvent: tuple = ()             # the built-in resolvent and its data
        self._choices = {"convolution": "auto", "quadrature": "left"}
        self._near_delta = 0.0                  # delta of set_kernel_near (0: no near cells)
        self._fit: tuple | None = None          # (fit, entry) of set_kernel_fit
        self._failure: list = [None]           # an exception raised in a Python callback
        self._derivatives: tuple | None = None  # (fu, d2, d3) of set_rhs_derivatives
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
        self._raise_jit(rc)
        message = _python_calls(_L.dmi_last_error(self._handle).decode())
        if rc == _lib.ECALLBACK and "callback returned 2 " in message and \
                self._jit_slots():
            message += _JIT_SHAPE
        raise from_code(rc, message)

    def _jit_slots(self) -> list[str]:
        """The slots a jit=True callback fills now, in order of name."""
        return sorted(k for k, b in self._keep.items() if b.jit)

    def _raise_jit(self, rc: int) -> None:
        """Raises the exception of a jit=True callback whose compiled code failed (rc
        DMI_ECALLBACK): the Python function's own, called again where the compiled one failed."""
        if rc == _lib.ECALLBACK and (slots := self._jit_slots()):
            from . import _jit
            exc = _jit.raised([self._keep[k] for k in slots])
            if exc is not None:
                raise exc

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
        self._watch()

    def _watch(self) -> None:
        """The jit=True callbacks whose closures and globals the steps watch: f and the
        resolvent, which the steps call (the kernel and the history are called by init only),
        while they read variables and have not warned (a warned callback is left alone until the
        next set_* or init); _same() says whether their variables all hold the objects of their
        snapshots."""
        watched = tuple(b for k in ("rhs", "resolvent")
                        if (b := self._keep.get(k)) is not None and b.jit and b.watching)
        self._watched = watched
        if len(watched) == 2:
            first, second = watched[0].same, watched[1].same
            self._same = lambda: first() and second()
        else:
            self._same = watched[0].same if watched else _unwatched

    def _rebound(self, stacklevel: int) -> None:
        """Warns of a closure variable or global of a jit=True f or resolvent rebound since its
        values were written (the compiled code does not see it, the Python function would).
        Called when _same() is False (one identity check per variable: the steps' cost)."""
        for b in self._watched:
            if (message := b.rebound()) is not None:
                warnings.warn(message, UserWarning, stacklevel=stacklevel + 1)
        self._watch()

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
        """Sets the right-hand side f (``dmi_set_rhs``).  Takes effect from the next step; may be
        called at any time.

        Parameters
        ----------
        f : callable, C function or None
            ``f(t, u) -> array (n)`` (t in time units, u in state units), or a C function
            ``int f(double t, const double *u, double *out, void *user)``
            (``dmi.RHS_SIGNATURE``).  None restores f = 0.
        user : optional
            The C function's user pointer: a NumPy array or ctypes object (its data; the solver
            keeps the object alive), a ctypes pointer or an int address (the memory is yours to
            keep alive); a LowLevelCallable's own user_data when None.  Not for Python functions.
        jit : bool, optional
            True: ``f(t, u)`` is a plain Python function (def or lambda), compiled by numba into
            the C function; numbers and NumPy arrays of its closure are passed at each call
            (docs/python.md, "jit=True"); the same holds for the other ``set_*`` callbacks.

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: f is neither callable nor a C function, a C function or
            LowLevelCallable without libdmi's signature, ``user`` without a function, with a
            Python function or of an unusable type; with ``jit=True``: numba missing, a
            function numba cannot compile, a closure value that is not a number or float64
            array, or a ``user``.
        """
        self._set_callback("rhs", cb.RHS, _L.dmi_set_rhs, f, user, jit)
        self._derivatives = None   # those of the former f: set them again for this one

    def set_rhs_derivatives(self, fu: Callable[..., Any] | None,
                            d2: Callable[..., Any] | None = None,
                            d3: Callable[..., Any] | None = None) -> None:
        """Sets the derivatives of f in u, for the analyses that differentiate f
        (:mod:`dmi.analysis`: the Jacobian at an equilibrium, the first Lyapunov coefficient of a
        Hopf point); the scheme does not use them.  Without them those analyses take central
        differences of f (docs/stability.md, "Criticality of a Hopf point").  Call it after
        :meth:`set_rhs`: setting f again forgets them.

        Parameters
        ----------
        fu : callable or None
            ``fu(t, u) -> array (n, n)``: the Jacobian df/du (units of f per state unit).  None
            forgets all three.
        d2 : callable, optional
            ``d2(t, u, v, w) -> array (n)``: the second derivative of f at u in the directions
            v and w, sum_jk d^2 f / du_j du_k v_j w_k.
        d3 : callable, optional
            ``d3(t, u, v, w, z) -> array (n)``: the third derivative in the directions v, w, z.
            Given without d2 it is not used for the Jacobian's directional derivatives; each
            missing one is taken by central differences of the next lower one given (or of f).

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: a derivative that is not callable, d2 or d3 without fu, or no
            f set (:meth:`set_rhs`) to be the derivatives of.

        Notes
        -----
        The functions are Python callables, called with float64 NumPy arrays (t a float); the
        analyses check fu and d2, d3 against central differences of f at the points they use
        them and refuse derivatives that disagree.
        """
        for name, g in (("fu", fu), ("d2", d2), ("d3", d3)):
            if g is not None and not callable(g):
                raise InvalidArgument(_lib.EINVAL, f"set_rhs_derivatives: {name} = {g!r} is not "
                                      "callable (give a function, or None)")
        if fu is None:
            if d2 is not None or d3 is not None:
                raise InvalidArgument(_lib.EINVAL, "set_rhs_derivatives: d2 or d3 without fu; "
                                      "give the Jacobian fu(t, u) too")
            self._derivatives = None
            return
        if not self.has("rhs"):
            raise InvalidArgument(_lib.EINVAL, "set_rhs_derivatives: no right-hand side f is set; "
                                  "call set_rhs(f) first (setting f forgets its derivatives)")
        self._derivatives = (fu, d2, d3)

    @property
    def rhs_derivatives(self) -> tuple[Callable[..., Any], Callable[..., Any] | None,
                                       Callable[..., Any] | None] | None:
        """(fu, d2, d3) of :meth:`set_rhs_derivatives` (d2, d3 None where not given), None where
        none is set."""
        return self._derivatives

    def set_resolvent(self, r: Callback | None, user: Any = None, *, jit: bool = False) -> None:
        """Sets A through its resolvent (``dmi_set_resolvent``).  Replaces an earlier resolvent,
        friction or box; may be called at any time.

        Parameters
        ----------
        r : callable, C function or None
            ``r(lam, x) -> (I + lam A)^{-1} x``, array (n), lam = h (time units); or a C function
            ``int r(double lam, const double *x, double *out, void *user)``
            (``dmi.RESOLVENT_SIGNATURE``).  None restores A = 0.
        user, jit : optional
            The C function's user pointer, and ``jit=True`` to compile the Python function r
            with numba, as for :meth:`set_rhs`.

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: r, ``user`` or ``jit`` refused as in :meth:`set_rhs`.
        """
        self._set_callback("resolvent", cb.RESOLVENT, _L.dmi_set_resolvent, r, user, jit)
        self._resolvent = ("callback",) if r is not None else ()

    def set_friction(self, alpha: Any) -> None:
        """Sets the built-in dry friction A(u)_i = alpha_i sigma(u_i), sigma the sign graph
        (``dmi_set_friction``).  Replaces an earlier resolvent, friction or box.

        Parameters
        ----------
        alpha : array_like, shape (n,)
            The coefficients, finite and >= 0 (alpha_i = 0: no friction on u_i; units of f).

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: alpha is not n numbers, or a value is negative, NaN or infinite.
        """
        a = _array(alpha, (self._n,), "alpha")
        with self._using() as s:
            self._check(_L.dmi_set_friction(s, _ptr(a)))
        self._keep["resolvent"] = cb.Bound(None, None, ())
        self._watch()
        self._resolvent = ("friction", a.copy())

    def set_box(self, lo: Any, hi: Any) -> None:
        """Sets the built-in normal cone of the box prod_i [lo_i, hi_i] (the resolvent is the
        projection, ``dmi_set_box``).  Replaces an earlier resolvent, friction or box.

        Parameters
        ----------
        lo, hi : array_like, shape (n,)
            The bounds (state units), no NaN, lo_i <= hi_i; infinite bounds allowed.

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: lo or hi is not n numbers, has a NaN, lo_i > hi_i,
            lo_i = +inf or hi_i = -inf (an empty box).
        """
        lo_a, hi_a = _array(lo, (self._n,), "lo"), _array(hi, (self._n,), "hi")
        with self._using() as s:
            self._check(_L.dmi_set_box(s, _ptr(lo_a), _ptr(hi_a)))
        self._keep["resolvent"] = cb.Bound(None, None, ())
        self._watch()
        self._resolvent = ("box", lo_a.copy(), hi_a.copy())

    def set_kernel(self, H: Callback | None, user: Any = None, *, jit: bool = False) -> None:
        """Sets the kernel H (``dmi_set_kernel``); replaces one of :meth:`set_kernel_exp`.  Sampled
        by :meth:`init`, so refused after it.

        Parameters
        ----------
        H : callable, C function or None
            ``H(s) -> array (n, n)`` for 0 <= s < tau (time units), or a C function
            ``int H(double s, double *out, void *user)`` writing n*n values row-major
            (``dmi.KERNEL_SIGNATURE``).  None: H = 0.
        user, jit : optional
            The C function's user pointer, and ``jit=True`` to compile the Python function H
            with numba, as for :meth:`set_rhs`.

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: H, ``user`` or ``jit`` refused as in :meth:`set_rhs`; code
            ``dmi.ESTATE``: after :meth:`init`.
        """
        self._set_callback("kernel", cb.KERNEL, _L.dmi_set_kernel, H, user, jit)
        self._fit = None

    def set_kernel_exp(self, a: Any, b: Any, C: Any, D: Any = None) -> None:
        """Sets the kernel as K exponential terms
        H(s) = sum_k exp(a_k s) (C_k cos(b_k s) + D_k sin(b_k s)) (``dmi_set_kernel_exp``);
        replaces one of :meth:`set_kernel`.  Refused after :meth:`init`.

        Parameters
        ----------
        a, b : array_like, shape (K,)
            Rates (a decay if negative) and angular frequencies, K >= 1, finite (1 / time unit).
        C, D : array_like, shape (K, n, n)
            The matrices of the cosines and the sines, finite (units of H); D None: zero.

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: a is not of shape (K,) with K >= 1, b, C or D of another shape,
            or a NaN or infinite value; code ``dmi.ESTATE``: after :meth:`init`.
        dmi.Error
            Code ``dmi.ENOMEM``: the terms cannot be stored.
        """
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
        self._fit = None

    def set_history(self, z: Callback | None, user: Any = None, *, jit: bool = False) -> None:
        """Sets the history z, u = z on [-tau, 0] (``dmi_set_history``).  Sampled by :meth:`init`,
        so refused after it.

        Parameters
        ----------
        z : callable, C function or None
            ``z(t) -> array (n)`` (state units) for -tau <= t <= 0 (time units), or a C function
            ``int z(double t, double *out, void *user)`` (``dmi.HISTORY_SIGNATURE``).  None: z = 0.
        user, jit : optional
            The C function's user pointer, and ``jit=True`` to compile the Python function z
            with numba, as for :meth:`set_rhs`.

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: z, ``user`` or ``jit`` refused as in :meth:`set_rhs`; code
            ``dmi.ESTATE``: after :meth:`init`.
        """
        self._set_callback("history", cb.HISTORY, _L.dmi_set_history, z, user, jit)

    def set_convolution(self, method: str) -> None:
        """Sets the method of the delay sum (``dmi_set_convolution``).  Any time, also between
        steps; the methods differ by rounding only.

        Parameters
        ----------
        method : str
            ``"auto"`` (default), ``"direct"``, ``"fft"`` or ``"recursive"`` (exponential kernels
            of :meth:`set_kernel_exp`, see ``dmi_set_convolution``).

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: another method; ``"recursive"`` for a callback kernel, a growing
            term (a_k > 0) or one with |b_k| h > pi; ``"fft"`` in a libdmi built without the FFT.
        dmi.Error
            Code ``dmi.ENOMEM`` (the FFT engine cannot be allocated after :meth:`init`) or
            ``dmi.ENONFINITE`` (a kernel sample, when leaving the recursion after :meth:`init`);
            the former method stays.
        """
        code = _choice(_lib.CONV, method, "set_convolution: method")
        with self._using() as s:
            self._check(_L.dmi_set_convolution(s, code))
        self._choices["convolution"] = method

    # ---- time stepping -------------------------------------------------------------------------

    def init(self) -> None:
        """Samples the kernel and the history and sets t = 0 (p = 0, ``dmi_init``); again: restarts
        from t = 0.

        A ``jit=True`` callback computes with its closure's and globals' values as they are now
        (docs/python.md, "jit=True").

        Warns
        -----
        UserWarning
            The exponent of :meth:`set_quadrature` ``(..., singularity=)`` is larger than the
            kernel's near 0 (the weights are right; the warning names the exponent measured).

        Raises
        ------
        Exception
            The exception a Python kernel or history callback raised, as it is.
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: a value a ``jit=True`` callback reads changed its type since its
            ``set_*`` call (set it again);
            code ``dmi.ECALLBACK``: a Python callback returned a result of another shape or type;
            code ``dmi.EINVAL``: under the cell rule, a kernel it cannot integrate or that grows
            faster near 0 than the exponent of :meth:`set_quadrature` ``(..., singularity=)``
            (the message names that call and the exponent measured); near cells of
            :meth:`set_kernel_near` without a kernel of
            :meth:`set_kernel_exp` or with ceil(delta / h) + 1 > N, or ``"recursive"`` for a
            kernel it refuses (see :meth:`set_convolution`).
        dmi.Error
            Code ``dmi.ECALLBACK`` (a C callback returned nonzero), ``dmi.ENONFINITE`` (a NaN or
            infinite sample) or ``dmi.ENOMEM``.  The solver is then unchanged.
        """
        with self._using() as s:
            if slots := self._jit_slots():   # (the values jit=True callbacks read: as they are now)
                from . import _jit
                for slot in slots:
                    _jit.refresh(self._keep[slot], "init")
                self._watch()
            before = _L.dmi_last_error(s)
            self._check(_L.dmi_init(s))
            note = _L.dmi_last_error(s)
        if note != before and note.startswith(b"dmi_init: note: "):
            # (a declared singularity exponent larger than the kernel's: the weights are right)
            warnings.warn(_python_calls(note.decode()[len("dmi_init: note: "):]), UserWarning,
                          stacklevel=2)

    def step(self) -> None:
        """One step t_p -> t_{p+1} (``dmi_step``).  On failure the solver is bitwise where it was,
        and a retry gives a clean run's result.

        Raises
        ------
        Exception
            The exception a Python callback (f, the resolvent) raised, as it is.
        dmi.InvalidArgument
            Code ``dmi.ESTATE``: before :meth:`init`; code ``dmi.ECALLBACK``: a Python callback
            returned a result of another shape or type.
        dmi.Error
            Code ``dmi.ECALLBACK``: a C callback returned nonzero; code ``dmi.ENONFINITE``:
            f, the delay sum W^p, the resolvent's argument X^p or U^{p+1} has a NaN or infinity.
        """
        if self._watched and not self._same():
            self._rebound(2)
        with self._using() as s:
            self._check(_L.dmi_step(s))

    def advance(self, steps: int) -> None:
        """Takes ``steps`` steps in C (``dmi_advance``).  Stops at the first failing step (the
        steps before it are kept, :attr:`step_index` tells how many) and raises its error.

        Parameters
        ----------
        steps : int
            Number of steps, >= 0.

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: steps is not an integer >= 0; otherwise as :meth:`step`.
        dmi.Error
            As :meth:`step`.
        """
        steps = _count(steps, "steps", 0)
        if self._watched and not self._same():
            self._rebound(2)
        with self._using() as s:
            self._check(_L.dmi_advance(s, steps))

    def run(self, steps: int, stride: int = 1) -> tuple[np.ndarray, np.ndarray]:
        """Takes ``steps`` steps in C, recording the states at p0, p0 + stride, ...,
        p0 + k stride <= p0 + steps, and at p0 + steps (the last row), p0 the step index at the
        call.

        Parameters
        ----------
        steps : int
            Number of steps, >= 0.
        stride : int, optional
            Steps between recorded rows, >= 1.

        Returns
        -------
        t : numpy.ndarray, shape (rows,)
            The times (time units).
        U : numpy.ndarray, shape (rows, n)
            The states there (state units).

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: steps or stride is not an integer >= 0 or >= 1; otherwise as
            :meth:`step`.
        dmi.Error
            As :meth:`step`.  On a failing step the steps before it are kept, and the exception
            (of any type) has the rows recorded until then as ``partial = (t, U)``.
        """
        t, U, _ = self._run(steps, stride, False)
        return t, U

    def run_terms(self, steps: int, stride: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`run` that also records the resolvent's argument, still in one call to C.

        Parameters
        ----------
        steps, stride : int
            As for :meth:`run`.

        Returns
        -------
        t : numpy.ndarray, shape (rows,)
            The times (time units).
        U : numpy.ndarray, shape (rows, n)
            The states there (state units).
        X : numpy.ndarray, shape (rows - 1, n)
            X[k] the argument X^{q-1} of the step into U[k + 1] (at step q; :meth:`step_terms`
            after that step; state units).

        Raises
        ------
        dmi.InvalidArgument
            As :meth:`run`.
        dmi.Error
            As :meth:`run`.
        """
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
        if self._watched and not self._same():
            self._rebound(3)
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
        """The step counter p (steps since :meth:`init`); :class:`dmi.InvalidArgument` (code
        ``dmi.ESTATE``) before it."""
        p = ctypes.c_uint64()
        with self._using() as s:
            self._check(_L.dmi_get_step_index(s, ctypes.byref(p)))
        return p.value

    @property
    def state(self) -> np.ndarray:
        """U^p, a new array (n,) (state units); :class:`dmi.InvalidArgument` (code ``dmi.ESTATE``)
        before :meth:`init`."""
        u = np.empty(self._n)
        with self._using() as s:
            self._check(_L.dmi_get_state(s, _ptr(u)))
        return u

    def past(self, lag: int) -> np.ndarray:
        """A stored state (``dmi_get_past``).

        Parameters
        ----------
        lag : int
            0 <= lag <= N steps back.

        Returns
        -------
        numpy.ndarray, shape (n,)
            U^{p - lag}, a new array (history values for p - lag <= 0; state units).

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: lag is not an integer in [0, N]; code ``dmi.ESTATE``: before
            :meth:`init`.
        """
        lag = _count(lag, "lag", 0)
        if lag > self._N:
            raise InvalidArgument(_lib.EINVAL, f"past: lag = {lag} > N = {self._N}")
        u = np.empty(self._n)
        with self._using() as s:
            self._check(_L.dmi_get_past(s, lag, _ptr(u)))
        return u

    def get_window(self) -> np.ndarray:
        """The window of stored states (``dmi_get_window``, since libdmi 1.2): with the step
        counter, the whole state of the scheme's step map.

        Returns
        -------
        numpy.ndarray, shape (N + 1, n)
            U^{p-N}, ..., U^p, oldest first, a new array (state units).

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.ESTATE``: before :meth:`init`.
        """
        U = np.empty((self._N + 1, self._n))
        with self._using() as s:
            self._check(_L.dmi_get_window(s, _ptr(U)))
        return U

    def set_window(self, U: Any) -> None:
        """Replaces the stored states, keeping the step counter (``dmi_set_window``, since libdmi
        1.2); the delay sum's engine is recomputed from them.

        Parameters
        ----------
        U : array_like, shape (N + 1, n)
            The new window, oldest first (row N is the new U^p; state units), finite.

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: U has another shape or a NaN or infinite value (the solver is
            unchanged); code ``dmi.ESTATE``: before :meth:`init`.
        """
        a = _array(U, (self._N + 1, self._n), "U")
        with self._using() as s:
            self._check(_L.dmi_set_window(s, _ptr(a)))

    def step_terms(self) -> tuple[np.ndarray, np.ndarray]:
        """Terms of the last step, t_{p-1} -> t_p (``dmi_get_step_terms``).

        Returns
        -------
        W : numpy.ndarray, shape (n,)
            W^{p-1}, the delay sum.
        X : numpy.ndarray, shape (n,)
            X^{p-1}, the resolvent's argument (state units); (X - U^p) / h is the element of
            A(U^p) selected, the friction force for friction.

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.ESTATE``: before :meth:`init` or before the first step.
        """
        W, X = np.empty(self._n), np.empty(self._n)
        with self._using() as s:
            self._check(_L.dmi_get_step_terms(s, _ptr(W), _ptr(X)))
        return W, X

    def kernel_weights(self) -> tuple[np.ndarray, np.ndarray]:
        """The weights of the delay sum as the steps use them (``dmi_get_kernel_weights``, since
        libdmi 1.5): W^p = sum_l G[l] @ U^{p-l}, l = 0..N-1.

        Returns
        -------
        G : numpy.ndarray, shape (N, n, n)
            G[l], the weight of U^{p-l} (kernel units times time units): h H(l h) under the left
            rule, the integral of H over cell l under the cell rule, the near kernel's integral
            over a near cell (:meth:`set_kernel_near`, :meth:`set_kernel_fit` with delta > 0).
        G_near : numpy.ndarray, shape (N, n, n)
            The part of G[l] the near cells add to the exponential sum's weights (zero beyond
            the near cells and without them).

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.ESTATE``: before :meth:`init` (the weights are computed there).
        """
        n, N = self._n, self._N
        G, G_near = np.empty((N, n, n)), np.empty((N, n, n))
        with self._using() as s:
            self._check(_L.dmi_get_kernel_weights(s, 0, N, _ptr(G), _ptr(G_near)))
        return G, G_near

    # ---- saving and restoring ------------------------------------------------------------------

    def save_state(self) -> bytes:
        """Saves the time-stepping state (``dmi_state_save``).

        Returns
        -------
        bytes
            The step counter, the N + 1 stored states, the last terms and an exponential kernel's
            sums; not the callbacks, resolvent, method or kernel.

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.ESTATE``: before :meth:`init`.
        """
        with self._using() as s:
            size = _L.dmi_state_size(s)
            buf = ctypes.create_string_buffer(size)
            self._check(_L.dmi_state_save(s, buf, size))
        return buf.raw

    def load_state(self, data: bytes) -> None:
        """Restores a state of :meth:`save_state` (``dmi_state_load``); needs :meth:`init` first.
        Stepping on is bitwise the saving solver's.

        Parameters
        ----------
        data : bytes-like
            Bytes of :meth:`save_state` from a solver with the same n, N, tau, h (and exponential
            kernel).

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: data is not bytes-like, or bad bytes (another size, solver or
            format; the solver is unchanged); code ``dmi.ESTATE``: before :meth:`init`.
        dmi.Error
            Code ``dmi.ENOMEM``.
        """
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
            self._watched = ()

    def __enter__(self) -> Solver:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self, _free: Any = _L.dmi_free, _byref: Any = ctypes.byref) -> None:
        # dmi_free and byref bound at definition: during interpreter shutdown the module's globals
        # (_L, ctypes) may already be None when a solver left alive is collected
        if getattr(self, "_handle", None) is not None:
            _free(_byref(self._handle))
            self._handle = None

    def set_quadrature(self, rule: str, singularity: float | None = None) -> None:
        """Sets the quadrature rule of the delay integral, before :meth:`init`
        (``dmi_set_quadrature``).  Every convolution method computes the same sum.

        Parameters
        ----------
        rule : str
            ``"left"`` (default) the paper's rectangle rule h H(l h) per cell; ``"cell"`` exact
            cell weights, the integral of H over each cell (closed form for
            :meth:`set_kernel_exp`, tanh-sinh quadrature for a callback, which is then called
            inside the cells, never at s = 0: kernels singular at 0 such as s^-1/2 run).
        singularity : float, optional
            The exponent alpha, 0 <= alpha < 1, of the kernel's singularity H ~ s^-alpha g(s) at
            0 (of a callback kernel's first cell, and of the near kernel of
            :meth:`set_kernel_near`); None (default): estimated from H close to 0
            (``dmi_set_kernel_singularity``).

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: another rule, ``"left"`` with near cells
            (:meth:`set_kernel_near`), or ``singularity`` outside [0, 1); code ``dmi.ESTATE``:
            after :meth:`init` (the message names this call and says to call it before
            :meth:`init`).  :meth:`init` checks ``singularity`` against the kernel near 0: a
            kernel that grows faster than s^-singularity is refused there (``dmi.EINVAL``, the
            message naming this call and the exponent measured); a ``singularity`` larger than the
            kernel's gives a ``UserWarning`` (the weights are right).
        """
        code = _choice(_lib.QUAD, rule, "set_quadrature: rule")
        if rule == "left" and self._near_delta > 0:
            raise InvalidArgument(_lib.EINVAL, "set_quadrature('left'): the near cells of "
                                  "set_kernel_fit or set_kernel_near need the cell rule (remove "
                                  "them first: set_kernel_near(None, 0))")
        alpha = math.nan if singularity is None else float(singularity)
        call = f"set_quadrature({rule!r}" + ("" if singularity is None else
                                             f", singularity={singularity!r}") + ")"
        with self._using() as s:
            # the exponent first: a refused one leaves the rule as it was
            rc = _L.dmi_set_kernel_singularity(s, alpha)
            if rc == _lib.OK:
                rc = _L.dmi_set_quadrature(s, code)
            if rc == _lib.ESTATE:
                raise InvalidArgument(rc, f"{call}: the kernel's weights are computed by init() "
                                      "and cannot change afterwards: call set_quadrature before "
                                      "init() (or make a new Solver)")
            if rc != _lib.OK:   # (an exponent outside [0, 1): libdmi's reason, in Python's words)
                why = _L.dmi_last_error(s).decode().split(": ", 1)[-1]
                raise from_code(rc, f"{call}: " + why.replace("alpha = ", "singularity = ", 1)
                                .replace("or NAN to", "or None to"))
        self._choices["quadrature"] = rule

    def set_kernel_near(self, H: Callback | None, delta: float, user: Any = None) -> None:
        """Sets the exact kernel of the cells below ``delta``, whose weights become H's exact cell
        integrals, while the kernel of :meth:`set_kernel_exp` (a fit on [delta, tau]) gives the
        other cells: a kernel singular at 0 in O(1) per step (``dmi_set_kernel_near``).  Before
        :meth:`init`, which checks the combination.  Near cells need the cell rule
        (:meth:`set_quadrature` ``("cell")``): under the left rule the quadrature is switched to
        the cell rule, with a ``UserWarning`` that says so.

        Parameters
        ----------
        H : callable, C function or None
            ``H(s) -> array (n, n)`` (or a C kernel function, as for :meth:`set_kernel`), called
            for 0 < s <= ceil(delta / h) h.  None removes the near cells.
        delta : float
            Length of the near part, finite and >= 0 (time units); 0: no near cells.
        user : optional
            The C function's user pointer, as for :meth:`set_rhs`.

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: delta negative or not finite, H or ``user`` refused as in
            :meth:`set_rhs`; code ``dmi.ESTATE``: after :meth:`init`.
        TypeError, ValueError
            delta is not a number.
        """
        def setter(s: Any, address: Any, u: Any) -> int:
            return _L.dmi_set_kernel_near(s, address, u, float(delta))
        self._set_callback("kernel_near", cb.KERNEL, setter, H, user, False)
        self._near_delta = float(delta) if H is not None else 0.0
        self._fit = None        # the kernel is no longer the fit's alone (set_kernel_fit resets it)
        if self._near_delta > 0 and self._choices["quadrature"] == "left":
            # the left rule would sample the fit at l h while the near cells are exact integrals;
            # the rule alone is switched: an exponent given by set_quadrature(singularity=) stays
            with self._using() as s:
                self._check(_L.dmi_set_quadrature(s, _choice(_lib.QUAD, "cell", "set_quadrature")))
            self._choices["quadrature"] = "cell"
            warnings.warn("near cells (delta > 0, of set_kernel_fit or set_kernel_near) need the "
                          "cell rule; the quadrature is now the cell rule (call "
                          "set_quadrature('cell') first to make this explicit)", UserWarning,
                          stacklevel=2)

    def set_kernel_fit(self, fit: Any, entry: tuple[int, int] | None = None, near: Callback | None = None,
                       ) -> None:
        """Sets the kernel of a :class:`dmi.kernels.KernelFit` (:meth:`set_kernel_exp`, and
        :meth:`set_kernel_near` for its near cells).  Use :meth:`set_quadrature` ``("cell")``
        with a fit of ``delta > 0``.  Before :meth:`init`.

        Parameters
        ----------
        fit : dmi.kernels.KernelFit
            An n x n fit fills the whole kernel; a scalar fit goes to ``entry``, or fills the
            kernel of an n = 1 solver.
        entry : tuple of int, optional
            ``(i, j)``: the entry of a scalar fit (the other entries zero).
        near : callable or C function, optional
            For a fit with ``delta > 0`` (a kernel singular at 0): the exact scalar or n x n
            kernel of the near cells (default: the fit's own ``kernel`` when it carries one, a
            :class:`dmi.kernels.PowerKernel`).

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: fit not a KernelFit (None included: to remove the kernel,
            :meth:`set_kernel` ``(None)`` and :meth:`set_kernel_near` ``(None, 0)``), a matrix fit
            of another size or with ``entry``, a scalar fit without ``entry`` for n > 1 or with an
            entry outside n x n, a fit with ``delta > 0`` and no exact kernel, or as
            :meth:`set_kernel_exp` and :meth:`set_kernel_near`; code ``dmi.ESTATE``: after
            :meth:`init`.  From :meth:`init`: code ``dmi.ECALLBACK`` when the near kernel of a
            scalar fit does not return a scalar.
        """
        if not all(hasattr(fit, k) for k in ("a", "b", "C", "D", "delta")):
            raise InvalidArgument(_lib.EINVAL, f"set_kernel_fit: fit is {type(fit).__name__}; "
                                  "expected a dmi.kernels.KernelFit (to remove the kernel: "
                                  "set_kernel(None) and set_kernel_near(None, 0))")
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
        # the near cells first: a kernel they refuse leaves the solver's kernel as it was
        if fit.delta > 0:
            c_kernel = isinstance(exact, ctypes._CFuncPtr) or hasattr(exact, "address")
            if i is not None and c_kernel and n > 1:
                raise InvalidArgument(_lib.EINVAL, "set_kernel_fit: a scalar fit's near kernel "
                                      "for entry (i, j) of an n > 1 solver must be a Python "
                                      "function (a C kernel writes all n x n values)")
            if i is not None and callable(exact) and not c_kernel:
                scalar = exact   # a Python scalar kernel: as an n x n one

                def exact(s: float, _i: int = i, _j: int = j) -> np.ndarray:
                    v = np.asarray(scalar(s))
                    if v.size != 1:
                        raise InvalidArgument(_lib.ECALLBACK, "set_kernel_fit: the near kernel of "
                                              f"a scalar fit must return a scalar; at s = {s!r} it "
                                              f"returned shape {v.shape} (an n x n near kernel "
                                              "goes with an n x n fit)")
                    out = np.zeros((n, n))
                    out[_i, _j] = v.item()
                    return out
            self.set_kernel_near(exact, fit.delta)
        else:
            self.set_kernel_near(None, 0.0)
        self.set_kernel_exp(fit.a, fit.b, C, D)
        self._fit = (fit, None if i is None else (i, j))

    # ---- the model as set (what dmi.analysis and dmi.identify read) -------------------------------

    @property
    def resolvent_kind(self) -> str:
        """What A is: ``""`` (A = 0), ``"friction"`` (:meth:`set_friction`), ``"box"``
        (:meth:`set_box`) or ``"callback"`` (:meth:`set_resolvent`)."""
        return self._resolvent[0] if self._resolvent else ""

    @property
    def friction(self) -> np.ndarray | None:
        """The coefficients alpha (n,) of :meth:`set_friction` (a copy), None for another A."""
        return self._resolvent[1].copy() if self.resolvent_kind == "friction" else None

    @property
    def box(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The bounds (lo, hi), each (n,), of :meth:`set_box` (copies), None for another A."""
        if self.resolvent_kind != "box":
            return None
        return self._resolvent[1].copy(), self._resolvent[2].copy()

    @property
    def kernel_kind(self) -> str:
        """What H is: ``""`` (H = 0), ``"exp"`` (:meth:`set_kernel_exp`, :meth:`set_kernel_fit`)
        or ``"callback"`` (:meth:`set_kernel`)."""
        bound = self._keep.get("kernel")
        if bound is None or (bound.address is None and not bound.keep):
            return ""
        return "exp" if bound.address is None else "callback"

    @property
    def kernel_terms(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
        """The terms (a (K,), b (K,), C (K, n, n), D (K, n, n)) of an exponential kernel (copies;
        D zero when not given), None for another kernel."""
        if self.kernel_kind != "exp":
            return None
        a, b, C, D = self._keep["kernel"].keep
        return a.copy(), b.copy(), C.copy(), (np.zeros_like(C) if D is None else D.copy())

    @property
    def kernel_near_delta(self) -> float:
        """delta of :meth:`set_kernel_near` (time units); 0.0 without near cells."""
        return self._near_delta

    @property
    def kernel_fit(self) -> tuple[Any, tuple[int, int] | None] | None:
        """(fit, entry) of :meth:`set_kernel_fit` (the :class:`dmi.kernels.KernelFit` as given,
        entry (i, j) of a scalar fit, None for an n x n fit), None when the kernel was set otherwise."""
        return self._fit

    @property
    def convolution(self) -> str:
        """The method asked of :meth:`set_convolution` (``"auto"`` unless set)."""
        return self._choices["convolution"]

    @property
    def quadrature(self) -> str:
        """The rule of :meth:`set_quadrature` (``"left"`` unless set)."""
        return self._choices["quadrature"]

    def has(self, part: str) -> bool:
        """Whether the model has a part other than its default (zero).

        Parameters
        ----------
        part : str
            ``"rhs"``, ``"resolvent"`` (any A), ``"kernel"``, ``"kernel_near"`` or ``"history"``.

        Returns
        -------
        bool
            False where that part is the default, zero.

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: another part.
        """
        if part == "resolvent":
            return self.resolvent_kind != ""
        if part == "kernel":
            return self.kernel_kind != ""
        if part not in ("rhs", "kernel_near", "history"):
            raise InvalidArgument(_lib.EINVAL, f"has: part {part!r} is not one of 'rhs', "
                                  "'resolvent', 'kernel', 'kernel_near', 'history'")
        bound = self._keep.get(part)
        return bound is not None and bound.address is not None

    def _call_slot(self, slot: str, fn_type: Any, args: tuple, size: int,
                   what: Callable[[], str]) -> np.ndarray:
        """Calls the C-level function of ``slot`` (libdmi's signature) with args and an output of
        ``size`` doubles, failing as :meth:`_call_failed` says."""
        out = np.zeros(size)
        bound = self._keep[slot]
        rc = fn_type(bound.address)(*args, out.ctypes.data, bound.user)
        if rc != 0 or self._failure[0] is not None:
            self._call_failed(rc, bound, what)
        return out

    def _call_failed(self, rc: int, bound: cb.Bound, what: Callable[[], str]) -> None:
        """Raises for a call of a callback outside libdmi that returned rc: a Python callback's
        exception as it is, with a note; a jit=True callback's, its Python function's own; else
        an Error (code ECALLBACK), which says what 2 means for the jit=True callback ``bound``.
        ``what()`` names the call (built only on failure: a repr of u costs more than a call)."""
        failure, self._failure[0] = self._failure[0], None
        if failure is not None:
            failure.add_note(f"raised by the model's {what()}")
            raise failure
        self._raise_jit(_lib.ECALLBACK if rc != 0 else rc)
        if rc != 0:
            raise Error(_lib.ECALLBACK, f"the model's {what()} returned {rc}"
                        + (_JIT_SHAPE if rc == 2 and bound.jit else ""))

    def eval_rhs(self, t: float, u: Any) -> np.ndarray:
        """f(t, u) of :meth:`set_rhs` (zero without one), through the same function the
        scheme calls (Python, ``jit=True`` or C).

        Parameters
        ----------
        t : float
            Time (time units).
        u : array_like, shape (n,)
            State (state units).

        Returns
        -------
        numpy.ndarray, shape (n,)
            f(t, u).

        Raises
        ------
        Exception
            A Python callback's own exception; :class:`dmi.Error` (code ``dmi.ECALLBACK``) for a
            nonzero return.  Non-finite values are returned as they are.
        """
        x = np.ascontiguousarray(np.asarray(u, dtype=float).reshape(self._n))
        if not self.has("rhs"):
            return np.zeros(self._n)
        return self._call_slot("rhs", _lib.RhsFn, (float(t), x.ctypes.data), self._n,
                               lambda: f"rhs at t = {float(t)!r}, u = {x!r}")

    def eval_resolvent(self, lam: float, x: Any) -> np.ndarray:
        """(I + lam A)^-1 x (n,): the built-in friction (soft threshold by lam alpha), box (a
        clip), a callback of :meth:`set_resolvent`, or x itself for A = 0.

        Parameters
        ----------
        lam : float
            lam = h in the scheme (time units).
        x : array_like, shape (n,)
            The resolvent's argument (state units).

        Returns
        -------
        numpy.ndarray, shape (n,)
            (I + lam A)^-1 x.

        Raises
        ------
        Exception
            As :meth:`eval_rhs`.
        """
        x = np.ascontiguousarray(np.asarray(x, dtype=float).reshape(self._n))
        kind = self.resolvent_kind
        if kind == "friction":
            lam_a = float(lam) * self._resolvent[1]
            return np.sign(x) * np.maximum(np.abs(x) - lam_a, 0.0)
        if kind == "box":
            return np.clip(x, self._resolvent[1], self._resolvent[2])
        if kind == "callback":
            return self._call_slot("resolvent", _lib.ResolventFn, (float(lam), x.ctypes.data),
                                   self._n, lambda: f"resolvent at lam = {float(lam)!r}, x = {x!r}")
        return x.copy()

    def eval_kernel(self, s: float) -> np.ndarray:
        """H(s) (n, n): the exponential sum or the callback of the kernel (zero without one);
        the near kernel of :meth:`set_kernel_near` is :meth:`eval_kernel_near`.

        Parameters
        ----------
        s : float
            Lag (time units).

        Returns
        -------
        numpy.ndarray, shape (n, n)
            H(s).

        Raises
        ------
        Exception
            As :meth:`eval_rhs`.
        """
        n = self._n
        kind = self.kernel_kind
        if kind == "exp":
            a, b, C, D = self.kernel_terms  # type: ignore[misc]
            s = float(s)
            e = np.exp(a * s)
            return np.tensordot(e * np.cos(b * s), C, axes=1) + np.tensordot(e * np.sin(b * s), D,
                                                                              axes=1)
        if kind == "callback":
            return self._call_slot("kernel", _lib.KernelFn, (float(s),), n * n,
                                   lambda: f"kernel at s = {float(s)!r}").reshape(n, n)
        return np.zeros((n, n))

    def eval_kernel_near(self, s: float) -> np.ndarray:
        """The near kernel of :meth:`set_kernel_near` at s (zero without one).

        Parameters
        ----------
        s : float
            Lag (time units).

        Returns
        -------
        numpy.ndarray, shape (n, n)
            The near kernel at s.

        Raises
        ------
        Exception
            As :meth:`eval_rhs`.
        """
        n = self._n
        if not self.has("kernel_near"):
            return np.zeros((n, n))
        return self._call_slot("kernel_near", _lib.KernelFn, (float(s),), n * n,
                               lambda: f"near kernel at s = {float(s)!r}").reshape(n, n)

    def eval_history(self, t: float) -> np.ndarray:
        """z(t) of :meth:`set_history` (zero without one).

        Parameters
        ----------
        t : float
            Time, -tau <= t <= 0 (time units).

        Returns
        -------
        numpy.ndarray, shape (n,)
            z(t).

        Raises
        ------
        Exception
            As :meth:`eval_rhs`.
        """
        if not self.has("history"):
            return np.zeros(self._n)
        return self._call_slot("history", _lib.HistoryFn, (float(t),), self._n,
                               lambda: f"history at t = {float(t)!r}")

    def eval_rhs_many(self, t: Any, U: Any) -> np.ndarray:
        """f(t_c, U_c) of :meth:`set_rhs` at many points (zero without one), through the same
        function the scheme calls, without :meth:`eval_rhs`'s per-call bookkeeping (a failing
        call is named by its point).

        Parameters
        ----------
        t : array_like, shape (P,)
            Times (time units).
        U : array_like, shape (P, n)
            States (state units).

        Returns
        -------
        numpy.ndarray, shape (P, n)
            f(t_c, U_c), row c.

        Raises
        ------
        ValueError
            t and U of other shapes.
        Exception
            As :meth:`eval_rhs`.
        """
        n = self._n
        tt = np.ascontiguousarray(np.asarray(t, dtype=float).ravel())
        X = np.ascontiguousarray(np.asarray(U, dtype=float))
        if X.shape != (tt.size, n):
            raise ValueError(f"eval_rhs_many: U has shape {X.shape}; expected ({tt.size}, {n}) "
                             "(one state a time)")
        out = np.zeros((tt.size, n))
        if not self.has("rhs") or tt.size == 0:
            return out
        bound = self._keep["rhs"]
        fn = _lib.RhsFn(bound.address)
        x0, o0 = X.ctypes.data, out.ctypes.data
        step = 8 * n
        for c in range(tt.size):
            rc = fn(float(tt[c]), x0 + c * step, o0 + c * step, bound.user)
            if rc != 0 or self._failure[0] is not None:
                self._call_failed(rc, bound, lambda: f"rhs at t = {float(tt[c])!r}, u = {X[c]!r}")
        return out

    def _tangent(self, others: list[Solver], delta: np.ndarray, steps: int,
                 S0: np.ndarray | list | None, dWU: np.ndarray | None, depends: np.ndarray | None,
                 jumps: bool, terms: tuple | None = None
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Steps this (initialised) solver ``steps`` times with the sensitivities of its states in
        P parameters through libdmi's tangent (``dmi_tangent_run``): ``others`` the models at
        p + delta_j e_j, ``S0`` the window's sensitivity ((N + 1, n, P), None: zero; a list of
        parameters: sampled from those models' history callbacks by libdmi), ``dWU`` the
        kernel parameters' part of the delay sum ((steps, n, P), None: zero), ``depends`` which
        parameters f depends on (P booleans, None: libdmi's rule), ``jumps`` the saltation factor
        at reversals, ``terms`` the exponential kernel's terms' derivatives (da, db, dC, dD) as
        ``dmi_tangent_set_kernel_terms`` takes them (None: none).  Returns U (steps + 1, n), X (steps, n), S (steps + 1, n, P), dX
        (steps, n, P) and the switches (steps, n) as DMI_SWITCH_* codes (for dmi.identify).

        Raises dmi.Error with libdmi's message (the solver then is where it was); a Python
        callback's own exception, of this solver or of another, is dropped: the caller runs its
        own loop to raise it."""
        n, P = self._n, len(others)
        c = np.ascontiguousarray
        delta = c(delta, dtype=float)
        U, X = np.empty((steps + 1, n)), np.empty((steps, n))
        S, dX = np.empty((steps + 1, n, P)), np.empty((steps, n, P))
        switches = np.zeros((steps, n), np.int8)
        columns = None
        if isinstance(S0, list):
            columns = (ctypes.c_int * P)(*[int(j in S0) for j in range(P)])
            S0 = None
        S0 = None if S0 is None else c(S0, dtype=float)
        dWU = None if dWU is None else c(dWU, dtype=float)
        for m in (self, *others):
            if m._watched and not m._same():
                m._rebound(3)
        handles = (ctypes.c_void_p * P)(*[o._handle for o in others])
        tangent = ctypes.c_void_p()
        try:
            with self._using() as s:
                rc = _L.dmi_tangent_create(ctypes.byref(tangent), s, P, handles, _ptr(delta))
                if rc == _lib.OK and S0 is not None:
                    rc = _L.dmi_tangent_set_history(tangent, _ptr(S0))
                if rc == _lib.OK and columns is not None:
                    rc = _L.dmi_tangent_sample_history(tangent, columns)
                if rc == _lib.OK and terms is not None:
                    arrays = [c(a, dtype=float) for a in terms]
                    rc = _L.dmi_tangent_set_kernel_terms(tangent, *[_ptr(a) for a in arrays])
                if rc == _lib.OK and depends is not None:
                    flags = (ctypes.c_int * P)(*[int(bool(d)) for d in depends])
                    rc = _L.dmi_tangent_set_rhs_parameters(tangent, flags)
                if rc == _lib.OK:
                    rc = _L.dmi_tangent_run(tangent, steps, 0 if jumps else 1, _ptr(dWU), _ptr(U),
                                            _ptr(X), _ptr(S), _ptr(dX),
                                            switches.ctypes.data_as(ctypes.c_void_p))
                if rc != _lib.OK:
                    for o in others:
                        o._failure[0] = None
                    self._failure[0] = None
                    raise from_code(rc, _python_calls(_L.dmi_last_error(s).decode()))
        finally:
            _L.dmi_tangent_free(ctypes.byref(tangent))
        return U, X, S, dX, switches

    def c_callback(self, part: str) -> tuple[int, int] | None:
        """The C function libdmi calls for a part of the model, for code that calls it directly
        (compiled code: no Python in between).

        Parameters
        ----------
        part : str
            ``"rhs"``, ``"resolvent"``, ``"kernel"``, ``"kernel_near"`` or ``"history"``.

        Returns
        -------
        tuple of int or None
            (address, user): the function's address, with libdmi's signature for that part
            (``dmi.RHS_SIGNATURE`` and the others of include/dmi.h), and its user pointer (0 for
            NULL), valid while the solver keeps that callback; None where the part is not a
            callback (absent, built-in friction or box, an exponential kernel) or is a Python
            function (called through a Python trampoline; use the ``eval_*`` methods).  A
            ``jit=True`` callback reads the closure values written at :meth:`init`.

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: another part.
        """
        if part not in ("rhs", "resolvent", "kernel", "kernel_near", "history"):
            raise InvalidArgument(_lib.EINVAL, f"c_callback: part {part!r} is not one of 'rhs', "
                                  "'resolvent', 'kernel', 'kernel_near', 'history'")
        bound = self._keep.get(part)
        if bound is None or bound.address is None or bound.python:
            return None
        return int(bound.address), int(bound.user or 0)

    def same_callback(self, other: Solver, part: str) -> bool:
        """Whether another solver's callback for a part computes what this one's does: both
        absent, or the same function with the same data.  True only where that is certain: a C
        function at the same address with the same user pointer; a ``jit=True`` callback
        compiled from the same code, with equal closure values and globals passed (numbers bit
        for bit, arrays element by element); a Python function of the same code and globals
        whose closure values and defaults are the same objects, equal numbers or equal arrays
        (functions among them compared in the same way).  Anything else (a closure holding
        another object, callbacks of different kinds) counts as different.

        Parameters
        ----------
        other : dmi.Solver
            The solver compared with this one.
        part : str
            ``"rhs"``, ``"resolvent"``, ``"kernel"``, ``"kernel_near"`` or ``"history"``.

        Returns
        -------
        bool
            True where both call the same function with the same data (or neither has one).

        Raises
        ------
        dmi.InvalidArgument
            Code ``dmi.EINVAL``: another part.
        TypeError
            other not a dmi.Solver.
        """
        if part not in ("rhs", "resolvent", "kernel", "kernel_near", "history"):
            raise InvalidArgument(_lib.EINVAL, f"same_callback: part {part!r} is not one of 'rhs', "
                                  "'resolvent', 'kernel', 'kernel_near', 'history'")
        if not isinstance(other, Solver):
            raise TypeError(f"same_callback: other is a {type(other).__name__}; expected a dmi.Solver")
        a, b = self._keep.get(part), other._keep.get(part)
        a = a if a is not None and a.address is not None else None
        b = b if b is not None and b.address is not None else None
        if a is None or b is None:
            return a is None and b is None
        if a.jit or b.jit:
            return a.jit and b.jit and _same_jit(a, b)
        if a.python or b.python:
            return a.python and b.python and _same_function(a.keep[1], b.keep[1], 0)
        return a.address == b.address and a.user == b.user

    def __repr__(self) -> str:
        if self._h_given is not None:
            return f"dmi.Solver(n={self._n}, tau={self._tau!r}, h={self._h_given!r})"
        return f"dmi.Solver(n={self._n}, tau={self._tau!r}, N={self._N})"
