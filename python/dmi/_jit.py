# jit=True of the Solver's set_rhs, set_resolvent, set_kernel and set_history: a plain Python
# function with the Python callback's signature, compiled by numba into the C callback libdmi
# calls.  The function's source (checked against its code object: an edited file is refused) is
# recompiled with its closure variables and the numbers and arrays among its globals as extra
# arguments, so that their values travel at run time in the callback's user data (numbers by
# value, NumPy arrays by address), written at set_* and again at every init(); the compiled code
# is cached per process, keyed on the function's code, those values' types and the identity of the
# other globals and closure values it reads (modules, functions: constants of the machine code).
# Errors as the Python function's: numba's NumPy error model (1/0 = inf), index checks, and an
# exception in the compiled code fails the call (returns 3) with its arguments kept in the user
# data, where raised() calls the Python function again to raise its exception.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""numba compilation of plain Python callbacks (``jit=True``); private to the package."""
from __future__ import annotations

import __future__
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
from ._errors import Error, InvalidArgument

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


def _global_type(value: Any) -> tuple:
    """The key of a global the function reads: a passed value's type key (as a closure's), or
    ("k", id) for any other value (a constant of the compiled code, as numba freezes globals)."""
    try:
        return _param_type("", value, "")
    except InvalidArgument:
        return ("k", id(value))


_ANALYSIS_MAX = 4096
_analysed: dict[types.CodeType, tuple[tuple[str, ...], tuple[str, ...]]] = {}


def _analysis(code: types.CodeType) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """What the bytecode says, kept per code object (a function of its bytecode, names and
    constants alone, so every function of that code shares it; the values are read per call):
    the names code loads as globals (LOAD_GLOBAL, LOAD_NAME), in order of first use, and those
    its nested code objects (comprehensions, nested functions, at any depth) load."""
    got = _analysed.get(code)
    if got is None:
        nested: list[str] = []
        for c in _nested_codes(code):
            nested += [g for g in _loaded_globals(c) if g not in nested]
        got = (_loaded_globals(code), tuple(nested))
        if len(_analysed) >= _ANALYSIS_MAX:
            _analysed.clear()
        _analysed[code] = got
    return got


def _loaded_globals(code: types.CodeType) -> tuple[str, ...]:
    """The names code loads as globals or module names, in order of first use (each once)."""
    import dis
    names: list[str] = []
    for ins in dis.get_instructions(code):
        if ins.opname in ("LOAD_GLOBAL", "LOAD_NAME") and ins.argval not in names:
            names.append(ins.argval)
    return tuple(names)


def _global_names(code: types.CodeType, f: types.FunctionType) -> list[str]:
    """The names code reads from f's globals (LOAD_GLOBAL; not builtins), in order of first use."""
    g = f.__globals__
    return [name for name in _analysis(code)[0] if name in g]


def _nested_codes(code: types.CodeType) -> list[types.CodeType]:
    """The code objects inside code (comprehensions, nested functions), at any depth."""
    out = []
    for c in code.co_consts:
        if isinstance(c, types.CodeType):
            out += [c, *_nested_codes(c)]
    return out


def _parameters(f: types.FunctionType, what: str) -> tuple[list[str], list[Any], list[tuple]]:
    """The names, current values and keys of what the compiled code reads besides its arguments:
    the closure's cells, then the globals."""
    code = f.__code__
    names = list(code.co_freevars)
    values = [c.cell_contents for c in (f.__closure__ or ())]
    keys = [_param_type(name, v, what) for name, v in zip(names, values)]
    for g in _global_names(code, f):
        names.append(g)
        values.append(f.__globals__[g])
        keys.append(_global_type(values[-1]))
    glob = f.__globals__
    for g in sorted({g for g in _analysis(code)[1] if g in glob} - set(names)):
        names.append(g)   # read inside a comprehension or nested function: a constant, keyed
        values.append(f.__globals__[g])
        keys.append(("k", id(values[-1])))
    return names, values, keys


