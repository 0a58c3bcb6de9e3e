# jit=True of the Solver's set_rhs, set_resolvent, set_kernel and set_history: a plain Python
# function with the Python callback's signature, compiled by numba into the C callback libdmi
# calls.  The function's source is recompiled with its closure variables as extra arguments, so
# that their values travel at run time in the callback's user data (numbers by value, NumPy
# arrays by address) instead of being frozen into the machine code; the compiled code is cached
# per process, keyed on the function's code and the closure values' types.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""numba compilation of plain Python callbacks (``jit=True``); private to the package."""
from __future__ import annotations

import ast
import copy
import inspect
import linecache
import re
import textwrap
import threading
import types
from typing import Any

import numpy as np

from . import _lib
from ._callbacks import KERNEL, Bound, Kind
from ._errors import InvalidArgument

# Array dtypes a closure may hold, by NumPy's dtype.str.
_DTYPES = {"<f8": "float64", "<f4": "float32", "<i8": "int64", "<i4": "int32"}

_lock = threading.Lock()
_cache: dict[tuple, Any] = {}  # key -> the numba cfunc
_compilations = [0]
_helpers: dict[str, Any] = {}  # numba helpers, made at the first compilation


def compilations() -> int:
    """How many callbacks this process has compiled (cache misses)."""
    return _compilations[0]


# ---- the closure's values ------------------------------------------------------------------------

def _param_type(name: str, value: Any, what: str) -> tuple:
    """The type key of a closure value: ("f",), ("i",), ("b",), ("a", dtype, ndim), or ("k", id)
    for a module or function (not passed: a constant of the compiled code)."""
    if isinstance(value, (bool, np.bool_)):
        return ("b",)
    if isinstance(value, (int, np.integer)):
        if not -2**63 <= int(value) < 2**63:
            raise InvalidArgument(_lib.EINVAL, f"{what}: the closure's {name} = {value} does not "
                                  "fit a 64-bit integer")
        return ("i",)
    if isinstance(value, (float, np.floating)):
        return ("f",)
    if isinstance(value, types.ModuleType) or callable(value):
        return ("k", id(value))  # a module or function: a compile-time constant, as a global
    if isinstance(value, np.ndarray):
        if value.dtype.str not in _DTYPES or value.ndim < 1:
            raise InvalidArgument(_lib.EINVAL, f"{what}: the closure's array {name} has dtype "
                                  f"{value.dtype} and {value.ndim} dimensions; jit=True passes "
                                  "arrays of float64, float32, int64 or int32 with >= 1 dimension")
        return ("a", value.dtype.str, value.ndim)
    raise InvalidArgument(_lib.EINVAL, f"{what}: the closure's {name} is a {type(value).__name__}; "
                          "jit=True passes numbers and NumPy arrays from a closure (and takes "
                          "modules and functions as they are at compile time)")


def _user_data(n: int, values: list[Any], keys: list[tuple]) -> tuple[np.ndarray, list]:
    """The callback's user data: int64 slots, n first, then each value (a number's bits, or an
    array's address and shape); and the arrays to keep alive."""
    slots: list[Any] = [n]
    keep = []
    for v, k in zip(values, keys):
        if k[0] == "k":
            continue
        if k[0] == "a":
            a = v if v.flags.c_contiguous else np.ascontiguousarray(v)
            keep.append(a)
            slots += [a.ctypes.data, *a.shape]
        elif k[0] == "f":
            slots.append(np.array(float(v)).view(np.int64).item())
        else:
            slots.append(int(v))
    return np.array(slots, dtype=np.int64), keep


# ---- the source, recompiled with the closure as arguments ------------------------------------------

