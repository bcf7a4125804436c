"""One design as the models see it: its resonator and, for the wall models, the cap's modes, each computed once.

Also the words each wall model uses for its source, with the numbers of one evaluation. Lengths mm, moduli Pa,
frequencies Hz.
"""

from __future__ import annotations

from functools import cached_property

from matcad.acoustics import wall as wall_model
from matcad.acoustics.design import Design
from matcad.acoustics.resonator import cap_shape, resonator, wall_modes


class Evaluation:
    """``design`` with its :class:`~matcad.acoustics.resonator.Resonator` (given, or computed from the design) and,
    on first use, the cap's shape and its wall modes at the middle of the silicone's static and kHz modulus
    ranges."""

    def __init__(self, design: Design, res=None):
        self.design = design
        self.res = resonator(design) if res is None else res

    @cached_property
    def cap_shape(self) -> wall_model.CapShape:
        return cap_shape(self.res)

    @cached_property
    def static_modes(self) -> wall_model.Modes:
        return wall_modes(self.res, self.design.wall.static_moduli_pa()[1])

    @cached_property
    def dynamic_modes(self) -> wall_model.Modes:
        return wall_modes(self.res, self.design.wall.dynamic_moduli_pa()[1])


def describe_end_corrected(ev: Evaluation, f0_hz: float) -> str:
    return f"Eq. 1 with l + {ev.design.mouth} outer correction + Ingard 1953 inner correction"


def describe_soft_wall(ev: Evaluation, f0_hz: float) -> str:
    static = ev.design.wall.static_moduli_pa()[1]
    return (f"transmission line with a quasi-static (massless) silicone wall (Lame cylinder + half-space end) at "
            f"G = {static / 1e6:.3g} MPa static; valid only when the cap's wall modes lie >= "
            f"{wall_model.QUASI_STATIC_RATIO:g} x f")


def describe_elastic_wall(ev: Evaluation, f0_hz: float) -> str:
    dynamic, loss = ev.design.wall.dynamic_moduli_pa()[1], ev.design.wall.loss_factors()[1]
    coupled = ", ".join(f"{f:.0f}" for f in ev.dynamic_modes.coupled_hz()[:4])
    return (f"transmission line coupled to the cap's wall modes (from the coupled FEM's elastic operator, "
            f"wall_modes.json) at G = {dynamic / 1e6:.3g} MPa (kHz), eta = {loss:.2g}; coupled wall modes "
            f"{coupled} Hz; peak of the driven response")
