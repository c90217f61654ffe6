"""What the replay draws: every shape of a world as a compact description in its body's frame.

A description is a plain dict (JSON-ready apart from the NumPy arrays of hulls and meshes)::

    {"body_count": N,
     "shapes": [{"body": i, "kind": "box", "size": [hx, hy, hz],
                 "position": [x, y, z], "quat": [w, x, y, z]}, ...],
     "meshes": [{"vertices": (v, 3) float32, "faces": (f, 3) uint32}, ...]}

``position`` and ``quat`` place the shape in the body frame, relative to the body frame's *origin* (the point
``Trajectory.position`` records; the model stores shapes relative to the centre of mass, so the COM offset is
added back). ``size`` depends on ``kind``:

==========  ====================================  ==============================================
kind        ``size``                              shape frame
==========  ====================================  ==============================================
sphere      ``[r]``                               centred
box         ``[hx, hy, hz]`` (half extents)       centred
capsule     ``[r, half_length]``                  segment along z, ``z ∈ [-half, half]``
cylinder    ``[r, half_height]``                  axis z, centred
hull, mesh  ``[]``; ``"mesh": k`` indexes         ``meshes[k]`` (hull corners and outward faces,
            ``meshes``                            or the triangle mesh as given)
plane       ``[nx, ny, nz, offset]``              the points ``n · x = offset``
==========  ====================================  ==============================================

Equal hulls and meshes share one ``meshes`` entry. The page turns each plane into a large quad around the scene
(:func:`plane_quads`), since a plane has no size of its own.
"""

from __future__ import annotations

import numpy as np

from ..rotation import quat_multiply, quat_rotate
from ..shapes import Box, Capsule, ConvexHull, Cylinder, Plane, Sphere, TriMesh
from ..vehicles import quadrotors

__all__ = ["scene_geometry", "fallback_geometry", "body_radius", "plane_quads", "check_geometry"]

_KINDS = ("sphere", "box", "capsule", "cylinder", "hull", "mesh", "plane")


def _describe(shape, meshes: list, mesh_index: dict) -> tuple[str, list[float], int | None]:
    """``(kind, size, mesh)`` of one shape; appends hulls and meshes to ``meshes`` once per distinct shape."""
    if isinstance(shape, Sphere):
        return "sphere", [shape.radius], None
    if isinstance(shape, Box):
        return "box", shape.half_extents.tolist(), None
    if isinstance(shape, Capsule):
        return "capsule", [shape.radius, 0.5 * shape.length], None
    if isinstance(shape, Cylinder):
        return "cylinder", [shape.radius, 0.5 * shape.height], None
    if isinstance(shape, Plane):
        return "plane", [*shape.normal.tolist(), shape.offset], None
    if isinstance(shape, (ConvexHull, TriMesh)):
        kind = "hull" if isinstance(shape, ConvexHull) else "mesh"
        if shape not in mesh_index:
            mesh_index[shape] = len(meshes)
            meshes.append(
                {
                    "vertices": np.asarray(shape.vertices, dtype=np.float32),
                    "faces": np.asarray(shape.faces, dtype=np.uint32),
                }
            )
        return kind, [], mesh_index[shape]
    raise TypeError(f"the replay cannot draw shape {shape!r} (of type {type(shape).__name__})")


def scene_geometry(world) -> dict:
    """Every shape of ``world`` in its body's frame (see the module docstring for the layout).

    Args:
        world: a :class:`~tumble.World`; its bodies are numbered as in the trajectories it records.

    Returns:
        dict with ``body_count``, ``shapes`` (one dict per shape, in model order) and ``meshes``.
    """
    from ..world import World

    if not isinstance(world, World):
        raise TypeError(f"world must be a tumble.World, got {type(world).__name__}")
    model = world.model
    # The model places shapes relative to the COM; the trajectory records the body frame's origin.
    position = model.shape_pos_local + model.body_com_local[model.shape_body]
    meshes: list[dict] = []
    mesh_index: dict = {}
    shapes = []
    for k, shape in enumerate(model.shapes):
        kind, size, mesh = _describe(shape, meshes, mesh_index)
        entry = {
            "body": int(model.shape_body[k]),
            "kind": kind,
            "size": [float(s) for s in size],
            "position": position[k].tolist(),
            "quat": model.shape_quat_local[k].tolist(),
        }
        if mesh is not None:
            entry["mesh"] = mesh
        shapes.append(entry)
    parts, vehicles = _vehicle_parts(world)
    return {"body_count": int(model.body_count), "shapes": shapes + parts, "meshes": meshes, "vehicles": vehicles}


