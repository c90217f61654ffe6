"""Numerics of a Lagrangian system: SymPy expressions lambdified to NumPy, integrated by ``solve_ivp``.

The state is ``y = [q, q̇]``. Without constraints ``q̈`` solves ``M q̈ = f``. With holonomic constraints
the equations form an index-3 DAE; it is reduced to index 1 by asking the constraints to hold at the
acceleration level, stabilised after Baumgarte (1972, "Stabilization of constraints and integrals of
motion in dynamical systems"): ``Φ̈ + 2α Φ̇ + β² Φ = 0``, so that drift from round-off decays instead of
growing. Each right-hand side solves the saddle-point system

    [ M    Φ_qᵀ ] [ q̈ ]   [ f                   ]
    [ Φ_q  0    ] [ λ  ] = [ γ - 2α Φ̇ - β² Φ    ]

(``Φ_q q̈ = γ`` is ``Φ̈ = 0``). The motion reports the constraint residual ``Φ(q(t))`` along the way.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

from ..errors import SimulationError
from ._checks import TIME, as_parameter_values, as_real, as_state, show

__all__ = ["NumericSystem", "Motion", "compile_expressions", "resolve_parameters"]

# A start that violates the constraints by more than this is refused: integrating it would report
# a motion of another system. 1e-8 is far above float64 round-off of a configuration and far below
# anything a user would call consistent.
_START_TOLERANCE = 1e-8


@dataclasses.dataclass(frozen=True)
class Motion:
    """A simulated motion of a :class:`System`.

    Attributes:
        t: (T,) float64 [s], the output times.
        q: (T, n) float64, the coordinates.
        qd: (T, n) float64, their rates.
        multipliers: (T, m) float64, the Lagrange multipliers ``λ`` (m = 0 without constraints).
        constraint_residual: (T, m) float64, ``Φ(q(t), t)``.
        energy: (T,) float64, the energy function ``Σ q̇ ∂L/∂q̇ - L``.
        t_events: one (k,) array per event function (empty list without events).
        q_events, qd_events: one (k, n) array per event function.
        coordinates: the coordinate names.
        nfev: right-hand-side evaluations.
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    multipliers: np.ndarray
    constraint_residual: np.ndarray
    energy: np.ndarray
    t_events: list
    q_events: list
    qd_events: list
    coordinates: tuple
    nfev: int

    @property
    def max_constraint_residual(self) -> float:
        """``max |Φ|`` over the motion (0.0 without constraints)."""
        return float(np.max(np.abs(self.constraint_residual))) if self.constraint_residual.size else 0.0


def resolve_parameters(symbols, defaults, parameters, *, allowed=()) -> dict:
    """``{Symbol: float}`` for every one of ``symbols``, from ``defaults`` updated by ``parameters``.

    Keys are matched by name, so ``"m"`` and ``Symbol("m", positive=True)`` give the same value. A key of
    ``parameters`` that names none of the symbols (nor of ``allowed``, symbols that may be given but are
    not needed), or a symbol left without a value, raises ``ValueError`` naming them. Defaults that name
    other symbols are ignored: they may serve loads given later.
    """
    names = {s.name for s in symbols}
    permitted = names | {s.name for s in allowed}
    values: dict[str, float] = {}
    for key, value in as_parameter_values("parameters", defaults).items():
        name = key if isinstance(key, str) else key.name
        if name in names:
            values[name] = value
    given = as_parameter_values("parameters", parameters)
    unknown = sorted({key if isinstance(key, str) else key.name for key in given} - permitted)
    if unknown:
        raise ValueError(
            f"parameters name symbols the system does not have: {', '.join(unknown)} "
            f"(its symbols are {', '.join(sorted(permitted)) or 'none'})"
        )
    for key, value in given.items():
        name = key if isinstance(key, str) else key.name
        if name in names:
            values[name] = value
    missing = sorted(names - set(values))
    if missing:
        raise ValueError(f"parameters are missing values for the symbols {', '.join(missing)}")
    return {symbol: values[symbol.name] for symbol in symbols}