_HEAD = 4  # user data slots before the values: n, failed, the failing t, the scratch's address


def _user_data(kind: Kind, n: int, values: list[Any], keys: list[tuple]) -> tuple[np.ndarray, list]:
    """The callback's user data: int64 slots, the head (n; 0, the failure flag; the failing t
    (or s, lam); the address of a scratch of 2 n doubles, the failing u and the copy of u the
    function gets, for f(t, u) and r(lam, x)) and each value (a number's bits, or an array's
    address and shape); and the arrays to keep alive (the scratch first)."""
    scratch = np.zeros(2 * n if kind.args == "dppp" else 0)
    slots: list[Any] = [n, 0, 0, scratch.ctypes.data]
    keep = [scratch]
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
        _check_source(f, what, ast.Lambda(args=ast.arguments(
            posonlyargs=[], args=copy.deepcopy(args), vararg=None, kwonlyargs=[], kw_defaults=[],
            kwarg=None, defaults=[]), body=copy.deepcopy(body)), l0)
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
    _check_source(f, what, node, code.co_firstlineno)
    return node.args.args, node.body


def _check_source(f: types.FunctionType, what: str, node: ast.FunctionDef | ast.Lambda,
                  line: int) -> None:
    """Refuses source that no longer compiles to f's code object (the file edited after f was
    made): the source is compiled inside a function that makes f's free variables cells, as
    f's own enclosing function did, after imports of the names its file imports at module level
    (Python compiles a method call on an imported module otherwise), and the code objects are
    compared."""
    code = f.__code__
    if isinstance(node, ast.Lambda):
        inner: ast.stmt = ast.Assign(targets=[ast.Name(id="__dmi_f", ctx=ast.Store())], value=node)
    else:
        inner = copy.deepcopy(node)
        inner.decorator_list = []
    body: list[ast.stmt] = []
    if code.co_freevars:
        body.append(ast.Assign(targets=[ast.Name(id=v, ctx=ast.Store()) for v in code.co_freevars],
                               value=ast.Constant(value=None)))
    outer = ast.FunctionDef(name="__dmi_outer", args=ast.arguments(
        posonlyargs=[], args=[], vararg=None, kwonlyargs=[], kw_defaults=[], kwarg=None,
        defaults=[]), body=body + [inner], decorator_list=[], returns=None)
    imports = [ast.Import(names=[ast.alias(name="_", asname=nm)]) for nm in _imported(code.co_filename)]
    module = ast.fix_missing_locations(ast.Module(body=imports + [outer], type_ignores=[]))
    try:
        compiled = compile(module, code.co_filename, "exec", dont_inherit=True,
                           flags=code.co_flags & __future__.annotations.compiler_flag)
        made = next(c for c in _nested_codes(compiled) if c.co_name == code.co_name)
    except (SyntaxError, StopIteration):
        made = None
    if made is None or not _same_code(made, code):
        raise InvalidArgument(_lib.EINVAL, f"{what}: jit=True compiles the source of "
                              f"{f.__qualname__} ({code.co_filename}, line {line}), which no "
                              "longer matches the function object (its file was edited after "
                              "the function was made): reload the module, make the function "
                              "again and set it again")


def _imported(filename: str) -> list[str]:
    """The names the file's module scope binds by import statements (none if it cannot be read)."""
    try:
        tree = ast.parse("".join(linecache.getlines(filename)))
    except (SyntaxError, ValueError):
        return []
    names: set[str] = set()
    todo: list[ast.AST] = list(tree.body)
    while todo:
        node = todo.pop()
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef, ast.Lambda)):
            continue  # (their own scopes)
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            names.update((a.asname or a.name).split(".")[0] for a in node.names if a.name != "*")
        todo.extend(ast.iter_child_nodes(node))
    return sorted(names)