# Rotor discs and blades of the drawn quadrotors, in arm lengths: about a Crazyflie's propeller.
_ROTOR_RADIUS, _ROTOR_LIFT = 0.55, 0.12


def _vehicle_parts(world) -> tuple[list[dict], list[dict]]:
    """What the replay draws of each quadrotor besides its collision shapes: an arm from its centre to each hub
    and a rotor disc over each hub (drawn only; positions in the body frame from its origin, as the rotors'), and
    the vehicle itself (body, name, hubs, spins, rotor radius) for its blades and reference path."""
    parts, vehicles = [], []
    for quad in quadrotors(world):
        i, arm = quad.body.index, quad.params["arm_length"]
        hubs = []
        for rotor in quad.rotors:
            hub = np.asarray(rotor.position, dtype=float)
            heading = float(np.arctan2(hub[1], hub[0]))
            turn = [float(np.cos(heading / 2)), 0.0, 0.0, float(np.sin(heading / 2))]  # x onto the arm
            length = float(np.hypot(hub[0], hub[1]))
            parts.append({"body": i, "kind": "box", "size": [0.5 * length, 0.06 * arm, 0.04 * arm],
                          "position": (0.5 * hub).tolist(), "quat": turn})  # fmt: skip
            disc = hub + (0.0, 0.0, _ROTOR_LIFT * arm)
            parts.append({"body": i, "kind": "cylinder", "size": [_ROTOR_RADIUS * arm, 0.015 * arm],
                          "position": disc.tolist(), "quat": [1.0, 0.0, 0.0, 0.0]})  # fmt: skip
            hubs.append((disc + (0.0, 0.0, 0.03 * arm)).tolist())
        vehicles.append({"body": i, "name": quad.body.name or f"#{i}", "hubs": hubs,
                         "spins": [float(r.spin) for r in quad.rotors], "radius": _ROTOR_RADIUS * arm})  # fmt: skip
    return parts, vehicles


def fallback_geometry(body_mass: np.ndarray, body_inertia: np.ndarray, body_com_local: np.ndarray) -> dict:
    """A sphere per moving body when no world is at hand: the solid ball of the same mass and mean moment.

    A solid ball has ``I = 2/5 m r²`` about every axis, so ``r = sqrt(5 tr(I) / (6 m))``; bodies without mass
    (static ones, whose shapes are unknown) are left out.
    """
    shapes = []
    for i, (m, inertia, com) in enumerate(zip(body_mass, body_inertia, body_com_local, strict=True)):
        if not m > 0.0:
            continue
        radius = float(np.sqrt(5.0 * np.trace(inertia) / (6.0 * m)))
        shapes.append(
            {
                "body": i,
                "kind": "sphere",
                "size": [radius if radius > 0.0 else 0.05],
                "position": np.asarray(com, dtype=float).tolist(),
                "quat": [1.0, 0.0, 0.0, 0.0],
            }
        )
    return {"body_count": len(body_mass), "shapes": shapes, "meshes": []}


