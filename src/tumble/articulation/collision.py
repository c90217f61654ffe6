"""The collision geoms of an :class:`~tumble.articulation.Articulation` and the pairs that may touch, as MuJoCo
decides them (a mixin of the facade, and the packing into ``model.geom_*``/``pair_*``; the contacts themselves are
``contacts.py``).

Which pairs: two geoms may touch unless they are on one rigid body (links joined by ``Fixed`` joints, and the world
with everything welded to it, are one body), or on a body and its parent body (the nearest ancestor that carries
mass or geoms: the massless links between several joints of one MuJoCo body count as the joint), or their
``contype``/``conaffinity`` bits do not meet (``contype₁ & conaffinity₂`` or ``contype₂ & conaffinity₁``), or the
bodies are excluded (MuJoCo's ``<exclude>``). A pair mixes the two geoms' settings as MuJoCo does (documentation,
*Modeling*: "Contact parameters"): the larger friction and ``condim``, the margins added, ``solref``/``solimp``
averaged with the ``solmix`` weights.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from .. import portable
from .._validate import _show, as_array, as_float, as_quaternion, as_vector3
from .joints import Fixed
from .limits import SoftConstraint, readonly
from .model import (
    CAPSULE,
    GEOM_INT_WIDTH,
    GEOM_LINK,
    GEOM_POS,
    GEOM_QUAT,
    GEOM_REAL_WIDTH,
    GEOM_SIZE,
    GEOM_TYPE,
    PAIR_A,
    PAIR_B,
    PAIR_CONDIM,
    PAIR_FRICTION,
    PAIR_INT_WIDTH,
    PAIR_MARGIN,
    PAIR_REAL_WIDTH,
    PAIR_SOLIMP,
    PAIR_SOLREF,
    PAIR_WEIGHT,
    PLANE,
    SPHERE,
)

__all__ = ["Collisions", "Geom", "pack_geoms", "pack_pairs", "pair_weights"]

KINDS = {"plane": PLANE, "sphere": SPHERE, "capsule": CAPSULE}
_SIZES = {"plane": 0, "sphere": 1, "capsule": 2}


@dataclass(frozen=True, eq=False)
class Geom:
    """A collision geom (read-only), with MuJoCo's contact settings.

    Attributes:
        index, name; link: the link it moves with, or ``None`` (the world); kind: ``"plane"``, ``"sphere"`` or
        ``"capsule"``; size (2,): a sphere's radius, a capsule's radius and half length along its z axis (a plane has
        none: it is the infinite plane through its position, normal to its z axis); position (3,), orientation (4,):
        in the link's frame (the world's); contype, conaffinity: the filter's bits; condim: 1 (no friction) or 3;
        friction: the sliding friction coefficient; margin [m]: the distance within which contacts act; softness:
        the contacts' ``solref``/``solimp``; solmix: its weight when two geoms' settings are mixed.
    """

    index: int
    name: str | None
    link: int | None
    kind: str
    size: np.ndarray
    position: np.ndarray
    orientation: np.ndarray
    contype: int
    conaffinity: int
    condim: int
    friction: float
    margin: float
    softness: SoftConstraint
    solmix: float


class Collisions:
    """Geoms and contact exclusions. Expects of the class it is mixed into: ``_links``, ``_loops``, ``_geoms``,
    ``_excluded``, ``_compiled`` (reset to ``None`` when the model changes), ``_compile`` and ``_check_link``."""

    def add_geom(self, link, kind, size=(), *, position=(0.0, 0.0, 0.0), orientation=(1.0, 0.0, 0.0, 0.0), contype=1,
                 conaffinity=1, condim=3, friction=1.0, margin=0.0, softness=None, solmix=1.0,
                 name=None) -> int:  # fmt: skip
        """Add a collision geom to ``link`` (``None``: the world); returns its index. Contacts are MuJoCo's soft
        constraints, solved with the joints' limits at every evaluation (``contacts.py``).

        Args:
            kind: ``"plane"`` (no size), ``"sphere"`` (``size=(radius,)``) or ``"capsule"`` (``size=(radius,
                half_length)``, along the geom's z axis).
            position: (3,) [m], orientation: (4,): the geom in the link's frame (the world's for ``None``).
            contype, conaffinity: non-negative integers, MuJoCo's collision bits; condim: 1 or 3; friction >= 0;
            margin >= 0 [m]; softness: a :class:`~tumble.articulation.SoftConstraint` (MuJoCo's defaults); solmix >= 0;
            name: optional unique label.
        """
        link = None if link is None else self._check_link("link", link)
        if self._loops:
            raise ValueError("contacts are not simulated with loop closures (yet); this articulation has loop closures")
        if not isinstance(kind, str) or kind not in KINDS:
            raise ValueError(f"kind must be one of {tuple(KINDS)}, got {_show(kind)}")
        if kind == "plane" and link is not None:
            raise ValueError(f"a plane belongs to the world (link=None), got link={link}")
        count = _SIZES[kind]
        values = as_array("size", size, (count,), batch=False)
        if np.any(values <= 0.0):
            raise ValueError(f"size must be positive for a {kind}, got {_show(size)}")
        padded = np.zeros(2)
        padded[:count] = values
        bits = []
        for label, value in (("contype", contype), ("conaffinity", conaffinity)):
            if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 0:
                raise ValueError(f"{label} must be a non-negative integer, got {_show(value)}")
            bits.append(int(value))
        if condim not in (1, 3) or isinstance(condim, bool):
            raise ValueError(f"condim must be 1 or 3, got {_show(condim)}")
        if softness is not None and not isinstance(softness, SoftConstraint):
            raise TypeError(f"softness must be a SoftConstraint or None, got {_show(softness)}")
        if name is not None and not isinstance(name, str):
            raise TypeError(f"name must be a string or None, got {_show(name)}")
        if name is not None and any(g.name == name for g in self._geoms):
            raise ValueError(f"name must be unique among the geoms, got {name!r}")
        geom = Geom(len(self._geoms), name, link, kind, readonly(padded), readonly(as_vector3("position", position)),
                    readonly(as_quaternion("orientation", orientation)), bits[0], bits[1], int(condim),
                    as_float("friction", friction, nonnegative=True), as_float("margin", margin, nonnegative=True),
                    softness or SoftConstraint(), as_float("solmix", solmix, nonnegative=True))  # fmt: skip
        self._geoms.append(geom)
        self._compiled = None
        return geom.index

    @property
    def geoms(self) -> tuple[Geom, ...]:
        return tuple(self._geoms)

    @property
    def contact_pairs(self) -> np.ndarray:
        """(P, 2) the geoms of every pair that may touch, after the filter (the first geom of a pair the one of the
        lower MuJoCo type: a contact's normal points from it to the other)."""
        return self._compile().views()[0].pair_ints[:, :2].copy()

    def exclude_contacts(self, link_a, link_b) -> None:
        """Let no geom of ``link_a``'s body touch one of ``link_b``'s (``None``: the world): MuJoCo's ``<exclude>``."""
        welds = [_weld(self._links, None if link is None else self._check_link(label, link))
                 for label, link in (("link_a", link_a), ("link_b", link_b))]  # fmt: skip
        self._excluded.add(frozenset(welds))
        self._compiled = None


def _weld(links, link):
    """The rigid body a link belongs to: the link, or for a ``Fixed`` joint its parent's (``None``: the world)."""
    while link is not None and isinstance(links[link].joint, Fixed):
        link = links[link].parent
    return link


def _parent_body(links, carriers, weld):
    """The weld of the nearest ancestor of ``weld`` that carries mass or geoms (``None``: the world)."""
    link = links[weld].parent
    while link is not None and link not in carriers:
        link = links[link].parent
    return _weld(links, link)


def _may_touch(links, carriers, excluded, a: Geom, b: Geom) -> bool:
    weld_a, weld_b = _weld(links, a.link), _weld(links, b.link)
    if weld_a == weld_b or (a.kind == "plane" and b.kind == "plane"):
        return False
    if weld_a is not None and weld_b is not None:
        if weld_a == _parent_body(links, carriers, weld_b) or weld_b == _parent_body(links, carriers, weld_a):
            return False
    if not (a.contype & b.conaffinity or b.contype & a.conaffinity):
        return False
    return frozenset((weld_a, weld_b)) not in excluded


def pack_geoms(geoms):
    """``pack_model``'s ``geoms``."""
    rows = []
    for geom in geoms:
        ints, reals = np.zeros(GEOM_INT_WIDTH, np.int64), np.zeros(GEOM_REAL_WIDTH)
        ints[GEOM_LINK], ints[GEOM_TYPE] = -1 if geom.link is None else geom.link, KINDS[geom.kind]
        reals[GEOM_SIZE : GEOM_SIZE + 2] = geom.size
        reals[GEOM_POS : GEOM_POS + 3], reals[GEOM_QUAT : GEOM_QUAT + 4] = geom.position, geom.orientation
        rows.append((ints, reals))
    return rows


def pack_pairs(links, geoms, excluded):
    """``pack_model``'s ``pairs`` (their weights still zero: :func:`pair_weights`), the lower MuJoCo type first."""
    carriers = {link.index for link in links if link.mass_properties is not None}
    carriers |= {geom.link for geom in geoms if geom.link is not None}
    rows = []
    for i, first in enumerate(geoms):
        for second in geoms[i + 1 :]:
            if not _may_touch(links, carriers, excluded, first, second):
                continue
            a, b = (first, second) if KINDS[first.kind] <= KINDS[second.kind] else (second, first)
            ints, reals = np.zeros(PAIR_INT_WIDTH, np.int64), np.zeros(PAIR_REAL_WIDTH)
            ints[PAIR_A], ints[PAIR_B], ints[PAIR_CONDIM] = a.index, b.index, max(a.condim, b.condim)
            total = a.solmix + b.solmix
            mix = 0.5 if total < 1e-15 else a.solmix / total
            reals[PAIR_FRICTION], reals[PAIR_MARGIN] = max(a.friction, b.friction), a.margin + b.margin
            for column, field in ((PAIR_SOLREF, "solref"), (PAIR_SOLIMP, "solimp")):
                own, other = np.array(getattr(a.softness, field)), np.array(getattr(b.softness, field))
                reals[column : column + own.size] = mix * own + (1.0 - mix) * other
            rows.append((ints, reals))
    return rows


def pair_weights(pair_ints, pair_reals, geoms, translation_weights, impratio: float) -> None:
    """Fill each pair's ``PAIR_WEIGHT`` in place: MuJoCo's ``diagApprox`` of a contact, the two bodies' translational
    ``invweight0`` (``translation_weights[link]``; the world's is 0), times ``2 μ² (1 + μ²) / impratio`` for a
    pyramid's edges (measured against MuJoCo's ``efc_R``)."""
    for ints, reals in zip(pair_ints, pair_reals, strict=True):
        weight = sum(0.0 if geoms[g].link is None else translation_weights[geoms[g].link] for g in ints[:2])
        if ints[PAIR_CONDIM] == 3:
            mu = reals[PAIR_FRICTION]
            weight *= 2.0 * mu * mu * (1.0 + mu * mu) / impratio
        reals[PAIR_WEIGHT] = weight


def translation_weight(jacobian: np.ndarray, inverse: np.ndarray) -> float:
    """MuJoCo's translational ``body_invweight0``: the mean of ``J H⁻¹ Jᵀ``'s diagonal over the three rows of a
    body's centre-of-mass Jacobian (``jacobian`` (6, nv), rows linear then angular; ``inverse``: ``H⁻¹``)."""
    linear = jacobian[:3]
    solved = portable.matmul(inverse, linear.T)
    return math.fsum(math.fsum(linear[i] * solved[:, i]) for i in range(3)) / 3.0
