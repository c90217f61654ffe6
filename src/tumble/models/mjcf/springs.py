"""``springdamper``: a joint's spring and damper sized from its effective mass, MuJoCo's compiler rule.

For a hinge or slide with ``springdamper="τ ζ"`` (both positive) MuJoCo replaces the joint's ``stiffness`` and
``damping`` by ``k = m / (τ ζ)²`` and ``b = 2 m / τ``, where ``m = 1 / (M⁻¹)ᵢᵢ`` is the joint's effective mass (or
moment of inertia) in the model's pose ``qpos0``, armature included (MuJoCo's ``dof_invweight0``): a mass, spring
and damper of natural frequency ``1 / (τ ζ)`` and damping ratio ``ζ``, the parametrisation of MuJoCo's ``solref``
(measured against MuJoCo 4's compiled ``jnt_stiffness`` and ``dof_damping``).
"""

from __future__ import annotations

from dataclasses import replace

from ... import portable
from ..description import ModelDescription

__all__ = ["sized_springs"]

_DOFS = {"free": 6, "ball": 3, "hinge": 1, "slide": 1}


def sized_springs(model: ModelDescription) -> ModelDescription:
    """``model`` with every ``springdamper`` joint's stiffness and damping set from its effective mass."""
    if not any(joint.springdamper for body in model.bodies for joint in body.joints):
        return model
    from ..build import to_articulation

    # its tree alone (it starts at qpos0): the mass matrix needs no geoms, tendons or actuators
    tree = replace(model, bodies=tuple(replace(body, geoms=()) for body in model.bodies), world_geoms=(), tendons=(),
                   actuators=(), excludes=())  # fmt: skip
    articulation = to_articulation(tree)
    inverse = portable.inverse(articulation.mass_matrix(articulation.q))
    dof, bodies = 0, []
    for body in model.bodies:
        joints = []
        for joint in body.joints:
            if joint.springdamper is not None:
                timeconst, dampratio = joint.springdamper
                mass = 1.0 / inverse[dof, dof]
                joint = replace(joint, stiffness=mass / (timeconst * dampratio) ** 2, damping=2.0 * mass / timeconst)
            joints.append(joint)
            dof += _DOFS[joint.type]
        bodies.append(replace(body, joints=tuple(joints)))
    return replace(model, bodies=tuple(bodies))
