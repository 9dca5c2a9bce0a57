"""The syntax tree of a ``.mrg`` file: frozen dataclasses, one per grammar rule, each with its source span.

This is the *unchecked* tree: declarations keep their ``:key value`` properties as written, and predicate
atoms keep their names as written.  :mod:`mrgc.language.check` turns it into the typed, checked
:mod:`mrgc.language.model`.  Spans never take part in equality, so ``parse(print(tree)) == tree``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Union

from mrgc.errors import Span

NOWHERE = Span("<generated>", 1, 1, 1, 2)


def _span() -> Span:
    return field(default=NOWHERE, compare=False, repr=False)


# ---------------------------------------------------------------- values
@dataclass(frozen=True)
class Number:
    """A real number as written (SI units: metres; angles in degrees)."""

    value: float
    span: Span = _span()


@dataclass(frozen=True)
class Symbol:
    """A bare name used as a value, e.g. ``:kind panda`` or ``:base fixed``, or a signed axis word (``-z``)."""

    name: str
    span: Span = _span()


@dataclass(frozen=True)
class String:
    """A double-quoted string (paths): ``value`` is the unescaped text."""

    value: str
    span: Span = _span()


@dataclass(frozen=True)
class ListValue:
    """A parenthesised list: a vector ``(0 0 1)``, a name list ``(top side)``, a shape ``(box 1 2 3)``."""

    items: tuple[Number | Symbol | String, ...]
    span: Span = _span()


Value = Union[Number, Symbol, String, ListValue]


@dataclass(frozen=True)
class Property:
    """``:key value`` inside a declaration; ``key`` is written without its colon."""

    key: str
    value: Value
    span: Span = _span()


@dataclass(frozen=True)
class Decl:
    """A declared thing: a bare name (``r1``) or a name with properties (``(r1 :kind panda ...)``)."""

    name: str
    props: tuple[Property, ...] = ()
    bare: bool = True
    span: Span = _span()


# ---------------------------------------------------------------- domain sections
@dataclass(frozen=True)
class Requirements:
    """``(:requirements :handover ...)``; flags written without their colon."""

    flags: tuple[str, ...]
    flag_spans: tuple[Span, ...] = field(default=(), compare=False, repr=False)
    span: Span = _span()


@dataclass(frozen=True)
class RobotKindDecl:
    """``(:robot-kind NAME :urdf ... :base ... ...)``: a kind of robot problems instantiate."""

    name: str
    props: tuple[Property, ...]
    span: Span = _span()


@dataclass(frozen=True)
class Grasps:
    """``(:grasps top (top-x :approach -z :fingers x) ...)``: the domain's grasp vocabulary.

    A bare name (``top``) is a built-in grasp (or, in a domain without robot kinds, just a name); a
    declaration (``(NAME :approach AXIS :fingers AXIS ...)``) gives a grasp its geometry.
    """

    decls: tuple[Decl, ...]
    span: Span = _span()

    @property
    def names(self) -> tuple[str, ...]:
        """The declared names, in order."""
        return tuple(d.name for d in self.decls)


@dataclass(frozen=True)
class Include:
    """``(:include "path")``: bring the domains of another file into scope."""

    path: str
    span: Span = _span()


DomainSection = Union[Requirements, RobotKindDecl, Grasps, Include]


# ---------------------------------------------------------------- problem sections
@dataclass(frozen=True)
class DomainRef:
    """``(:domain NAME)``: the domain a problem is posed in."""

    name: str
    span: Span = _span()


@dataclass(frozen=True)
class DeclSection:
    """``(:robots ...)``, ``(:fixed ...)``, ``(:regions ...)``, ``(:movable ...)`` or ``(:handover-points ...)``.

    ``kind`` is the section keyword without its colon.
    """

    kind: str
    decls: tuple[Decl, ...]
    span: Span = _span()


@dataclass(frozen=True)
class Atom:
    """A predicate literal ``(name arg ...)``; ``arg_spans`` locates each argument."""

    predicate: str
    args: tuple[str, ...]
    arg_spans: tuple[Span, ...] = field(default=(), compare=False, repr=False)
    span: Span = _span()


@dataclass(frozen=True)
class Init:
    """``(:init atom ...)``: the geometric facts that hold initially."""

    atoms: tuple[Atom, ...]
    span: Span = _span()


@dataclass(frozen=True)
class Goal:
    """``(:goal atom)`` or ``(:goal (and atom ...))``; ``conjunction`` records which form was written."""

    atoms: tuple[Atom, ...]
    conjunction: bool = True
    span: Span = _span()


ProblemSection = Union[DomainRef, DeclSection, Init, Goal, Include]


# ---------------------------------------------------------------- definitions
@dataclass(frozen=True)
class DomainDef:
    """``(define (domain NAME) section ...)``."""

    name: str
    sections: tuple[DomainSection, ...]
    span: Span = _span()


@dataclass(frozen=True)
class ProblemDef:
    """``(define (problem NAME) section ...)``."""

    name: str
    sections: tuple[ProblemSection, ...]
    span: Span = _span()


@dataclass(frozen=True)
class SourceFile:
    """A whole ``.mrg`` file: its definitions in order."""

    definitions: tuple[DomainDef | ProblemDef, ...]
    path: str = field(default="<string>", compare=False)
