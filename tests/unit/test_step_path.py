"""The walk of a step (issue 45, part 4): ``dt`` from ``World.step`` reaches the pipeline through the stepping room
and the runner only, and a plain step calls no vehicle or flight code (``docs/step.md`` shows the same path)."""

from __future__ import annotations

import sys

import tumble


def _calls_of_one_step(world: tumble.World) -> tuple[list[str], list[str]]:
    """``(stack, visited)``: the tumble modules on the stack when ``compiled_world`` is first entered (the runner takes
    the world's record of arrays from it, then steps in compiled code), outermost first (each once), and every tumble
    module the step called into."""
    stack: list[str] = []
    visited: set[str] = set()

    def profile(frame, event, arg):
        if event != "call":
            return
        module = frame.f_globals.get("__name__", "")
        if not module.startswith("tumble"):
            return
        visited.add(module)
        if module == "tumble.compiled_world" and not stack:
            outer = frame
            while outer is not None:
                name = outer.f_globals.get("__name__", "")
                if name.startswith("tumble") and (not stack or stack[-1] != name):
                    stack.append(name)
                outer = outer.f_back

    sys.setprofile(profile)
    try:
        world.step(1.0 / 60.0)
    finally:
        sys.setprofile(None)
    return stack[::-1], sorted(visited)


def test_dt_from_world_step_reaches_the_pipeline_through_the_runner_only():
    world = tumble.World()
    world.add_static(tumble.Plane())
    world.add_body(tumble.Box((0.1, 0.1, 0.1)), mass=1.0, position=(0.0, 0.0, 0.2))
    world.step(1.0 / 60.0)  # the model built and the kernels loaded before the walk is watched
    stack, visited = _calls_of_one_step(world)
    assert stack == ["tumble.world", "tumble.world_stepping", "tumble.runner", "tumble.compiled_world"]
    assert not [m for m in visited if m.split(".")[1] in ("control", "vehicles")]


def test_a_world_with_a_flown_quadrotor_steps_through_the_same_walk():
    from tumble.control import Hover, SE3Controller
    from tumble.vehicles import Quadrotor

    world = tumble.World()
    world.add_static(tumble.Plane())
    quad = Quadrotor(world, position=(0.0, 0.0, 1.0))
    quad.fly(SE3Controller(quad), Hover((0.0, 0.0, 1.0)))
    world.step(1.0 / 100.0)
    stack, visited = _calls_of_one_step(world)
    assert stack == ["tumble.world", "tumble.world_stepping", "tumble.runner", "tumble.compiled_world"]
    assert "tumble.control.fly" in visited  # the flight ran as a controller, before the step


def test_a_flown_quadrotor_takes_every_step_of_simulate_in_one_call_of_the_runners_loop():
    """Free bodies with a compiled controller stage: the runner's one compiled loop takes all the steps, the stage
    bound into it (issue 45, part 1); no flight code keeps a loop of its own."""
    from tumble.control import Hover, SE3Controller, native
    from tumble.vehicles import Quadrotor

    world = tumble.World()
    quad = Quadrotor(world, position=(0.0, 0.0, 1.0))
    quad.fly(SE3Controller(quad), Hover((0.0, 0.0, 1.0)))
    world.simulate(0.01, 1e-3)  # the kernels loaded before the calls are counted
    calls: list[str] = []

    def profile(frame, event, arg):
        if event == "call" and frame.f_globals.get("__name__") == "tumble.runner":
            calls.append(frame.f_code.co_name)

    sys.setprofile(profile)
    try:
        world.simulate(0.1, 1e-3)
    finally:
        sys.setprofile(None)
    assert calls.count("simulate_steps") == 1 and calls.count("_free_body_steps") == 1
    assert world.step_count == 110
    assert not hasattr(native, "fly_steps") and not hasattr(native.NativeFlights, "fly_free")
