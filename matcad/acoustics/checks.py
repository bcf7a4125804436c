"""Validity checks of the acoustic models: where each model's assumptions hold, and what to say when they do not.

A check is a test on an evaluated design (:class:`matcad.acoustics.evaluation.Evaluation`, or its arrays in a sweep)
at the f0 the model gave, and the warning that names the failed assumption. Models (:mod:`matcad.acoustics.registry`)
list the checks they depend on; the FEM rung reports its own (from the solved mode) with the texts here.
Lengths mm, frequencies Hz, speeds m/s.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from matcad.acoustics import models
from matcad.acoustics import wall as wall_model

PLANE_WAVE_CUTOFF_KA = 1.8412
"""First non-planar (1,1) mode of a circular duct cuts on at k·a = 1.8412 (zero of J1')."""
PANCAKE_L_OVER_D = 0.3
LUMPED_NECK_AIR_RATIO = 0.1
LUMPED_END_CORRECTION_RATIO = 0.1
"""Uncorrected Eq. 1 needs the neck's end corrections ≪ its length (they are 24 % of it on the paper taxel)."""
MODE_IN_CAVITY_FRACTION = 0.3
"""The rigid FEM's Helmholtz mode keeps at least this share of its energy in the cavity (a spurious exterior mode
keeps almost none)."""


@dataclass(frozen=True)
class Check:
    """One assumption: ``test(ev, f0_hz)`` is True (or an array of them) where it holds; ``warning(model, ev)`` the
    text when it does not."""

    name: str
    test: Callable | None
    warning: Callable[[str, object], str]


def _plane_waves(ev, f0_hz):
    res = ev.res
    k = 2 * np.pi * f0_hz / (res.c_m_s * models.MM_PER_M)
    return k * res.cavity_diameter / 2 < PLANE_WAVE_CUTOFF_KA


CHECKS: dict[str, Check] = {c.name: c for c in (
    Check("neck_air_ratio_small",
          lambda ev, f0: ev.res.neck_area * ev.res.neck_length / ev.res.volume < LUMPED_NECK_AIR_RATIO,
          lambda name, ev: f"{name}: neck holds much air relative to the cavity (A*l/V >= {LUMPED_NECK_AIR_RATIO}); "
                           "lumped neck assumption fails"),
    Check("end_corrections_small",
          lambda ev, f0: (ev.res.outer_correction + ev.res.inner_step) / ev.res.neck_length
          < LUMPED_END_CORRECTION_RATIO,
          lambda name, ev: f"{name}: the neck's end corrections are >= {LUMPED_END_CORRECTION_RATIO:g} x its length; "
                           "uncorrected Eq. 1 overestimates f"),
    Check("ingard_xi_below_0.4",
          lambda ev, f0: np.sqrt(ev.res.neck_area / ev.res.cavity_area) < models.INGARD_XI_LIMIT,
          lambda name, ev: f"{name}: Ingard's inner correction used at xi = {ev.res.diameter_ratio:.3g}, outside its "
                           f"stated xi < {models.INGARD_XI_LIMIT}"),
    Check("plane_waves_in_cavity", _plane_waves,
          lambda name, ev: f"{name}: cavity wider than the plane-wave limit at f0 (k*D/2 >= {PLANE_WAVE_CUTOFF_KA}); "
                           "1-D model unreliable"),
    Check("not_pancake", lambda ev, f0: ev.res.cavity_length / ev.res.cavity_diameter >= PANCAKE_L_OVER_D,
          lambda name, ev: f"{name}: flat cavity (L/D < {PANCAKE_L_OVER_D}); radial modes add a few percent error"),
    Check("quasi_static_wall", lambda ev, f0: wall_model.quasi_static_valid(ev.static_modes, f0),
          lambda name, ev: f"{name}: the cap's wall modes lie below {wall_model.QUASI_STATIC_RATIO:g} x f0, where a "
                           "quasi-static (massless) wall is invalid: it ignores the wall's inertia, which moves f up "
                           "when the modes lie below f; use elastic_wall or --model fem"),
    Check("wall_shape_in_table", lambda ev, f0: wall_model.shape_in_table(ev.cap_shape),
          lambda name, ev: f"{name}: the cap's shape lies outside the wall-mode table (clamped to its edge); check with "
                           "--model fem"),
    Check("no_wall_mode_near_f", lambda ev, f0: np.logical_not(wall_model.mode_coupled_near(ev.dynamic_modes, f0)),
          lambda name, ev: f"{name}: a cap wall mode with volume coupling lies within "
                           f"{100 * wall_model.HYBRID_BAND:.0f} % of f0: cavity and wall hybridise, two resonances can "
                           "compete, and this fast model's measured error is larger there (the band carries it); check "
                           "with --model fem"),
    Check("mode_in_cavity", None,
          lambda name, ev: f"{name}: the mode found keeps less than {MODE_IN_CAVITY_FRACTION:g} of its energy in the "
                           "cavity: it may be a mode of the air outside, not the taxel's; refine with --fem-level or "
                           "trust the transmission line"),
    Check("fundamental_found", None,
          lambda name, ev: f"{name}: no resonance with Q above 1 was found near the guess: the FEM did not resolve the "
                           "taxel's fundamental; refine with --fem-level or trust the cheaper rungs"),
)}
"""Every check by name; a model's checks are evaluated in the order it lists them."""


def evaluate(names, ev, f0_hz) -> dict:
    """{check: passed} for the named checks at ``f0_hz``: plain bools for a scalar design, bool arrays for a sweep's."""
    out = {name: CHECKS[name].test(ev, f0_hz) for name in names}
    return {k: bool(v) for k, v in out.items()} if np.ndim(f0_hz) == 0 else out


REFERENCE = "reference_"
"""Prefix of a check the 'relative' model ran on its reference taxel (a hybridised reference makes ratios
unreliable, however clean this design is)."""


def warnings(model: str, checks: dict, ev, reference_ev=None) -> list[str]:
    """The warning of every failed check of ``model``, in its order; checks named :data:`REFERENCE` + a check ran
    on the reference taxel (``reference_ev``)."""
    out = []
    for name, ok in checks.items():
        if ok:
            continue
        if name.startswith(REFERENCE):
            out.append(CHECKS[name[len(REFERENCE):]].warning(f"{model} (on the reference taxel)", reference_ev)
                       + "; a ratio to this reference is unreliable: its doublet and the ratio's modulus spread are in "
                         "the band")
        else:
            out.append(CHECKS[name].warning(model, ev))
    return out