def _source_tree(f: types.FunctionType, what: str) -> tuple[list[ast.arg], list[ast.stmt]]:
    """The function's arguments and body as AST nodes, at the lines of its file."""
    code = f.__code__
    if f.__name__ == "<lambda>":
        # the body's exact span (Python 3.11's positions), parsed as an expression
        spans = [p for p in code.co_positions()
                 if None not in p and (p[0], p[2]) != (p[1], p[3])]  # (not RESUME's empty span)
        lines = linecache.getlines(code.co_filename)
        if not spans or not lines:
            raise InvalidArgument(_lib.EINVAL, f"{what}: jit=True needs the lambda's source "
                                  f"({code.co_filename} cannot be read)")
        l0, c0 = min((p[0], p[2]) for p in spans)
        l1, c1 = max((p[1], p[3]) for p in spans)
        text = "".join(lines[l0 - 1:l1]).encode()  # the columns count UTF-8 bytes
        end = len("".join(lines[l0 - 1:l1 - 1]).encode()) + c1
        body = ast.parse("(" + text[c0:end].decode() + "\n)", mode="eval").body
        ast.increment_lineno(body, l0 - 1)
        args = [ast.arg(arg=a) for a in code.co_varnames[:code.co_argcount]]
        ret = ast.Return(value=body, lineno=body.lineno, end_lineno=body.end_lineno,
                         col_offset=0, end_col_offset=0)
        return args, [ret]
    try:
        src = textwrap.dedent(inspect.getsource(f))
    except (OSError, TypeError) as e:
        raise InvalidArgument(_lib.EINVAL, f"{what}: jit=True needs the function's source: {e}") \
            from None
    tree = ast.parse(src)
    node = tree.body[0]
    if not isinstance(node, ast.FunctionDef):
        raise InvalidArgument(_lib.EINVAL, f"{what}: jit=True takes a def or a lambda")
    ast.increment_lineno(node, code.co_firstlineno - 1)
    return node.args.args, node.body


def _array_literal(node: ast.expr, np_names: set[str]) -> list[ast.expr] | None:
    """The items of np.array([a, b, ...]) (a flat list or tuple, no dtype), else None."""
    if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
            and node.func.attr in ("array", "asarray") and isinstance(node.func.value, ast.Name)
            and node.func.value.id in np_names and len(node.args) == 1 and not node.keywords):
        return None
    items = node.args[0]
    if not isinstance(items, (ast.List, ast.Tuple)):
        return None
    if any(isinstance(e, (ast.List, ast.Tuple, ast.Starred)) for e in items.elts):
        return None
    return items.elts


class _Returns(ast.NodeTransformer):
    """``return np.array([a, b])`` -> ``return (float(a), float(b))``: the values go straight to
    libdmi's output, with no array allocated per call."""

    def __init__(self, np_names: set[str]):
        self.np_names = np_names

    def visit_FunctionDef(self, node: ast.FunctionDef) -> ast.FunctionDef:
        return node  # not into nested functions

    def visit_Lambda(self, node: ast.Lambda) -> ast.Lambda:
        return node

    def visit_Return(self, node: ast.Return) -> ast.Return:
        items = _array_literal(node.value, self.np_names) if node.value is not None else None
        if items is not None:
            node.value = ast.copy_location(ast.Tuple(elts=[
                ast.copy_location(ast.Call(func=ast.Name(id="float", ctx=ast.Load()), args=[e],
                                           keywords=[]), e) for e in items], ctx=ast.Load()),
                node.value)
        return node


def _recompiled(f: types.FunctionType, args: list[ast.arg], body: list[ast.stmt],
                keys: list[tuple], literal: bool) -> types.FunctionType:
    """f as a module-level function of its arguments and then its closure's values, in f's globals
    with the closure's modules and functions (compiled with f's file name and lines, so that
    numba's messages point at them)."""
    names = f.__code__.co_freevars
    cells = [c.cell_contents for c in (f.__closure__ or ())]
    free = [v for v, k in zip(names, keys) if k[0] != "k"]
    scope = dict(f.__globals__)
    scope.update((v, c) for v, c, k in zip(names, cells, keys) if k[0] == "k")
    body = copy.deepcopy(body)  # the same nodes serve both attempts of _compile
    line, last = body[0].lineno, max(getattr(b, "end_lineno", b.lineno) for b in body)
    at = dict(lineno=line, end_lineno=line, col_offset=0, end_col_offset=0)
    fn = ast.FunctionDef(name="__dmi_jit", args=ast.arguments(
        posonlyargs=[], args=[ast.arg(arg=a, **at) for a in [a.arg for a in args] + free],
        vararg=None, kwonlyargs=[], kw_defaults=[], kwarg=None, defaults=[]),
        body=body, decorator_list=[], returns=None, lineno=line, end_lineno=last, col_offset=0,
        end_col_offset=0)
    if literal:
        np_names = {k for k, v in scope.items() if v is np}
        fn.body = [_Returns(np_names).visit(s) for s in fn.body]
    module = ast.Module(body=[fn], type_ignores=[])
    ast.fix_missing_locations(module)
    ns: dict[str, Any] = {}
    exec(compile(module, f.__code__.co_filename, "exec"), scope, ns)
    return ns["__dmi_jit"]


