"""``System``: Lagrange's equations of a system in generalised coordinates, derived with SymPy.

Lagrange's equations of the course (``course/004_…``, video 2.1b) with non-conservative generalised
forces ``Q`` and holonomic constraints ``Φ(q, t) = 0`` adjoined with multipliers ``λ``:

    d/dt (∂L/∂q̇) - ∂L/∂q - Q + Φ_qᵀ λ = 0,   L = K - P.

The derivation is ``sympy.physics.mechanics.LagrangesMethod`` (constraints through ``hol_coneqs``,
forces through its ``forcelist``); the equations are collected as ``M(q, t) q̈ + Φ_qᵀ λ = f(q, q̇, t)``
with the acceleration-level constraints ``Φ_q q̈ = γ(q, q̇, t)`` (``Φ̈ = 0``).

Sign of the multipliers: ``equations`` follow ``LagrangesMethod.eom`` (``+ Φ_qᵀ λ``). SymPy's own
``LagrangesMethod.mass_matrix`` puts ``-Φ_qᵀ`` in the multiplier columns, which solves for ``-λ``; the
``mass_matrix_full`` here uses ``+Φ_qᵀ`` so that every λ tumble reports is the one in ``equations``.
With ``Φ = (x² + z² - l²)/2`` for a pendulum in Cartesian coordinates, ``λ`` is the rod tension over ``l``.
"""

from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import LagrangesMethod, Point, ReferenceFrame

from ._checks import (
    TIME,
    as_coordinates,
    as_expression,
    as_parameter_values,
    check_holonomic,
    check_no_accelerations,
    show,
)
from .bodies import DEFAULT_GRAVITY, kinetic_energy, potential_energy
from .kinematics import angular_velocity, functions_of_time
from .loads import Force, Torque, generalized_forces_of

__all__ = ["System"]

# Entries with more operations than this are left as derived by accelerations(): simplify() is
# super-linear in expression size (a double pendulum's q̈ takes seconds), a pendulum's is instant.
_SIMPLIFY_MAX_OPS = 80