def compile_expressions(name: str, matrix: sp.Matrix, coordinates, values: dict):
    """``fn(t, q, qd) -> ndarray`` of ``matrix``'s shape, with the constant symbols set to ``values``.

    ``q(t)`` and ``q̇`` are replaced by plain symbols first; anything else left that is not ``t`` (an
    unknown function of time, a symbol without a value) raises ``ValueError`` naming it.
    """
    rates = [q.diff(TIME) for q in coordinates]
    q_args = [sp.Dummy(f"q{j}") for j in range(len(coordinates))]
    qd_args = [sp.Dummy(f"qd{j}") for j in range(len(coordinates))]
    replacements = {**dict(zip(rates, qd_args, strict=True)), **dict(zip(coordinates, q_args, strict=True))}
    numbers = {symbol: sp.Float(value) for symbol, value in values.items()}
    plain = sp.Matrix(matrix).xreplace(replacements).xreplace(numbers)
    leftovers = [d for d in plain.atoms(sp.Derivative)] + [
        f for f in plain.atoms(sp.Function) if isinstance(f, sp.core.function.AppliedUndef)
    ]
    if leftovers:
        raise ValueError(
            f"{name} depends on {leftovers[0]}, which is neither a coordinate nor its rate; make it a "
            "coordinate or write it as an expression of t"
        )
    strays = plain.free_symbols - {TIME, *q_args, *qd_args}
    if strays:
        names = ", ".join(sorted(str(s) for s in strays))
        raise ValueError(f"{name} has symbols without values: {names}")
    shape = plain.shape
    function = sp.lambdify([TIME, q_args, qd_args], plain, modules="numpy", cse=True)

    def evaluate(t, q, qd) -> np.ndarray:
        return np.asarray(function(t, q, qd), dtype=np.float64).reshape(shape)

    return evaluate