def _same_code(a: types.CodeType, b: types.CodeType) -> bool:
    """Whether two code objects have the same bytecode, names and constants (nested code too;
    line numbers and positions not compared)."""
    fields = ("co_code", "co_names", "co_varnames", "co_freevars", "co_cellvars", "co_argcount",
              "co_posonlyargcount", "co_kwonlyargcount")
    if any(getattr(a, k) != getattr(b, k) for k in fields) or len(a.co_consts) != len(b.co_consts):
        return False
    for x, y in zip(a.co_consts, b.co_consts):
        if isinstance(x, types.CodeType) and isinstance(y, types.CodeType):
            if not _same_code(x, y):
                return False
        elif (type(x), repr(x)) != (type(y), repr(y)):
            return False
    return True


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


def _recompiled(f: types.FunctionType, args: list[ast.arg], body: list[ast.stmt], names: list[str],
                values: list[Any], keys: list[tuple], literal: bool) -> types.FunctionType:
    """f as a module-level function of its arguments and then the values passed at run time (its
    closure's and globals' numbers and arrays), in f's globals with the closure's other values
    (compiled with f's file name and lines, so that numba's messages point at them)."""
    free = [v for v, k in zip(names, keys) if k[0] != "k"]
    scope = dict(f.__globals__)
    scope.update((v, c) for v, c, k in zip(names[:len(f.__code__.co_freevars)], values, keys)
                 if k[0] == "k")
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
    """The cfunc's source: unpacks the user data into the values passed, copies u into the
    scratch (the function may write into its argument, as into the Python callback's copy),
    calls the function and stores its result; an exception in the function (numba catches, it
    cannot bind) keeps the arguments in the user data and returns 3."""
    vector = kind.args == "dppp"
    head = "x, u_, out_, user" if vector else "x, out_, user"
    count = sum(1 + k[2] if k[0] == "a" else k[0] != "k" for k in keys)
    lines = [f"def adapter({head}):",
             f"    m = carray(user, ({_HEAD + count},), int64)",
             "    mf = carray(user, (m.shape[0],), float64)",
             "    n = m[0]"]
    if vector:
        lines += ["    src = carray(u_, (n,))",
                  "    failed_u = carray(address(m[3]), (n,), float64)",
                  "    u = carray(address(m[3] + 8 * n), (n,), float64)",
                  "    for i in range(n):",
                  "        u[i] = src[i]"]
    size = "n * n" if kind is KERNEL else "n"
    lines.append(f"    out = carray(out_, ({size},))")
    at, names = _HEAD, []
    for k, key in enumerate(keys):
        if key[0] == "k":
            continue
        v = f"c{k}"
        names.append(v)
        if key[0] == "f":
            lines.append(f"    {v} = mf[{at}]")
        elif key[0] == "i":
            lines.append(f"    {v} = m[{at}]")
        elif key[0] == "b":
            lines.append(f"    {v} = m[{at}] != 0")
        else:
            shape = ", ".join(f"m[{at + 1 + d}]" for d in range(key[2]))
            lines.append(f"    {v} = carray(address(m[{at}]), ({shape},), {_DTYPES[key[1]]})")
            at += key[2]
        at += 1
    call = ", ".join(["x", "u"] if vector else ["x"]) + "".join(f", {v}" for v in names)
    lines += ["    try:",
              f"        r = inner({call})",
              "    except Exception:",
              "        m[1] = 1",
              "        mf[2] = x"]
    if vector:
        lines += ["        for i in range(n):",
                  "            failed_u[i] = src[i]"]
    lines += ["        return 3",
              f"    return {'put_mat' if kind is KERNEL else 'put_vec'}(r, out, n)"]
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


_FORM = {"rhs": "f(t, u)", "resolvent": "r(lam, x)", "kernel": "H(s)", "history": "z(t)"}


def _result_refused(kind: Kind, f: types.FunctionType, result: Any) -> str | None:
    """Why numba's type of f's result cannot be libdmi's output, or None when it can."""
    from numba import types as nt
    if kind is KERNEL:
        if isinstance(result, nt.Array) and result.ndim == 2:
            return None
        return (f"the kernel must return an n x n array; {f.__qualname__} returns {result} "
                "(for n = 1 too: np.array([[value]]))")
    if (isinstance(result, nt.Array) and result.ndim == 1) or isinstance(result, nt.BaseTuple):
        return None
    return (f"the {kind.name} {_FORM[kind.name]} must return an array of shape (n,) (or a tuple of "
            f"n numbers); {f.__qualname__} returns {result}")


