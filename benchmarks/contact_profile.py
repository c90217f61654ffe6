"""Where a batched contact step's time goes, stage by stage (issue 49, part 1).

Run from the repository root:

    python -m benchmarks.contact_profile [--copies N] [--boxes N] [--steps N] [--substages]

The pile of ``benchmarks.batch`` (copies of ``scenes.box_pile(10)``, 60 Hz, the default 8 substeps) steps once as a
``tumble.Batch``; then each block's next steps run again stage by stage: the stages of ``pipeline.contact_stages``
in its order, each a compiled kernel of its own called from Python and timed. With ``--substages`` the substep
loop (``substep.run_substeps``) is split the same way into its passes (velocities, impacts, warm start, solve,
positions, relax, totals). A stage's call from Python costs microseconds; a stage of a block of 512 piles costs
milliseconds, so the split costs the profile a few percent. The replay must end on the bits that ``Batch.step``
gives a twin batch (``same_bits`` in the summary): if ``pipeline.contact_stages`` changes order, this replay no
longer matches and says so. Internals are called by name: this is a measurement of them, not an API.

Numbers are per body-step on the threads the batch uses (``TUMBLE_THREADS``; run with ``TUMBLE_THREADS=1`` to
read them as one core's time); nothing here compares timings.
"""

from __future__ import annotations

import argparse
import functools
import time
from dataclasses import dataclass

import numpy as np

import tumble
from tumble import scenes
from tumble._jit import kernel_for
from tumble.compiled_world import _FIELDS as compiled_world_fields
from tumble.compiled_world import compiled_world
from tumble.dynamics import contact_solver, islands, joint_solver, substep
from tumble.geometry import broad_phase, narrow_phase, toi

__all__ = ["ProfileSizes", "FULL", "QUICK", "profile"]

DT = 1.0 / 60.0
STATE_FIELDS = ("body_pos", "body_quat", "body_linvel", "body_angmom")


@dataclass(frozen=True)
class ProfileSizes:
    copies: int = 1024
    boxes: int = 10
    steps: int = 60  # the first is stepped by the batch itself; the profile replays the rest
    substages: bool = False


FULL = ProfileSizes()
QUICK = ProfileSizes(copies=4, boxes=10, steps=40, substages=True)  # some contacts found again within a step


@functools.cache
def _timed_kernel(function):
    """A compiled function as a kernel Python can call: a helper (no Python wrapper) is compiled again, from its own
    code under a name of its own, so that its cache entry never stands in for the helper's."""
    if isinstance(function, tumble._jit._Helper):
        return kernel_for(function.py_func, f"profiled_{function.py_func.__name__}")
    return function


_STAGES = {
    "to_angular_velocity": substep.to_angular_velocity,
    "update_aabbs": broad_phase.update_aabbs,
    "sweep_and_prune": broad_phase.sweep_and_prune,
    "collide_each": narrow_phase.compiled_collide_each,
    "keep_touching": narrow_phase.keep_touching,
    "match_warm_start": narrow_phase.match_warm_start,
    "wake_touched": islands.wake_touched,
    "prepare_contacts": contact_solver.prepare_contacts,
    "contact_passes": narrow_phase.contact_passes,
    "passes_due": narrow_phase.passes_due,
    "run_substeps": substep.run_substeps,
    "rebase_contacts": contact_solver.rebase_contacts,
    "apply_restitution": contact_solver.apply_restitution,
    "limit_to_impact": toi.limit_to_impact,
    "store_impulses": contact_solver.store_impulses,
    "update_sleep": islands.update_sleep,
    "to_angular_momentum": substep.to_angular_momentum,
    # the passes of run_substeps
    "impact_work": contact_solver.impact_work,
    "integrate_velocities": substep.integrate_velocities,
    "resolve_impacts": contact_solver.resolve_impacts,
    "warm_start_joints": joint_solver.warm_start_joints,
    "warm_start_contacts": contact_solver.warm_start_contacts,
    "solve_joints": joint_solver.solve_joints,
    "solve_contacts": contact_solver.solve_contacts,
    "integrate_positions": substep.integrate_positions,
    "accumulate_impulses": contact_solver.accumulate_impulses,
    # the same kernels where the replay names a second use apart
    "collide_again": narrow_phase.compiled_collide_each,
    "relax_contacts": contact_solver.solve_contacts,
    "relax_joints": joint_solver.solve_joints,
}