# ---- numba ---------------------------------------------------------------------------------------

def _numba_helpers() -> dict[str, Any]:
    """numba's pieces, made once: the address -> pointer intrinsic and the result's store into
    libdmi's output (0, or 2 when the result does not have libdmi's shape)."""
    if _helpers:
        return _helpers
    try:
        import numba
    except ImportError as e:
        raise InvalidArgument(_lib.EINVAL, f"jit=True needs numba (pip install 'dmi[numba]'): "
                              f"{e}") from None
    from numba import types as nt
    from numba.extending import intrinsic, overload

    @intrinsic
    def address(typingctx, a):
        def codegen(context, builder, signature, args):
            return builder.inttoptr(args[0], context.get_value_type(nt.voidptr))
        return nt.voidptr(nt.int64), codegen

    def put_vec(r, out, n):
        pass

    def put_mat(r, out, n):
        pass

    @overload(put_vec)
    def put_vec_impl(r, out, n):
        if isinstance(r, nt.Array) and r.ndim == 1:
            def impl(r, out, n):
                if r.shape[0] != n:
                    return 2
                for i in range(n):
                    out[i] = r[i]
                return 0
            return impl
        if isinstance(r, nt.UniTuple):
            def impl(r, out, n):
                if len(r) != n:
                    return 2
                for i in range(len(r)):
                    out[i] = r[i]
                return 0
            return impl
        if isinstance(r, nt.BaseTuple):
            def impl(r, out, n):
                if len(r) != n:
                    return 2
                i = 0
                for v in numba.literal_unroll(r):
                    out[i] = v
                    i += 1
                return 0
            return impl
        return None

    @overload(put_mat)
    def put_mat_impl(r, out, n):
        if isinstance(r, nt.Array) and r.ndim == 2:
            def impl(r, out, n):
                if r.shape[0] != n or r.shape[1] != n:
                    return 2
                for i in range(n):
                    for j in range(n):
                        out[i * n + j] = r[i, j]
                return 0
            return impl
        return None

    _helpers.update(numba=numba, address=address, put_vec=put_vec, put_mat=put_mat)
    return _helpers


def _adapter_source(kind: Kind, keys: list[tuple]) -> str:
    """The cfunc's source: unpacks the user data into the closure's values, calls the function,
    stores its result."""
    vector = kind.args == "dppp"
    head = "x, u_, out_, user" if vector else "x, out_, user"
    lines = [f"def adapter({head}):",
             f"    m = carray(user, ({1 + sum(1 + k[2] if k[0] == 'a' else k[0] != 'k' for k in keys)},), "
             "int64)",
             "    mf = carray(user, (m.shape[0],), float64)",
             "    n = m[0]"]
    if vector:
        lines.append("    u = carray(u_, (n,))")
    size = "n * n" if kind is KERNEL else "n"
    lines.append(f"    out = carray(out_, ({size},))")
    j, names = 1, []
    for k, key in enumerate(keys):
        if key[0] == "k":
            continue
        v = f"c{k}"
        names.append(v)
        if key[0] == "f":
            lines.append(f"    {v} = mf[{j}]")
        elif key[0] == "i":
            lines.append(f"    {v} = m[{j}]")
        elif key[0] == "b":
            lines.append(f"    {v} = m[{j}] != 0")
        else:
            shape = ", ".join(f"m[{j + 1 + d}]" for d in range(key[2]))
            lines.append(f"    {v} = carray(address(m[{j}]), ({shape},), {_DTYPES[key[1]]})")
            j += key[2]
        j += 1
    call = ", ".join(["x", "u"] if vector else ["x"]) + "".join(f", {v}" for v in names)
    lines.append(f"    r = inner({call})")
    lines.append(f"    return {'put_mat' if kind is KERNEL else 'put_vec'}(r, out, n)")
    return "\n".join(lines) + "\n"


