# dmi.kernels and Solver.set_kernel_fit refuse what they cannot answer, or say why: a power kernel
# that is not integrable, a kernel with 1/s at 0, complex kernels, a growing kernel (the warning
# says it grows), noisy samples (the warning says what the noise allows, against the noise put in),
# a fit with near cells under the left rule (switched to the cell rule with a warning; the run is
# the cell rule's, bitwise), set_kernel_fit(None), a near kernel returning a vector, and
# dmi-kernel-fit's bad --expr, --samples and --name, each named.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
import subprocess
import warnings

import numpy as np
import pytest

import dmi
from dmi import kernels


# ---- the kernel's integrability, reality and growth ----------------------------------------------

@pytest.mark.parametrize("beta", [1.0, 1.5])
def test_power_kernel_not_integrable_is_refused(beta):
    with pytest.raises(ValueError, match="integrable"):
        kernels.PowerKernel(beta)


def test_callable_not_integrable_at_zero_is_refused():
    with pytest.raises(ValueError, match="not integrable"):
        kernels.fit(lambda s: 1 / s, 1.0, tol=1e-6, relative=True, delta=1e-2)


def test_complex_kernel_is_refused():
    with pytest.raises(ValueError, match="complex"):
        kernels.fit(lambda s: np.exp((-1 + 1j) * s), 2.0)
    with pytest.raises(ValueError, match="complex"):   # a scalar-only callable, point by point
        kernels.fit(lambda s: complex(math.exp(-s), s), 2.0)
    s = np.linspace(0, 2, 101)
    with pytest.raises(ValueError, match="complex"):
        kernels.fit(None, 2.0, samples=(s, np.exp((-1 + 1j) * s)))


def test_growing_kernel_warning_says_it_grows():
    with pytest.warns(UserWarning) as record:
        f = kernels.fit(lambda s: np.exp(2 * s), 3.0, max_terms=8)
    text = " ".join(str(w.message) for w in record)
    assert "grows" in text and "+2" in text   # the rate of exp(2 s)
    assert "more terms do not help" in text
    assert np.all(f.a <= 0)


def test_noisy_samples_warning_says_what_the_noise_allows():
    rng = np.random.default_rng(11)
    sigma = 1e-3
    s = np.linspace(0, 4, 2001)
    v = np.exp(-s) * np.cos(2 * s) + sigma * rng.standard_normal(len(s))
    with pytest.warns(UserWarning, match="noise") as record:
        f = kernels.fit(None, 4.0, tol=1e-8, samples=(s, v))
    text = str(record[0].message)
    est = float(text.split("is about ")[1].split(":")[0])
    assert 0.8 * sigma <= est <= 1.25 * sigma          # the noise put in
    allowed = float(text.split("a tol of about ")[1].split(" ")[0])
    assert f.max_error == pytest.approx(allowed, rel=0.5)   # what a fit can reach: the noise's largest


# ---- Solver.set_kernel_fit ---------------------------------------------------------------------

FIT = None


def singular_fit() -> kernels.KernelFit:
    global FIT
    if FIT is None:
        FIT = kernels.fit(kernels.PowerKernel(0.5), 1.0, tol=1e-8, relative=True, delta=0.05)
    return FIT


def relaxation(rule: str | None) -> tuple[np.ndarray, dmi.Solver]:
    s = dmi.Solver(1, 1.0, 40)
    s.set_history(lambda t: np.array([1.0]))
    s.set_rhs(lambda t, u: -u)
    if rule is not None:
        s.set_quadrature(rule)
    s.set_kernel_fit(singular_fit())
    s.init()
    return s.run(40)[1][:, 0], s


def test_near_cells_under_the_left_rule_switch_to_the_cell_rule():
    cell, _ = relaxation("cell")
    with pytest.warns(UserWarning, match="cell rule"):
        switched, s = relaxation(None)
    assert s.quadrature == "cell"
    assert np.array_equal(switched, cell)   # the cell rule's run, bitwise
    t = dmi.Solver(1, 1.0, 40)
    t.set_quadrature("cell")
    t.set_kernel_fit(singular_fit())
    with pytest.raises(dmi.InvalidArgument, match="near cells .* need the cell rule"):
        t.set_quadrature("left")


def test_fitted_power_kernel_near_cells_give_its_integral():
    # s^-0.95 fitted on [0.01, 1] to 1e-8 relative, the near cells below 0.01 exact: with z = 1 the
    # first step's W is int_0^1 s^-0.95 ds = 20 (closed form), to the fit's 1e-8 of int |H|
    f = kernels.fit(kernels.PowerKernel(0.95), 1.0, tol=1e-8, relative=True, delta=0.01)
    s = dmi.Solver(1, 1.0, 100)
    s.set_history(lambda t: np.array([1.0]))
    s.set_quadrature("cell")
    s.set_kernel_fit(f)
    s.init()
    s.step()
    W = s.step_terms()[0][0]
    assert abs(W - 20.0) <= 20.0 * 1e-8, W


