"""Vehicles and wind in scene files, both ways: ``[[vehicles]]`` and ``[wind]`` built into a world, and a world's
quadrotors (with the controllers and trajectories of ``tumble.control`` that fly them) and wind written back.

A vehicle is written at its present state, its motors at their present speeds; its controller starts afresh (no
integral carried over) and its trajectory from its own time 0, as the loaded world's clock does.
"""

from __future__ import annotations

from contextlib import contextmanager

import numpy as np

from .. import wind as winds
from ..control import CascadedPID, Circle, Hover, Lissajous, MinimumSnap, SE3Controller
from ..vehicles import CRAZYFLIE, HUMMINGBIRD, Quadrotor
from . import schema

__all__ = ["build_vehicle", "build_wind", "vehicle_to_scene", "wind_to_scene"]

_PARAMETER_SETS = {"crazyflie": CRAZYFLIE, "hummingbird": HUMMINGBIRD}
_CONTROLLERS = {"se3": SE3Controller, "cascaded_pid": CascadedPID}
_REFERENCES = {"hover": Hover, "circle": Circle, "lissajous": Lissajous, "minimum_snap": MinimumSnap}


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


def _floats(values) -> list:
    return np.asarray(values, dtype=float).tolist()


def _spec_of(obj, kinds: dict, fields: tuple[str, ...]) -> dict | None:
    """``{"type": name, field: value, ...}`` for an instance of one of ``kinds``; None for anything else."""
    for name, kind in kinds.items():
        if type(obj) is kind:
            out = {"type": name}
            for field in fields:
                value = getattr(obj, field, None)
                if value is not None:
                    out[field] = value.tolist() if isinstance(value, np.ndarray) else value
            return out
    return None


_CONTROLLER_FIELDS = ("kp_pos", "kd_pos", "ki_pos", "kp_att", "kd_att", "feedforward", "kp_vel", "ki_vel", "kp_rate",
                      "integral_limit")  # fmt: skip
_REFERENCE_FIELDS = ("position", "center", "radius", "frequency", "A", "B", "a", "b", "delta", "waypoints", "times",
                     "yaw")  # fmt: skip


def vehicle_to_scene(quad: Quadrotor, name: str) -> dict:
    """The ``[[vehicles]]`` entry of ``quad`` now. A controller or trajectory that is not one of
    ``tumble.control``'s is left out (the vehicle is then written with its motors' present commands)."""
    body = quad.body
    params = {name: (_floats(value) if isinstance(value, np.ndarray) else value)
              for name, value in quad.params.items()}  # fmt: skip
    params["rotor_directions"] = [int(d) for d in quad.params["rotor_directions"]]
    entry = {"type": "quadrotor", "params": params, "layout": quad.layout, "position": _floats(body.position),
             "orientation": _floats(body.orientation), "velocity": _floats(body.velocity),
             "angular_velocity": _floats(body.angular_velocity), "rotor_speeds": _floats(quad.rotor_speeds),
             "name": name}  # fmt: skip
    flight = quad._flight
    controller = trajectory = None
    if flight is not None and flight.handle in quad.world.controllers:
        controller = _spec_of(flight.controller, _CONTROLLERS, _CONTROLLER_FIELDS)
        trajectory = _spec_of(flight.trajectory, _REFERENCES, _REFERENCE_FIELDS)
    if controller is not None and trajectory is not None:
        if flight.rate is not None:
            controller["rate"] = flight.rate
        entry.update(controller=controller, trajectory=trajectory)
    else:
        entry["commands"] = _floats(quad.commanded_rotor_speeds)
    return entry


def wind_to_scene(wind) -> dict | None:
    """The ``[wind]`` table of a world's wind (None for still air or a wind model of the user's own)."""
    if isinstance(wind, winds.Constant):
        return {"type": "constant", "velocity": _floats(wind.v)}
    if isinstance(wind, winds.Sinusoid):
        return {"type": "sinusoid", "mean": _floats(wind.mean), "amplitude": _floats(wind.amplitude),
                "frequency": wind.frequency}  # fmt: skip
    if isinstance(wind, winds.Dryden):
        out = {"type": "dryden", "mean": _floats(wind.mean), "sigma": _floats(wind.sigma),
               "length_scale": _floats(wind.length_scale)}  # fmt: skip
        if wind.seed is not None:
            out["seed"] = wind.seed
        return out
    return None
