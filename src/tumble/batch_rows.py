"""Copies of one world as the rows of one bigger world: the model, contacts and joint impulses of ``k`` copies laid
out one copy after the other (``tumble.batch`` steps such a world through the ordinary pipeline).

Copy ``j``'s bodies are rows ``j B .. (j + 1) B - 1`` (``B`` bodies a copy), its shapes rows ``j S ..`` and its
joints rows ``j J ..``. Nothing couples rows of different copies: the broad phase pairs no shapes of different
copies (``Model.copy_shape_count``), joints and exclusions stay within a copy, and every other stage works row by
row or pair by pair in pair order, which keeps each copy's order. So each copy steps bit for bit as the world.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .model import Model
from .state import CONTACT_FIELDS, JOINT_FIELDS, State

__all__ = ["rows_model", "tiled_impulses", "copy_impulses", "splice_contacts", "DRIVE_TARGET"]

DRIVE_TARGET = 6  # the column of JointArrays.drive that holds a spring drive's target

# GeometryArrays fields with one row per shape; the others (vertices, faces, edges) are shared by every copy, and
# the shapes' ranges into them stay valid.
_PER_SHAPE = (
    "shape_type", "shape_params", "shape_pos_local", "shape_quat_local", "shape_aabb_center_local",
    "shape_aabb_half_local", "shape_vertex_start", "shape_vertex_count", "shape_face_start", "shape_face_count",
    "shape_edge_start", "shape_edge_count",
)  # fmt: skip


def _tiled(array: np.ndarray, k: int) -> np.ndarray:
    return np.tile(array, (k,) + (1,) * (array.ndim - 1))


def _offsets(k: int, per_copy: int, rows: int) -> np.ndarray:
    """``j * per_copy`` for each of the ``rows`` rows of each copy ``j``."""
    return np.repeat(np.arange(k, dtype=np.int64) * per_copy, rows)


def rows_model(base: Model, tables: dict[str, np.ndarray], *, fold_gravity: bool) -> Model:
    """``k`` copies of ``base`` as one model, each with its row of ``tables``: ``gravity`` (k, 3), ``mass``,
    ``inv_mass`` (k, B), ``inertia``, ``inv_inertia`` (k, B, 3, 3), ``friction``, ``restitution`` (k, S),
    ``drive_target`` (k, J).

    ``fold_gravity``: free bodies, whose kernel takes one gravity for all rows: each copy's weight goes into its
    rows' constant force (``F + m g``, the sum the kernel forms) and the model's gravity is zero. Otherwise each
    row falls under its copy's gravity (``Model.body_gravity``).
    """
    k = tables["gravity"].shape[0]
    bodies, shapes = base.body_count, base.shape_count
    geom = base.geometry
    per_shape = {name: _tiled(getattr(geom, name), k) for name in _PER_SHAPE}
    per_shape["shape_body"] = _tiled(geom.shape_body, k) + _offsets(k, bodies, shapes)
    joints = base.joints
    joint_rows = joints.kind.shape[0]
    shift = _offsets(k, bodies, joint_rows)
    body_a, body_b = _tiled(joints.body_a, k), _tiled(joints.body_b, k)
    drive = _tiled(joints.drive, k)
    drive[:, DRIVE_TARGET] = tables["drive_target"].reshape(-1)
    copy_joints = joints._replace(
        kind=_tiled(joints.kind, k), body_a=np.where(body_a >= 0, body_a + shift, body_a),
        body_b=np.where(body_b >= 0, body_b + shift, body_b), local_anchor_a=_tiled(joints.local_anchor_a, k),
        local_anchor_b=_tiled(joints.local_anchor_b, k), local_frame_a=_tiled(joints.local_frame_a, k),
        local_frame_b=_tiled(joints.local_frame_b, k), drive=drive,
    )  # fmt: skip
    exclusions = (base.joint_exclusions[None] + (np.arange(k) * bodies)[:, None, None]).reshape(-1, 2)
    mass = tables["mass"]
    gravity_rows = np.repeat(tables["gravity"], bodies, axis=0)
    if fold_gravity:
        constant_force = (base.body_constant_force + tables["gravity"][:, None, :] * mass[:, :, None]).reshape(-1, 3)
        gravity, gravity_rows = np.zeros(3), np.zeros_like(gravity_rows)
    else:
        constant_force, gravity = _tiled(base.body_constant_force, k), tables["gravity"][0].copy()
    return dataclasses.replace(
        base, gravity=gravity, body_gravity=gravity_rows, body_mass=mass.reshape(-1),
        body_inv_mass=tables["inv_mass"].reshape(-1), body_inertia_local=tables["inertia"].reshape(-1, 3, 3),
        body_inv_inertia_local=tables["inv_inertia"].reshape(-1, 3, 3), body_com_local=_tiled(base.body_com_local, k),
        body_is_dynamic=_tiled(base.body_is_dynamic, k), body_linear_damping=_tiled(base.body_linear_damping, k),
        body_angular_damping=_tiled(base.body_angular_damping, k), body_name=base.body_name * k,
        geometry=geom._replace(**per_shape), shape_friction=tables["friction"].reshape(-1),
        shape_restitution=tables["restitution"].reshape(-1), shape_rolling=_tiled(base.shape_rolling, k),
        shape_core_radius=_tiled(base.shape_core_radius, k), shape_group=_tiled(base.shape_group, k),
        shape_mask=_tiled(base.shape_mask, k), shapes=base.shapes * k, body_constant_force=constant_force,
        body_constant_torque=_tiled(base.body_constant_torque, k), joints=copy_joints, joint_exclusions=exclusions,
        copy_shape_count=shapes,
    )  # fmt: skip


def tiled_impulses(state: State, template: State, k: int, shapes: int) -> None:
    """Give ``state`` (``k`` copies' rows) the template's contacts and joint impulses in every copy."""
    for name in JOINT_FIELDS:
        setattr(state, name, _tiled(getattr(template, name), k))
    count = template.contact_count
    for name in CONTACT_FIELDS:
        setattr(state, name, _tiled(getattr(template, name), k))
    for name in ("contact_shape_a", "contact_shape_b"):
        getattr(state, name)[:] += _offsets(k, shapes, count)


def splice_contacts(state: State, copies: np.ndarray, template: State | None, shapes: int) -> None:
    """Replace the contacts of the local ``copies`` in ``state`` by the template's (none if ``template`` is None),
    keeping the list sorted by shape pair as the warm start's merge walk needs."""
    if shapes == 0:
        return
    keep = ~np.isin(state.contact_shape_a // shapes, copies)
    parts = {name: [getattr(state, name)[keep]] for name in CONTACT_FIELDS}
    if template is not None and template.contact_count and copies.size:
        count = template.contact_count
        for name in CONTACT_FIELDS:
            parts[name].append(_tiled(getattr(template, name), copies.size))
        for name in ("contact_shape_a", "contact_shape_b"):
            parts[name][-1] = parts[name][-1] + np.repeat(copies * shapes, count)
    merged = {name: np.concatenate(arrays) for name, arrays in parts.items()}
    total = max(1, int(merged["contact_shape_b"].max(initial=0)) + 1)
    order = np.argsort(merged["contact_shape_a"] * total + merged["contact_shape_b"], kind="stable")
    for name, array in merged.items():
        setattr(state, name, array[order])


def copy_impulses(state: State, j: int, shapes: int, joints: int) -> dict[str, np.ndarray]:
    """Local copy ``j``'s contacts and joint impulses in ``state``, numbered as in one world."""
    out = {name: getattr(state, name)[j * joints : (j + 1) * joints].copy() for name in JOINT_FIELDS}
    mine = state.contact_shape_a // shapes == j if shapes else np.zeros(state.contact_count, bool)
    for name in CONTACT_FIELDS:
        out[name] = getattr(state, name)[mine].copy()
    out["contact_shape_a"] -= j * shapes
    out["contact_shape_b"] -= j * shapes
    return out