def _compile(kind: Kind, f: types.FunctionType, names: list[str], values: list[Any],
             keys: list[tuple], what: str) -> Any:
    h = _numba_helpers()
    numba = h["numba"]
    want = 2 if kind.args == "dppp" else 1
    if f.__code__.co_argcount != want or f.__code__.co_kwonlyargcount or \
            f.__code__.co_flags & (inspect.CO_VARARGS | inspect.CO_VARKEYWORDS):
        raise InvalidArgument(_lib.EINVAL, f"{what}: jit=True takes a function of {want} "
                              f"argument(s), as the Python callback {_FORM[kind.name]}")
    args, body = _source_tree(f, what)
    from numba import carray, float64, int64
    for literal in ((True, False) if kind is not KERNEL else (False,)):
        try:
            # numba's NumPy error model (x / 0 = inf, as NumPy's floats give) and index checks
            inner = numba.njit(_recompiled(f, args, body, names, values, keys, literal),
                               error_model="numpy", boundscheck=True)
            sig = _signature(kind, keys)
            inner.compile(sig)  # the function's own errors first
            why = _result_refused(kind, f, inner.overloads[sig].signature.return_type)
            if why is not None:
                if literal:
                    continue
                raise InvalidArgument(_lib.EINVAL, f"{what}(jit=True): {why}")
            ns = {"carray": carray, "float64": float64, "int64": int64, "float32": numba.float32,
                  "int32": numba.int32, "inner": inner, "address": h["address"],
                  "put_vec": h["put_vec"], "put_mat": h["put_mat"]}
            exec(_adapter_source(kind, keys), ns)
            return numba.cfunc(kind.numba)(ns["adapter"])
        except InvalidArgument:
            raise
        except Exception as e:  # numba's errors, and Python's raised while numba reads the code
            if literal:
                continue  # try the function as written
            where = _located(e, f, body)
            text = re.sub(r"\x1b\[[0-9;]*m", "", str(e))
            raise InvalidArgument(_lib.EINVAL, f"{what}(jit=True): numba cannot compile "
                                  f"{f.__qualname__}{where or ' (numba names no line)'}: "
                                  f"{type(e).__name__}: {text}") from None
    raise AssertionError("unreachable")


_MISSING = object()  # a closure cell emptied, a global deleted


def _same_passed(v: Any, old: Any, key: tuple) -> bool:
    """Whether v, rebound in place of old (not the same object), is what the compiled code was
    given: a number of the same type and value, an array of the same memory."""
    if key[0] == "a":
        return isinstance(v, np.ndarray) and v.flags.c_contiguous and v.dtype == old.dtype \
            and v.shape == old.shape and v.ctypes.data == old.ctypes.data
    if key[0] in ("f", "i", "b"):
        try:
            return _param_type("", v, "") == key and v == old
        except (InvalidArgument, ValueError, TypeError):
            return False
    return False  # a module or function: a constant of the compiled code