class _Replay:
    """The stages as timed kernels, and the seconds each has taken (``seconds[stage]``)."""

    def __init__(self, substages: bool) -> None:
        compiled = {function: _timed_kernel(function) for function in set(_STAGES.values())}
        self.run = {name: compiled[function] for name, function in _STAGES.items()}
        self.substages = substages
        self.seconds: dict[str, float] = {}
        self.counts = {"contacts": 0, "pairs": 0, "found_again": 0}

    def timed(self, stage: str, *args):
        start = time.perf_counter()
        result = self.run[stage](*args)
        self.seconds[stage] = self.seconds.get(stage, 0.0) + time.perf_counter() - start
        return result

    def substeps(self, *args):
        """``substep.run_substeps`` (the same arguments), whole or pass by pass."""
        if not self.substages:
            return self.timed("run_substeps", *args)
        (bodies, moving, inv_mass, gravity, force, torque, acts, rows, count, inv_inertia, pos, quat, pos0, quat0,
         linvel, angvel, h, first, last, push_max, threshold, joints, joint_impulses, joint_hertz, joint_damping,
         joint_force, joint_moment) = args  # fmt: skip
        body_args = (inv_mass, inv_inertia, pos, quat, pos0, quat0, linvel, angvel)
        joint_args = (joints, joint_impulses, inv_mass, inv_inertia, pos, quat, linvel, angvel)
        jointed = joints.kind.shape[0] > 0
        impacts = self.run["impact_work"]()
        for k in range(first, last):
            self.timed("integrate_velocities", bodies, moving, gravity, force, torque, acts, k * h, quat, linvel,
                       angvel, h)  # fmt: skip
            self.timed("resolve_impacts", rows, count, *body_args, h, threshold, gravity, force, bodies.constant_force,
                       impacts)  # fmt: skip
            if jointed:
                self.timed("warm_start_joints", *joint_args, joint_force, joint_moment)
            self.timed("warm_start_contacts", rows, count, *body_args)
            if jointed:
                self.timed("solve_joints", *joint_args, h, joint_hertz, joint_damping, push_max, True, joint_force,
                           joint_moment)  # fmt: skip
            self.timed("solve_contacts", rows, count, *body_args, 1.0 / h, push_max, True, threshold)
            self.timed("integrate_positions", bodies, moving, linvel, angvel, pos, quat, inv_inertia, h)
            if jointed:
                self.timed("relax_joints", *joint_args, h, joint_hertz, joint_damping, push_max, False, joint_force,
                           joint_moment)  # fmt: skip
            self.timed("relax_contacts", rows, count, *body_args, 1.0 / h, push_max, False, threshold)
            self.timed("accumulate_impulses", rows, count)

    def step(self, values: tuple, count: int, dt: float, substeps: int) -> int:
        """One ``pipeline.contact_stages`` step of a block's record ``values`` (``compiled_world``), stage by stage;
        returns the step's contact count."""
        fields = dict(zip(compiled_world_fields, values, strict=True))
        model_rows, body_state, joint_impulses = fields["model_rows"], fields["body_state"], fields["joint_impulses"]
        loads, buffers, settings = fields["loads"], fields["buffers"], fields["settings"]
        bodies, geom, gravity, free_to_sweep, shape_rows, filters, segment_size, joints, collider_of = model_rows
        pos, quat, linvel, angmom, sleep_time, sleeping, island = body_state
        force, torque, acts = loads
        (pairs_a, pairs_b, manifolds, fresh, rows, warm_normal, warm_tangent, stored, angvel, inv_inertia_world,
         aabb_lo, aabb_hi, joint_force_total, joint_moment_total, island_parent, island_min_time) = buffers  # fmt: skip
        contact_state = tuple(column[:count] for column in stored)
        h, margin = dt / substeps, settings.speculative_distance
        self.timed("to_angular_velocity", bodies, quat, angmom, angvel, inv_inertia_world)
        self.timed("update_aabbs", geom, pos, quat, linvel, margin, dt, aabb_lo, aabb_hi)
        group, mask, excluded = filters
        pair_count = self.timed("sweep_and_prune", geom, pos, quat, aabb_lo, aabb_hi, bodies.is_dynamic, group, mask,
                                excluded, margin, segment_size, pairs_a, pairs_b)  # fmt: skip
        if pair_count > pairs_a.shape[0] or pair_count > manifolds.shape_a.shape[0]:
            raise RuntimeError(f"{pair_count} candidate pairs overflow the buffers reserved for the profile")
        pairs_a, pairs_b = pairs_a[:pair_count], pairs_b[:pair_count]
        self.timed("collide_each", geom, pos, quat, linvel, angvel, pairs_a, pairs_b, margin, dt, manifolds,
                   collider_of)  # fmt: skip
        count = self.timed("keep_touching", manifolds, pair_count)
        self.timed("match_warm_start", manifolds, count, *contact_state, warm_normal, warm_tangent)
        if settings.sleep and sleeping.any():
            self.timed("wake_touched", bodies.is_dynamic, geom.shape_body, manifolds, count, joints.body_a,
                       joints.body_b, sleep_time, sleeping, island)  # fmt: skip
        moving = bodies.is_dynamic & ~sleeping
        inv_mass = np.where(moving, bodies.inv_mass, 0.0)
        inv_inertia_world[~moving] = 0.0
        friction, restitution, rolling, core_radius = shape_rows
        self.timed("prepare_contacts", manifolds, count, geom.shape_body, friction, restitution, rolling, core_radius,
                   inv_mass, inv_inertia_world, pos, linvel, angvel, warm_normal, warm_tangent, settings.contact_hertz,
                   settings.contact_damping_ratio, h, rows)  # fmt: skip
        pos0, quat0 = pos.copy(), quat.copy()
        joint_force_total[:] = 0.0
        joint_moment_total[:] = 0.0
        substeps_args = (bodies, moving, inv_mass, gravity, force, torque, acts, rows, count, inv_inertia_world, pos,
                         quat, pos0, quat0, linvel, angvel, h)  # fmt: skip
        solver_args = (settings.contact_push_max, settings.restitution_threshold, joints, joint_impulses,
                       settings.joint_hertz, settings.joint_damping_ratio, joint_force_total,
                       joint_moment_total)  # fmt: skip
        passes = np.empty(count, np.int64)
        first, most = 0, 1
        if substeps > 1:
            most = self.timed("contact_passes", geom.shape_body, geom.shape_aabb_center_local,
                              geom.shape_aabb_half_local, moving, manifolds.shape_a, manifolds.shape_b, count, linvel,
                              angvel, dt, passes)  # fmt: skip
        if most > 1:
            listed = np.empty(count, np.int64)
            for k in range(1, substeps):
                due = self.run["passes_due"](passes, count, k, substeps, listed)
                if due == 0:
                    continue
                self.substeps(*substeps_args, first, k, *solver_args)
                again = listed[:due]
                self.counts["found_again"] += due
                self.timed("collide_again", geom, pos, quat, linvel, angvel, manifolds.shape_a[again],
                           manifolds.shape_b[again], margin, (substeps - k) * h, fresh, collider_of)  # fmt: skip
                self.timed("rebase_contacts", again, fresh, manifolds, rows, inv_mass, inv_inertia_world, pos, quat,
                           pos0, quat0, linvel, angvel)  # fmt: skip
                first = k
        self.substeps(*substeps_args, first, substeps, *solver_args)
        self.timed("apply_restitution", rows, count, inv_mass, inv_inertia_world, pos, quat, pos0, quat0, linvel,
                   angvel, settings.restitution_threshold)  # fmt: skip
        self.timed("limit_to_impact", geom, bodies.is_dynamic, pairs_a, pairs_b, pos0, quat0, pos, quat,
                   free_to_sweep)  # fmt: skip
        self.timed("store_impulses", manifolds, rows, count, *stored)
        if settings.sleep:
            self.timed("update_sleep", bodies.is_dynamic, geom.shape_body, manifolds, count, joints.body_a,
                       joints.body_b, linvel, angvel, dt, settings.sleep_linear, settings.sleep_angular,
                       settings.time_to_sleep, sleep_time, sleeping, island, island_parent,
                       island_min_time)  # fmt: skip
        self.timed("to_angular_momentum", bodies, quat, angvel, angmom)
        self.counts["contacts"] += count
        self.counts["pairs"] += pair_count
        return count