def check_geometry(geometry, body_count: int) -> None:
    """Raise ValueError unless ``geometry`` describes ``body_count`` bodies in the layout above."""
    if not isinstance(geometry, dict) or not {"shapes", "meshes"} <= set(geometry):
        raise TypeError("geometry must be a dict with 'shapes' and 'meshes', as scene_geometry(world) returns")
    if geometry.get("body_count", body_count) != body_count:
        raise ValueError(
            f"geometry describes {geometry['body_count']} bodies but the trajectory has {body_count}; "
            "pass the world (or its scene_geometry) that recorded this trajectory"
        )
    for k, shape in enumerate(geometry["shapes"]):
        if shape.get("kind") not in _KINDS:
            raise ValueError(f"geometry['shapes'][{k}]['kind'] must be one of {_KINDS}, got {shape.get('kind')!r}")
        if not 0 <= int(shape["body"]) < body_count:
            raise ValueError(f"geometry['shapes'][{k}]['body'] must be in [0, {body_count}), got {shape['body']!r}")
        if shape["kind"] in ("hull", "mesh") and not 0 <= int(shape.get("mesh", -1)) < len(geometry["meshes"]):
            raise ValueError(
                f"geometry['shapes'][{k}]['mesh'] must index geometry['meshes'], got {shape.get('mesh')!r}"
            )


def _shape_radius(shape: dict, meshes: list) -> float:
    """Radius of a ball about the shape frame's origin that holds the shape (planes: 0, they are drawn apart)."""
    kind, size = shape["kind"], shape["size"]
    if kind == "sphere":
        return size[0]
    if kind == "box":
        return float(np.linalg.norm(size))
    if kind in ("capsule", "cylinder"):
        return size[1] + size[0] if kind == "capsule" else float(np.hypot(size[0], size[1]))
    if kind in ("hull", "mesh"):
        vertices = meshes[shape["mesh"]]["vertices"]
        return float(np.max(np.linalg.norm(vertices, axis=1))) if len(vertices) else 0.0
    return 0.0


def body_radius(geometry: dict, body_count: int) -> np.ndarray:
    """(body_count,) [m]: a ball about each body frame's origin that holds its shapes (planes left out)."""
    radius = np.zeros(body_count)
    for shape in geometry["shapes"]:
        if shape["kind"] == "plane":
            continue
        reach = float(np.linalg.norm(shape["position"])) + _shape_radius(shape, geometry["meshes"])
        radius[shape["body"]] = max(radius[shape["body"]], reach)
    return radius


def _quat_z_to(normal: np.ndarray) -> np.ndarray:
    """The shortest rotation taking +z onto the unit vector ``normal``, ``[w, x, y, z]``."""
    z = np.array([0.0, 0.0, 1.0])
    c = float(normal @ z)
    if c < -1.0 + 1e-12:
        return np.array([0.0, 1.0, 0.0, 0.0])  # half turn about x
    q = np.array([1.0 + c, *np.cross(z, normal)])
    return q / np.linalg.norm(q)


def plane_quads(geometry: dict, body_pos: np.ndarray, body_quat: np.ndarray, center, half_size: float) -> list:
    """World-frame squares for the planes: centred on the foot of ``center`` on each plane, ``2 half_size`` wide.

    Args:
        body_pos: (N, 3) [m] and body_quat: (N, 4): the (static) bodies' poses.
        center: (3,) [m], the middle of the scene; half_size [m].

    Returns:
        list of dicts ``{"body", "center" (3,), "quat" (4,) turning z onto the normal, "half"}``.
    """
    quads = []
    center = np.asarray(center, dtype=float)
    for shape in geometry["shapes"]:
        if shape["kind"] != "plane":
            continue
        body = shape["body"]
        # Shape frame -> body frame -> world frame.
        frame_quat = quat_multiply(body_quat[body], np.asarray(shape["quat"], dtype=float))
        frame_pos = body_pos[body] + quat_rotate(body_quat[body], np.asarray(shape["position"], dtype=float))
        normal_local, offset = np.asarray(shape["size"][:3], dtype=float), float(shape["size"][3])
        normal = quat_rotate(frame_quat, normal_local)
        point = frame_pos + quat_rotate(frame_quat, offset * normal_local)
        foot = center - float((center - point) @ normal) * normal
        quads.append(
            {
                "body": body,
                "center": foot.tolist(),
                "quat": _quat_z_to(normal / np.linalg.norm(normal)).tolist(),
                "half": float(half_size),
            }
        )
    return quads
