"""The FEM rung of the ladder: the rigid-wall acoustic FEM (:mod:`matcad.acoustics.fem`) or, for a silicone wall,
the elastic cap coupled to the air (:mod:`matcad.acoustics.fsi`), on a design, as a registry result.
Lengths mm, frequencies Hz, moduli Pa."""

from __future__ import annotations

import numpy as np

from matcad.acoustics import models
from matcad.acoustics.checks import MODE_IN_CAVITY_FRACTION
from matcad.acoustics.registry import ModelResult


def fem_result(d, c_m_s: float, f_guess_hz: float, level: int) -> ModelResult:
    """The FEM reference for design ``d``: rigid walls (acoustic eigenmode), or the elastic silicone cap coupled to
    the air (forced-response peak) at the middle of the wall's kHz modulus and loss ranges; ``level`` elements across
    the neck radius, the search started at ``f_guess_hz``."""
    from matcad.acoustics import fem

    if d.wall.model == "silicone":
        from matcad.acoustics import fsi

        shear, loss = d.wall.dynamic_moduli_pa()[1], d.wall.loss_factors()[1]
        run = fsi.solve(fem.geometry(d), fsi.cap(d, shear, loss), f_guess_hz, level, c_m_s)
        modes = ", ".join(f"{f:.0f}" for f in run.wall_modes_hz)
        return ModelResult(run.f0_hz, {"fundamental_found": run.q > fem.MIN_Q},
                           f"coupled elastic cap + air FEM (scikit-fem, Taylor-Hood P2/P1 cap, P2 air), level "
                           f"{run.level}, {run.dofs} dofs, G = {shear / 1e6:.3g} MPa, eta = {loss:.2g}: peak of "
                           f"the driven response, Q = {run.q:.1f}; cap modes in vacuo {modes} Hz; "
                           f"{run.seconds:.2f} s")
    k_guess = 2 * np.pi * f_guess_hz / (c_m_s * models.MM_PER_M)
    run = fem.solve(fem.geometry(d), k_guess, level, speed_of_sound_m_s=c_m_s)
    checks = {"mode_in_cavity": run.cavity_energy_fraction > MODE_IN_CAVITY_FRACTION, "fundamental_found": run.q > fem.MIN_Q}
    return ModelResult(run.f0_hz, checks, f"axisymmetric P2 FEM (scikit-fem), level {run.level}, {run.dofs} "
                                          f"dofs, Q = {run.q:.1f}, {run.seconds:.2f} s")