class NumericSystem:
    """A :class:`System` with numbers for its symbols: mass matrix, forcing, accelerations, simulation.

    Made by :meth:`System.lambdify`. Arrays are float64; ``q`` and ``qd`` are (n,) in coordinate order.

    Args:
        system: the symbolic system.
        parameters: ``{symbol or name: number}`` over the system's defaults.
        baumgarte: ``(α, β)`` [1/s], the constraint stabilisation ``Φ̈ + 2αΦ̇ + β²Φ = 0``; ``(0, 0)``
            integrates the bare acceleration-level constraints.
    """

    def __init__(self, system, parameters=None, *, baumgarte=(5.0, 5.0)) -> None:
        self.system = system
        self.values = resolve_parameters(system.symbols, system.parameters, parameters)
        self.baumgarte = _as_baumgarte(baumgarte)
        self.size = len(system.coordinates)
        self.constraint_count = len(system.constraints)
        coords = system.coordinates
        self._mass_matrix = compile_expressions("the mass matrix", system.mass_matrix, coords, self.values)
        self._forcing = compile_expressions("the forcing", system.forcing, coords, self.values)
        self._energy = compile_expressions("the energy", sp.Matrix([system.energy_function]), coords, self.values)
        if self.constraint_count:
            constraints = sp.Matrix(system.constraints)
            self._phi = compile_expressions("the constraints", constraints, coords, self.values)
            self._phi_rate = compile_expressions("the constraint rates", system.constraint_rates, coords, self.values)
            self._jacobian = compile_expressions(
                "the constraint Jacobian", system.constraint_jacobian, coords, self.values
            )
            self._gamma = compile_expressions("the constraint forcing", system.constraint_forcing, coords, self.values)

    # --- evaluations ---------------------------------------------------------------------------------

    def mass_matrix(self, q, qd=None, t=0.0) -> np.ndarray:
        """``M(q, t)``, (n, n)."""
        q, qd = self._state(q, qd)
        return self._mass_matrix(t, q, qd)

    def forcing(self, q, qd=None, t=0.0) -> np.ndarray:
        """``f(q, q̇, t)``, (n,)."""
        q, qd = self._state(q, qd)
        return self._forcing(t, q, qd)[:, 0]

    def constraints(self, q, t=0.0) -> np.ndarray:
        """``Φ(q, t)``, (m,)."""
        q, qd = self._state(q, None)
        return self._phi(t, q, qd)[:, 0] if self.constraint_count else np.zeros(0)

    def accelerations(self, q, qd, t=0.0) -> np.ndarray:
        """``q̈``, (n,), from the equations (with the stabilised constraints when there are any)."""
        q, qd = self._state(q, qd)
        return self._solve(t, q, qd)[0]

    def multipliers(self, q, qd, t=0.0) -> np.ndarray:
        """``λ``, (m,), as in :meth:`accelerations`."""
        q, qd = self._state(q, qd)
        return self._solve(t, q, qd)[1]

    def energy(self, q, qd, t=0.0):
        """The energy function ``Σ q̇ ∂L/∂q̇ - L``: a float for (n,) states, (T,) for (T, n)."""
        q_array = np.asarray(q, dtype=np.float64)
        qd_array = np.asarray(qd, dtype=np.float64)
        if q_array.ndim == 2:
            times = np.broadcast_to(np.asarray(t, dtype=np.float64), (q_array.shape[0],))
            return np.array([self.energy(a, b, s) for a, b, s in zip(q_array, qd_array, times, strict=True)])
        q_vec, qd_vec = self._state(q_array, qd_array)
        return float(self._energy(t, q_vec, qd_vec)[0, 0])

    def rhs(self, t, y) -> np.ndarray:
        """``dy/dt`` for ``y = [q, q̇]``, the signature ``solve_ivp`` wants."""
        n = self.size
        q, qd = y[:n], y[n:]
        qdd, _ = self._solve(t, q, qd)
        return np.concatenate([qd, qdd])

    def _solve(self, t, q, qd) -> tuple[np.ndarray, np.ndarray]:
        M = self._mass_matrix(t, q, qd)
        f = self._forcing(t, q, qd)[:, 0]
        try:
            if not self.constraint_count:
                return np.linalg.solve(M, f), np.zeros(0)
            alpha, beta = self.baumgarte
            J = self._jacobian(t, q, qd)
            phi = self._phi(t, q, qd)[:, 0]
            phi_rate = self._phi_rate(t, q, qd)[:, 0]
            gamma = self._gamma(t, q, qd)[:, 0] - 2.0 * alpha * phi_rate - beta**2 * phi
            m = self.constraint_count
            saddle = np.block([[M, J.T], [J, np.zeros((m, m))]])
            solution = np.linalg.solve(saddle, np.concatenate([f, gamma]))
        except np.linalg.LinAlgError as error:
            what = "mass matrix" if not self.constraint_count else "matrix [[M, Φ_qᵀ], [Φ_q, 0]]"
            raise ValueError(
                f"the {what} is singular at t={t!r}, q={show(np.asarray(q))}: does every coordinate carry "
                "inertia, and are the constraints independent?"
            ) from error
        return solution[: self.size], solution[self.size :]

    def _state(self, q, qd) -> tuple[np.ndarray, np.ndarray]:
        q_vec = as_state("q", q, self.size)
        qd_vec = np.zeros(self.size) if qd is None else as_state("qd", qd, self.size)
        return q_vec, qd_vec

    # --- simulation ----------------------------------------------------------------------------------

    def simulate(
        self,
        q0,
        qd0,
        t_span,
        *,
        t_eval=None,
        events=None,
        rtol: float = 1e-10,
        atol: float = 1e-12,
        method: str = "DOP853",
        max_step: float = np.inf,
    ) -> Motion:
        """Integrate from ``(q0, qd0)`` at ``t_span[0]`` to ``t_span[1]`` with ``scipy.integrate.solve_ivp``.

        Args:
            q0, qd0: (n,) the start; with constraints it must satisfy ``Φ = 0`` and ``Φ̇ = 0`` (to 1e-8).
            t_span: ``(t0, t1)`` [s].
            t_eval: times to report (default: the solver's steps).
            events: callables ``event(t, q, qd) -> float`` (zero crossings are located; optional
                ``terminal`` and ``direction`` attributes as for ``solve_ivp``).
            rtol, atol, method, max_step: passed to ``solve_ivp``; the defaults (DOP853, 1e-10, 1e-12)
                keep a pendulum's energy to ~1e-11 over many periods.

        Returns:
            a :class:`Motion`. Raises :class:`tumble.SimulationError` when the integrator fails.
        """
        n = self.size
        q_start = as_state("q0", q0, n)
        qd_start = as_state("qd0", qd0, n)
        t0, t1 = _as_span(t_span)
        self._check_start(t0, q_start, qd_start)
        wrapped_events = _wrap_events(events, n)
        result = solve_ivp(
            self.rhs,
            (t0, t1),
            np.concatenate([q_start, qd_start]),
            method=method,
            t_eval=t_eval,
            events=wrapped_events,
            rtol=as_real("rtol", rtol),
            atol=atol,
            max_step=max_step,
        )
        if result.status == -1:
            raise SimulationError(f"integration of the Lagrangian system failed: {result.message}")
        return self._motion(result, wrapped_events is not None)

    def _check_start(self, t0, q, qd) -> None:
        if not self.constraint_count:
            return
        phi = self._phi(t0, q, qd)[:, 0]
        rate = self._phi_rate(t0, q, qd)[:, 0]
        for label, values, given in (("Φ(q0)", phi, "q0"), ("Φ̇(q0, qd0)", rate, "qd0")):
            worst = int(np.argmax(np.abs(values)))
            if abs(values[worst]) > _START_TOLERANCE:
                raise ValueError(
                    f"{given} violates constraint {worst} ({self.system.constraints[worst]}): {label} = "
                    f"{values[worst]:.3g}; start on the constraint manifold"
                )

    def _motion(self, result, has_events: bool) -> Motion:
        n = self.size
        t = result.t
        q, qd = result.y[:n].T.copy(), result.y[n:].T.copy()
        m = self.constraint_count
        lam = np.zeros((t.size, m))
        residual = np.zeros((t.size, m))
        if m:
            for k in range(t.size):
                lam[k] = self._solve(t[k], q[k], qd[k])[1]
                residual[k] = self._phi(t[k], q[k], qd[k])[:, 0]
        energy = np.array([self._energy(t[k], q[k], qd[k])[0, 0] for k in range(t.size)])
        t_events = list(result.t_events) if has_events else []
        y_events = list(result.y_events) if has_events else []
        return Motion(
            t=t,
            q=q,
            qd=qd,
            multipliers=lam,
            constraint_residual=residual,
            energy=energy,
            t_events=t_events,
            q_events=[y[:, :n] for y in y_events],
            qd_events=[y[:, n:] for y in y_events],
            coordinates=tuple(str(c.func) for c in self.system.coordinates),
            nfev=int(result.nfev),
        )

    def __repr__(self) -> str:
        values = ", ".join(f"{s.name}={v:g}" for s, v in sorted(self.values.items(), key=lambda kv: kv[0].name))
        return f"NumericSystem({self.system!r}, {values})"


