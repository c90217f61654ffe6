"""Statics by the principle of virtual work (course ``course/004_…``, video 2.1b).

A system is in static equilibrium when the virtual work of the applied forces vanishes for every
virtual displacement, ``δW = Σ_j Q_j δq_j = 0``. For independent coordinates that is ``Q(q) = 0``; with
holonomic constraints ``Φ(q) = 0`` only displacements with ``Φ_q δq = 0`` are admissible, so ``Q`` must
lie in the row space of ``Φ_q``: ``Q - Φ_qᵀ λ = 0`` (the multipliers are the constraint forces, the same
λ as in the equations of motion at rest).

``equilibrium`` solves for the configuration with ``scipy.optimize.root`` (analytic Jacobian), falling
back to ``least_squares``; ``balancing`` solves for unknown loads at a given configuration (usually a
linear least-squares problem, since loads enter ``Q`` linearly).
"""

from __future__ import annotations

import numpy as np
import sympy as sp
from scipy.optimize import least_squares, root

from ._checks import TIME, as_parameter_values, as_real, as_state, show
from .numeric import compile_expressions, resolve_parameters

__all__ = ["equilibrium", "balancing", "balancing_expressions"]

# A residual |Q - Φ_qᵀλ| below this (relative to the size of the forces involved) counts as balanced:
# the solvers reach ~1e-14 on well-posed problems, so 1e-8 only refuses genuine failures.
_BALANCE_RTOL = 1e-8
# Configurations handed to balancing() must satisfy the constraints to this (as simulate's start).
_CONSTRAINT_TOL = 1e-8


def equilibrium(system, guess, parameters=None, *, applied=None, t=0.0) -> np.ndarray:
    """See :meth:`System.equilibrium`."""
    n, m = len(system.coordinates), len(system.constraints)
    q_guess = as_state("guess", guess, n)
    t = as_real("t", t)
    Q = system.generalized_forces(applied)
    values = resolve_parameters(_statics_symbols(system, Q), system.parameters, parameters, allowed=system.symbols)
    lam = [sp.Dummy(f"lam{k}") for k in range(m)]
    J = system.constraint_jacobian
    residual = Q - J.T * sp.Matrix(lam) if m else Q
    if m:
        residual = residual.col_join(sp.Matrix(system.constraints))
    unknowns = sp.Matrix([*system.coordinates, *lam])
    jac = residual.jacobian(unknowns)
    # λ are plain symbols: give them to the compiler as extra "coordinates" with no rates
    coords = list(system.coordinates)
    lam_functions = [sp.Function(f"_lam{k}")(TIME) for k in range(m)]
    to_functions = dict(zip(lam, lam_functions, strict=True))
    unknown_functions = coords + lam_functions
    residual_fn = compile_expressions(
        "the equilibrium residual", residual.xreplace(to_functions), unknown_functions, values
    )
    jac_fn = compile_expressions("the equilibrium Jacobian", jac.xreplace(to_functions), unknown_functions, values)
    rates = np.zeros(n + m)

    def fun(z):
        return residual_fn(t, z, rates)[:, 0]

    def fun_jac(z):
        return jac_fn(t, z, rates)

    z0 = np.concatenate([q_guess, np.zeros(m)])
    if m:
        z0[n:] = _multiplier_guess(fun, z0, n)
    scale = max(1.0, float(np.max(np.abs(fun(z0)))))
    # xtol: MINPACK's relative step tolerance; 1e-14 takes the root to round-off (the default stops ~1e-11)
    solution = root(fun, z0, jac=fun_jac, method="hybr", options={"xtol": 1e-14})
    z = solution.x
    if not np.all(np.isfinite(z)) or np.max(np.abs(fun(z))) > _BALANCE_RTOL * scale:
        fallback = least_squares(fun, z0, jac=fun_jac, xtol=1e-15, ftol=1e-15, gtol=1e-15)
        z = fallback.x
    worst = float(np.max(np.abs(fun(z))))
    if not np.isfinite(worst) or worst > _BALANCE_RTOL * scale:
        raise ValueError(
            f"no static equilibrium found near guess={show(q_guess)}: the best point {show(z[:n])} leaves a "
            f"generalised force (or constraint) residual of {worst:.3g}"
        )
    return z[:n].copy()