def _blocks_ready(batch: tumble.Batch, room: int) -> list[list]:
    """Each block's record values and contact count, its buffers grown to ``room`` pairs first (the replay does not
    grow them mid-step as the runner does)."""
    ready = []
    for block in batch._blocks:
        block.scratch.reserve_contacts(room, keep=block.state.contact_count)
        values = compiled_world(block.model, block.state, block.inputs, batch._params, block.scratch, block.acts).values
        ready.append([values, block.state.contact_count])
    return ready


def profile(sizes: ProfileSizes = FULL) -> dict:
    """The seconds of each stage over ``sizes.steps - 1`` replayed steps (``stages``), the per-step counts, the
    whole replay's seconds, a twin batch's ``Batch.step`` seconds for the same steps, and whether the two ended on
    the same bits."""
    world = scenes.box_pile(sizes.boxes)
    replay = _Replay(sizes.substages)
    twin = tumble.Batch(world, sizes.copies)
    twin.step(DT)
    twin_start = time.perf_counter()
    twin.step(DT, sizes.steps - 1)
    twin_seconds = time.perf_counter() - twin_start
    batch = tumble.Batch(world, sizes.copies)
    batch.step(DT)
    substeps = batch._params.solver.substeps_for(DT)
    blocks = _blocks_ready(batch, 40 * sizes.copies * sizes.boxes)
    start = time.perf_counter()
    for _ in range(sizes.steps - 1):
        for block in blocks:
            block[1] = replay.step(block[0], block[1], DT, substeps)
    replay_seconds = time.perf_counter() - start
    same = all(np.array_equal(getattr(batch.state, f), getattr(twin.state, f)) for f in STATE_FIELDS)
    body_steps = sizes.copies * batch.body_count * (sizes.steps - 1)
    per_step = {name: value / (sizes.steps - 1) for name, value in replay.counts.items()}
    return {"stages": replay.seconds, "per_step": per_step, "body_steps": body_steps, "substeps": substeps,
            "replay_s": replay_seconds, "batch_step_s": twin_seconds, "same_bits": same}  # fmt: skip