def _as_baumgarte(value) -> tuple[float, float]:
    try:
        alpha, beta = value
    except (TypeError, ValueError) as error:
        raise TypeError(f"baumgarte must be a pair (alpha, beta) of numbers, got {show(value)}") from error
    alpha, beta = as_real("baumgarte[0]", alpha), as_real("baumgarte[1]", beta)
    if alpha < 0.0 or beta < 0.0:
        raise ValueError(f"baumgarte must be >= 0 (a negative gain makes the drift grow), got {(alpha, beta)}")
    return alpha, beta


def _as_span(t_span) -> tuple[float, float]:
    try:
        t0, t1 = t_span
    except (TypeError, ValueError) as error:
        raise TypeError(f"t_span must be a pair (t0, t1) of times, got {show(t_span)}") from error
    t0, t1 = as_real("t_span[0]", t0), as_real("t_span[1]", t1)
    if t0 == t1:
        raise ValueError(f"t_span must have t0 != t1, got {(t0, t1)}")
    return t0, t1


def _wrap_events(events, n: int):
    if events is None:
        return None
    items = [events] if callable(events) else list(events)
    wrapped = []
    for i, event in enumerate(items):
        if not callable(event):
            raise TypeError(f"events[{i}] must be a callable event(t, q, qd), got {show(event)}")

        def on_state(t, y, event=event):
            return event(t, y[:n], y[n:])

        for attribute in ("terminal", "direction"):
            if hasattr(event, attribute):
                setattr(on_state, attribute, getattr(event, attribute))
        wrapped.append(on_state)
    return wrapped
