"""A quadrotor's parameters, validated and read-only (:func:`quadrotor_params`), the two sets tumble ships
(:data:`CRAZYFLIE`, :data:`HUMMINGBIRD`) and the rotor layouts (:func:`rotor_hubs`, the package's docstring)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from types import MappingProxyType

import numpy as np

from .. import portable
from .._validate import as_array, as_float, as_vector3

__all__ = ["CRAZYFLIE", "HUMMINGBIRD", "quadrotor_params", "rotor_hubs"]

_PARAMETER_NAMES = ("mass", "inertia", "arm_length", "k_thrust", "k_moment", "k_drag", "k_inflow", "speed_min",
                    "speed_max", "time_constant", "rotor_directions", "drag_coefficients", "kp_att",
                    "kd_att")  # fmt: skip


def quadrotor_params(**values) -> Mapping:
    """A read-only parameter set for :class:`Quadrotor`, validated: ``mass`` [kg], ``inertia`` (3, 3) [kg m²] about
    the centre of mass in the body frame, ``arm_length`` [m] (centre of mass to hub), ``k_thrust`` [N s²/rad²],
    ``k_moment`` [N m s²/rad²], ``k_drag`` and ``k_inflow`` [N s²/(m rad)] (rotor drag across and along the axis),
    ``speed_min``/``speed_max`` [rad/s], ``time_constant`` [s] (the motors' lag), ``rotor_directions`` (4,) of ±1
    ``drag_coefficients`` (3,) [kg/m] (parasitic drag of the frame, ``world.add_drag``), and the attitude gains
    the vehicle flies well with, ``kp_att`` [1/s²] and ``kd_att`` [1/s] (the motors' lag bounds them; the
    controllers of ``tumble.control`` take them by default, as RotorPy's do). Every name is needed;
    start from a shipped set to change a few: ``quadrotor_params(**{**CRAZYFLIE, "mass": 0.035})``."""
    unknown = sorted(set(values) - set(_PARAMETER_NAMES))
    missing = [name for name in _PARAMETER_NAMES if name not in values]
    if unknown or missing:
        raise ValueError(f"quadrotor parameters: unknown {unknown}, missing {missing}; the names are "
                         f"{list(_PARAMETER_NAMES)}")  # fmt: skip
    p = {name: as_float(name, values[name], positive=True) for name in ("mass", "arm_length", "k_thrust")}
    for name in ("k_moment", "k_drag", "k_inflow", "speed_min", "time_constant", "kp_att", "kd_att"):
        p[name] = as_float(name, values[name], nonnegative=True)
    p["speed_max"] = as_float("speed_max", values["speed_max"], positive=True)
    if p["speed_min"] >= p["speed_max"]:
        raise ValueError(f"speed_min must be < speed_max, got {p['speed_min']!r} >= {p['speed_max']!r}")
    inertia = as_array("inertia", values["inertia"], (3, 3), batch=False)
    if not np.allclose(inertia, inertia.T, rtol=1e-12, atol=0.0) or portable.eigh(inertia)[0][0] <= 0.0:
        raise ValueError(f"inertia must be symmetric and positive definite, got {inertia.tolist()}")
    directions = as_array("rotor_directions", values["rotor_directions"], (4,), batch=False)
    if not np.all(np.abs(directions) == 1.0):
        raise ValueError(f"rotor_directions must be four of +1 or -1, got {directions.tolist()}")
    drag = as_vector3("drag_coefficients", values["drag_coefficients"])
    if (drag < 0).any():
        raise ValueError(f"drag_coefficients must be >= 0, got {drag.tolist()}")
    for array in (inertia, directions, drag):
        array.flags.writeable = False
    p.update(inertia=inertia, rotor_directions=directions, drag_coefficients=drag)
    return MappingProxyType({name: p[name] for name in _PARAMETER_NAMES})


# The Crazyflie 2.0 (Bitcraze), with RotorPy's figures: inertia and rotor coefficients from J. Förster, "System
# identification of the Crazyflie 2.0 nano quadrocopter", ETH Zürich, 2015; thrust from 14.5 g at 2500 rad/s;
# attitude gains RotorPy 3.0's (its 72 ms motors leave the attitude loop with little phase to spare).
CRAZYFLIE = quadrotor_params(
    mass=0.03, inertia=np.diag([1.43e-5, 1.43e-5, 2.89e-5]), arm_length=0.043, k_thrust=2.3e-8, k_moment=7.8e-10,
    k_drag=1.02506e-6, k_inflow=7.553e-7, speed_min=0.0, speed_max=2500.0, time_constant=0.072,
    rotor_directions=(1, -1, 1, -1), drag_coefficients=(0.0, 0.0, 0.0), kp_att=310.0, kd_att=57.0,
)  # fmt: skip

# The AscTec Hummingbird, with RotorPy's figures: mass and inertia from D. Mellinger, "Trajectory generation and
# control for quadrotors", PhD thesis, University of Pennsylvania, 2012, and M. Achtelik et al.; rotor coefficients
# from E. Kaufman et al. (IEEE 7991501, 2017) and the identification of A. Mehrotra (University of New Mexico
# thesis, ece_etds 1189); the rotor drag and inflow coefficients are RotorPy's, a tenth of those papers'.
HUMMINGBIRD = quadrotor_params(
    mass=0.5, inertia=np.diag([3.65e-3, 3.68e-3, 7.03e-3]), arm_length=0.17, k_thrust=5.57e-6, k_moment=1.36e-7,
    k_drag=1.19e-4, k_inflow=2.32e-4, speed_min=0.0, speed_max=1500.0, time_constant=0.005,
    rotor_directions=(1, -1, 1, -1), drag_coefficients=(0.5e-2, 0.5e-2, 1e-2), kp_att=544.0, kd_att=46.64,
)  # fmt: skip

_LAYOUTS = {
    "x": np.array([[1.0, 1.0, 0.0], [1.0, -1.0, 0.0], [-1.0, -1.0, 0.0], [-1.0, 1.0, 0.0]]) / math.sqrt(2.0),
    "+": np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]]),
}


def rotor_hubs(layout: str, arm_length: float) -> np.ndarray:
    """(4, 3) [m] the rotors' hubs in the body frame for ``layout`` ``"x"`` or ``"+"`` (module docstring)."""
    if layout not in _LAYOUTS:
        raise ValueError(f"layout must be 'x' or '+', got {layout!r}")
    return _LAYOUTS[layout] * arm_length
