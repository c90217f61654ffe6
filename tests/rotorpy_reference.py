"""Reference flights from RotorPy (PyPI ``rotorpy``), the quadrotor simulator tumble's vehicle is compared with.

Run it where RotorPy 3.0 or later is installed (torch is not needed) to write ``data/rotorpy_reference.npz``::

    python tests/rotorpy_reference.py

The cases are plain data, read by ``tests/analytic/test_quadrotor_vs_rotorpy.py`` (against the stored file, no
RotorPy needed) and by ``tests/peers/test_rotorpy_live.py`` (against RotorPy itself, when it is installed). Each
flight is stepped here as RotorPy's ``Environment`` steps it, one ``Multirotor.step`` of ``dt`` per control
period with the command held, except that the time is counted (``k dt``), not accumulated, and that ``solve_ivp``
runs with ``DOP853`` at rtol 1e-10, atol 1e-12 (RotorPy's default, RK45 at rtol 1e-3, would compare its
integration error rather than the physics).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parent / "data" / "rotorpy_reference.npz"
INTEGRATOR = {"method": "DOP853", "rtol": 1e-10, "atol": 1e-12}
G = 9.81
CRAZYFLIE_MASS, CRAZYFLIE_K_THRUST = 0.03, 2.3e-8
HOVER_SPEED = float(np.sqrt(CRAZYFLIE_MASS * G / (4 * CRAZYFLIE_K_THRUST)))
STORE_EVERY = 5  # closed-loop flights are stored every 5th control period (0.05 s); their statistics use them all

# Every case: the Crazyflie from rest at ``start`` with its motors at the hover speed.
CASES = {
    "open_loop_equal": {"start": (0.0, 0.0, 1.0), "commands": (2000.0,) * 4, "duration": 1.0, "dt": 0.01},
    "open_loop_unequal": {
        "start": (0.0, 0.0, 1.0),
        "commands": (1900.0, 1700.0, 1850.0, 1750.0),
        "duration": 1.0,
        "dt": 0.01,
    },  # fmt: skip
    "hover_offset": {
        "start": (0.3, -0.2, 0.8),
        "trajectory": ("hover", (0.0, 0.0, 1.0)),
        "duration": 10.0,
        "dt": 0.01,
    },  # fmt: skip
    "circle": {
        "start": (1.0, 0.0, 1.0),
        "trajectory": ("circle", (0.0, 0.0, 1.0), 1.0, 0.2),
        "duration": 10.0,
        "dt": 0.01,
    },  # fmt: skip
    "figure_eight": {
        "start": (0.0, 0.0, 1.0),
        "trajectory": ("lissajous", 1.0, 0.5, 1.0, 2.0, 1.0),
        "duration": 10.0,
        "dt": 0.01,
    },  # fmt: skip
    "wind": {
        "start": (0.0, 0.0, 1.0),
        "trajectory": ("hover", (0.0, 0.0, 1.0)),
        "wind": (2.0, 0.0, 0.0),
        "duration": 10.0,
        "dt": 0.01,
    },  # fmt: skip
}
FIELDS = ("position", "velocity", "orientation", "angular_velocity_body", "rotor_speeds")


def error_statistics(time: np.ndarray, error: np.ndarray) -> np.ndarray:
    """``(RMS, max)`` of the position error over the whole flight and from 2 s on."""
    late = time >= 2.0
    return np.array([np.sqrt(np.mean(error**2)), error.max(), np.sqrt(np.mean(error[late] ** 2)), error[late].max()])


def _rotorpy_trajectory(spec):
    from rotorpy.trajectories.circular_traj import ThreeDCircularTraj
    from rotorpy.trajectories.hover_traj import HoverTraj
    from rotorpy.trajectories.lissajous_traj import TwoDLissajous

    kind, *args = spec
    if kind == "hover":
        return HoverTraj(x0=np.array(args[0]))
    if kind == "circle":
        center, radius, frequency = args
        return ThreeDCircularTraj(np.array(center), np.array([radius, radius, 0.0]), np.array([frequency] * 2 + [0.0]))
    A, B, a, b, height = args
    return TwoDLissajous(A=A, B=B, a=a, b=b, height=height)


def rotorpy_flight(case: dict) -> dict[str, np.ndarray]:
    """One case flown by RotorPy: the state at every ``k dt`` (quaternions as w, x, y, z) and the reference."""
    from rotorpy.controllers.quadrotor_control import SE3Control
    from rotorpy.vehicles.crazyflie_params import quad_params
    from rotorpy.vehicles.multirotor import Multirotor

    wind = np.array(case.get("wind", (0.0, 0.0, 0.0)), float)
    state = {"x": np.array(case["start"], float), "v": np.zeros(3), "q": np.array([0.0, 0.0, 0.0, 1.0]),
             "w": np.zeros(3), "wind": wind, "rotor_speeds": np.full(4, HOVER_SPEED)}  # fmt: skip
    vehicle = Multirotor(quad_params, initial_state=state, integrator_kwargs=INTEGRATOR)
    controller = SE3Control(quad_params) if "trajectory" in case else None
    trajectory = _rotorpy_trajectory(case["trajectory"]) if controller else None
    steps = int(round(case["duration"] / case["dt"]))
    out = {name: [] for name in (*FIELDS, "reference", "time")}
    for k in range(steps + 1):
        t = k * case["dt"]
        if controller:
            flat = trajectory.update(t)
            control = controller.update(t, state, flat)
            out["reference"].append(flat["x"])
        else:
            control = {"cmd_motor_speeds": np.array(case["commands"], float)}
            out["reference"].append(np.full(3, np.nan))
        out["time"].append(t)
        out["position"].append(state["x"].copy())
        out["velocity"].append(state["v"].copy())
        out["orientation"].append(np.roll(state["q"], 1))  # RotorPy's [x, y, z, w] as [w, x, y, z]
        out["angular_velocity_body"].append(state["w"].copy())
        out["rotor_speeds"].append(state["rotor_speeds"].copy())
        if k < steps:
            state["wind"] = wind
            state = vehicle.step(state, control, case["dt"])
    return {name: np.array(values) for name, values in out.items()}


def tumble_flight(case: dict, dt: float | None = None) -> dict[str, np.ndarray]:
    """The same case flown by tumble (the SE(3) controller at ``1 / case["dt"]`` Hz, the world stepped at ``dt``,
    by default the control period), sampled at every control period."""
    import tumble
    from tumble.control import Circle, Hover, Lissajous, SE3Controller
    from tumble.vehicles import Quadrotor

    period = case["dt"]
    dt = period if dt is None else dt
    world = tumble.World()
    world.wind = case.get("wind")
    quad = Quadrotor(world, position=case["start"])
    quad.rotor_speeds = [quad.hover_rotor_speed] * 4
    trajectory = None
    if "trajectory" in case:
        kind, *args = case["trajectory"]
        if kind == "hover":
            trajectory = Hover(args[0])
        elif kind == "circle":
            trajectory = Circle(*args)
        else:
            A, B, a, b, height = args
            trajectory = Lissajous(A, B, a, b, center=(0.0, 0.0, height))
        quad.fly(SE3Controller(quad), trajectory, rate=1.0 / period)
    else:
        quad.command_rotor_speeds(case["commands"])
    speeds = [quad.rotor_speeds]

    def rotor_log(world, t):
        speeds.append(quad.rotor_speeds)

    every = int(round(period / dt))
    world.add_controller(rotor_log, rate=1.0 / period)
    recording = world.simulate(case["duration"], dt, record_every=every)
    i = quad.body.index
    time = recording.time
    body_rates = np.einsum("tji,tj->ti", tumble.rotation.quat_to_matrix(recording.orientation[:, i]),
                           recording.angular_velocity[:, i])  # fmt: skip
    speeds.append(quad.rotor_speeds)
    reference = np.array([trajectory(t)["position"] for t in time]) if trajectory else np.full((len(time), 3), np.nan)
    return {"time": time, "position": recording.position[:, i], "velocity": recording.velocity[:, i],
            "orientation": recording.orientation[:, i], "angular_velocity_body": body_rates,
            "rotor_speeds": np.array(speeds[1:]), "reference": reference}  # fmt: skip


def main() -> None:
    arrays = {}
    for name, case in CASES.items():
        flight = rotorpy_flight(case)
        if "trajectory" in case:
            error = np.linalg.norm(flight["position"] - flight["reference"], axis=1)
            arrays[f"{name}/statistics"] = error_statistics(flight["time"], error)
            flight = {key: value[::STORE_EVERY] for key, value in flight.items()}
        for key, value in flight.items():
            arrays[f"{name}/{key}"] = value
        print(name, "stored", len(flight["time"]), "samples", file=sys.stderr)
    DATA.parent.mkdir(exist_ok=True)
    np.savez_compressed(DATA, **arrays)


if __name__ == "__main__":
    main()
