"""Tests of dmi.analysis.plane: grids over q and the two-parameter diagram."""
