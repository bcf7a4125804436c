"""The cap pressed by a rigid flat plate: axisymmetric, large strain, nearly incompressible (FElupe).

Model (units mm, N, MPa): the cap section of :mod:`matcad.mechanics.mesh` in bilinear quads with FElupe's
u–p–J formulation (``SolidBodyNearlyIncompressible``: constant pressure and volume ratio per cell, condensed,
so no volumetric locking; Simo, Taylor & Pister 1985). Base bonded to the neck plate (all displacements zero),
flange top and rim held by the clamp guide, axis r = 0 radially fixed. The plate is a rigid line z = H − x driven
by a reference node: ``sticking`` ties the top face to it (no slip, the silicone is tacky), ``frictionless``
makes every top node a unilateral frictionless contact (``MultiPointContact``, a penalty); in both, the free
outside of the body may roll onto the plate without friction. F is the plate's reaction (N, the whole ring).

Load steps are equal plate increments to ``displacement_mm``; a step whose Newton iterations (at most
``MAX_NEWTON``) do not converge, that inverts a cell, or that ends in a state the model cannot hold (a cell's
volume ratio off 1 by more than ``J_TOLERANCE``, or a cavity larger than at the step before: the cavity surface
folded through itself, whose self-contact is not modelled), is cut in half, at most ``MAX_CUTS`` times, and a whole
curve spends at most ``NEWTON_BUDGET_PER_STEP`` × max(steps, ``BUDGET_MIN_STEPS``) iterations; past either bound
the curve stops at the last converged step and :attr:`CapCurve.message` says where and why. A failed step restores
the last converged state of every item that keeps one (FElupe's ``checkpoint``/``restore``): the displacements and
the nearly-incompressible solid's condensed pressure and volume ratio, so that the curve's end does not depend on
``steps`` (paper cap, 1/2/3/4/10 steps: 0/1.0/1.33/1.5/2.0 mm of 2 mm before, all 2.0 mm now).
"""

from __future__ import annotations

import dataclasses
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from matcad.mechanics.material import Hyperelastic
from matcad.mechanics.mesh import CapMesh, mesh_section
from matcad.mechanics.section import CapSection, cavity_volume_mm3

CONTACTS = ("sticking", "frictionless")
MAX_NEWTON = 12
MAX_CUTS = 5
NEWTON_BUDGET_PER_STEP = 40
BUDGET_MIN_STEPS = 10
"""All Newton iterations of a curve, failed ones included, stay below NEWTON_BUDGET_PER_STEP × max(steps,
BUDGET_MIN_STEPS): a bound on the run time. A curve asked in fewer steps than the default 10 gets the default's
budget, since its step cuts make the steps it did not ask for (1 step ran out after its first cut before)."""
NEWTON_TOL = 1e-8
J_TOLERANCE = 0.01
"""A converged step whose cells' volume ratio J leaves 1 ± this is not a state of the silicone: K/G = 1000 keeps J
within 1e-3 of 1 at the cap's stresses (:data:`matcad.mechanics.material.BULK_PER_SHEAR`), so ten times that is a
hydrostatic stress of ~10 G, met only where the cavity's creased surface passes through itself (Ogden thin top and
thick cap at 40 % travel: J 0.974 and 0.981, the cavity volume jumping from 5.9 to 24.0 mm³)."""
PENALTY_PER_G_MM = 1e5
"""Contact penalty = this × G × outer radius (N/mm): a plate penetration below 1e-4 mm at the cap's forces."""


@dataclass(frozen=True)
class CapStep:
    """One converged load step: plate travel ``displacement_mm`` (mm), plate force ``force_n`` (N), cavity volume
    (mm³), the deformed cavity outline (k, 2) as (r, z) mm from the wall's foot to the axis, the peak principal
    Hencky strain |ln λ| (cell means) and the range over the cells of their volume ratio J (deformed / undeformed
    revolved volume)."""

    displacement_mm: float
    force_n: float
    cavity_volume_mm3: float
    cavity_outline: np.ndarray = field(repr=False)
    peak_strain: float
    volume_ratio_range: tuple[float, float]