def table(result: dict) -> list[str]:
    """The profile as Markdown rows: stage, ns per body-step, share of the replay's stages."""
    total = sum(result["stages"].values())
    lines = ["| stage | ns per body-step | share |", "| --- | ---: | ---: |"]
    for name, seconds in sorted(result["stages"].items(), key=lambda item: -item[1]):
        lines.append(f"| {name} | {1e9 * seconds / result['body_steps']:.0f} | {100 * seconds / total:.1f} % |")
    lines.append(f"| all stages | {1e9 * total / result['body_steps']:.0f} | 100 % |")
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.contact_profile", description=__doc__.split("\n")[0])
    parser.add_argument("--copies", type=int, default=FULL.copies)
    parser.add_argument("--boxes", type=int, default=FULL.boxes)
    parser.add_argument("--steps", type=int, default=FULL.steps)
    parser.add_argument("--substages", action="store_true", help="split the substep loop into its passes")
    args = parser.parse_args(argv)
    sizes = ProfileSizes(args.copies, args.boxes, args.steps, args.substages)
    profile(sizes)  # compiles or loads every stage a step of these piles reaches (a stage's first call)
    result = profile(sizes)
    print("\n".join(table(result)))
    counts = ", ".join(f"{name} {value:.1f}" for name, value in result["per_step"].items())
    print(f"\n{sizes.copies} copies of box_pile({sizes.boxes}), {sizes.steps - 1} steps of 1/60 s, "
          f"{result['substeps']} substeps; per step: {counts}")  # fmt: skip
    body_steps = result["body_steps"]
    print(f"replay {1e9 * result['replay_s'] / body_steps:.0f} ns per body-step, Batch.step "
          f"{1e9 * result['batch_step_s'] / body_steps:.0f}; the same bits: {result['same_bits']}")  # fmt: skip
    return 0 if result["same_bits"] else 1


if __name__ == "__main__":
    raise SystemExit(main())
