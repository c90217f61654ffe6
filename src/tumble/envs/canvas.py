"""A small raster canvas for the environments' ``rgb_array`` pictures: thick segments and discs in NumPy.

Coordinates are world metres on a plane; ``scale`` pixels per metre and the world point at the image centre
``centre`` place them. Each primitive fills the pixels within its distance of the shape, computed over the
shape's bounding box only.
"""

from __future__ import annotations

import numpy as np

__all__ = ["Canvas"]


class Canvas:
    """An (height, width, 3) uint8 image with world-to-pixel placement (``y`` up)."""

    def __init__(self, width: int, height: int, scale: float, centre=(0.0, 0.0), background=(255, 255, 255)):
        self.image = np.empty((height, width, 3), dtype=np.uint8)
        self.image[...] = background
        self.scale = float(scale)
        self.centre = (float(centre[0]), float(centre[1]))

    def _pixel(self, point) -> tuple[float, float]:
        """(column, row) of a world point."""
        height, width = self.image.shape[:2]
        return (width / 2 + (point[0] - self.centre[0]) * self.scale,
                height / 2 - (point[1] - self.centre[1]) * self.scale)  # fmt: skip

    def _box(self, points, reach: float):
        """The clipped pixel grid around ``points`` widened by ``reach`` pixels: (rows slice, cols slice, x, y)."""
        height, width = self.image.shape[:2]
        xs, ys = [p[0] for p in points], [p[1] for p in points]
        c0, c1 = max(int(min(xs) - reach), 0), min(int(max(xs) + reach) + 2, width)
        r0, r1 = max(int(min(ys) - reach), 0), min(int(max(ys) + reach) + 2, height)
        if c0 >= c1 or r0 >= r1:
            return None
        y, x = np.mgrid[r0:r1, c0:c1]
        return slice(r0, r1), slice(c0, c1), x + 0.5, y + 0.5

    def segment(self, a, b, width: float, color) -> None:
        """A segment from ``a`` to ``b`` (world), ``width`` metres thick with round ends."""
        pa, pb = self._pixel(a), self._pixel(b)
        radius = 0.5 * width * self.scale
        box = self._box((pa, pb), radius)
        if box is None:
            return
        rows, cols, x, y = box
        dx, dy = pb[0] - pa[0], pb[1] - pa[1]
        length2 = dx * dx + dy * dy
        t = np.zeros_like(x) if length2 == 0.0 else np.clip(((x - pa[0]) * dx + (y - pa[1]) * dy) / length2, 0, 1)
        inside = (x - pa[0] - t * dx) ** 2 + (y - pa[1] - t * dy) ** 2 <= max(radius, 0.5) ** 2
        self.image[rows, cols][inside] = color

    def disc(self, centre, radius: float, color) -> None:
        """A filled disc of ``radius`` metres."""
        self.segment(centre, centre, 2.0 * radius, color)