def test_switch_to_the_cell_rule_keeps_the_exponent_given():
    # a near kernel that cannot be evaluated below 1e-30 runs with its exponent given; the switch
    # from the left rule that set_kernel_fit makes keeps it: W = int_0^1 s^-1/2 ds = 2
    f = kernels.fit(kernels.PowerKernel(0.5), 1.0, tol=1e-10, relative=True, delta=0.05)

    def near(s: float) -> float:
        if s < 1e-30:
            raise ValueError("not below 1e-30")
        return s ** -0.5
    s = dmi.Solver(1, 1.0, 100)
    s.set_history(lambda t: np.array([1.0]))
    s.set_quadrature("left", singularity=0.5)
    with pytest.warns(UserWarning, match="cell rule"):
        s.set_kernel_fit(f, near=near)
    s.init()
    s.step()
    assert s.quadrature == "cell" and abs(s.step_terms()[0][0] - 2.0) <= 2.0 * 1e-9


def test_set_kernel_fit_none_is_a_clear_error():
    s = dmi.Solver(1, 1.0, 10)
    with pytest.raises(dmi.InvalidArgument, match="expected a dmi.kernels.KernelFit"):
        s.set_kernel_fit(None)


def test_near_kernel_returning_a_vector_is_named():
    s = dmi.Solver(2, 1.0, 40)
    s.set_quadrature("cell")
    s.set_kernel_fit(singular_fit(), entry=(1, 0), near=lambda x: np.array([x ** -0.5, 0.0]))
    with pytest.raises(dmi.InvalidArgument, match="near kernel of a scalar fit must return a scalar"):
        s.init()


def test_certified_says_what_it_covers():
    doc = kernels.KernelFit.__doc__
    part = doc[doc.index("certified :"):doc.index("l1_error :")]
    assert "[delta, tau]" in part and "not the near cells" in part


# ---- dmi-kernel-fit --------------------------------------------------------------------------

def cli(capsys, *argv: str) -> tuple[int, str]:
    rc = kernels.main(list(argv))
    return rc, capsys.readouterr().err


@pytest.mark.parametrize("expr", ["s.foo", "'abc' + s", "s +", "1j * s"])
def test_cli_bad_expression_is_named(capsys, expr):
    rc, err = cli(capsys, "--expr", expr, "--tau", "1")
    assert rc == 2 and err.startswith("dmi-kernel-fit: --expr ")


def test_cli_bad_sample_files_are_named(capsys, tmp_path):
    one = tmp_path / "one.txt"
    one.write_text("\n".join(str(x) for x in np.linspace(0, 1, 20)) + "\n")
    empty = tmp_path / "empty.txt"
    empty.write_text("")
    binary = tmp_path / "data.bin"
    binary.write_bytes(bytes(range(256)) * 4)
    for path, what in ((one, "1 column"), (empty, "no data"), (binary, "not a text file")):
        rc, err = cli(capsys, "--samples", str(path), "--tau", "1")
        assert rc == 2 and err.startswith(f"dmi-kernel-fit: --samples {path}: ") and what in err


@pytest.mark.parametrize("fmt", ["c", "fortran"])
def test_cli_name_that_does_not_compile_is_refused_one_that_does_compiles(capsys, tmp_path, fmt):
    rc, err = cli(capsys, "--expr", "np.exp(-s)", "--tau", "1", "--name", "my kernel-1", "--format", fmt)
    assert rc == 2 and err.startswith("dmi-kernel-fit: --name: ")
    with pytest.raises(ValueError, match="not a"):
        kernels.fit(lambda s: np.exp(-s), 1.0).to_c("2k")
    if fmt == "fortran":
        return
    rc = kernels.main(["--expr", "np.exp(-s)", "--tau", "1", "--name", "_my_kernel1"])
    src = tmp_path / "k.c"
    src.write_text(capsys.readouterr().out + "int main(void) { return _my_kernel1_K == 1 && _my_kernel1_a[0] < 0 && _my_kernel1_b[0] == 0 "
                   "&& _my_kernel1_C[0] > 0 && _my_kernel1_D[0] == 0 ? 0 : 1; }\n")
    cc = subprocess.run(["cc", "-std=c99", "-Wall", "-Werror", "-c", str(src), "-o", str(tmp_path / "k.o")],
                        capture_output=True, text=True, timeout=60)
    assert rc == 0 and cc.returncode == 0, cc.stderr
