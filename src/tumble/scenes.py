"""Shared scenes: the same builders serve the tests, the examples and the benchmarks.

Each function returns a new :class:`~tumble.World` (z up, ground plane at z = 0 where there is one), with the
bodies named so that tests can find them (``world.body("top")``).
"""

from __future__ import annotations

import numpy as np

from .rotation import quat_from_axis_angle, quat_from_rotvec
from .shapes import Box, Capsule, ConvexHull, Cylinder, Plane, Sphere, TriMesh
from .world import World

__all__ = [
    "box_pile",
    "pyramid",
    "tower",
    "card_house",
    "dominoes",
    "friction_ramp",
    "newtons_cradle",
    "bullets",
    "mixed_pile",
    "bowl_mesh",
]


def box_pile(
    count: int = 1000, size: float = 0.2, spacing: float = 1.5, jitter: float = 0.02, seed: int = 0, **world_settings
) -> World:
    """``count`` cubes of edge ``size`` dropped in a square grid of columns (``spacing`` edges apart), each offset
    by up to ``jitter`` metres and turned by a small random rotation, since an aligned grid only tests columns."""
    world = World(**world_settings)
    world.add_static(Plane(), name="ground")
    rng = np.random.default_rng(seed)
    side = int(np.ceil(np.sqrt(count / max(1, int(np.ceil(count ** (1 / 3)))))))
    layers = int(np.ceil(count / side**2))
    pitch = size * spacing
    k = 0
    for layer in range(layers):
        for i in range(side):
            for j in range(side):
                if k == count:
                    return world
                offset = rng.uniform(-jitter, jitter, 3)
                position = (
                    np.array(
                        [
                            (i - (side - 1) / 2) * pitch,
                            (j - (side - 1) / 2) * pitch,
                            size * (0.5 + spacing * layer) + 0.05,
                        ]
                    )
                    + offset
                )
                world.add_body(
                    Box((size, size, size)),
                    density=1000.0,
                    position=position,
                    orientation=quat_from_rotvec(rng.normal(scale=0.05, size=3)),
                    name=f"box{k}",
                )
                k += 1
    return world


def pyramid(base: int = 20, size: float = 0.5, gap: float = 0.0, **world_settings) -> World:
    """A 2-D pyramid of cubes: ``base`` on the ground, one fewer in each row above (``base (base + 1) / 2`` in
    all); the top cube is named ``"top"``."""
    world = World(**world_settings)
    world.add_static(Plane(), name="ground")
    for row in range(base):
        n = base - row
        for i in range(n):
            x = (i - (n - 1) / 2) * (size + gap)
            name = "top" if row == base - 1 else None
            world.add_body(Box((size, size, size)), density=1000.0, position=(x, 0.0, size * (row + 0.5)), name=name)
    return world


def tower(count: int = 10, size: float = 0.5, **world_settings) -> World:
    """``count`` cubes stacked in one column; the top one is ``"top"``."""
    world = World(**world_settings)
    world.add_static(Plane(), name="ground")
    for k in range(count):
        world.add_body(
            Box((size, size, size)),
            density=500.0,
            position=(0.0, 0.0, size * (k + 0.5)),
            name="top" if k == count - 1 else f"box{k}",
        )
    return world


def card_house(levels: int = 2, card=(0.06, 0.001 * 8, 0.09), angle_deg: float = 20.0, **world_settings) -> World:
    """A house of cards: leaning pairs (``angle_deg`` from vertical) with flat cards across them, ``levels`` high.
    Cards are thin boxes ``(width, thickness, height)``; high friction holds them. Two levels stand and sleep;
    three creep apart at the second level and fall within a second (issue 3, open)."""
    world = World(**world_settings)
    world.add_static(Plane(), name="ground", friction=0.9)
    width, thick, height = card
    tilt = np.radians(angle_deg)
    half_span = height / 2 * np.sin(tilt) + thick / 2 * np.cos(tilt)
    rise = height * np.cos(tilt) + thick * np.sin(tilt)  # height of a leaning card, corners included
    z0 = 0.0
    for level in range(levels):
        pairs = levels - level
        for p in range(pairs):
            x = (p - (pairs - 1) / 2) * 4 * half_span * 1.05
            for sign in (-1, 1):
                q = quat_from_axis_angle((0, 1, 0), -sign * tilt)  # tops lean in and meet over x
                world.add_body(
                    Box((thick, width, height)),
                    density=600.0,
                    orientation=q,
                    friction=0.9,
                    position=(x + sign * half_span, 0.0, z0 + rise / 2),
                )
        # Flat cards bridging the tops of neighbouring pairs (and capping a single pair).
        for p in range(max(1, pairs - 1)):
            x = (p - (max(1, pairs - 1) - 1) / 2) * 4 * half_span * 1.05
            world.add_body(
                Box((6 * half_span, width, thick)),  # overhangs the apexes it rests on
                density=600.0,
                friction=0.9,
                position=(x, 0.0, z0 + rise + thick / 2),
            )
        z0 += rise + thick
    return world


