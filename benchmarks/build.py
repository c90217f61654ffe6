"""Build benchmark (issue 20): how long a world takes to build, through the API and from a scene file, beside MuJoCo
compiling the same bodies from MJCF, in the same process.

Run through ``python -m benchmarks.run --only build``.

A build is timed from an empty world to a packed model (``world.model``: what the first step needs), so a lazy
packing cannot hide. The worlds, each at several sizes to show how the cost grows:

- ``free bodies``: ``n`` boxes of 0.2 m on a 100-wide grid of layers, each named and made with its own ``Box``
  (as a scene file makes them), and a ground plane. MuJoCo: the same boxes, each a body with a free joint.
- ``chain``: ``n`` capsules in a row, each joined to the one before by a ball joint (the first to the world).
  MuJoCo: free bodies held by ``connect`` equality constraints, as tumble's world joints hold them (MJCF's own
  way, nested bodies, compiles in quadratic time: 1.4 s for 400 links, so 10 000 would not finish).
- ``grid``: a square grid of spheres, each joined by ball joints to its right and upper neighbours, ``≈ n`` joints
  with loops everywhere. MuJoCo: free bodies held by ``connect`` equality constraints.

Scene files: the same worlds written as TOML beforehand; the timing is ``scene_file.load`` (read, validate, build)
and the packing. Columns: ``build_s``, ``us_per_item`` (per body, or per joint for the jointed worlds),
``x_api`` (a scene file's time over the API's for the same world) and ``x_mujoco`` (tumble's time over MuJoCo's
compile: above 1 is slower; MuJoCo is not run above :data:`MUJOCO_MAX_BODIES`). Each configuration runs
``min(repeat, 3)`` times (once at 100 000 bodies, and MuJoCo once above 2 000); the best is kept.
"""

from __future__ import annotations

import gc
import math
import tempfile
import time
from pathlib import Path

import numpy as np

import tumble
from tumble import scene_file

__all__ = ["api_world", "bench_build", "grid_side", "mjcf", "scene_toml"]

BOX = 0.2  # [m] edge of the free boxes
LINK = 0.3  # [m] spacing of chain links and grid nodes
ROW = 100  # free boxes per row
# MuJoCo 4.0's compile grows with the square of the bodies (free boxes: 0.17 s for 1 000, 3.2 s for 4 000 on the
# development VM; 10 000: 20 s), so 100 000 would take about half an hour: above this many bodies it is not run.
MUJOCO_MAX_BODIES = 20_000


def grid_side(joints: int) -> int:
    """The side ``s`` of the square grid whose ``2 s (s - 1)`` joints come closest to ``joints``."""
    return max(2, round(0.5 + math.sqrt(0.25 + joints / 2)))


