"""Shared scenes: the same builders serve the tests, the examples and the benchmarks.

Each function returns a new :class:`~tumble.World` (z up, ground plane at z = 0 where there is one), with the
bodies named so that tests can find them (``world.body("top")``).
"""

from __future__ import annotations

import math

import numpy as np

from . import portable
from .joints import BallJoint, HingeJoint, SliderJoint
from .rotation import quat_from_axis_angle, quat_from_rotvec
from .shapes import Box, Capsule, ConvexHull, Cylinder, Plane, Sphere, TriMesh
from .world import World

__all__ = [
    "files",
    "box_pile",
    "pyramid",
    "tower",
    "card_house",
    "dominoes",
    "friction_ramp",
    "newtons_cradle",
    "bullets",
    "mixed_pile",
    "mixed_drop",
    "bowl_mesh",
    "pendulum_chain",
    "slider_crank",
    "four_bar",
    "hinged_door",
    "rope_bridge",
    "ragdoll_stairs",
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
    half_span = height / 2 * portable.sin(tilt) + thick / 2 * portable.cos(tilt)
    rise = height * portable.cos(tilt) + thick * portable.sin(tilt)  # height of a leaning card, corners included
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
    normal = np.array([-portable.sin(theta), 0.0, portable.cos(theta)])
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
            vertices.append((r * portable.cos(a), r * portable.sin(a), depth * (r / radius) ** 2))
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


def _mixed_shapes(rng, count: int) -> list:
    """``count`` shapes in turn a sphere, capsule, box, cylinder and hull, each about 0.1-0.3 m across; the hulls
    share one set of 12 random points (drawn from ``rng`` first)."""
    hull_points = rng.normal(size=(12, 3)) * 0.08
    makers = [
        lambda: Sphere(0.08),
        lambda: Capsule(0.05, 0.1),
        lambda: Box((0.14, 0.1, 0.08)),
        lambda: Cylinder(0.06, 0.1),
        lambda: ConvexHull(hull_points),
    ]
    return [makers[k % len(makers)]() for k in range(count)]


def _add_mixed_body(world: World, shape, k: int, position, rng) -> None:
    world.add_body(
        shape,
        density=800.0,
        position=position,
        orientation=quat_from_rotvec(rng.normal(size=3)),
        name=f"{type(shape).__name__.lower()}{k}",
    )


def mixed_pile(count: int = 40, seed: int = 1, **world_settings) -> World:
    """Spheres, capsules, boxes, cylinders and hulls dropped into a static mesh bowl."""
    world = World(**world_settings)
    world.add_static(bowl_mesh(), name="bowl")
    rng = np.random.default_rng(seed)
    for k, shape in enumerate(_mixed_shapes(rng, count)):
        position = (rng.uniform(-0.4, 0.4), rng.uniform(-0.4, 0.4), 0.5 + 0.2 * k)
        _add_mixed_body(world, shape, k, position, rng)
    return world


def mixed_drop(count: int = 60, seed: int = 1, height: float = 5.0, **world_settings) -> World:
    """The shapes of :func:`mixed_pile` dropped onto the ground from ``height`` [m] up, in layers of 16 on a 4 x 4
    grid of 0.4 m pitch (jittered by up to 5 cm), 0.4 m apart: from 5 m they land at 10-11 m/s, the hard impacts
    of issue 44's deep overlaps."""
    world = World(**world_settings)
    world.add_static(Plane(), name="ground")
    rng = np.random.default_rng(seed)
    for k, shape in enumerate(_mixed_shapes(rng, count)):
        layer, cell = divmod(k, 16)
        row, column = divmod(cell, 4)
        jitter = rng.uniform(-0.05, 0.05, 2)
        position = ((row - 1.5) * 0.4 + jitter[0], (column - 1.5) * 0.4 + jitter[1], height + 0.4 * layer)
        _add_mixed_body(world, shape, k, position, rng)
    return world


# --- scenes with world joints (issue 4) -------------------------------------------------------------------------


def _capsule_between(p, q, radius: float) -> tuple[Capsule, np.ndarray, np.ndarray]:
    """A capsule whose full extent (caps included) runs from ``p`` to ``q``: the shape, its centre and the
    orientation that turns its z axis onto ``q − p``."""
    p, q = np.asarray(p, np.float64), np.asarray(q, np.float64)
    span = q - p
    extent = float(portable.norm(span))
    direction = span / extent
    axis = np.cross((0.0, 0.0, 1.0), direction)
    sine = float(portable.norm(axis))
    angle = float(portable.arctan2(sine, direction[2]))
    if sine < 1e-12:  # along ±z: no turn, or a half turn about x
        axis = np.array([1.0, 0.0, 0.0])
    return Capsule(radius, max(extent - 2 * radius, 0.0)), (p + q) / 2, quat_from_axis_angle(axis, angle)


def _in_plane(angle: float) -> np.ndarray:
    """The unit vector at ``angle`` [rad] counter-clockwise from +x in the x–z plane (x right, z up)."""
    return np.array([portable.cos(angle), 0.0, portable.sin(angle)])


# Hinges in the x–z plane turn about −y, so that a positive angle is counter-clockwise as drawn (x right, z up).
_PLANAR_AXIS = (0.0, -1.0, 0.0)


def pendulum_chain(
    links: int = 20, length: float = 0.1, mass: float = 0.1, radius: float = 0.01, angle_deg: float = 0.0,
    self_collide: bool = False, **world_settings,
) -> World:  # fmt: skip
    """``links`` capsules (``"link0"`` at the pivot, …), each ``length`` long caps included and of ``mass``,
    hinged end to end about y; the first is hinged to the world at (0, 0, 3). The chain is released straight,
    ``angle_deg`` below the horizontal (+x) (0: horizontal, the issue's benchmark); there is no ground. Links
    pass through each other unless ``self_collide`` (the benchmark's chain has no contacts)."""
    world = World(**world_settings)
    pivot = np.array([0.0, 0.0, 3.0])
    direction = _in_plane(-np.radians(angle_deg))
    previous = None
    for i in range(links):
        start = pivot + direction * length * i
        shape, centre, orientation = _capsule_between(start, start + direction * length, radius)
        link = world.add_body(
            shape, mass=mass, position=centre, orientation=orientation, name=f"link{i}",
            collision_mask=0xFFFFFFFF if self_collide else 0,
        )  # fmt: skip
        if previous is None:
            world.add_joint(HingeJoint(link, None, start, (0.0, 1.0, 0.0)))  # to the world at the pivot
        else:
            world.add_joint(HingeJoint(previous, link, start, (0.0, 1.0, 0.0)))
        previous = link
    return world


def slider_crank(crank: float = 0.1, rod: float = 0.3, speed: float = 2 * math.pi, **world_settings) -> World:
    """A slider–crank in the x–z plane: the ``"crank"`` (``crank`` m) hinged to the world at the origin and
    driven by a hinge motor at ``speed`` rad/s (up to 100 N m), the connecting ``"rod"`` (``rod`` m), and the
    ``"piston"`` on a slider along x, so that ``x = r cos θ + √(l² − r² sin² θ)``. It starts at the outer dead
    centre (all along +x). No gravity unless ``gravity=`` is given."""
    world_settings.setdefault("gravity", (0.0, 0.0, 0.0))
    world = World(**world_settings)
    crank_body = world.add_body(Box((crank, 0.02, 0.02)), mass=0.5, position=(crank / 2, 0.0, 0.0), name="crank")
    rod_body = world.add_body(Box((rod, 0.02, 0.02)), mass=0.3, position=(crank + rod / 2, 0.0, 0.0), name="rod")
    piston = world.add_body(Box((0.05, 0.05, 0.05)), mass=0.4, position=(crank + rod, 0.0, 0.0), name="piston")
    world.add_joint(HingeJoint(crank_body, None, (0.0, 0.0, 0.0), _PLANAR_AXIS, motor_speed=speed,
                               max_motor_torque=100.0))  # fmt: skip
    world.add_joint(HingeJoint(crank_body, rod_body, (crank, 0.0, 0.0), _PLANAR_AXIS))
    world.add_joint(HingeJoint(rod_body, piston, (crank + rod, 0.0, 0.0), _PLANAR_AXIS))
    world.add_joint(SliderJoint(piston, None, (1.0, 0.0, 0.0)))
    return world


def _four_bar_joint(ground: float, crank: float, coupler: float, rocker: float, theta: float) -> np.ndarray:
    """Where the coupler meets the rocker in the x–z plane of :func:`four_bar` (ground pivots at (0, 1) and
    (``ground``, 1) as (x, z)), with the crank at ``theta`` [rad] counter-clockwise from +x: the upper of the two
    intersections of the circles of radius ``coupler`` about the crank pin and ``rocker`` about the rocker's
    pivot. Returns (3,) [m], world frame."""
    pin = np.array([crank * portable.cos(theta), 1.0 + crank * portable.sin(theta)])
    pivot = np.array([ground, 1.0])
    d = float(portable.norm(pivot - pin))
    along = (coupler**2 - rocker**2 + d**2) / (2 * d)  # from the pin towards the pivot
    across = math.sqrt(coupler**2 - along**2)
    u = (pivot - pin) / d
    x, z = pin + along * u + across * np.array([-u[1], u[0]])  # the left normal of pin→pivot: the upper branch
    return np.array([x, 0.0, z])


def four_bar(
    ground: float = 0.4, crank: float = 0.1, coupler: float = 0.35, rocker: float = 0.3, speed: float = 2 * math.pi,
    **world_settings,
) -> World:  # fmt: skip
    """A crank–rocker four-bar linkage in the x–z plane, hinges about y: the ``"crank"`` turns about (0, 0, 1)
    on a motor at ``speed`` rad/s (up to 100 N m), the ``"rocker"`` swings about (``ground``, 0, 1), and the
    ``"coupler"`` joins their ends (Grashof: shortest + longest <= the other two, the crank shortest). It is
    assembled with the crank along +x and the coupler–rocker joint where the circles about the crank pin
    (radius ``coupler``) and the rocker pivot (``rocker``) meet, on the upper branch, and set moving with the
    crank at ``speed`` and the velocities that keep the loop closed."""
    lengths = (ground, crank, coupler, rocker)
    if not (crank == min(lengths) and min(lengths) + max(lengths) <= sum(lengths) - min(lengths) - max(lengths)):
        raise ValueError(f"not a Grashof crank–rocker: {crank=}, {ground=}, {coupler=}, {rocker=}")
    world = World(**world_settings)
    o_crank, o_rocker = np.array([0.0, 0.0, 1.0]), np.array([ground, 0.0, 1.0])
    pin = o_crank + crank * _in_plane(0.0)
    joint = _four_bar_joint(ground, crank, coupler, rocker, 0.0)

    # Start in steady motion, the crank already at ``speed``: the coupler's and rocker's angular speeds close the
    # loop's velocities, v_pin + ω_coupler ⊥(joint − pin) = ω_rocker ⊥(joint − o_rocker), ⊥ turning a quarter
    # counter-clockwise in the plane (so that the motor needs no impulsive start).
    def perp(r):
        return np.array([-r[2], 0.0, r[0]])

    v_pin = speed * perp(pin - o_crank)
    closure = np.column_stack([perp(joint - pin)[[0, 2]], -perp(joint - o_rocker)[[0, 2]]])
    w_coupler, w_rocker = portable.solve(closure, -v_pin[[0, 2]])
    links = {
        "crank": (o_crank, pin, o_crank, np.zeros(3), speed),
        "coupler": (pin, joint, pin, v_pin, w_coupler),
        "rocker": (o_rocker, joint, o_rocker, np.zeros(3), w_rocker),
    }
    bodies = {}
    for name, (p, q, pivot, v_pivot, spin) in links.items():
        shape, centre, orientation = _capsule_between(p, q, 0.015)
        bodies[name] = world.add_body(
            shape,
            density=2700.0,
            position=centre,
            orientation=orientation,
            velocity=v_pivot + spin * perp(centre - pivot),
            angular_velocity=spin * np.array(_PLANAR_AXIS),
            name=name,
        )
    world.add_joint(HingeJoint(bodies["crank"], None, o_crank, _PLANAR_AXIS, motor_speed=speed, max_motor_torque=100.0))
    world.add_joint(HingeJoint(bodies["crank"], bodies["coupler"], pin, _PLANAR_AXIS))
    world.add_joint(HingeJoint(bodies["coupler"], bodies["rocker"], joint, _PLANAR_AXIS))
    world.add_joint(HingeJoint(bodies["rocker"], None, o_rocker, _PLANAR_AXIS))
    return world


def hinged_door(speed: float = 1.0, max_torque: float = 50.0, **world_settings) -> World:
    """A ``"door"`` (box 1 × 0.05 × 2 m, 20 kg, 1 cm above the floor) hinged to the world along its edge on the z
    axis next to a static ``"post"``, opened (counter-clockwise from above, +x towards +y) by a hinge motor at
    ``speed`` rad/s with at most ``max_torque`` N m up to a stop (hinge limit) at 110°; a 0.3 m, 5 kg ``"box"``
    on the floor stands in its way (first touched at about 32°), and the door sweeps it along."""
    world = World(**world_settings)
    world.add_static(Plane(), name="ground")
    # The post stands behind the hinge, on the closed side: the door swings away from it (28 mm clear at 110°).
    world.add_static(Box((0.12, 0.12, 2.2)), position=(-0.12, -0.05, 1.1), name="post")
    door = world.add_body(Box((1.0, 0.05, 2.0)), mass=20.0, position=(0.5, 0.0, 1.01), name="door")
    world.add_joint(HingeJoint(door, None, (0.0, 0.0, 1.01), (0.0, 0.0, 1.0), upper=math.radians(110.0),
                               motor_speed=speed, max_motor_torque=max_torque))  # fmt: skip
    world.add_body(Box((0.3, 0.3, 0.3)), mass=5.0, position=(0.45, 0.55, 0.15), name="box")
    return world


def _hanging_chain(links: int, pitch: float, span: float) -> np.ndarray:
    """The ``links + 1`` joint points, (x, z) relative to the left end, of ``links`` equal straight links of
    ``pitch`` hanging at rest between two points ``span`` apart at one height: the discrete catenary. Each link
    lies along the tension it carries, whose horizontal part ``H`` is the same in all links and whose vertical
    part changes by one link's weight from one to the next, so ``tan φ_k = (k − (links − 1)/2) W / H``; ``W / H``
    is found by bisection so that the horizontal extent is ``span``."""
    turn = np.arange(links) - (links - 1) / 2

    def extent(ratio: float) -> float:
        return float(pitch * portable.cos(portable.arctan(ratio * turn)).sum())

    lo, hi = 0.0, 1e3
    for _ in range(100):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if extent(mid) > span else (lo, mid)
    angles = portable.arctan(lo * turn)
    steps = pitch * np.column_stack([portable.cos(angles), portable.sin(angles)])
    return np.vstack([np.zeros(2), np.cumsum(steps, axis=0)])


def rope_bridge(planks: int = 12, **world_settings) -> World:
    """A rope bridge 2 m above the ground: ``planks`` wooden planks (``"plank0"`` … from −x, 0.25 × 1 × 0.04 m,
    6 kg) 0.3 m apart, each tied to its neighbours by two ball joints at its edges (y = ±0.45; the pair acts as a
    hinge about y), the end planks tied to two static ``"post_left"``/``"post_right"`` blocks whose tops are 95 %
    of the chain's length apart; it starts at rest in its hanging shape (the discrete catenary). Three 0.2 m
    boxes (``"load0"`` …, 4 kg) are dropped on it from 0.3 m. The planks are damped (1 /s, linear and angular: the
    ropes and knots dissipate); undamped, the bridge rings in its 2.25 Hz mode for many seconds (its soft joints
    stretch a few millimetres as they take the load, which is enough to start it), and does not sleep."""
    world = World(**world_settings)
    world.add_static(Plane(), name="ground")
    height, pitch, thickness, width = 2.0, 0.3, 0.04, 1.0
    span = 0.95 * planks * pitch
    points = _hanging_chain(planks, pitch, span) + np.array([-span / 2, height])
    left = world.add_static(Box((0.6, 1.6, height)), position=(-span / 2 - 0.3, 0.0, height / 2), name="post_left")
    right = world.add_static(Box((0.6, 1.6, height)), position=(span / 2 + 0.3, 0.0, height / 2), name="post_right")
    previous = left
    for i in range(planks):
        (x0, z0), (x1, z1) = points[i], points[i + 1]
        plank = world.add_body(
            Box((pitch - 0.05, width, thickness)),
            density=600.0,
            position=((x0 + x1) / 2, 0.0, (z0 + z1) / 2),
            orientation=quat_from_axis_angle(_PLANAR_AXIS, portable.arctan2(z1 - z0, x1 - x0)),
            linear_damping=1.0,
            angular_damping=1.0,
            name=f"plank{i}",
        )
        for y in (-0.45 * width, 0.45 * width):
            world.add_joint(BallJoint(plank, previous, (x0, y, z0)))
        previous = plank
    for y in (-0.45 * width, 0.45 * width):
        world.add_joint(BallJoint(previous, right, (points[-1][0], y, points[-1][1])))
    for k, x in enumerate((-0.3 * span, 0.0, 0.25 * span)):
        z = float(np.interp(x, points[:, 0], points[:, 1]))
        world.add_body(Box((0.2, 0.2, 0.2)), density=500.0, position=(x, 0.1 * k, z + thickness / 2 + 0.4),
                       name=f"load{k}")  # fmt: skip
    return world


def ragdoll_stairs(steps: int = 8, rise: float = 0.2, run: float = 0.3, push: float = 1.0, **world_settings) -> World:
    """A 70 kg ragdoll standing at the top of a staircase, pushed forward (+x; the torso at ``push`` m/s) so that
    it falls down the ``steps`` steps (``rise`` high, ``run`` deep, 3 m wide): a ``"landing"`` at the top (x < 0),
    ``"step1"`` … below it, the ground last.

    The ragdoll (1.8 m, masses after Winter's segment tables) has a box ``"pelvis"`` and ``"torso"``, a
    sphere ``"head"`` and capsule limbs ``"upper_arm_left"``, ``"lower_arm_left"`` (forearm and hand),
    ``"thigh_left"``, ``"shin_left"`` (shin and foot) and their ``_right`` twins: ball joints at the neck, the
    waist, the shoulders and the hips, hinges about y at the elbows (0 to 150°, forwards) and the knees (0 to
    150°, backwards)."""
    world = World(**world_settings)
    world.add_static(Plane(), name="ground", friction=0.7)
    top = steps * rise
    world.add_static(Box((1.0, 3.0, top)), position=(-0.5, 0.0, top / 2), name="landing", friction=0.7)
    for k in range(1, steps):
        h = top - k * rise
        world.add_static(Box((run, 3.0, h)), position=((k - 0.5) * run, 0.0, h / 2), name=f"step{k}", friction=0.7)

    # The ragdoll stands 15 cm back from the edge of the landing, facing +x; heights from its soles.
    foot_x, z0 = -0.15, top + 0.01

    def at(x: float, y: float, z: float) -> np.ndarray:
        return np.array([foot_x + x, y, z0 + z])

    def limb(name: str, p, q, radius: float, mass: float):
        shape, centre, orientation = _capsule_between(p, q, radius)
        return world.add_body(shape, mass=mass, position=centre, orientation=orientation, friction=0.7, name=name)

    pelvis = world.add_body(Box((0.2, 0.32, 0.2)), mass=10.0, position=at(0.0, 0.0, 1.0), friction=0.7, name="pelvis")
    torso = world.add_body(Box((0.22, 0.36, 0.45)), mass=25.0, position=at(0.0, 0.0, 1.33), friction=0.7,
                           name="torso")  # fmt: skip
    head = world.add_body(Sphere(0.11), mass=5.5, position=at(0.0, 0.0, 1.68), friction=0.7, name="head")
    world.add_joint(BallJoint(torso, pelvis, at(0.0, 0.0, 1.1)))  # waist
    world.add_joint(BallJoint(head, torso, at(0.0, 0.0, 1.565)))  # neck
    for side, y in (("left", 1.0), ("right", -1.0)):
        upper = limb(f"upper_arm_{side}", at(0.0, 0.25 * y, 1.52), at(0.0, 0.25 * y, 1.22), 0.045, 2.0)
        lower = limb(f"lower_arm_{side}", at(0.0, 0.25 * y, 1.22), at(0.0, 0.25 * y, 0.9), 0.04, 1.6)
        thigh = limb(f"thigh_{side}", at(0.0, 0.1 * y, 0.92), at(0.0, 0.1 * y, 0.47), 0.065, 7.0)
        shin = limb(f"shin_{side}", at(0.0, 0.1 * y, 0.47), at(0.0, 0.1 * y, 0.0), 0.05, 4.5)
        world.add_joint(BallJoint(upper, torso, at(0.0, 0.25 * y, 1.475)))  # shoulder
        world.add_joint(BallJoint(thigh, pelvis, at(0.0, 0.1 * y, 0.92 - 0.065)))  # hip
        # Elbow: the forearm turns forwards (−z towards +x: about −y); knee: the shin turns backwards (about +y).
        world.add_joint(HingeJoint(upper, lower, at(0.0, 0.25 * y, 1.22), (0.0, -1.0, 0.0), lower=0.0,
                                   upper=np.radians(150)))  # fmt: skip
        world.add_joint(HingeJoint(thigh, shin, at(0.0, 0.1 * y, 0.47), (0.0, 1.0, 0.0), lower=0.0,
                                   upper=np.radians(150)))  # fmt: skip
    # The push: the whole body starts to topple as one about its soles, the torso's centre moving at ``push``.
    spin = np.array([0.0, push / 1.33, 0.0])
    for body in world.bodies:
        if not body.is_static:
            body.velocity = np.cross(spin, body.center_of_mass - at(0.0, 0.0, 0.0))
            body.angular_velocity = spin
    return world


def files() -> list:
    """The scene files shipped with tumble (``pathlib.Path``\\ s, sorted by name): load one with
    ``tumble.load_scene(path)``; ``tumble examples`` lists and copies them."""
    from .scene_file import shipped

    return shipped()