@dataclass(frozen=True)
class CapCurve:
    """A load curve: unloaded volume and cavity outline (``outline[corner]`` is where wall meets closed end), the
    converged steps, whether it reached the asked travel (``complete``),
    a ``message`` when it did not, the mesh size and the run time."""

    section: CapSection
    material: Hyperelastic
    contact: str
    unloaded_volume_mm3: float
    unloaded_outline: np.ndarray = field(repr=False)
    corner: int
    steps: tuple[CapStep, ...]
    complete: bool
    message: str
    nodes: int
    cells: int
    element_size_mm: float
    newton_iterations: int
    seconds: float

    def split(self, outline: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A cavity outline as (wall from its foot to the corner, closed end from the corner to the axis)."""
        return outline[:self.corner + 1], outline[self.corner:]

    def scaled(self, factor: float) -> CapCurve:
        """This curve for the same silicone ``factor`` times as stiff: every force times ``factor``, the rest the
        same. Exact for these laws: each has one modulus scale (K/G fixed, the contact penalty ∝ G), so
        equilibrium at travel x holds with every stress, hence the plate's force, scaled by it."""
        if factor == 1.0:
            return self
        return dataclasses.replace(self, material=self.material.scaled(factor),
                                   steps=tuple(dataclasses.replace(s, force_n=s.force_n * factor) for s in self.steps))

    def column(self, name: str) -> np.ndarray:
        """One per-step quantity as an array, the unloaded state (0, 0, V0) first: displacement_mm, force_n,
        cavity_volume_mm3, peak_strain."""
        start = {"displacement_mm": 0.0, "force_n": 0.0, "cavity_volume_mm3": self.unloaded_volume_mm3,
                 "peak_strain": 0.0}[name]
        return np.array([start] + [getattr(s, name) for s in self.steps])


def _cell_volumes_mm3(points_rz: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Revolved volume of each quad (mm³), Pappus: (π/3)·Σ (r_i² + r_i r_j + r_j²)(z_i − z_j) over its edges."""
    p = points_rz[cells]
    r, z = p[..., 0], p[..., 1]
    r1, z1 = np.roll(r, -1, axis=1), np.roll(z, -1, axis=1)
    return np.pi / 3 * np.sum((r * r + r * r1 + r1 * r1) * (z - z1), axis=1)


def _cell_strains(field_container, cells: int) -> np.ndarray:
    """Peak principal Hencky strain |ln λ| of each cell's mean deformation gradient."""
    f = field_container.extract(grad=True, sym=False, add_identity=True)[0].mean(axis=2)
    f = np.moveaxis(f, (0, 1), (-2, -1)).reshape(cells, 3, 3)
    stretch2 = np.linalg.eigvalsh(np.einsum("...ki,...kj->...ij", f, f))
    return np.max(np.abs(0.5 * np.log(stretch2)), axis=1)


def _finite_spsolve(a, b):
    """scipy's sparse solve, refusing a non-finite stiffness or residual (a diverging Newton step) before SuperLU
    sees it: BLAS prints 'illegal value' warnings on such input and SuperLU may crash, whereas a FloatingPointError
    makes the caller cut the step."""
    from scipy.sparse.linalg import spsolve

    if not (np.isfinite(a.data).all() and np.isfinite(b).all()):
        raise FloatingPointError("the Newton step diverged (non-finite stiffness or residual)")
    return spsolve(a, b)


def _singular_corner(cm: CapMesh, sec: CapSection, point) -> str:
    """Name the sharp corner next to ``point`` (r, z mm), where the surface creases first, or ''."""
    near = 3 * cm.element_size_mm
    if len(cm.cavity) and np.min(np.hypot(*(cm.points[cm.cavity] - point).T)) < near:
        return " (the cavity surface creases there: its self-contact is not modelled)"
    if np.hypot(point[0] - sec.outer_radius, point[1] - sec.flange_thickness) < near:
        return " (the body folds over the clamp guide's edge there)"
    if np.hypot(point[0] - sec.outer_radius, point[1] - sec.height) < near:
        return " (the body folds onto the plate at the top edge there)"
    return ""


def cap_curve(case, progress=None) -> CapCurve:
    """The load curve of a :class:`~matcad.mechanics.case.CapCase` (see :func:`compress`), read from the disk cache
    of :mod:`matcad.mechanics.store` when an earlier run computed this case with this code, else computed and
    stored. ``progress(steps done, steps)`` is told as each load step converges (:mod:`matcad.progress`)."""
    from matcad.mechanics import store

    curve = store.load(case, CapCurve, CapStep)
    if curve is None:
        curve = compress(case.section, case.material, case.contact, case.displacement_mm, case.steps,
                         case.element_size_mm, progress=progress)
        store.save(case, curve)
    return curve


class UnphysicalStep(ArithmeticError):
    """A step converged to a state the model cannot hold (:func:`unphysical`): cut like one that did not converge."""


def unphysical(j_range: tuple[float, float], volume_mm3: float, previous_mm3: float) -> str:
    """Why a converged step is not a state of the pressed silicone cap ('' when it is): its cells' volume ratio
    range ``j_range`` leaves 1 ± :data:`J_TOLERANCE`, or its cavity (``volume_mm3``, mm³) is not smaller than at the
    step before (``previous_mm3``; a body without a cavity, 0, is not checked): a press only shrinks the cavity; it
    grows when the creased surface has folded through itself, whose self-contact is not modelled."""
    if max(1 - j_range[0], j_range[1] - 1) > J_TOLERANCE:
        return (f"a cell's volume ratio J = {j_range[0]:.4f}-{j_range[1]:.4f} left 1 ± {J_TOLERANCE:g} (nearly "
                "incompressible silicone)")
    if previous_mm3 > 0 and not volume_mm3 < previous_mm3:
        return (f"the cavity grew from {previous_mm3:.4g} to {volume_mm3:.4g} mm³ under the press (its surface "
                "folded through itself)")
    return ""


def compress(sec: CapSection, material: Hyperelastic, contact: str = "sticking", displacement_mm: float = 2.0,
             steps: int = 10, element_size_mm: float | None = None, mesh: CapMesh | None = None,
             linear: bool = False, progress=None) -> CapCurve:
    """Press the cap ``sec`` by ``displacement_mm`` (mm) in ``steps`` equal steps; F(x), V(x), outlines, strain.

    ``mesh`` replaces the cap's own (e.g. :func:`matcad.mechanics.mesh.disc_mesh` for the bonded-disc check);
    ``linear`` swaps the hyperelastic law for small-strain linear elasticity with the same G and K on the same
    mesh (the small-strain reference; displacement-based cells, so keep K/G moderate there).
    Never raises for a non-converging case: the returned curve stops at its last converged step with a message.
    Raises ValueError for a bad ``contact`` or non-positive travel/steps.
    """
    import felupe as fem

    if contact not in CONTACTS:
        raise ValueError(f"contact {contact!r} invalid, must be one of {', '.join(CONTACTS)}")
    if not displacement_mm > 0 or steps < 1:
        raise ValueError(f"displacement_mm = {displacement_mm!r} and steps = {steps!r} must be > 0 and >= 1")
    t0 = time.perf_counter()
    cm: CapMesh = mesh if mesh is not None else mesh_section(sec, element_size_mm)
    n = len(cm.points)
    ref, guide = n, n + 1  # reference nodes of the plate and of the clamp guide's face, points without cells
    points = np.vstack([cm.points[:, ::-1], [[sec.height * (1 + 1e-9), 0.0], [sec.flange_thickness * (1 - 1e-9), 0.0]]])
    mesh = fem.Mesh(points, cm.cells[:, ::-1].copy(), "quad")
    u = fem.FieldAxisymmetric(fem.RegionQuad(mesh), dim=2)
    fields = fem.FieldContainer([u])
    if linear:
        g_mpa, k_mpa = material.shear_modulus_mpa, material.bulk_modulus_mpa
        nu = (3 * k_mpa - 2 * g_mpa) / (2 * (3 * k_mpa + g_mpa))
        solid = fem.SolidBody(fem.LinearElastic(E=2 * g_mpa * (1 + nu), nu=nu), fields)
    else:
        solid = fem.SolidBodyNearlyIncompressible(material.umat(), fields, bulk=material.bulk_modulus_mpa)
    penalty = PENALTY_PER_G_MM * material.shear_modulus_mpa * sec.outer_radius
    # the body bulges over the clamp guide's face (z = flange top): without this contact it folds through it
    items = [solid, fem.MultiPointContact(fields, cm.side, guide, skip=(False, True), multiplier=penalty)]
    if contact == "sticking":
        items += [fem.MultiPointConstraint(fields, cm.top, ref, multiplier=penalty),
                  fem.MultiPointContact(fields, cm.side, ref, skip=(False, True), multiplier=penalty)]
    else:
        items += [fem.MultiPointContact(fields, np.concatenate([cm.top, cm.side]), ref, skip=(False, True),
                                        multiplier=penalty)]
    mask = np.zeros(n + 2, dtype=bool)

    def at(ids):
        m = mask.copy()
        m[ids] = True
        return m

    plate = fem.Boundary(u, mask=at([ref]), skip=(0, 1))
    boundaries = {"held": fem.Boundary(u, mask=at(np.concatenate([cm.base, cm.clamp, [guide]]))),
                  "axis": fem.Boundary(u, mask=at(cm.axis), skip=(1, 0)),
                  "plate_radial": fem.Boundary(u, mask=at([ref]), skip=(1, 0)), "plate": plate}
    dof0, dof1 = fem.dof.partition(fields, boundaries)
    outline0 = cm.points[cm.cavity]
    v0 = cavity_volume_mm3(outline0)
    volumes0 = _cell_volumes_mm3(cm.points, cm.cells)
    centres, hot = cm.points[cm.cells].mean(axis=1), np.zeros(2)
    converged = [v0]  # the cavity volume (mm³) of the last converged step, sub-steps included

    def solve_at(x):
        plate.value = -x
        ext0 = fem.dof.apply(fields, boundaries, dof0)
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            res = fem.newtonraphson(items=items, dof1=dof1, dof0=dof0, ext0=ext0, maxiter=MAX_NEWTON,
                                    tol=NEWTON_TOL, verbose=0, solver=_finite_spsolve)
            strains = _cell_strains(fields, len(cm.cells))
            strain = float(strains.max())
            deformed = cm.points + u.values[:n, ::-1]
            ratio = _cell_volumes_mm3(deformed, cm.cells) / volumes0
        if not (np.isfinite(strain) and ratio.min() > 0):
            raise FloatingPointError("a cell inverted (J <= 0)")
        hot[:] = centres[int(np.argmax(strains))]
        j_range = (float(ratio.min()), float(ratio.max()))
        force = float(-res.fun.reshape(-1, 2)[ref, 0])
        outline = deformed[cm.cavity]
        volume = cavity_volume_mm3(outline)
        problem = unphysical(j_range, volume, converged[-1])
        if problem:
            raise UnphysicalStep(problem)
        return res.iterations, CapStep(x, force, volume, outline, strain, j_range)

    results: list[CapStep] = []
    step = displacement_mm / steps
    x_done, inc, iterations, message = 0.0, step, 0, ""
    for target in np.linspace(step, displacement_mm, steps):
        while x_done < target - 1e-12 * displacement_mm:
            dx = min(inc, target - x_done)
            if iterations > NEWTON_BUDGET_PER_STEP * max(steps, BUDGET_MIN_STEPS):
                message = (f"stopped at x = {x_done:.4g} mm (last converged step) of {displacement_mm:g} mm: "
                           f"{iterations} Newton iterations spent (budget {NEWTON_BUDGET_PER_STEP} per step, at "
                           f"least {BUDGET_MIN_STEPS} steps), the curve is too hard to follow here")
                break
            saved = [(item, item.checkpoint()) for item in items if hasattr(item, "checkpoint")]
            try:
                its, state = solve_at(x_done + dx)
            except (ValueError, ArithmeticError, RuntimeError, np.linalg.LinAlgError) as exc:
                for item, checkpoint in saved:  # the displacements and the condensed pressure and volume ratio
                    item.restore(checkpoint)
                iterations += MAX_NEWTON
                inc = dx / 2
                if inc < step / 2 ** MAX_CUTS:
                    reason = str(exc).strip().splitlines()[0]
                    crease = _singular_corner(cm, sec, hot)
                    message = (f"stopped at x = {x_done:.4g} mm (last converged step) of {displacement_mm:g} mm: "
                               f"{'no physical state' if isinstance(exc, UnphysicalStep) else 'no convergence'} "
                               f"at x = {x_done + dx:.4g} mm after {MAX_CUTS} step cuts ({reason}); "
                               f"G = {material.shear_modulus_mpa:g} MPa, top {sec.top_thickness:g} mm; peak strain "
                               f"{results[-1].peak_strain if results else 0:.2f} in the cell at r = {hot[0]:.2f}, "
                               f"z = {hot[1]:.2f} mm{crease}")
                    break
                continue
            iterations += its
            converged.append(state.cavity_volume_mm3)
            x_done = x_done + dx
            inc = min(step, 2 * dx)
        if message:
            if x_done > 0 and (not results or results[-1].displacement_mm < x_done):
                results.append(state)  # the last converged sub-step: the curve ends where the message says
            break
        results.append(state)
        if progress is not None:
            progress(len(results), steps)
    return CapCurve(section=sec, material=material, contact=contact, unloaded_volume_mm3=v0,
                    unloaded_outline=outline0, corner=cm.corner, steps=tuple(results), complete=not message, message=message,
                    nodes=n, cells=len(cm.cells), element_size_mm=cm.element_size_mm, newton_iterations=iterations,
                    seconds=time.perf_counter() - t0)
