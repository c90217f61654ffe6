"""Islands and sleeping: bodies at rest stop being simulated until something touches or pushes them.

An island is a set of dynamic bodies linked by touching contacts or joints (static bodies do not link: a floor
does not join everything standing on it). Each body keeps a timer of how long its speeds have stayed below
``sleep_linear`` and ``sleep_angular``; when every body of an island has been still for ``time_to_sleep``, the
whole island sleeps: velocities zeroed, skipped by the integrator and the solver (Box2D's scheme, E. Catto,
"Box2D v3 islands", 2023). A sleeping island wakes whole when an awake body touches it, or when a force,
impulse or velocity is applied to one of its bodies.

Islands are found with a union-find over the contact pairs (path halving, union by smaller root index, so the
result does not depend on the order of the pairs beyond what the sorted pairs fix).
"""

from __future__ import annotations

import math

from .._jit import inline

__all__ = ["update_sleep", "wake_touched"]


@inline
def _find(parent, i):
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


@inline
def _union(parent, a, b):
    ra, rb = _find(parent, a), _find(parent, b)
    if ra < rb:
        parent[rb] = ra
    elif rb < ra:
        parent[ra] = rb


@inline
def _islands(is_dynamic, shape_body, manifold_a, manifold_b, point_count, separation, count, joint_a, joint_b,
             parent):  # fmt: skip
    """Union the dynamic bodies of every touching manifold (a point with separation <= 0) and of every joint."""
    for i in range(parent.shape[0]):
        parent[i] = i
    for j in range(joint_a.shape[0]):
        a, b = joint_a[j], joint_b[j]
        if a >= 0 and b >= 0 and is_dynamic[a] and is_dynamic[b]:
            _union(parent, a, b)
    for m in range(count):
        a, b = shape_body[manifold_a[m]], shape_body[manifold_b[m]]
        if not (is_dynamic[a] and is_dynamic[b]):
            continue
        for j in range(point_count[m]):
            if separation[m, j] <= 0.0:
                _union(parent, a, b)
                break
    for i in range(parent.shape[0]):
        parent[i] = _find(parent, i)


@inline(counted=False)
def update_sleep(
    is_dynamic, shape_body, manifolds, count, joint_a, joint_b, linvel, angvel, dt, sleep_linear, sleep_angular,
    time_to_sleep, sleep_time, sleeping, island, parent, island_min_time,
):  # fmt: skip
    """Advance the sleep timers and put to sleep the islands whose bodies have all been still long enough.

    Reads: the step's manifolds, velocities. Writes: sleep_time, sleeping, island (the root body of each body's
    island, -1 for static bodies), linvel and angvel of bodies put to sleep (zeroed).
    """
    n = linvel.shape[0]
    for i in range(n):
        if not is_dynamic[i] or sleeping[i]:
            continue
        v2 = linvel[i, 0] ** 2 + linvel[i, 1] ** 2 + linvel[i, 2] ** 2
        w2 = angvel[i, 0] ** 2 + angvel[i, 1] ** 2 + angvel[i, 2] ** 2
        if v2 > sleep_linear * sleep_linear or w2 > sleep_angular * sleep_angular:
            sleep_time[i] = 0.0
        else:
            sleep_time[i] += dt
    _islands(is_dynamic, shape_body, manifolds.shape_a, manifolds.shape_b, manifolds.point_count,
             manifolds.separation, count, joint_a, joint_b, parent)  # fmt: skip
    for i in range(n):
        island_min_time[i] = math.inf
    for i in range(n):
        if is_dynamic[i]:
            root = parent[i]
            island_min_time[root] = min(island_min_time[root], sleep_time[i])
    for i in range(n):
        island[i] = parent[i] if is_dynamic[i] else -1
        if is_dynamic[i] and not sleeping[i] and island_min_time[parent[i]] >= time_to_sleep:
            sleeping[i] = True
            for k in range(3):
                linvel[i, k] = 0.0
                angvel[i, k] = 0.0


@inline
def _wake_island(sleeping, sleep_time, island, root):
    woken = 0
    for i in range(sleeping.shape[0]):
        if sleeping[i] and island[i] == root:
            sleeping[i] = False
            sleep_time[i] = 0.0
            woken += 1
    return woken


@inline(counted=False)
def wake_touched(is_dynamic, shape_body, manifolds, count, joint_a, joint_b, sleep_time, sleeping, island):
    """Wake every sleeping island that an awake dynamic body touches (or nearly touches) or is jointed to.

    Returns the number of bodies woken. Writes: sleeping, sleep_time.
    """
    woken = 0
    for m in range(count):
        a, b = shape_body[manifolds.shape_a[m]], shape_body[manifolds.shape_b[m]]
        for sleeper, other in ((a, b), (b, a)):
            if sleeping[sleeper] and is_dynamic[other] and not sleeping[other]:
                woken += _wake_island(sleeping, sleep_time, island, island[sleeper])
    for j in range(joint_a.shape[0]):
        a, b = joint_a[j], joint_b[j]
        if a < 0 or b < 0:
            continue
        for sleeper, other in ((a, b), (b, a)):
            if sleeping[sleeper] and is_dynamic[other] and not sleeping[other]:
                woken += _wake_island(sleeping, sleep_time, island, island[sleeper])
    return woken
