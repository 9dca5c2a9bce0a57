"""Footprints on the floor: the 2-D outlines the generators lay out without overlap.

Everything a generator places (objects, regions, walls, robot bases) stands on a horizontal surface, so
two of them overlap iff their floor outlines overlap.  A :class:`Footprint` is a rectangle (centre, half
sizes, yaw) or a disc (centre, radius); the tests are exact (separating axes for rectangles, closest
point for discs), with a ``gap`` that must stay free between two footprints.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Footprint:
    """A rectangle of half sizes ``hx``, ``hy`` turned by ``yaw`` degrees, or (``radius`` > 0) a disc."""

    x: float
    y: float
    hx: float = 0.0
    hy: float = 0.0
    yaw: float = 0.0
    radius: float = 0.0

    @property
    def disc(self) -> bool:
        """Whether the footprint is a disc (else a box)."""
        return self.radius > 0

    def axes(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """The footprint's unit x and y axes in the world."""
        c, s = math.cos(math.radians(self.yaw)), math.sin(math.radians(self.yaw))
        return (c, s), (-s, c)

    def half_box(self) -> tuple[float, float]:
        """Half sizes of the axis-aligned bounding box."""
        if self.disc:
            return self.radius, self.radius
        (c, s), _ = self.axes()
        return abs(c) * self.hx + abs(s) * self.hy, abs(s) * self.hx + abs(c) * self.hy

    def to_local(self, px: float, py: float) -> tuple[float, float]:
        """A world point in the footprint's frame."""
        (ax, ay), (bx, by) = self.axes()
        dx, dy = px - self.x, py - self.y
        return dx * ax + dy * ay, dx * bx + dy * by

    def distance_to_point(self, px: float, py: float) -> float:
        """Distance from a point to the footprint (0 inside)."""
        if self.disc:
            return max(math.hypot(px - self.x, py - self.y) - self.radius, 0.0)
        lx, ly = self.to_local(px, py)
        return math.hypot(max(abs(lx) - self.hx, 0.0), max(abs(ly) - self.hy, 0.0))

    def corners(self) -> list[tuple[float, float]]:
        """A box footprint's four corners in the world."""
        (ax, ay), (bx, by) = self.axes()
        return [
            (self.x + sx * self.hx * ax + sy * self.hy * bx, self.y + sx * self.hx * ay + sy * self.hy * by)
            for sx, sy in ((1, 1), (-1, 1), (-1, -1), (1, -1))
        ]

    def inside(self, outer: "Footprint", margin: float = 0.0) -> bool:
        """Whether this footprint lies inside the rectangle ``outer``, at least ``margin`` from its edges."""
        assert not outer.disc
        if self.disc:
            lx, ly = outer.to_local(self.x, self.y)
            return abs(lx) + self.radius + margin <= outer.hx and abs(ly) + self.radius + margin <= outer.hy
        for cx, cy in self.corners():
            lx, ly = outer.to_local(cx, cy)
            if abs(lx) + margin > outer.hx or abs(ly) + margin > outer.hy:
                return False
        return True


def overlaps(a: Footprint, b: Footprint, gap: float = 0.0) -> bool:
    """Whether ``a`` and ``b`` come closer than ``gap`` (``gap`` = 0: whether their interiors overlap)."""
    if a.disc and b.disc:
        return math.hypot(a.x - b.x, a.y - b.y) < a.radius + b.radius + gap
    if a.disc or b.disc:
        disc, rect = (a, b) if a.disc else (b, a)
        return rect.distance_to_point(disc.x, disc.y) < disc.radius + gap
    # separating axes; with a gap the rectangles are grown by gap/2 each (conservative at the corners)
    for axis in (*a.axes(), *b.axes()):
        pa = [cx * axis[0] + cy * axis[1] for cx, cy in a.corners()]
        pb = [cx * axis[0] + cy * axis[1] for cx, cy in b.corners()]
        if min(pa) - gap >= max(pb) or min(pb) - gap >= max(pa):
            return False
    return True
