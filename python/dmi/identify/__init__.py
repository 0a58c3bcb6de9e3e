# dmi.identify: parameters of a model from measurements.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""dmi.identify: sensitivities of the scheme and least-squares identification of a model
``make(p) -> dmi.Solver`` from measured records (docs/identify.md).

:func:`sensitivities` gives dU/dp through friction, boxes, memory and history, converging to the
equation's sensitivity at O(h) through reversals, sticks and slip onsets; :func:`estimate` fits p
to one or more :class:`Record` with SciPy's trust-region ``least_squares`` and returns an
:class:`Estimate` (covariance, correlations, AIC/BIC, the combinations the data cannot determine);
:func:`profile_likelihood` gives a parameter's :class:`Profile`: its likelihood-ratio interval
beside the Wald one.
"""
from __future__ import annotations

from .fitting import Estimate, FitOptions, Parameter, Record, estimate
from .profile import Profile, profile_likelihood
from .sensitivity import MAX_STEPS, Sensitivities, sensitivities

__all__ = ["sensitivities", "Sensitivities", "MAX_STEPS", "Record", "estimate", "Estimate",
           "FitOptions", "Parameter", "profile_likelihood", "Profile"]
