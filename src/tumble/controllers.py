"""A world's controllers: Python callbacks that run before its steps, each at its own rate (zero-order hold), and
the compiled stage that may stand in for them.

A controller is ``callback(world, t)``. Without a rate it runs before every step; with ``rate`` (Hz) it runs before
the first step whose start time is at or past each tick ``k / rate`` (``k = 0, 1, ...``), once per step even when
a step spans several ticks. Whatever it commands (actuator commands, applied loads it stores elsewhere) holds
until its next call: a zero-order hold, as a digital controller on real hardware.

Time is counted, not accumulated: ``t = t0 + n dt`` with ``n`` the steps taken at this ``dt`` since ``t0`` (the
time when ``dt`` last changed), so a 10 s run at 100 Hz has exactly 1000 steps and a 50 Hz controller in a 1 kHz
world runs at exactly every 20th step. A tick counts as reached within a billionth of a step of it.

A callback may name a compiled stage that runs it in its place (``callback.compiled_stage``, see
:meth:`Controllers.compiled_stage` and ``docs/step.md``): the engine knows the stage's interface, not what it flies.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from .errors import SimulationError

__all__ = ["TICK_TOLERANCE", "Controller", "Controllers", "StepClock", "controller_failed"]

# A tick at most this fraction of a step after the step's start time counts as reached (round-off in k / rate).
TICK_TOLERANCE = 1e-9


class Controller:
    """Handle of a controller in a world (``world.add_controller``).

    Attributes:
        callback: the callable, ``callback(world, t)``.
        rate: calls per simulated second, or ``None`` for every step.
        name: the name given, else the callback's name.
        calls: how many times it has run.
    """

    def __init__(self, owner: Controllers, callback: Callable, rate: float | None, name: str):
        self._owner = owner
        self.callback = callback
        self.rate = rate
        self.name = name
        self.calls = 0
        self._next_tick = 0  # the index k of the next tick k / rate

    def remove(self) -> None:
        """Stop running this controller (removing it twice is an error)."""
        self._owner.remove(self)

    @property
    def next_tick(self) -> int:
        """The index ``k`` of the next tick ``k / rate`` (0 for a controller of every step)."""
        return self._next_tick

    def count_calls(self, calls: int, next_tick: int) -> None:
        """Count ``calls`` made in its place (by a compiled stage), whose next tick is now ``next_tick``."""
        self.calls += int(calls)
        self._next_tick = int(next_tick)

    def _due(self, t: float, dt: float) -> bool:
        if self.rate is None:
            return True
        return t >= self._next_tick / self.rate - TICK_TOLERANCE * dt

    def _advance(self, t: float, dt: float) -> None:
        if self.rate is not None:  # the first tick after this step's start
            self._next_tick = max(self._next_tick + 1, math.floor((t + TICK_TOLERANCE * dt) * self.rate) + 1)

    def __repr__(self) -> str:
        rate = "every step" if self.rate is None else f"{self.rate:g} Hz"
        return f"<Controller {self.name!r} at {rate}, {self.calls} calls>"


class StepClock:
    """A world's counted time: the start of the next step is ``t0 + n dt``, ``n`` the steps taken at this ``dt``
    since ``t0``, when ``dt`` last changed (or the world's time was set apart from the count, as by a restore)."""

    def __init__(self):
        self._origin = (0.0, 0, math.nan)  # (time, step count, dt) when the count started

    def start_of_next_step(self, world_time: float, step_count: int, dt: float) -> float:
        origin_time, origin_step, origin_dt = self._origin
        counted = origin_time + (step_count - origin_step) * dt
        # The world's accumulated time agrees with the count to round-off, unless it was set from elsewhere.
        if dt != origin_dt or step_count < origin_step or abs(counted - world_time) > 0.5 * dt:
            self._origin = world_time, step_count, dt
            return world_time
        return counted

    def count(self, world_time: float, step_count: int, dt: float) -> tuple[float, int]:
        """``(t0, n)``: the next step starts at ``t0 + n dt`` (as :meth:`start_of_next_step` counts, rebased first
        where it would be), for a compiled loop that counts the steps after it itself."""
        self.start_of_next_step(world_time, step_count, dt)
        origin_time, origin_step, _ = self._origin
        return origin_time, step_count - origin_step


def controller_failed(name: str, error: Exception, t: float, step: int) -> SimulationError:
    """The error that stops a run when the controller ``name`` raised ``error`` before ``step``, at ``t``."""
    return SimulationError(
        f"controller {name!r} raised {type(error).__name__}: {error} at t = {t:.6g} s (before step {step}); the world "
        "keeps its state from before that step",
        step=step,
        controller=name,
    )


class Controllers:
    """A world's controllers, in the order added."""

    def __init__(self):
        self._items: list[Controller] = []

    def __len__(self) -> int:
        return len(self._items)

    def __iter__(self):
        return iter(list(self._items))

    def add(self, callback, rate=None, name=None) -> Controller:
        if not callable(callback):
            raise TypeError(f"callback must be callable as callback(world, t), got {callback!r}")
        if rate is not None:
            if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not math.isfinite(rate) or rate <= 0:
                raise ValueError(f"rate must be a finite number of Hz > 0 or None, got {rate!r}")
            rate = float(rate)
        if name is None:
            name = getattr(callback, "__name__", type(callback).__name__)
        elif not isinstance(name, str):
            raise TypeError(f"name must be a string or None, got {name!r}")
        controller = Controller(self, callback, rate, name)
        self._items.append(controller)
        return controller

    def remove(self, controller: Controller) -> None:
        if controller not in self._items:
            raise ValueError(f"controller {controller.name!r} is not in this world (removed already?)")
        self._items.remove(controller)

    def compiled_stage(self, world):
        """The compiled stage that runs every controller of ``world`` in their place, or None.

        Each callback may name a stage maker, ``callback.compiled_stage(world, controllers)``, which gives a stage
        or None (it cannot run these). The stage is used only when every controller names the same maker and it
        accepts them all: one stage, one kernel call before each step, instead of a Python call each. A stage has

        - ``command(model, state, acts, t, dt)``: before the step of ``dt`` from ``t`` (counted by the world's
          :class:`StepClock`), the due controllers write their commands into the actuator arrays ``acts``; a
          controller that fails raises :func:`controller_failed`'s error, the world as it was;
        - ``compiled_command`` and ``compiled_data``: a compiled function ``compiled_command(compiled_data, gravity,
          acts, pos, quat, linvel, angmom, t, h)`` that does what ``command`` does and returns the index of the
          controller that failed, or -1. The runner's compiled loops (``tumble.runner``: free bodies, or contacts and
          joints) call it before each step, so that all the steps of ``simulate`` take one call;
        - ``failure(index, t, step)``: the error of the controller ``compiled_command`` said failed, before the step
          ``step`` from ``t``;
        - ``finish()``: the calls made, the next ticks and the controllers' own state handed back to them.
        """
        makers = {getattr(controller.callback, "compiled_stage", None) for controller in self._items}
        if len(makers) != 1 or None in makers:
            return None
        return makers.pop()(world, list(self._items))

    def run(self, world, t: float, dt: float) -> None:
        """Run the controllers due before the next step, of ``dt`` from ``t`` (the :class:`StepClock`'s).

        Raises:
            SimulationError: a controller raised; the message names it and the time, the world is as it was.
        """
        if not self._items:
            return
        state = world.state
        for controller in self:
            if not controller._due(t, dt):
                continue
            try:
                controller.callback(world, t)
            except Exception as error:
                raise controller_failed(controller.name, error, t, state.step_count) from error
            controller.calls += 1
            controller._advance(t, dt)