def _located(e: Exception, f: types.FunctionType, body: list[ast.stmt]) -> str:
    """Where numba refused f: " at <file>, line <n>: <source line>" (or "" if nowhere)."""
    text = re.sub(r"\x1b\[[0-9;]*m", "", str(e))
    file = f.__code__.co_filename
    lines = [int(n) for p, n in re.findall(r"at (\S+) \((\d+)\)", text) if p == file]
    if not lines:  # a name or attribute numba does not know: its first use in the function
        name = re.search(r"name '(\w+)' is not defined", text)
        attr = re.search(r"(?:no attribute|Unknown attribute) '(\w+)'", text)
        for node in (n for b in body for n in ast.walk(b)):
            if (name and isinstance(node, ast.Name) and node.id == name.group(1)) or (
                    attr and isinstance(node, ast.Attribute) and node.attr == attr.group(1)):
                lines = [node.lineno]
                break
    if not lines:
        return ""
    return f" at {file}, line {lines[0]}: {linecache.getline(file, lines[0]).strip()}"


def _signature(kind: Kind, keys: list[tuple]) -> tuple:
    """The numba types of the function's arguments as the adapter passes them."""
    from numba import types as nt
    args: list[Any] = [nt.float64]
    if kind.args == "dppp":
        args.append(nt.Array(nt.float64, 1, "C"))
    for k in (k for k in keys if k[0] != "k"):
        args.append(nt.float64 if k[0] == "f" else nt.int64 if k[0] == "i" else nt.boolean
                    if k[0] == "b" else nt.Array(getattr(nt, _DTYPES[k[1]]), k[2], "C"))
    return tuple(args)


def _compile(kind: Kind, f: types.FunctionType, keys: list[tuple], what: str) -> Any:
    h = _numba_helpers()
    numba = h["numba"]
    args, body = _source_tree(f, what)
    want = 2 if kind.args == "dppp" else 1
    if len(args) != want or f.__code__.co_flags & (inspect.CO_VARARGS | inspect.CO_VARKEYWORDS):
        form = {"rhs": "f(t, u)", "resolvent": "r(lam, x)", "kernel": "H(s)", "history": "z(t)"}
        raise InvalidArgument(_lib.EINVAL, f"{what}: jit=True takes a function of {want} "
                              f"argument(s), as the Python callback {form[kind.name]}")
    from numba import carray, float64, int64
    for literal in ((True, False) if kind is not KERNEL else (False,)):
        try:
            inner = numba.njit(_recompiled(f, args, body, keys, literal))
            inner.compile(_signature(kind, keys))  # the function's own errors first
            ns = {"carray": carray, "float64": float64, "int64": int64, "float32": numba.float32,
                  "int32": numba.int32, "inner": inner, "address": h["address"],
                  "put_vec": h["put_vec"], "put_mat": h["put_mat"]}
            exec(_adapter_source(kind, keys), ns)
            return numba.cfunc(kind.numba)(ns["adapter"])
        except Exception as e:  # numba's errors, and Python's raised while numba reads the code
            if literal:
                continue  # try the function as written
            where = _located(e, f, body)
            text = re.sub(r"\x1b\[[0-9;]*m", "", str(e))
            raise InvalidArgument(_lib.EINVAL, f"{what}(jit=True): numba cannot compile "
                                  f"{f.__qualname__}{where or ' (numba names no line)'}: "
                                  f"{type(e).__name__}: {text}") from None
    raise AssertionError("unreachable")


def bind(kind: Kind, f: Any, user: Any, n: int) -> Bound:
    """What set_<kind>(f, jit=True) hands to libdmi: the compiled callback (cached) and its user
    data holding the closure's current values."""
    what = f"set_{kind.name}"
    if user is not None:
        raise InvalidArgument(_lib.EINVAL, f"{what}: jit=True takes no user pointer (the closure's "
                              "values are passed as its user data)")
    if not isinstance(f, types.FunctionType):
        raise InvalidArgument(_lib.EINVAL, f"{what}: jit=True compiles a Python function (def or "
                              f"lambda), not {type(f).__name__}")
    code = f.__code__
    values = [c.cell_contents for c in (f.__closure__ or ())]
    keys = [_param_type(name, v, what) for name, v in zip(code.co_freevars, values)]
    key = (code, id(f.__globals__), kind.name, tuple(keys))
    with _lock:
        c = _cache.get(key)
        if c is None:
            c = _compile(kind, f, keys, what)
            _cache[key] = c
            _compilations[0] += 1
    data, arrays = _user_data(n, values, keys)
    return Bound(int(c.address), int(data.ctypes.data), (c, data, arrays, f))