def balancing(system, unknowns, q, parameters=None, *, applied=None, t=0.0) -> dict:
    """See :meth:`System.balancing`."""
    n, m = len(system.coordinates), len(system.constraints)
    symbols = _as_unknowns(unknowns)
    q_values = as_state("q", q, n)
    t = as_real("t", t)
    Q = system.generalized_forces(applied)
    _check_unknowns_appear(symbols, Q)
    unknown_names = {u.name for u in symbols}
    known = [s for s in _statics_symbols(system, Q) if s.name not in unknown_names]
    given = as_parameter_values("parameters", parameters)
    clash = [key for key in given if (key if isinstance(key, str) else key.name) in unknown_names]
    if clash:
        raise ValueError(f"parameters give a value to the unknown {clash[0]}; leave the unknowns out")
    # a default value of an unknown is set aside: balancing solves for it
    values = resolve_parameters(known, system.parameters, given, allowed=system.symbols)
    at_q = {**dict(zip(system.coordinates, q_values, strict=True)), TIME: t}
    numbers = {s: sp.Float(v) for s, v in values.items()}
    if m:
        phi = np.array([float(c.xreplace(numbers).subs(at_q)) for c in system.constraints])
        if np.max(np.abs(phi)) > _CONSTRAINT_TOL:
            k = int(np.argmax(np.abs(phi)))
            raise ValueError(
                f"q violates constraint {k} ({system.constraints[k]}) by {phi[k]:.3g}; pass a consistent q"
            )
    lam = [sp.Dummy(f"lam{k}") for k in range(m)]
    residual = Q - system.constraint_jacobian.T * sp.Matrix(lam) if m else Q
    residual = residual.xreplace(numbers).subs(at_q)
    z = sp.Matrix([*symbols, *lam])
    A_sym = residual.jacobian(z)
    if A_sym.free_symbols & set(z):
        return _balance_nonlinear(residual, z, symbols, q_values)
    A = np.array(A_sym.evalf(), dtype=np.float64)
    b = -np.array(residual.xreplace(dict.fromkeys(z, 0)).evalf(), dtype=np.float64)[:, 0]
    solution, *_ = np.linalg.lstsq(A, b, rcond=None)
    _check_balanced(A @ solution - b, b, symbols, q_values)
    if np.linalg.matrix_rank(A) < A.shape[1]:
        raise ValueError(
            f"the unknowns {', '.join(s.name for s in symbols)} are not determined by equilibrium at "
            f"q={show(q_values)} (the virtual work depends on fewer combinations of them than there are)"
        )
    return {s: float(solution[i]) for i, s in enumerate(symbols)}


def balancing_expressions(system, unknowns, *, applied=None) -> dict:
    """See :meth:`System.balancing_expressions`."""
    symbols = _as_unknowns(unknowns)
    Q = system.generalized_forces(applied)
    _check_unknowns_appear(symbols, Q)
    m = len(system.constraints)
    lam = [sp.Dummy(f"lam{k}") for k in range(m)]
    residual = Q - system.constraint_jacobian.T * sp.Matrix(lam) if m else Q
    solutions = sp.solve(list(residual), [*symbols, *lam], dict=True)
    if not solutions:
        raise ValueError(f"no values of {', '.join(s.name for s in symbols)} balance the system")
    first = solutions[0]
    missing = [s for s in symbols if s not in first]
    if missing:
        raise ValueError(f"{missing[0]} is not determined by the equilibrium conditions")
    return {s: sp.simplify(first[s]) for s in symbols}


def _as_unknowns(unknowns) -> list:
    items = [unknowns] if isinstance(unknowns, sp.Symbol) else unknowns
    if isinstance(items, (str, bytes)) or not hasattr(items, "__iter__"):
        raise TypeError(f"unknowns must be a SymPy Symbol or a sequence of them, got {show(unknowns)}")
    items = list(items)
    if not items:
        raise ValueError("unknowns must name at least one symbol, got an empty sequence")
    for i, item in enumerate(items):
        if not isinstance(item, sp.Symbol):
            raise TypeError(f"unknowns[{i}] must be a SymPy Symbol, got {show(item)} ({type(item).__name__})")
    return items


def _check_unknowns_appear(symbols, Q) -> None:
    for s in symbols:
        if not Q.has(s):
            raise ValueError(
                f"the unknown {s} does not appear in the generalised forces; put it in forces= or applied="
            )


def _statics_symbols(system, Q) -> set:
    """The symbols statics needs: those of the forces at rest and of the constraints (not the inertia)."""
    found = set(Q.free_symbols).union(*[c.free_symbols for c in system.constraints])
    return found - {TIME}


def _multiplier_guess(fun, z0: np.ndarray, n: int) -> np.ndarray:
    """Least-squares multipliers at the guess: the λ that best balance ``Q`` there."""
    m = z0.size - n
    base = fun(z0)[:n]
    columns = []
    for k in range(m):
        probe = z0.copy()
        probe[n + k] += 1.0
        columns.append(fun(probe)[:n] - base)
    A = np.stack(columns, axis=1)
    lam, *_ = np.linalg.lstsq(A, -base, rcond=None)
    return lam


def _balance_nonlinear(residual, z, symbols, q_values) -> dict:
    fn = sp.lambdify([list(z)], list(residual), modules="numpy")
    jac = sp.lambdify([list(z)], residual.jacobian(z), modules="numpy")
    result = least_squares(
        lambda x: np.asarray(fn(x), dtype=np.float64),
        np.zeros(len(z)),
        jac=lambda x: np.asarray(jac(x), dtype=np.float64),
        xtol=1e-15,
        ftol=1e-15,
        gtol=1e-15,
    )
    _check_balanced(result.fun, np.ones(1), symbols, q_values)
    return {s: float(result.x[i]) for i, s in enumerate(symbols)}


def _check_balanced(leftover: np.ndarray, forces: np.ndarray, symbols, q_values) -> None:
    scale = max(1.0, float(np.max(np.abs(forces))) if forces.size else 1.0)
    worst = float(np.max(np.abs(leftover))) if leftover.size else 0.0
    if worst > _BALANCE_RTOL * scale:
        raise ValueError(
            f"no values of {', '.join(s.name for s in symbols)} balance the system at q={show(q_values)} "
            f"(the best leave a generalised force of {worst:.3g})"
        )