class JitBound(Bound):
    """A jit=True callback as handed to libdmi, with what raised(), refresh() and rebound()
    need: what its closure cells and globals held when their values were written (set_* or
    init), to notice a rebinding the compiled code does not see."""

    jit = True

    def __init__(self, kind: Kind, f: types.FunctionType, n: int, keys: list[tuple], cfunc: Any,
                 data: np.ndarray, arrays: list, names: list[str], values: list[Any]):
        super().__init__(int(cfunc.address), int(data.ctypes.data), (cfunc, data, arrays, f))
        self.kind, self.f, self.n, self.keys, self.data = kind, f, n, keys, data
        self.snapshot(names, values, f"set_{kind.name}")

    def snapshot(self, names: list[str], values: list[Any], when: str) -> None:
        """Remembers the objects the closure cells and globals hold now (their values written),
        and makes same(): whether they still hold them."""
        free = len(self.f.__code__.co_freevars)
        self.cells = tuple(zip(self.f.__closure__ or (), values[:free], names[:free],
                               self.keys[:free]))
        self.globs = tuple(zip(names[free:], values[free:], self.keys[free:]))
        self.when, self.watching = when, bool(self.cells or self.globs)  # (nothing to watch)
        self.same = _identity_check(self.cells, self.globs, self.f.__globals__)

    def rebound(self) -> str | None:
        """After same() found an object replaced: the warning that names the variables rebound
        to another value than the compiled code's (once: same() is then always True until the
        next snapshot), or None when the new objects are the same values (taken as the
        snapshot's)."""
        if not self.watching:
            return None
        changed: list[tuple[str, str, bool]] = []   # (name, "closure" | "global", type kept)
        for cell, old, name, key in self.cells:
            try:
                v = cell.cell_contents
            except ValueError:
                v = _MISSING
            if v is not old and not _same_passed(v, old, key):
                changed.append((name, "closure variable", _kept(v, key)))
        g = self.f.__globals__
        for name, old, key in self.globs:
            v = g.get(name, _MISSING)
            if v is not old and not _same_passed(v, old, key):
                changed.append((name, "global", _kept(v, key)))
        if not changed:   # (equal values: the compiled code's, as the Python function's)
            self.snapshot([nm for _, _, nm, _ in self.cells] + [nm for nm, _, _ in self.globs],
                          [_current(c) for c, *_ in self.cells]
                          + [g.get(nm, _MISSING) for nm, *_ in self.globs], self.when)
            return None
        self.watching = False   # (warned once, until the next set_* or init)
        self.same = _always
        k = self.kind.name
        what = ", ".join(f"{kind} {name!r}" for name, kind, _ in changed)
        how = (f"init() takes the new value (and restarts at t = 0), set_{k}(..., jit=True) "
               "takes it from the next step" if all(kept for *_, kept in changed) else
               f"it no longer fits the compiled code (another type, or a module or function): "
               f"call set_{k}(..., jit=True) again")
        return (f"the jit=True {k} callback {self.f.__qualname__} reads {what}, rebound since "
                f"{self.when}: its compiled code still computes with the value of {self.when}, "
                f"while the Python function reads the new one; {how}")


def _always() -> bool:
    return True


def _current(cell: Any) -> Any:
    try:
        return cell.cell_contents
    except ValueError:
        return _MISSING


_checks: dict[tuple, Any] = {}  # (cells, global names) -> the maker of same()


def _identity_check(cells: tuple, globs: tuple, g: dict) -> Any:
    """A function without arguments: whether every cell and global still holds its object, one
    `is` per variable (made from source: no loop, no call but dict.get, for the step's cost).
    The source depends only on the number of cells and the globals' names: it is compiled once
    for them, into a maker that closes over the objects of each call."""
    if not cells and not globs:
        return _always
    shape = (len(cells), tuple(name for name, *_ in globs))
    maker = _checks.get(shape)
    if maker is None:
        tests = [f"c{i}.cell_contents is o{i}" for i in range(len(cells))]
        tests += [f"g.get({name!r}, M) is p{j}" for j, name in enumerate(shape[1])]
        args = [f"c{i}, o{i}" for i in range(len(cells))] + [f"p{j}" for j in range(len(globs))]
        src = (f"def maker(g, M, {', '.join(args)}):\n"
               "    def same():\n        try:\n            return " + " and ".join(tests) +
               "\n        except ValueError:\n            return False\n"   # (a cell emptied)
               "    return same\n")
        scope: dict[str, Any] = {}
        exec(src, scope)  # noqa: S102 - our own expression
        maker = scope["maker"]
        if len(_checks) >= _ANALYSIS_MAX:
            _checks.clear()
        _checks[shape] = maker
    values = [v for cell, old, *_ in cells for v in (cell, old)] + [old for _, old, _ in globs]
    return maker(g, _MISSING, *values)


