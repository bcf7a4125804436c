"""The end correction of a tube's mouth by a 3-D finite-element potential-flow solve (scikit-fem, P1 tetrahedra on
:mod:`matcad.acoustics.fem_cut`'s meshes). Lengths mm.

At low frequency (the fipple tube's f1 has ka ≈ 0.16) the air at a mouth moves as an incompressible potential flow,
and the mouth's end correction δ is that flow's inertance in excess of the bore's, as a length of bore (Rayleigh,
The Theory of Sound II §303–306: 1/δ·S is his conductance). Solved here: ∇²φ = 0 in the air; a uniform unit flux
into the bore across its section where it leaves the far box (``FAR_PER_A`` radii from the mouth); rigid walls
(∂φ/∂n = 0) elsewhere, the plane of symmetry y = 0 among them; and on the far box the monopole's condition
∂φ/∂n = −(n·r/|r|²) φ, r from the mouth (exact for the far field of a source of net flux). Then
δ = S φ̄ / Q − (the plane's distance from the mouth), S the bore's discrete cross-section, φ̄ φ's mean over it. The (ka)² term of δ is not in this route (an unflanged pipe's δ falls
by 0.0044 a from ka = 0.048 to 0.182, docs/tube.md).

Mouths (:data:`MOUTHS`): ``fipple`` the printed window as :mod:`matcad.parts.tube` cuts it (the window through the
wall over the windway's width, the labium's two bevels above it, the bore's floor funnel below it; not the windway
slot, a dead end at ka → 0), its δ measured from the edge; ``transverse`` the side window of a transverse mouth
(its sides and gable, the funnel below; not the windway's boss), measured from its sides' top; ``baffled`` a pipe
ending in an infinite rigid baffle (Norris & Sheng 1989's 0.8216 a, the closed form that verifies this route); ``unflanged`` a pipe of wall w ending
in free space (the axisymmetric exterior FEM's geometry, :mod:`matcad.acoustics.fem`, the second route).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from matcad.acoustics import fem_cut
from matcad.spec.tube import EDGE_LAND_MM, SEAT_CONE_DEG, WINDOWED, transverse_floor_mm, transverse_window_mm

FAR_PER_A = 20.0
"""The far box's half size in bore radii (the monopole condition on it), and the bore's length to its driven end."""
DEFAULT_LEVEL = 8
"""Cells across the bore's radius near the mouth."""
CG_TOLERANCE = 1e-10
MOUTHS = ("fipple", "transverse", "baffled", "unflanged")


