"""Which parts a spec asks for, from the part registry. Laser parts are plain data; 3-D parts load build123d
only when asked."""

from __future__ import annotations

from matcad.parts.coupon import PRINTED_COUPON_POSE
from matcad.parts.flat import Flat
from matcad.parts.registry import Kind, PrintPose, parts, wanted

__all__ = ["PrintPose", "laser_parts", "print_poses", "in_print_pose", "printed_parts", "needs_cad_kernel"]


_LAST_LASER: list = [(None, ())]
"""The last spec :func:`laser_parts` was asked for and its parts, as one pair (read and replaced whole, so that
threads asking for different specs never mix them): the laser rules ask for one spec's parts in turn."""


def laser_parts(spec) -> list[Flat]:
    """Every laser part ``[outputs]`` asks for (design intent, finished sizes). Asked again for the very same spec
    object (specs are frozen), the same parts are given again without being made again."""
    last, parts = _LAST_LASER[0]
    if last is not spec:
        parts = tuple(p.make(spec) for p in wanted(spec, Kind.LASER))
        _LAST_LASER[0] = (spec, parts)
    return list(parts)


def print_poses() -> dict[str, PrintPose]:
    """Print orientation of every exported 3-D part (each registered part's pose, and the printed coupon's):
    flat face down, no overhang that needs support."""
    return {p.name: p.pose for p in parts() if p.pose is not None} | {"coupon_printed": PRINTED_COUPON_POSE}


def in_print_pose(name: str, solid):
    """``solid`` (design frame) turned into its print pose: (solid, 4 x 4 matrix design → print frame)."""
    from build123d import Pos, Rot

    pose = print_poses()[name]
    turned = Rot(pose.rx_deg, 0, 0) * solid if pose.rx_deg else solid
    z_min = turned.bounding_box(optimal=True).min.Z
    return Pos(0, 0, -z_min) * turned, pose.matrix(z_min)


def printed_parts(spec) -> dict[str, object]:
    """Name → build123d solid, in its design frame, for every 3-D part ``[outputs]`` asks for (imports the CAD
    kernel). The exporter turns each into its :func:`print_poses` pose."""
    return {p.name: p.make(spec) for p in wanted(spec) if p.solid}


def needs_cad_kernel(spec) -> bool:
    """Whether building ``spec`` needs build123d: any 3-D part asked for, or the assembly."""
    return spec.outputs.assembly or any(p.solid for p in wanted(spec))