def _kept(v: Any, key: tuple) -> bool:
    """Whether v can be passed where a value of key was (init() takes it without compiling)."""
    if v is _MISSING or key[0] == "k":
        return False
    try:
        return _param_type("", v, "") == key
    except InvalidArgument:
        return False


def bind(kind: Kind, f: Any, user: Any, n: int) -> Bound:
    """What set_<kind>(f, jit=True) hands to libdmi: the compiled callback (cached) and its user
    data holding the current values of the closure and of the globals passed."""
    what = f"set_{kind.name}"
    if user is not None:
        raise InvalidArgument(_lib.EINVAL, f"{what}: jit=True takes no user pointer (the closure's "
                              "values are passed as its user data)")
    if not isinstance(f, types.FunctionType):
        raise InvalidArgument(_lib.EINVAL, f"{what}: jit=True compiles a Python function (def or "
                              f"lambda), not {type(f).__name__}")
    names, values, keys = _parameters(f, what)
    key = (f.__code__, id(f.__globals__), kind.name, tuple(names), tuple(keys))
    with _lock:
        c = _cache.get(key)
        if c is None:
            c = _compile(kind, f, names, values, keys, what)
            _cache[key] = c
            _compilations[0] += 1
    data, arrays = _user_data(kind, n, values, keys)
    return JitBound(kind, f, n, keys, c, data, arrays, names, values)


def refresh(bound: JitBound, what: str) -> None:
    """Writes the current values of the function's closure and globals into the user data libdmi
    holds (init(): the compiled callback then computes with them, as the Python function would).

    Raises
    ------
    dmi.InvalidArgument
        A value changed its type, or a module or function it reads was rebound, since set_*:
        the compiled code no longer fits (set the callback again).
    """
    names, values, keys = _parameters(bound.f, what)
    if keys != bound.keys:
        changed = next((nm for nm, k, old in zip(names, keys, bound.keys) if k != old), names[-1])
        raise InvalidArgument(_lib.EINVAL, f"{what}: the jit=True {bound.kind.name} callback's "
                              f"{changed!r} changed its type or was rebound since set_"
                              f"{bound.kind.name}; its compiled code no longer fits: call "
                              f"set_{bound.kind.name}(..., jit=True) again")
    data, arrays = _user_data(bound.kind, bound.n, values, keys)
    bound.data[_HEAD:] = data[_HEAD:]    # (the head stays: the scratch's address)
    bound.keep = (bound.keep[0], bound.data, [bound.keep[2][0]] + arrays[1:], bound.f)
    bound.snapshot(names, values, what + "()")


def raised(bounds: list[Bound]) -> BaseException | None:
    """The exception of a jit=True callback whose compiled code failed (returned 3): the Python
    function called again at the arguments it failed at, which raises the same exception (with a
    note); an Error when the Python function does not raise there; None if none failed."""
    for b in bounds:
        if not isinstance(b, JitBound) or b.data[1] == 0:
            continue
        b.data[1] = 0
        x = float(b.data[2:3].view(np.float64)[0])
        args: tuple = (x,)
        if b.kind.args == "dppp":
            args += (b.keep[2][0][:b.n].copy(),)
        where = f"{_FORM[b.kind.name].split('(')[1][:-1]} = " + ", ".join(repr(a) for a in args)
        try:
            b.f(*args)
        except Exception as e:  # noqa: BLE001 - the user's own exception, raised as it is
            e.add_note(f"raised by the jit=True {b.kind.name} callback {b.f.__qualname__} at "
                       f"{where} (its compiled code failed there; this is the Python function's "
                       "exception at the same arguments)")
            return e
        return Error(_lib.ECALLBACK, f"the jit=True {b.kind.name} callback {b.f.__qualname__} "
                     f"failed in its compiled code at {where} (an exception, or an index out of "
                     "range), but the Python function does not raise there")
    return None