@dataclass(frozen=True)
class Mouth:
    """A mouth's geometry (mm, deg): the bore's radius ``a``, the printed wall, and for a window its width across
    the jet's path and height along the bore (a fipple's B and W; a transverse window's W and its sides' height,
    under a ``gable`` of that rise), a fipple's labium bevel, and the block's (a fipple) or the floor's (transverse)
    depth below the window (:func:`from_tube` fills them)."""

    kind: str
    a: float
    wall: float = 0.0
    window_width: float = 0.0
    window_height: float = 0.0
    edge_angle: float = 0.0
    block_length: float = 0.0
    gable: float = 0.0

    def __post_init__(self) -> None:
        if self.kind not in MOUTHS:
            raise ValueError(f"mouth {self.kind!r} invalid, must be one of {MOUTHS}")

    @property
    def mouth_z(self) -> float:
        """The plane δ is measured from (mm): a window's top (a fipple's edge, a transverse window's sides' top,
        where the spec's ``tube.length`` starts), the pipe's end otherwise."""
        return self.window_height if self.kind in WINDOWED else 0.0

    @property
    def plane_z(self) -> float:
        """The driven plane (mm): the far box's top, where the bore leaves it."""
        return self.mouth_z + FAR_PER_A * self.a

    @property
    def centre(self) -> np.ndarray:
        """Where the far field's monopole sits (mm)."""
        if self.kind in WINDOWED:
            return np.array([self.a + self.wall, 0.0, self.window_height / 2])
        return np.zeros(3)

    def distance(self, q: np.ndarray) -> np.ndarray:
        """Signed distance of points (3, n) to the solid (mm, > 0 in the air); the bore runs along +z from the mouth
        (z = 0) out of the far box."""
        x, y, z = q
        r = np.hypot(x, y)
        a = self.a
        bore = a - r
        if self.kind == "baffled":
            return np.maximum(-z, np.minimum(bore, z + a))  # the half space below the baffle, and the pipe
        outer = a + self.wall
        if self.kind == "unflanged":
            return np.maximum(np.maximum(r - outer, -z), bore)
        cone = math.radians(SEAT_CONE_DEG)
        floor = (np.minimum(z, 0.0) + a / math.tan(cone)) * math.tan(cone)  # the bore's radius, funnel below z = 0
        carved = np.where(z < 0, (floor - r) * math.cos(cone), a - r)
        body = np.minimum(outer - r, z + self.block_length)
        openings = self._transverse(x, y, z) if self.kind == "transverse" else self._fipple(x, y, z)
        return np.maximum.reduce([-body, carved, *openings])

    def _fipple(self, x, y, z) -> tuple:
        """The fipple's window through the wall over the windway's width and the labium's two bevels above it."""
        a, W, half = self.a, self.window_height, self.window_width / 2
        cone = math.radians(SEAT_CONE_DEG)
        bevel = math.radians(self.edge_angle)
        tip = a + EDGE_LAND_MM
        across = half - np.abs(y)
        window = np.minimum.reduce([across, x, z, W - z])
        # the labium's bevels, from halfway up the window (inside it there) so that no wall-less seam remains at z = W
        outside = np.minimum.reduce([across, z - W / 2, (x - tip - (z - W) * math.tan(bevel)) * math.cos(bevel)])
        inside = np.minimum.reduce([across, z - W / 2, x, (tip - (z - W) * math.tan(cone) - x) * math.cos(cone)])
        return window, outside, inside

    def _transverse(self, x, y, z) -> tuple:
        """The transverse window (:func:`matcad.parts.tube.transverse_tube`): through the wall on +x, W wide along
        y, its sides ``window_height`` high under the gable at 30° from vertical. Not the windway's boss beside it
        (it breaks the plane of symmetry y = 0; outside the tube, it moves δ little)."""
        half, cone = self.window_width / 2, math.radians(SEAT_CONE_DEG)
        roof = (self.window_height + (half - np.abs(y)) / math.tan(cone) - z) * math.sin(cone)
        return (np.minimum.reduce([half - np.abs(y), x, z, roof]),)

    def axes(self, level: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Grid lines (mm): cells a/level over the mouth and the tube's section, graded out to the far box."""
        a, h = self.a, self.a / level
        outer, far = a + self.wall, FAR_PER_A * a
        reach = outer + 0.5 * a
        top = self.plane_z
        xs = fem_cut.graded(-reach, reach, h, -far, far, planes=(0.0,))
        ys = fem_cut.graded(0.0, reach, h, 0.0, far, planes=(0.0, self.window_width / 2))
        ys = ys[ys >= 0]
        fine_top = self.mouth_z + max(1.5 * a, self.gable + 0.5 * a)
        below = fem_cut.graded(-a, fine_top, h, self.mouth_z - far, fine_top, planes=(0.0, self.mouth_z))
        zs = fem_cut.merged(np.concatenate([below, _bore_lines(fine_top, top, h, a)]), h / 4, (0.0, self.mouth_z))
        return xs, ys, zs


def _bore_lines(start: float, stop: float, h: float, a: float) -> np.ndarray:
    """Grid lines along the bore from the mouth's region to the driven plane (mm), growing from h by 1.25 to a:
    the flow there is plane, so long cells cost no accuracy."""
    lines, step = [start], h
    while lines[-1] < stop - 1e-9:
        step = min(step * 1.25, a)
        lines.append(min(lines[-1] + step, stop))
    return np.array(lines)


def from_tube(td) -> Mouth:
    """The :class:`Mouth` of a :class:`matcad.acoustics.tube.TubeDesign` (its ``mouth``: fipple, transverse,
    flanged or unflanged; 'flanged' is the baffled pipe)."""
    if td.mouth == "transverse":
        sides, gable = transverse_window_mm(td.windway_height, td.windway_width, td.edge_distance)
        a = td.bore_diameter / 2
        return Mouth("transverse", a, td.tube_wall, td.edge_distance, sides, 0.0,
                     transverse_floor_mm(a, td.tube_wall), gable)
    kind = {"flanged": "baffled"}.get(td.mouth, td.mouth)
    return Mouth(kind, td.bore_diameter / 2, td.tube_wall, td.windway_width, td.edge_distance, td.edge_angle,
                 td.block_length)


@dataclass(frozen=True)
class MouthResult:
    """δ (mm) at one level, with the mesh's node count."""

    delta_mm: float
    level: int
    nodes: int


def end_correction(mouth: Mouth, level: int = DEFAULT_LEVEL) -> MouthResult:
    """δ (mm) of ``mouth`` by the 3-D potential-flow FEM with ``level`` cells across the bore's radius."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components
    from scipy.sparse.linalg import cg
    from skfem import Basis, BilinearForm, ElementTetP1, FacetBasis, LinearForm, MeshTet, asm
    from skfem.helpers import dot, grad

    xs, ys, zs = mouth.axes(level)
    points, tets = fem_cut.mesh(xs, ys, zs, mouth.distance)
    m = MeshTet(points, tets)
    facets = m.boundary_facets()
    mid = m.p[:, m.facets[:, facets]].mean(1)
    driven_mask = (np.abs(mid[2] - mouth.plane_z) < 1e-9) & (np.hypot(mid[0], mid[1]) < mouth.a)
    far_mask = ((np.abs(mid[0] - xs[0]) < 1e-9) | (np.abs(mid[0] - xs[-1]) < 1e-9) | (np.abs(mid[1] - ys[-1]) < 1e-9)
                | (np.abs(mid[2] - zs[0]) < 1e-9) | ((np.abs(mid[2] - zs[-1]) < 1e-9) & ~driven_mask))
    element = ElementTetP1()
    driven = FacetBasis(m, element, facets=facets[driven_mask])
    section = float(driven.dx.sum())
    centre = mouth.centre[:, None, None]

    @BilinearForm
    def laplace(u, v, w):
        return dot(grad(u), grad(v))

    @BilinearForm
    def far_field(u, v, w):
        r = w.x - centre
        return (w.n * r).sum(0) / (r**2).sum(0) * u * v

    @LinearForm
    def inflow(v, w):
        return v / section

    k = asm(laplace, Basis(m, element)) + asm(far_field, FacetBasis(m, element, facets=facets[far_mask]))
    f = asm(inflow, driven)
    _, label = connected_components(k, directed=False)
    keep = np.nonzero(label == label[m.facets[0, facets[driven_mask][0]]])[0]  # the air joined to the bore
    ks = k[keep][:, keep].tocsr()
    phi = np.zeros(k.shape[0])
    phi[keep], info = cg(ks, f[keep], rtol=CG_TOLERANCE, maxiter=100 * len(keep), M=sp.diags(1 / ks.diagonal()))
    if info:
        raise RuntimeError(f"the potential-flow solve did not converge (level {level})")
    delta = section * float(f @ phi) - (mouth.plane_z - mouth.mouth_z)
    return MouthResult(delta, level, m.p.shape[1])
