"""build123d helpers shared by the 3-D parts: aligned primitives and a flat part as a solid (mm)."""

from build123d import Align, Box, Cone, Cylinder, Pos

BOTTOM = (Align.CENTER, Align.CENTER, Align.MIN)
TOP = (Align.CENTER, Align.CENTER, Align.MAX)


def cylinder_up(radius: float, height: float, x: float = 0.0, y: float = 0.0, z: float = 0.0):
    """Cylinder along +z with its base centred at (x, y, z) (mm)."""
    return Pos(x, y, z) * Cylinder(radius, height, align=BOTTOM)


def frustum_up(bottom_radius: float, top_radius: float, height: float, x=0.0, y=0.0, z=0.0):
    """Truncated cone along +z with its base at (x, y, z); a cylinder when the radii are equal (mm)."""
    if abs(bottom_radius - top_radius) < 1e-9:
        return cylinder_up(bottom_radius, height, x, y, z)
    return Pos(x, y, z) * Cone(bottom_radius, top_radius, height, align=BOTTOM)


def tilted_cylinder(radius: float, length: float, end, theta_deg: float):
    """Cylinder whose axis is (cos θ, 0, sin θ) — θ from the xy plane, tilted toward +x — ending at point ``end``
    and reaching ``length`` back from it (mm, degrees)."""
    from build123d import Location, Rot

    tilt = 90.0 - theta_deg  # rotating +z about y by (90 − θ) gives (cos θ, 0, sin θ)
    return Location(tuple(end)) * Rot(0, tilt, 0) * Cylinder(radius, length, align=(Align.CENTER, Align.CENTER,
                                                                                     Align.MAX))


def flat_solid(flat, z0: float = 0.0):
    """A laser part (design intent, finished sizes) as a solid from z0 to z0 + thickness (mm)."""
    body = Pos(0, 0, z0) * Box(flat.width, flat.depth, flat.thickness, align=BOTTOM)
    return body.cut(*(cylinder_up(h.diameter / 2, flat.thickness, h.x, h.y, z0) for h in flat.holes))


def engraved(engravings, top: float, depth: float) -> list:
    """Solids to subtract from a part to recess ``engravings`` (glyph outlines, :func:`engraving_outlines`)
    ``depth`` into its face at z = ``top``: letter faces built with even-odd nesting (outer loop minus its
    counters), extruded from top − depth to 1 mm above the face (mm)."""
    from build123d import Face, Solid, Vector, Wire

    from matcad.parts.flat import engraving_outlines, even_odd_faces

    def loop(points):
        return Wire.make_polygon([(x, y, top - depth) for x, y in points], close=True)

    return [Solid.extrude(Face(loop(outer), [loop(p) for p in inner]), Vector(0, 0, depth + 1.0))
            for t in engravings for outer, inner in even_odd_faces(engraving_outlines(t))]
