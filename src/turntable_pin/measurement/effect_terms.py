"""Terms of effects the user writes: one place of the chain varying in one simple way.

A term says *where* an angle is added and *how* it varies from position to position
(``docs/measurements.md``, section 4b):

- the site: a base error of the table (``dphi_z2``, ``<joint>.position``, ...), a rotation
  before or after the chain (``pre.x`` .. ``post.z``) or a measured angle itself (``dpsi``,
  ``dtheta``, ``dgamma``);
- the shape: harmonics of some orders of a joint angle (``phiK``) or of the sum or difference of
  two (``phi1+phi2``, ``phi1-phi2``); a polynomial of degree d (no constant: the base absorbs it) in
  a numeric data column (``time_s``, ``temperature_c``, ...); or the sign of an approach direction
  ``dirK``.

The inline form of a term is ``SITE~SHAPE(VARIABLE)``: ``dphi_z2~h3(phi2)`` (order 3),
``dphi_z2~h1..2(phi2)`` (orders 1 to 2), ``dpsi~poly1(temperature_c)``, ``dphi_y1~sign(dir1)``.
It contains no comma, so a comma-separated ``effects`` list can hold it. Parameters: ``cK, sK``
(arcsec) of a harmonic of order K, ``pK`` (arcsec per unit of the column to the power K) of a
polynomial, ``b`` (arcsec) of a sign term; each may carry the term's ``prefix``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from ..core.exceptions import InputError
from ..model.angles import ANGLE_NAMES
from .effects.base import ARCSEC, MEASURED, ChainTerm, ParameterSpec, PositionVariables

__all__ = [
    "MAX_HARMONIC_ORDER",
    "MAX_POLYNOMIAL_DEGREE",
    "SHAPES",
    "EffectTerm",
    "parse_orders",
    "parse_term",
]

SHAPES = ("harmonics", "polynomial", "sign")
"""The ways a term can vary with the position."""
MAX_HARMONIC_ORDER = 100
"""Highest harmonic order a term may have."""
MAX_POLYNOMIAL_DEGREE = 5
"""Highest degree of a polynomial term."""

_INLINE = re.compile(r"^(?P<site>[^~\s]+)~(?P<kind>h|poly|sign)(?P<orders>[0-9.]*)"
                     r"\((?P<variable>[^()\s]+)\)$")  # fmt: skip
_JOINT = re.compile(r"^phi([1-9][0-9]*)$")
_PAIR = re.compile(r"^phi([1-9][0-9]*)([+-])phi([1-9][0-9]*)$")
_DIR = re.compile(r"^dir([1-9][0-9]*)$")
_COLUMN = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
INLINE_HELP = (
    "SITE~hK(VAR), SITE~hA..B(VAR), SITE~polyD(COLUMN) or SITE~sign(dirK), e.g. "
    "dphi_z2~h3(phi2), dpsi~poly1(temperature_c), dphi_y1~sign(dir1)"
)


@dataclass(frozen=True)
class EffectTerm:
    """One term: ``site`` varies as ``shape`` of ``variable``.

    Attributes:
        site: a base error name, ``pre.x`` .. ``post.z``, or ``dpsi`` / ``dtheta`` / ``dgamma``.
        shape: one of :data:`SHAPES`.
        variable: ``phiK``, ``phiA+phiB``, ``phiA-phiB`` (harmonics), a column (polynomial),
            ``dirK`` (sign).
        orders: harmonic orders, or the powers 1..d of a polynomial; empty for a sign.
        prefix: put before each parameter name (to keep the names of several terms apart).
    """

    site: str
    shape: str
    variable: str
    orders: tuple[int, ...] = ()
    prefix: str = ""

    def spec(self) -> str:
        """The inline form (``dphi_z2~h1..2(phi2)``); :func:`parse_term` reads it back."""
        if self.shape == "sign":
            return f"{self.site}~sign({self.variable})"
        if self.shape == "polynomial":
            return f"{self.site}~poly{max(self.orders)}({self.variable})"
        lo, hi = min(self.orders), max(self.orders)
        if list(self.orders) != list(range(lo, hi + 1)):
            raise InputError(f"harmonic orders {list(self.orders)} have no inline form")
        orders = str(lo) if lo == hi else f"{lo}..{hi}"
        return f"{self.site}~h{orders}({self.variable})"

    def required_columns(self) -> tuple[str, ...]:
        """The data columns the term needs (``time_s``, ``dirK``, an extra column)."""
        return () if self.shape == "harmonics" else (self.variable,)

    def parameters(self) -> tuple[ParameterSpec, ...]:
        """The term's parameters, in user units (see the module docstring)."""
        p, v = self.prefix, self.variable
        what = self.site
        if self.shape == "sign":
            return (ParameterSpec(f"{p}b", "arcsec", ARCSEC, f"{what}: coefficient of {v} "
                                  "(+1/-1)"),)  # fmt: skip
        if self.shape == "polynomial":
            return tuple(
                ParameterSpec(f"{p}p{k}", f"arcsec/{v}" + (f"^{k}" if k > 1 else ""), ARCSEC,
                              f"{what}: coefficient of {v}" + (f"^{k}" if k > 1 else ""))
                for k in self.orders
            )  # fmt: skip
        out = []
        for k in self.orders:
            times = "" if k == 1 else f"{k} "
            for name, fn in ((f"{p}c{k}", "cos"), (f"{p}s{k}", "sin")):
                text = f"{what}: {fn}({times}{v}) coefficient"
                out.append(ParameterSpec(name, "arcsec", ARCSEC, text))
        return tuple(out)

    def definition(self) -> str:
        """How the term changes the chain, in words of ``docs/measurements.md``."""
        names = [s.name for s in self.parameters()]
        v = self.variable
        if self.shape == "sign":
            change = f"{names[0]} {v}"
        elif self.shape == "polynomial":
            change = " + ".join(
                f"{n} {v}" + (f"^{k}" if k > 1 else "")
                for n, k in zip(names, self.orders, strict=True)
            )
        else:
            change = " + ".join(
                f"{c} cos({'' if k == 1 else f'{k} '}{v}) + {s} sin({'' if k == 1 else f'{k} '}{v})"
                for c, s, k in zip(names[::2], names[1::2], self.orders, strict=True)
            )
        where, dot, axis = self.site.partition(".")
        if dot and where == "pre":
            return f"Rt -> R{axis}({change}) Rt"
        if dot and where == "post":
            return f"Rt -> Rt R{axis}({change})"
        return f"{self.site} += {change}"

    def _values(self, variables: PositionVariables) -> np.ndarray:
        v = self.variable
        pair = _PAIR.match(v)
        if pair:
            a, b = variables.angle(int(pair[1])), variables.angle(int(pair[3]))
            return a + b if pair[2] == "+" else a - b
        values = variables.column(v)
        if values is None:
            raise InputError(
                f"term '{self.spec()}' needs the column {variables.missing_columns_words([v])}"
            )
        return np.asarray(values, dtype=float)

    def chain_term(self, variables: PositionVariables) -> ChainTerm:
        """The :class:`ChainTerm` of this term at the positions of ``variables``."""
        x = self._values(variables)
        names = [s.name for s in self.parameters()]
        if self.shape == "sign":
            weights = {names[0]: x}
        elif self.shape == "polynomial":
            weights = {n: x**k for n, k in zip(names, self.orders, strict=True)}
        else:
            weights = {}
            for c, s, k in zip(names[::2], names[1::2], self.orders, strict=True):
                weights[c], weights[s] = np.cos(k * x), np.sin(k * x)
        where, dot, axis = self.site.partition(".")
        if dot and where in ("pre", "post") and axis in ("x", "y", "z"):
            return ChainTerm(where, axis, weights)
        if self.site in ANGLE_NAMES:
            return ChainTerm(MEASURED, self.site, weights)
        return ChainTerm(self.site, None, weights)

    def check(self, table) -> EffectTerm:
        """``self`` if its site and variable make sense on ``table`` (a ``MeasuredTable``)."""
        sites = (*table.base_names, *(f"{w}.{a}" for w in ("pre", "post") for a in "xyz"),
                 *ANGLE_NAMES)  # fmt: skip
        if self.site not in sites:
            raise InputError(f"unknown site '{self.site}'; sites of this table: {', '.join(sites)}")
        if self.shape not in SHAPES:
            raise InputError(f"unknown shape '{self.shape}'; shapes: {', '.join(SHAPES)}")
        getattr(self, f"_check_{self.shape}")(self.variable, table.n_joints)
        if self.prefix and not _COLUMN.match(self.prefix):
            raise InputError(f"prefix '{self.prefix}': use letters, digits and '_' (e.g. x_)")
        return self

    def _check_harmonics(self, v: str, n: int) -> None:
        """Harmonics of one of the ``n`` joint angles or of the sum or difference of two."""
        joint = [int(j) for j in re.findall(r"phi([0-9]+)", v)]
        if not (_JOINT.match(v) or _PAIR.match(v)) or any(j > n for j in joint):
            angles = ", ".join(f"phi{k}" for k in range(1, n + 1))
            raise InputError(
                f"harmonics of '{v}': expected a joint angle ({angles}) or the sum or "
                f"difference of two (phi1+phi2, phi1-phi2)"
            )
        if _PAIR.match(v) and joint[0] == joint[1]:
            raise InputError(f"harmonics of '{v}': the two angles must differ")
        bad = [k for k in self.orders if not 1 <= k <= MAX_HARMONIC_ORDER]
        if not self.orders or bad or len(set(self.orders)) != len(self.orders):
            raise InputError(
                f"harmonic orders {list(self.orders)}: give distinct whole numbers 1.."
                f"{MAX_HARMONIC_ORDER}"
            )

    def _check_polynomial(self, v: str, n: int) -> None:
        """A polynomial of a numeric data column (not a joint angle or a direction)."""
        if not _COLUMN.match(v) or _JOINT.match(v) or _DIR.match(v):
            raise InputError(
                f"polynomial in '{v}': expected a numeric column of the data file (time_s, "
                "temperature_c, ...); use harmonics for a joint angle, sign for dirK"
            )
        d = max(self.orders, default=0)
        if not 1 <= d <= MAX_POLYNOMIAL_DEGREE:
            raise InputError(f"polynomial degree {d}: expected 1..{MAX_POLYNOMIAL_DEGREE}")

    def _check_sign(self, v: str, n: int) -> None:
        """The sign of one of the ``n`` joints' approach directions."""
        match = _DIR.match(v)
        if not match or int(match[1]) > n:
            dirs = ", ".join(f"dir{k}" for k in range(1, n + 1))
            raise InputError(f"sign of '{v}': expected an approach direction ({dirs})")


