"""Triangle meshes for the design page's 3-D view (mm): a build123d solid's triangulation read straight from the
kernel into numpy, and a part made by a :class:`matcad.parts.recipe.Recipe` as mesh booleans (manifold3d) of its
tools' meshes, which the preview keeps between edits (:class:`matcad.serve.preview.PartCache`).

The preview cuts the same tools from the same stock in the same two steps as the build, on meshes of the tools
made at the preview's tolerance, so what it draws is the built part to within that tessellation
(``tests/test_preview_cache.py`` compares volume, area, genus, bounds and the volume in one but not the other with
the built solid). After a cap edit on the 4-taxel board this takes ~0.2 s CPU (meshing that cap's tools ~0.05 s,
the mesh booleans ~0.14 s), where the build's B-rep booleans and build123d's tessellation took ~2 s
(``benchmarks/page.py --cpu``).
"""

from __future__ import annotations

SNAP_DECIMALS = 6
"""Tool vertices are rounded to 1e-6 mm before the mesh booleans: the kernel leaves ~1e-16 mm of round-off where a
solid was turned (a cap's base face turned upside down is tilted by that much), and faces meant to be coplanar
must be exactly coplanar for the booleans to treat them as such (else a film of zero thickness is left)."""


def triangulate(shape, tolerance: float, angular_tolerance_rad: float):
    """``shape``'s triangulation as (vertices (n, 3) float mm, triangles (m, 3) int, outward by the right-hand
    rule): the faces' triangulations in the kernel's face order, each face's nodes its own (as build123d's
    ``Shape.tessellate``, same parameters: the deflection relative to each edge's size), read node by node
    without a Python object per vertex."""
    import numpy as np
    from OCP.BRep import BRep_Tool
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.BRepTools import BRepTools
    from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopLoc import TopLoc_Location
    from OCP.TopoDS import TopoDS

    wrapped = shape.wrapped
    if not BRepTools.Triangulation_s(wrapped, tolerance):
        BRepMesh_IncrementalMesh(wrapped, tolerance, True, angular_tolerance_rad, True)
    vertices, triangles, offset = [], [], 0
    explorer = TopExp_Explorer(wrapped, TopAbs_FACE)
    while explorer.More():
        face = TopoDS.Face(explorer.Current())
        explorer.Next()
        location = TopLoc_Location()
        poly = BRep_Tool.Triangulation_s(face, location)
        if poly is None:
            continue
        nodes = np.array([poly.Node(i).Coord() for i in range(1, poly.NbNodes() + 1)], dtype=float)
        if not location.IsIdentity():
            t = location.Transformation()
            m = np.array([[t.Value(r, c) for c in range(1, 5)] for r in range(1, 4)])
            nodes = nodes @ m[:, :3].T + m[:, 3]
        tri = np.array([poly.Triangle(i).Get() for i in range(1, poly.NbTriangles() + 1)], dtype=np.int64)
        if face.Orientation() == TopAbs_REVERSED:
            tri = tri[:, [0, 2, 1]]
        vertices.append(nodes)
        triangles.append(tri - 1 + offset)
        offset += len(nodes)
    if not vertices:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    return np.concatenate(vertices), np.concatenate(triangles)


def manifold(shape, tolerance: float, angular_tolerance_rad: float):
    """``shape`` as a closed manifold3d mesh: :func:`triangulate`, the vertices snapped
    (:data:`SNAP_DECIMALS`) and shared between faces. ValueError if the triangulation is not closed."""
    import manifold3d
    import numpy as np

    vertices, triangles = triangulate(shape, tolerance, angular_tolerance_rad)
    snapped = np.round(vertices, SNAP_DECIMALS).astype(np.float32) + np.float32(0.0)  # -0.0 → 0.0
    unique, index = np.unique(snapped, axis=0, return_inverse=True)
    mesh = manifold3d.Manifold(manifold3d.Mesh(vert_properties=np.ascontiguousarray(unique),
                                               tri_verts=index.reshape(-1)[triangles].astype(np.uint32)))
    if mesh.status() != manifold3d.Error.NoError:
        raise ValueError(f"a tool's triangulation is not a closed surface ({mesh.status().name})")
    return mesh


def recipe_mesh(recipe, tool_meshes):
    """The part ``recipe`` makes, as a manifold3d mesh: the stock fused with the ``add`` tools' meshes, then the
    ``cut`` tools' meshes subtracted, each step one batch boolean like the build's. ``tool_meshes(tool)`` gives a
    tool's meshes (one per solid it makes; the caller keeps them)."""
    from manifold3d import Manifold, OpType

    part = Manifold.batch_boolean([*tool_meshes(recipe.stock), *(m for t in recipe.add for m in tool_meshes(t))],
                                  OpType.Add)
    return Manifold.batch_boolean([part, *(m for t in recipe.cut for m in tool_meshes(t))], OpType.Subtract)
