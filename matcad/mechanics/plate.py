"""The neck plate as a beam: how far a force on one taxel bends it, in closed form (mm, N, MPa).

The plate is bolted at its four corners over spacers and pressed through a cap between them. Along its long side
it is a beam of the plate's full width spanning the two bolt rows; matcad takes it as simply supported there
(the spacers are 5 mm squares under a bolt that may tilt: a clamped end would halve the centre deflection or
better, so this is the softer, safer end). The deflection of a simply supported beam under a concentrated load is
Roark's Formulas for Stress and Strain (Young & Budynas, 7th ed., Table 8.1, case 1e); it is exact for a slender
beam in small deflection, the limit of a long narrow board. Left out, each named where :func:`deflection_mm` is
used: the holes, the guides bolted over the plate (unbonded, holed by the flanges: they add little), the
two-way action of a squarer plate on point supports (softer than the beam there), large deflection (beyond about
half the thickness a plate held in-plane stiffens; one on bolts in clearance holes barely is). With support
posts under it (:func:`matcad.parts.stack.plate_deflection_mm`) the same simply supported beam spans the bay
between the support lines either side of the load, and a cantilever (:func:`cantilever_deflection_mm`) carries
the load from the post line out to the neck.
"""

from __future__ import annotations

import numpy as np


def second_moment_mm4(width_mm: float, thickness_mm: float) -> float:
    """Second moment of area of a rectangular section about its neutral axis, b t³ / 12 (mm⁴)."""
    return width_mm * thickness_mm ** 3 / 12.0


def deflection_mm(force_n: float, load_mm: float, at_mm, span_mm: float, width_mm: float, thickness_mm: float,
                  modulus_mpa: float):
    """Deflection (mm, positive in the load's direction) at ``at_mm`` (a position or an array of them, measured
    from one support) of a simply supported beam of span ``span_mm`` and rectangular section ``width_mm`` x
    ``thickness_mm`` (modulus ``modulus_mpa``), under ``force_n`` at ``load_mm`` from the same support. Roark,
    Table 8.1 case 1e: for x < a, y = W b x (l² − b² − x²) / (6 E I l), b = l − a, and the mirror image beyond the
    load; under the load W a² b² / (3 E I l); at mid-span under a central load W l³ / (48 E I). Positions are
    clipped to the span (beyond a support nothing is modelled)."""
    ei = modulus_mpa * second_moment_mm4(width_mm, thickness_mm)
    l = span_mm
    a = float(np.clip(load_mm, 0.0, l))
    x = np.clip(np.asarray(at_mm, dtype=float), 0.0, l)
    near = force_n * (l - a) * x * (l * l - (l - a) ** 2 - x * x)
    far = force_n * a * (l - x) * (2 * l * x - x * x - a * a)
    return np.where(x <= a, near, far) / (6.0 * ei * l)


def cantilever_deflection_mm(force_n: float, length_mm: float, width_mm: float, thickness_mm: float,
                             modulus_mpa: float) -> float:
    """Deflection (mm, in the load's direction) at the free end of a cantilever of ``length_mm`` and rectangular
    section ``width_mm`` x ``thickness_mm`` (modulus ``modulus_mpa``), fixed at its root and loaded by ``force_n``
    at its free end: W l³ / (3 E I) (Roark, Table 8.1 case 1a). Exact for a slender beam in small deflection; 0
    for a zero length."""
    return force_n * length_mm ** 3 / (3.0 * modulus_mpa * second_moment_mm4(width_mm, thickness_mm))