class System:
    """Lagrange's equations of motion of a system in generalised coordinates.

    Args:
        coordinates: the generalised coordinates, functions of time made with
            ``sympy.physics.mechanics.dynamicsymbols`` (one, or a sequence of distinct ones).
        lagrangian: ``L = K - P``, a SymPy expression in the coordinates, their rates and the time.
        forces: non-conservative loads, either one generalised force per coordinate (SymPy expressions
            in ``q``, ``q̇``, ``t``, e.g. ``[-b * theta.diff()]``), or a list of :class:`Force` and
            :class:`Torque` (world-frame loads at points / on frames, mapped by virtual work).
        constraints: holonomic constraints ``Φ(q, t) = 0``: expressions (or ``sympy.Eq``), adjoined with
            Lagrange multipliers.
        parameters: default values of the constant symbols, ``{symbol or name: number}``; used by the
            numeric methods and overridable there.

    >>> import sympy as sp
    >>> from sympy.physics.mechanics import dynamicsymbols
    >>> theta = dynamicsymbols("theta")
    >>> m, g, l = sp.symbols("m g l", positive=True)
    >>> L = m * l**2 * theta.diff() ** 2 / 2 + m * g * l * sp.cos(theta)
    >>> System(theta, L).accelerations()
    Matrix([[-g*sin(theta(t))/l]])
    """

    def __init__(self, coordinates, lagrangian, *, forces=None, constraints=None, parameters=None) -> None:
        self._coordinates = as_coordinates(coordinates)
        self._lagrangian = as_expression("lagrangian", lagrangian)
        check_no_accelerations("lagrangian", self._lagrangian, self._coordinates)
        self._applied = generalized_forces_of("forces", forces, self._coordinates)
        self._constraints = _as_constraints(constraints, self._coordinates)
        self._parameters = as_parameter_values("parameters", parameters)
        self._bodies: tuple = ()
        self._gravity = None
        self._method = self._derive(forces)
        self._cache: dict = {}

    @classmethod
    def from_bodies(
        cls, coordinates, bodies, *, gravity=DEFAULT_GRAVITY, forces=None, constraints=None, parameters=None
    ) -> System:
        """The system of particles and rigid bodies placed by the coordinates, under uniform gravity.

        ``L = Σ (½ m v_c·v_c + ½ ω_bᵀ I_c ω_b) + Σ m g·x_c`` (see :mod:`tumble.lagrange.bodies`).

        Args:
            coordinates: as for :class:`System`.
            bodies: a sequence of :class:`Particle` and :class:`RigidBody`.
            gravity: 3 numbers or expressions [m/s²], world frame; default ``(0, 0, -9.81)``.
            forces, constraints, parameters: as for :class:`System`.
        """
        coords = as_coordinates(coordinates)
        lagrangian = kinetic_energy(bodies) - potential_energy(bodies, gravity)
        system = cls(coords, lagrangian, forces=forces, constraints=constraints, parameters=parameters)
        system._bodies = tuple(bodies)
        system._gravity = tuple(sp.Matrix(gravity))
        return system

    # --- derivation ----------------------------------------------------------------------------------

    def _derive(self, forces) -> LagrangesMethod:
        inertial = ReferenceFrame("N")
        forcelist = _forcelist(forces, self._applied, self._coordinates, inertial)
        lam_names = {f"lam{k + 1}" for k in range(len(self._constraints))}
        clash = [q for q in self._coordinates if str(q.func) in lam_names]
        if clash:
            raise ValueError(f"coordinates must not be named like SymPy's multipliers lam1, lam2, ...; got {clash[0]}")
        method = LagrangesMethod(
            self._lagrangian,
            list(self._coordinates),
            forcelist=forcelist or None,
            frame=inertial,
            hol_coneqs=list(self._constraints) or None,
        )
        method.form_lagranges_equations()
        return method

    # --- what the system is --------------------------------------------------------------------------

    @property
    def coordinates(self) -> tuple:
        """The generalised coordinates ``q(t)``."""
        return self._coordinates

    @property
    def velocities(self) -> tuple:
        """The generalised velocities ``q̇`` (SymPy derivatives)."""
        return tuple(q.diff(TIME) for q in self._coordinates)

    @property
    def time(self) -> sp.Symbol:
        """The time symbol ``t`` (``dynamicsymbols._t``)."""
        return TIME

    @property
    def lagrangian(self) -> sp.Expr:
        """``L = K - P``."""
        return self._lagrangian

    @property
    def applied_forces(self) -> sp.Matrix:
        """The non-conservative generalised forces ``Q`` (n x 1) from ``forces``."""
        return self._applied

    @property
    def constraints(self) -> tuple:
        """The holonomic constraints ``Φ_k(q, t)`` (each ``= 0``)."""
        return self._constraints

    @property
    def multipliers(self) -> tuple:
        """The Lagrange multipliers ``λ_k(t)`` of the constraints (SymPy names them ``lam1``, ...)."""
        return tuple(self._method.lam_vec)

    @property
    def parameters(self) -> dict:
        """The default values of the constant symbols (a copy)."""
        return dict(self._parameters)

    @property
    def symbols(self) -> tuple:
        """The constant symbols of the system (masses, lengths, ...), sorted by name; the time excluded."""
        pieces = [self._lagrangian, self._applied, *self._constraints]
        found = set().union(*[piece.free_symbols for piece in pieces]) - {TIME}
        return tuple(sorted(found, key=lambda s: s.name))

    @property
    def bodies(self) -> tuple:
        """The particles and rigid bodies of :meth:`from_bodies` (empty otherwise)."""
        return self._bodies

    @property
    def gravity(self) -> tuple | None:
        """The gravity of :meth:`from_bodies` (None otherwise)."""
        return self._gravity

    @property
    def method(self) -> LagrangesMethod:
        """The ``sympy.physics.mechanics.LagrangesMethod`` that derived the equations (for linearisation)."""
        return self._method

    # --- the equations -------------------------------------------------------------------------------

    @property
    def equations(self) -> sp.Matrix:
        """``d/dt ∂L/∂q̇ - ∂L/∂q - Q + Φ_qᵀ λ`` (n x 1): the equations of motion are ``equations = 0``."""
        return self._method.eom

    @property
    def mass_matrix(self) -> sp.Matrix:
        """``M(q, t)`` (n x n): the coefficients of ``q̈`` in :attr:`equations`."""
        n = len(self._coordinates)
        return self._method.mass_matrix[:, :n]

    @property
    def forcing(self) -> sp.Matrix:
        """``f(q, q̇, t)`` (n x 1) with ``M q̈ + Φ_qᵀ λ = f`` (``LagrangesMethod.forcing``)."""
        return self._method.forcing

    @property
    def constraint_jacobian(self) -> sp.Matrix:
        """``Φ_q`` (m x n), ``∂Φ_k/∂q_j``; zero rows without constraints."""
        if not self._constraints:
            return sp.zeros(0, len(self._coordinates))
        return -self._method.lam_coeffs

    @property
    def constraint_forcing(self) -> sp.Matrix:
        """``γ(q, q̇, t)`` (m x 1) with ``Φ_q q̈ = γ``: the constraints differentiated twice in time."""
        n = len(self._coordinates)
        return self._method.forcing_full[2 * n :, :]

    @property
    def constraint_rates(self) -> sp.Matrix:
        """``Φ̇ = Φ_q q̇ + ∂Φ/∂t`` (m x 1)."""
        return sp.Matrix(self._method.coneqs) if self._constraints else sp.zeros(0, 1)

    @property
    def mass_matrix_full(self) -> sp.Matrix:
        """The first-order form's matrix (2n+m square) acting on ``[q̇; q̈; λ]``:

        ``[[E, 0, 0], [0, M, Φ_qᵀ], [0, Φ_q, 0]]``, so that ``mass_matrix_full · [q̇; q̈; λ] = forcing_full``.
        """
        n, m = len(self._coordinates), len(self._constraints)
        J = self.constraint_jacobian
        top = sp.eye(n).row_join(sp.zeros(n, n + m))
        middle = sp.zeros(n, n).row_join(self.mass_matrix).row_join(J.T)
        bottom = sp.zeros(m, n).row_join(J).row_join(sp.zeros(m, m))
        return top.col_join(middle).col_join(bottom)

    @property
    def forcing_full(self) -> sp.Matrix:
        """``[q̇; f; γ]`` (2n+m x 1), the right-hand side for :attr:`mass_matrix_full`."""
        return sp.Matrix(self.velocities).col_join(self.forcing).col_join(self.constraint_forcing)

    @property
    def energy_function(self) -> sp.Expr:
        """Jacobi's energy function ``h = Σ q̇_j ∂L/∂q̇_j - L`` (``K + P`` when K is quadratic in q̇).

        Conserved when ``L`` has no explicit time and the forces do no work.
        """
        if "energy" not in self._cache:
            rates = self.velocities
            self._cache["energy"] = sum(qd * self._lagrangian.diff(qd) for qd in rates) - self._lagrangian
        return self._cache["energy"]

    def accelerations(self, *, simplify: bool = True) -> sp.Matrix:
        """``q̈`` solved from the equations (n x 1), multipliers eliminated.

        Without constraints ``q̈ = M⁻¹ f``. With constraints the acceleration-level constraints close the
        system: ``λ = (Φ_q M⁻¹ Φ_qᵀ)⁻¹ (Φ_q M⁻¹ f - γ)``, ``q̈ = M⁻¹ (f - Φ_qᵀ λ)``; valid on the constraint
        manifold. Small entries are simplified (``simplify=False`` skips it).
        """
        key = ("accelerations", simplify)
        if key not in self._cache:
            accelerations, multipliers = self._solve_symbolic()
            self._cache[key] = _tidy(accelerations, simplify)
            self._cache[("multipliers", simplify)] = _tidy(multipliers, simplify)
        return self._cache[key]

    def multiplier_expressions(self, *, simplify: bool = True) -> sp.Matrix:
        """The multipliers ``λ(q, q̇, t)`` (m x 1) solved as in :meth:`accelerations`."""
        self.accelerations(simplify=simplify)
        return self._cache[("multipliers", simplify)]

    def _solve_symbolic(self) -> tuple[sp.Matrix, sp.Matrix]:
        M, f = self.mass_matrix, self.forcing
        if not self._constraints:
            return M.LUsolve(f), sp.zeros(0, 1)
        # M and the Schur complement Φ_q M⁻¹ Φ_qᵀ are positive definite: LU needs no pivoting
        J, gamma = self.constraint_jacobian, self.constraint_forcing
        M_inv_f = M.LUsolve(f)
        M_inv_JT = M.LUsolve(J.T)
        lam = (J * M_inv_JT).LUsolve(J * M_inv_f - gamma)
        return M_inv_f - M_inv_JT * lam, lam

    # --- numerics ------------------------------------------------------------------------------------

    def lambdify(self, parameters=None, *, baumgarte=(5.0, 5.0)):
        """Numeric functions of this system with the constant symbols given values.

        Args:
            parameters: ``{symbol or name: number}``, added to (and overriding) the defaults. Every
                constant symbol must have a value; a missing one is named in a ``ValueError``.
            baumgarte: ``(α, β)`` [1/s] of the constraint stabilisation ``Φ̈ + 2αΦ̇ + β²Φ = 0``.

        Returns:
            a :class:`tumble.lagrange.NumericSystem` (cached per parameter values).
        """
        from .numeric import NumericSystem

        key = ("numeric", _freeze(parameters), tuple(baumgarte) if _is_pair(baumgarte) else id(baumgarte))
        if key not in self._cache:
            self._cache[key] = NumericSystem(self, parameters, baumgarte=baumgarte)
        return self._cache[key]

    def simulate(self, q0, qd0, t_span, *, parameters=None, baumgarte=(5.0, 5.0), **options):
        """Integrate the equations from ``(q0, qd0)`` over ``t_span``; see :meth:`NumericSystem.simulate`.

        ``options``: ``t_eval``, ``events``, ``rtol`` (1e-10), ``atol`` (1e-12), ``method`` ("DOP853"),
        ``max_step``. Returns a :class:`Motion` with ``t``, ``q``, ``qd`` and more.
        """
        return self.lambdify(parameters, baumgarte=baumgarte).simulate(q0, qd0, t_span, **options)

    def energy(self, q, qd, *, parameters=None, t=0.0):
        """The numeric energy function ``Σ q̇ ∂L/∂q̇ - L`` at ``(q, qd)`` ((n,) -> float, (T, n) -> (T,))."""
        return self.lambdify(parameters).energy(q, qd, t)

    # --- statics (virtual work) ----------------------------------------------------------------------

    def generalized_forces(self, applied=None) -> sp.Matrix:
        """The generalised forces at rest, ``Q(q, t)`` (n x 1), whose vanishing is static equilibrium.

        By the principle of virtual work (course deck 004, video 2.1b): ``δW = Σ Q_j δq_j = 0`` for every
        virtual displacement. With ``L = K(q, q̇) - P(q)`` this is ``Q = -∂P/∂q + Σ J_iᵀ F_i``, computed as
        the forcing ``f(q, q̇ = 0, t)`` (which also keeps centrifugal terms of a prescribed rotation) plus
        the virtual work of ``applied`` loads.

        Args:
            applied: extra loads for statics only, given as ``forces`` is (n generalised forces or
                Force/Torque loads); their symbols may be the unknowns of :meth:`balancing`.
        """
        at_rest = {qd: 0 for qd in self.velocities}
        Q = self.forcing.xreplace(at_rest)
        return Q + generalized_forces_of("applied", applied, self._coordinates)

    def equilibrium(self, guess, parameters=None, *, applied=None, t=0.0):
        """A configuration ``q*`` near ``guess`` where the generalised forces vanish (subject to the
        constraints, ``Q - Φ_qᵀ λ = 0`` and ``Φ = 0``), by ``scipy.optimize.root``.

        Returns:
            (n,) float64, raising ``ValueError`` when the solver finds no equilibrium.
        """
        from .statics import equilibrium

        return equilibrium(self, guess, parameters, applied=applied, t=t)

    def balancing(self, unknowns, q, parameters=None, *, applied=None, t=0.0) -> dict:
        """Numeric values of unknown load symbols that hold the system at rest at ``q``.

        Args:
            unknowns: a Symbol or a sequence of Symbols appearing in ``forces`` or ``applied``
                (e.g. a crank torque ``tau``).
            q: (n,) the configuration (consistent with the constraints).
            parameters: values of the other symbols.

        Returns:
            ``{symbol: float}``; ``ValueError`` when no value balances the system or the values are not
            determined.
        """
        from .statics import balancing

        return balancing(self, unknowns, q, parameters, applied=applied, t=t)

    def balancing_expressions(self, unknowns, *, applied=None) -> dict:
        """The unknown load symbols solved symbolically from ``Q - Φ_qᵀ λ = 0``: ``{symbol: expression}``."""
        from .statics import balancing_expressions

        return balancing_expressions(self, unknowns, applied=applied)

    def __repr__(self) -> str:
        coords = ", ".join(str(q.func) for q in self._coordinates)
        extra = f", constraints={len(self._constraints)}" if self._constraints else ""
        if self._bodies:
            extra += f", bodies={len(self._bodies)}"
        return f"System(coordinates=({coords}){extra})"


