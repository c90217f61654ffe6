"""Quadrotor benchmark (issue 19): one Crazyflie flying the figure eight, tumble beside RotorPy in the same process.

Run through ``python -m benchmarks.run --only quadrotor``.

The flight: RotorPy's Crazyflie (``tumble.vehicles.CRAZYFLIE``), from rest at the centre of the figure eight
``x = sin t``, ``y = 0.5 sin 2t`` at 1 m with its motors at the hover speed, the SE(3) controller (RotorPy's law and
gains) called at every step, for ``quadrotor_seconds`` of simulated time, at 100 Hz and at 500 Hz:

- tumble: ``quad.fly(SE3Controller(quad), Lissajous(...))`` and ``world.simulate`` (its default integrator, RK4
  over each step with the motors' exact lag); the flight runs inside the compiled loop (``tumble/control/native.py``).
- tumble with ``CascadedPID``: a controller in plain Python and NumPy, no compiled code of its own, as a user's
  callback would be.
- tumble with no controller, the rotors at fixed speeds: the compiled loop alone, the engine's floor.
- RotorPy (if installed), its default ``solve_ivp`` (RK45) and the same controller: through ``Environment.run``, as
  its users run it (``x_rotorpy`` is over this one), and as a bare loop of ``SE3Control.update`` and
  ``Multirotor.step``, without the environment's bookkeeping (sensors, logging).

Columns: ``steps_per_s``, ``realtime_x`` (simulated seconds per wall second), ``x_rotorpy`` (steps/s over
RotorPy's at the same rate), ``rms_error_cm`` (position error after 2 s, when the flight lasts that long). Each
configuration runs once untimed (compile, cache load), then ``min(repeat, 3)`` timed runs; the best is kept.
"""

from __future__ import annotations

import math
import time

import numpy as np

import tumble
from tumble.control import CascadedPID, Lissajous, SE3Controller
from tumble.vehicles import Quadrotor

__all__ = ["bench_quadrotor", "have_rotorpy", "rotorpy_figure_eight", "tumble_figure_eight"]

RATES = (100, 500)
FIGURE_EIGHT = {"A": 1.0, "B": 0.5, "a": 1.0, "b": 2.0, "height": 1.0}


def have_rotorpy() -> bool:
    try:
        import rotorpy  # noqa: F401
    except ImportError:
        return False
    return True


def _reference():
    f = FIGURE_EIGHT
    return Lissajous(f["A"], f["B"], f["a"], f["b"], center=(0.0, 0.0, f["height"]))


def tumble_figure_eight(rate: int, seconds: float, controller: str = "se3") -> tuple[float, np.ndarray, np.ndarray]:
    """``(wall seconds, times, position errors)`` of one flight; ``controller`` is ``"se3"``, ``"cascaded"`` or
    ``"none"`` (the rotors held at the hover speed)."""
    world = tumble.World()
    reference = _reference()
    quad = Quadrotor(world, position=reference(0.0)["position"])
    quad.rotor_speeds = [quad.hover_rotor_speed] * 4
    if controller == "none":
        quad.command_rotor_speeds(quad.rotor_speeds)
    else:
        law = SE3Controller(quad) if controller == "se3" else CascadedPID(quad)
        quad.fly(law, reference)
    start = time.perf_counter()
    recording = world.simulate(seconds, 1.0 / rate)
    wall = time.perf_counter() - start
    target = np.array([reference(t)["position"] for t in recording.time])
    return wall, recording.time, np.linalg.norm(recording.position[:, quad.body.index] - target, axis=1)