def dominoes(count: int = 20, size=(0.02, 0.1, 0.2), spacing: float = 0.12, **world_settings) -> World:
    """A row of dominoes along x; the first (``"first"``) is given a push about y so the row topples."""
    world = World(**world_settings)
    world.add_static(Plane(), name="ground", friction=0.6)
    thick, width, height = size
    for k in range(count):
        name = "first" if k == 0 else ("last" if k == count - 1 else None)
        world.add_body(Box(size), density=600.0, position=(k * spacing, 0.0, height / 2), friction=0.6, name=name)
    # Spun about its centre, the first domino pivots on its bottom edge with about a quarter of the spin
    # (I_com / I_edge): 8 rad/s leaves it enough energy to rise over the edge; 3 rad/s would not.
    world.body("first").angular_velocity = (0.0, 8.0, 0.0)
    return world


def friction_ramp(theta_deg: float = 30.0, frictions=(0.2, 0.4, 0.6, 0.8), **world_settings) -> World:
    """Boxes of different friction side by side on a ramp tilted by ``theta_deg`` (downhill is +x); those with
    ``μ > tan θ`` hold, the others slide. Box ``k`` is named ``"mu=<value>"``."""
    world = World(**world_settings)
    theta = np.radians(theta_deg)
    normal = np.array([-np.sin(theta), 0.0, np.cos(theta)])
    world.add_static(Plane(normal=normal), name="ramp", friction=1.0)
    q = quat_from_axis_angle((0, 1, 0), -theta)
    for k, mu in enumerate(frictions):
        position = 0.1 * normal + np.array([0.0, 0.4 * k, 0.0])
        world.add_body(
            Box((0.2, 0.2, 0.2)), density=500.0, orientation=q, position=position, friction=mu * mu, name=f"mu={mu}"
        )  # fmt: skip  (ramp friction 1: the mixed friction √(μ² · 1) is μ)
    return world


def newtons_cradle(balls: int = 5, radius: float = 0.1, speed: float = 2.0, **world_settings) -> World:
    """A row of touching balls with restitution 1 hit by a striker (``"striker"``) at ``speed``; no gravity,
    no strings: the momentum passes down the row to ``"last"``."""
    world = World(gravity=(0.0, 0.0, 0.0), **world_settings)
    for k in range(balls):
        world.add_body(
            Sphere(radius),
            density=1000.0,
            position=(2 * radius * k, 0.0, 0.0),
            restitution=1.0,
            friction=0.0,
            name="last" if k == balls - 1 else f"ball{k}",
        )
    world.add_body(
        Sphere(radius),
        density=1000.0,
        position=(-4 * radius, 0.0, 0.0),
        velocity=(speed, 0.0, 0.0),
        restitution=1.0,
        friction=0.0,
        name="striker",
    )
    return world


def bullets(speed: float = 100.0, wall_thickness: float = 0.02, **world_settings) -> World:
    """A ball (radius 5 cm, ``"ball"``) and a box (10 cm, ``"box"``) fired at ``speed`` at thin static walls."""
    world = World(gravity=(0.0, 0.0, 0.0), **world_settings)
    world.add_static(Box((wall_thickness, 1.0, 1.0)), position=(1.0, 0.0, 0.0), name="wall_ball")
    world.add_static(Box((wall_thickness, 1.0, 1.0)), position=(1.0, 2.0, 0.0), name="wall_box")
    world.add_body(Sphere(0.05), density=1000.0, velocity=(speed, 0.0, 0.0), name="ball")
    world.add_body(
        Box((0.1, 0.1, 0.1)), density=1000.0, position=(0.0, 2.0, 0.0), velocity=(speed, 0.0, 0.0), name="box"
    )
    return world


def bowl_mesh(radius: float = 1.5, depth: float = 0.6, segments: int = 24, rings: int = 6) -> TriMesh:
    """An open bowl (a paraboloid cap ``z = depth (r/radius)²``) as an upward-facing triangle mesh."""
    vertices = [(0.0, 0.0, 0.0)]
    for ring in range(1, rings + 1):
        r = radius * ring / rings
        for k in range(segments):
            a = 2 * np.pi * k / segments
            vertices.append((r * np.cos(a), r * np.sin(a), depth * (r / radius) ** 2))
    faces = []
    for k in range(segments):
        faces.append((0, 1 + k, 1 + (k + 1) % segments))
    for ring in range(1, rings):
        inner, outer = 1 + (ring - 1) * segments, 1 + ring * segments
        for k in range(segments):
            k1 = (k + 1) % segments
            faces.append((inner + k, outer + k, outer + k1))
            faces.append((inner + k, outer + k1, inner + k1))
    return TriMesh(np.array(vertices), np.array(faces))


def mixed_pile(count: int = 40, seed: int = 1, **world_settings) -> World:
    """Spheres, capsules, boxes, cylinders and hulls dropped into a static mesh bowl."""
    world = World(**world_settings)
    world.add_static(bowl_mesh(), name="bowl")
    rng = np.random.default_rng(seed)
    hull_points = rng.normal(size=(12, 3)) * 0.08
    makers = [
        lambda: Sphere(0.08),
        lambda: Capsule(0.05, 0.1),
        lambda: Box((0.14, 0.1, 0.08)),
        lambda: Cylinder(0.06, 0.1),
        lambda: ConvexHull(hull_points),
    ]
    for k in range(count):
        shape = makers[k % len(makers)]()
        position = (rng.uniform(-0.4, 0.4), rng.uniform(-0.4, 0.4), 0.5 + 0.2 * k)
        world.add_body(
            shape,
            density=800.0,
            position=position,
            orientation=quat_from_rotvec(rng.normal(size=3)),
            name=f"{type(shape).__name__.lower()}{k}",
        )
    return world