def _as_constraints(constraints, coordinates) -> tuple:
    if constraints is None:
        return ()
    if isinstance(constraints, (sp.Expr, sp.Eq)):
        constraints = [constraints]
    if isinstance(constraints, (str, bytes)) or not hasattr(constraints, "__iter__"):
        raise TypeError(f"constraints must be a sequence of SymPy expressions f(q, t) (= 0), got {show(constraints)}")
    out = []
    for k, item in enumerate(constraints):
        name = f"constraints[{k}]"
        if isinstance(item, sp.Eq):
            item = item.lhs - item.rhs
        expression = as_expression(name, item)
        check_holonomic(name, expression, coordinates)
        out.append(expression)
    return tuple(out)


def _forcelist(forces, applied: sp.Matrix, coordinates, inertial: ReferenceFrame) -> list:
    """LagrangesMethod's (Point, Vector) / (ReferenceFrame, Vector) list for the given forces.

    Loads become real points (velocity ``dr/dt``) and frames (angular velocity from ``Ṙ Rᵀ``).
    Generalised forces ``Q_j`` become a force ``Q_j N.x`` on a point moving with ``q̇_j N.x``: its
    partial velocity is ``N.x`` for ``q̇_j`` and zero for the others, so its virtual work is ``Q_j δq_j``.
    """
    if forces is None:
        return []
    items = list(forces) if not isinstance(forces, (Force, Torque)) else [forces]
    N = inertial
    basis = (N.x, N.y, N.z)

    def world(vector) -> object:
        return sum((component * axis for component, axis in zip(vector, basis, strict=True)), 0 * N.x)

    pairs = []
    if items and isinstance(items[0], (Force, Torque)):
        for i, load in enumerate(items):
            if isinstance(load, Force):
                point = Point(f"load{i}")
                point.set_vel(N, world(load.point.diff(TIME)))
                pairs.append((point, world(load.vector)))
            else:
                frame = ReferenceFrame(f"L{i}")
                omega = angular_velocity(load.rotation, functions_of_time(load.rotation), frame="world")
                frame.set_ang_vel(N, world(omega))
                pairs.append((frame, world(load.vector)))
        return pairs
    for j, (q, Q_j) in enumerate(zip(coordinates, applied, strict=True)):
        if Q_j == 0:
            continue
        point = Point(f"generalised{j}")
        point.set_vel(N, q.diff(TIME) * N.x)
        pairs.append((point, Q_j * N.x))
    return pairs


def _tidy(matrix: sp.Matrix, simplify: bool) -> sp.Matrix:
    if not simplify:
        return matrix
    return matrix.applyfunc(lambda e: sp.simplify(e) if sp.count_ops(e) <= _SIMPLIFY_MAX_OPS else e)


def _freeze(parameters):
    if parameters is None:
        return None
    try:
        return tuple(sorted((str(key), float(value)) for key, value in parameters.items()))
    except (AttributeError, TypeError, ValueError):
        return id(parameters)  # invalid: NumericSystem raises the precise error


def _is_pair(value) -> bool:
    try:
        return len(value) == 2 and all(isinstance(v, (int, float)) for v in value)
    except TypeError:
        return False