def parse_orders(text: str, what: str) -> tuple[int, ...]:
    """The orders of ``K`` or ``A..B`` (``what`` names them in the messages)."""
    lo, dots, hi = text.partition("..")
    try:
        first = int(lo)
        last = int(hi) if dots else first
    except ValueError:
        raise InputError(f"{what}: expected an order K or a range A..B, got '{text}'") from None
    if last < first:
        raise InputError(f"{what}: the range {text} is empty")
    if last - first >= MAX_HARMONIC_ORDER:
        raise InputError(f"{what}: at most {MAX_HARMONIC_ORDER} orders")
    return tuple(range(first, last + 1))


def parse_term(text: str, table) -> EffectTerm:
    """The inline term ``text`` (module docstring), checked against ``table``.

    Raises:
        InputError: not of the inline form, or a site, variable or order the table refuses.
    """
    text = str(text).strip()
    match = _INLINE.match(text)
    if not match:
        raise InputError(f"term '{text}': expected {INLINE_HELP}")
    kind, orders = match["kind"], match["orders"]
    try:
        if kind == "sign":
            if orders:
                raise InputError("sign takes no order: write SITE~sign(dirK)")
            term = EffectTerm(match["site"], "sign", match["variable"])
        elif kind == "poly":
            if not orders.isdigit():
                raise InputError("give the degree: SITE~polyD(COLUMN), e.g. poly1 or poly2")
            term = EffectTerm(match["site"], "polynomial", match["variable"],
                              tuple(range(1, int(orders) + 1)))  # fmt: skip
        else:
            if not orders:
                raise InputError("give the order: SITE~hK(VAR) or SITE~hA..B(VAR)")
            term = EffectTerm(match["site"], "harmonics", match["variable"],
                              parse_orders(orders, "harmonic orders"))  # fmt: skip
        return term.check(table)
    except InputError as exc:
        raise InputError(f"term '{text}': {exc.detail}") from None
