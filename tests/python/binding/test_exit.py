# A script that leaves solvers alive at exit (jit=True callbacks, a fitted kernel with near cells,
# the cell rule on a singular callback kernel) ends with an empty stderr: the solvers collected
# during interpreter shutdown are freed without a traceback.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os
import subprocess
import sys
import textwrap

SCRIPT = textwrap.dedent("""
    import numpy as np
    import dmi
    from dmi import kernels

    s = dmi.Solver(2, 1.0, 50)
    s.set_rhs(lambda t, u: np.array([-u[1], u[0]]), jit=True)
    s.init()
    s.advance(3)
    f = kernels.fit(kernels.PowerKernel(0.5), 1.0, delta=0.1, tol=1e-6)
    s2 = dmi.Solver(1, 1.0, 50)
    s2.set_quadrature("cell")
    s2.set_kernel_fit(f)
    s2.set_history(lambda t: np.array([1.0]))
    s2.init()
    s2.advance(3)
    s3 = dmi.Solver(1, 1.0, 20)
    s3.set_quadrature("cell")
    s3.set_kernel(lambda x: np.array([[x ** -0.5]]))
    s3.init()
    print("ran", s.step_index, s2.step_index)
""")


def test_script_leaving_solvers_alive_exits_with_an_empty_stderr(tmp_path):
    script = tmp_path / "leaves_solvers.py"   # (a file: jit=True reads the lambdas' source)
    script.write_text(SCRIPT)
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=dict(os.environ))
    try:
        out, err = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:   # (stopped by its own id if it hangs)
            proc.kill()
            proc.wait()
    assert out.strip() == "ran 3 3"
    assert proc.returncode == 0
    assert err == ""