def _free_position(i: int) -> tuple[float, float, float]:
    layer, k = divmod(i, ROW * ROW)
    return ((k % ROW) * 2 * BOX, (k // ROW) * 2 * BOX, 0.5 + layer * 2 * BOX)


def api_world(case: str, n: int) -> tumble.World:
    """The world of ``case`` built through ``World.add_*``, its model packed."""
    world = tumble.World()
    if case == "free bodies":
        for i in range(n):
            world.add_body(tumble.Box((BOX, BOX, BOX)), mass=1.0, position=_free_position(i), name=f"b{i}")
        world.add_static(tumble.Plane((0.0, 0.0, 1.0), 0.0))
    elif case == "chain":
        previous = None
        for i in range(n):
            link = world.add_body(tumble.Capsule(0.05, 0.2), mass=0.5, position=(LINK * i, 0.0, 2.0))
            world.add_joint(tumble.BallJoint(link, previous, anchor=(LINK * i - 0.5 * LINK, 0.0, 2.0)))
            previous = link
    else:
        side = grid_side(n)
        nodes = [[world.add_body(tumble.Sphere(0.1), mass=1.0, position=(LINK * x, LINK * y, 2.0))
                  for y in range(side)] for x in range(side)]  # fmt: skip
        for x in range(side):
            for y in range(side):
                for dx, dy in ((1, 0), (0, 1)):
                    if x + dx < side and y + dy < side:
                        anchor = (LINK * (x + 0.5 * dx), LINK * (y + 0.5 * dy), 2.0)
                        world.add_joint(tumble.BallJoint(nodes[x][y], nodes[x + dx][y + dy], anchor=anchor))
    world.model  # noqa: B018 - pack the model: the first step would
    return world


def scene_toml(case: str, n: int) -> str:
    """The same world as a scene file."""
    parts = ["[world]\ngravity = [0, 0, -9.81]\n"]
    if case == "free bodies":
        for i in range(n):
            x, y, z = _free_position(i)
            parts.append(f'[[bodies]]\nname = "b{i}"\nshape = {{ type = "box", extents = [{BOX}, {BOX}, {BOX}] }}\n'
                         f"mass = 1.0\nposition = [{x}, {y}, {z}]\n")  # fmt: skip
        parts.append('[[static]]\nshape = { type = "plane", normal = [0, 0, 1], offset = 0 }\n')
    elif case == "chain":
        for i in range(n):
            parts.append(f'[[bodies]]\nname = "l{i}"\nshape = {{ type = "capsule", radius = 0.05, length = 0.2 }}\n'
                         f"mass = 0.5\nposition = [{LINK * i}, 0, 2]\n")  # fmt: skip
        for i in range(n):
            other = f'b = "l{i - 1}"\n' if i else ""
            parts.append(f'[[joints]]\ntype = "ball"\na = "l{i}"\n{other}anchor = [{LINK * i - 0.5 * LINK}, 0, 2]\n')
    else:
        side = grid_side(n)
        for x in range(side):
            for y in range(side):
                parts.append(f'[[bodies]]\nname = "n{x}_{y}"\nshape = {{ type = "sphere", radius = 0.1 }}\n'
                             f"mass = 1.0\nposition = [{LINK * x}, {LINK * y}, 2]\n")  # fmt: skip
        for x in range(side):
            for y in range(side):
                for dx, dy in ((1, 0), (0, 1)):
                    if x + dx < side and y + dy < side:
                        anchor = f"[{LINK * (x + 0.5 * dx)}, {LINK * (y + 0.5 * dy)}, 2]"
                        parts.append(f'[[joints]]\ntype = "ball"\na = "n{x}_{y}"\nb = "n{x + dx}_{y + dy}"\n'
                                     f"anchor = {anchor}\n")  # fmt: skip
    return "\n".join(parts)


def mjcf(case: str, n: int) -> str:
    """The same bodies as MJCF for MuJoCo."""
    if case == "free bodies":
        half = BOX / 2
        bodies = "".join(
            f'<body name="b{i}" pos="{x} {y} {z}"><freejoint/><geom type="box" size="{half} {half} {half}" '
            f'mass="1"/></body>'
            for i, (x, y, z) in ((i, _free_position(i)) for i in range(n))
        )
        return f'<mujoco><worldbody><geom type="plane" size="0 0 1"/>{bodies}</worldbody></mujoco>'
    if case == "chain":
        bodies = "".join(f'<body name="l{i}" pos="{LINK * i} 0 2"><freejoint/><geom type="capsule" size="0.05" '
                         f'fromto="-0.1 0 0 0.1 0 0" mass="0.5"/></body>' for i in range(n))  # fmt: skip
        links = '<connect body1="l0" anchor="-0.15 0 0"/>' + "".join(
            f'<connect body1="l{i}" body2="l{i - 1}" anchor="{-0.5 * LINK} 0 0"/>' for i in range(1, n)
        )
        return f"<mujoco><worldbody>{bodies}</worldbody><equality>{links}</equality></mujoco>"
    side = grid_side(n)
    bodies = "".join(f'<body name="n{x}_{y}" pos="{LINK * x} {LINK * y} 2"><freejoint/><geom size="0.1" mass="1"/>'
                     f"</body>" for x in range(side) for y in range(side))  # fmt: skip
    links = "".join(f'<connect body1="n{x}_{y}" body2="n{x + dx}_{y + dy}" anchor="{0.5 * LINK * dx} '
                    f'{0.5 * LINK * dy} 0"/>' for x in range(side) for y in range(side)
                    for dx, dy in ((1, 0), (0, 1)) if x + dx < side and y + dy < side)  # fmt: skip
    return f"<mujoco><worldbody>{bodies}</worldbody><equality>{links}</equality></mujoco>"


def _best(function, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        gc.collect()
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def _mujoco_compile(case: str, n: int, bodies: int, repeat: int) -> float:
    """The best time MuJoCo takes to compile the MJCF of the world; NaN without MuJoCo or above
    :data:`MUJOCO_MAX_BODIES` bodies."""
    try:
        import mujoco
    except ImportError:
        return math.nan
    if bodies > MUJOCO_MAX_BODIES:
        return math.nan
    # MuJoCo's default arena is too small for thousands of bodies ("Could not allocate memory").
    xml = mjcf(case, n).replace("<mujoco>", f'<mujoco><size memory="{max(64, bodies // 10)}M"/>', 1)
    return _best(lambda: mujoco.MjModel.from_xml_string(xml), 1 if bodies > 2_000 else repeat)


def bench_build(sizes) -> list[dict]:
    """Free bodies, a chain and a grid of joints at ``sizes.build_bodies`` / ``sizes.build_joints``: the API, a
    scene file and MuJoCo's MJCF compile."""
    rows = []
    cases = [("free bodies", n) for n in sizes.build_bodies] + [
        (case, n) for case in ("chain", "grid") for n in sizes.build_joints
    ]
    with tempfile.TemporaryDirectory() as folder:
        for case, n in cases:
            repeat = 1 if n >= 100_000 else min(sizes.repeat, 3)
            world = api_world(case, n)
            bodies, joints = world.model.body_count, world.model.joint_count
            del world
            items = joints if joints else bodies
            path = Path(folder) / "scene.toml"
            path.write_text(scene_toml(case, n))
            api = _best(lambda case=case, n=n: api_world(case, n), repeat)
            scene = _best(lambda path=path: scene_file.load(path).world.model, repeat)
            mujoco = _mujoco_compile(case, n, bodies, repeat)
            for how, seconds in (("API", api), ("scene file", scene), ("MuJoCo MJCF", mujoco)):
                rows.append({
                    "case": case, "how": how, "bodies": bodies, "joints": joints, "build_s": seconds,
                    "us_per_item": 1e6 * seconds / items, "x_api": seconds / api,
                    "x_mujoco": seconds / mujoco if np.isfinite(mujoco) else math.nan,
                })  # fmt: skip
    return rows