def rotorpy_figure_eight(rate: int, seconds: float, environment: bool = False) -> tuple[float, np.ndarray, np.ndarray]:
    """The same flight in RotorPy, through its ``Environment`` or as a bare loop: ``(wall seconds, times, position
    errors)``."""
    from rotorpy.controllers.quadrotor_control import SE3Control
    from rotorpy.trajectories.lissajous_traj import TwoDLissajous
    from rotorpy.vehicles.crazyflie_params import quad_params
    from rotorpy.vehicles.multirotor import Multirotor

    f = FIGURE_EIGHT
    hover = math.sqrt(quad_params["mass"] * 9.81 / (4 * quad_params["k_eta"]))
    state = {"x": np.array([0.0, 0.0, f["height"]]), "v": np.zeros(3), "q": np.array([0.0, 0.0, 0.0, 1.0]),
             "w": np.zeros(3), "wind": np.zeros(3), "rotor_speeds": np.full(4, hover)}  # fmt: skip
    vehicle, controller = Multirotor(quad_params, initial_state=state), SE3Control(quad_params)
    trajectory = TwoDLissajous(A=f["A"], B=f["B"], a=f["a"], b=f["b"], height=f["height"])
    if environment:
        from rotorpy.environments import Environment
        from rotorpy.wind.default_winds import NoWind

        env = Environment(vehicle=vehicle, controller=controller, trajectory=trajectory, wind_profile=NoWind(),
                          sim_rate=rate)  # fmt: skip
        start = time.perf_counter()
        result = env.run(t_final=seconds, use_mocap=False, terminate=False, plot=False, animate_bool=False)
        wall = time.perf_counter() - start
        return wall, result["time"], np.linalg.norm(result["state"]["x"] - result["flat"]["x"], axis=1)
    steps, dt = int(round(seconds * rate)), 1.0 / rate
    times, errors = [], []
    start = time.perf_counter()
    for k in range(steps + 1):
        flat = trajectory.update(k * dt)
        times.append(k * dt)
        errors.append(np.linalg.norm(state["x"] - flat["x"]))
        if k < steps:
            state = vehicle.step(state, controller.update(k * dt, state, flat), dt)
    return time.perf_counter() - start, np.array(times), np.array(errors)


def _row(engine: str, controller: str, rate: int, seconds: float, runs) -> dict:
    """The best of ``runs`` (each ``(wall, times, errors)``) as a table row."""
    wall, times, errors = min(runs, key=lambda run: run[0])
    late = times >= 2.0
    return {
        "engine": engine,
        "controller": controller,
        "rate_hz": rate,
        "steps_per_s": rate * seconds / wall,
        "realtime_x": seconds / wall,
        "rms_error_cm": 100.0 * float(np.sqrt(np.mean(errors[late] ** 2))) if late.any() else math.nan,
    }


def bench_quadrotor(sizes) -> list[dict]:
    """One Crazyflie on the figure eight at 100 and 500 Hz: tumble (SE(3), cascaded PID, none) and RotorPy."""
    seconds = sizes.quadrotor_seconds
    repeat = min(sizes.repeat, 3)
    rows = []
    for rate in RATES:
        for controller, label in (("se3", "SE3Controller (in the loop)"), ("cascaded", "CascadedPID (Python)"),
                                  ("none", "none (compiled loop)")):  # fmt: skip
            tumble_figure_eight(rate, min(seconds, 0.1), controller)  # compile or load from the cache
            runs = [tumble_figure_eight(rate, seconds, controller) for _ in range(repeat)]
            rows.append(_row("tumble", label, rate, seconds, runs))
        if have_rotorpy():
            rotorpy_seconds = min(seconds, sizes.rotorpy_seconds)
            for environment, label in ((True, "SE3Control (Environment.run)"), (False, "SE3Control (step loop)")):
                runs = [rotorpy_figure_eight(rate, rotorpy_seconds, environment) for _ in range(min(repeat, 2))]
                rows.append(_row("rotorpy", label, rate, rotorpy_seconds, runs))
    for row in rows:
        theirs = [r for r in rows if r["engine"] == "rotorpy" and r["rate_hz"] == row["rate_hz"]
                  and "Environment" in r["controller"]]  # fmt: skip
        row["x_rotorpy"] = row["steps_per_s"] / theirs[0]["steps_per_s"] if theirs else math.nan
    return rows
