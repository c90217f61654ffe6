"""Vehicles and wind in scene files: ``[[vehicles]]`` and ``[wind]`` built into a world (``tumble.io.scene_dump``
writes them back).

A vehicle is written at its present state, its motors at their present speeds; its controller starts afresh (no
integral carried over) and its trajectory from its own time 0, as the loaded world's clock does.
"""

from __future__ import annotations

from contextlib import contextmanager

import numpy as np

from .. import wind as winds
from ..io.scene_dump import CONTROLLERS as _CONTROLLERS
from ..io.scene_dump import REFERENCES as _REFERENCES
from ..vehicles import CRAZYFLIE, HUMMINGBIRD, Quadrotor
from . import schema

__all__ = ["build_vehicle", "build_wind"]

_PARAMETER_SETS = {"crazyflie": CRAZYFLIE, "hummingbird": HUMMINGBIRD}


def _given(spec, exclude=()) -> dict:
    """The fields of ``spec`` that were given (not None), as plain values."""
    return {k: v for k, v in spec.model_dump(exclude={"type", *exclude}).items() if v is not None}


def _params(spec) -> dict:
    if isinstance(spec, str):
        return dict(_PARAMETER_SETS[spec])
    values = {**_PARAMETER_SETS[spec.base], **_given(spec, exclude={"base"})}
    inertia = np.asarray(values["inertia"], float)
    values["inertia"] = np.diag(inertia) if inertia.ndim == 1 else inertia
    return values


def build_vehicle(world, spec: schema.Vehicle) -> Quadrotor:
    """The quadrotor of ``spec`` in ``world``, its motors set and, if it has one, its controller flying."""
    quad = Quadrotor(world, _params(spec.params), spec.position, spec.orientation, spec.velocity,
                     spec.angular_velocity, spec.layout, spec.name)  # fmt: skip
    if spec.rotor_speeds == "hover":
        quad.rotor_speeds = [quad.hover_rotor_speed] * 4
    elif spec.rotor_speeds != "rest":
        quad.rotor_speeds = spec.rotor_speeds
    if spec.controller is None:
        quad.command_rotor_speeds(quad.rotor_speeds if spec.commands is None else spec.commands)
        return quad
    with _at("controller"):
        controller = _CONTROLLERS[spec.controller.type](quad, **_given(spec.controller, exclude={"rate"}))
    with _at("trajectory"):
        trajectory = _REFERENCES[spec.trajectory.type](**_given(spec.trajectory))
    quad.fly(controller, trajectory, rate=spec.controller.rate)
    return quad


@contextmanager
def _at(place: str):
    """Errors raised inside name ``place`` (``controller: kp_pos must be >= 0, ...``)."""
    try:
        yield
    except (ValueError, TypeError) as error:
        raise type(error)(f"{place}: {error}") from error


def build_wind(spec) -> winds.Wind | None:
    if spec is None:
        return None
    if spec.type == "constant":
        return winds.Constant(spec.velocity)
    kind = {"sinusoid": winds.Sinusoid, "dryden": winds.Dryden}[spec.type]
    return kind(**_given(spec))
