"""Name resolution and semantic checks: syntax tree → checked :mod:`~mrgc.language.model` objects.

Every check appends a diagnostic and carries on, so one run reports every semantic error of a file.  The
checks and their codes are listed in :mod:`mrgc.language.codes` and docs/errors.md.
"""

from __future__ import annotations

from typing import Any, Iterable, cast

from mrgc.errors import Diagnostic, Span
from mrgc.language import ast
from mrgc.language.model import (
    BUILTIN_GRASPS,
    DEFAULT_GRASP_DEPTH,
    DEFAULT_GRIPPER_OPENING,
    PREDICATE_WORDS,
    PREDICATES,
    REQUIREMENTS,
    Domain,
    Fact,
    FixedObject,
    GraspSpec,
    HandoverPoint,
    MovableObject,
    Problem,
    Region,
    Robot,
    RobotKind,
)
from mrgc.language.props import GEOMETRIC_PROPS, PropReader
from mrgc.language.suggest import by_meaning, did_you_mean

#: sort -> (code for an undeclared name, how the sort is named in messages)
SORTS: dict[str, tuple[str, str]] = {
    "robot": ("E210", "robot"),
    "movable": ("E211", "movable object"),
    "region": ("E212", "region"),
    "grasp": ("E213", "grasp"),
    "kind": ("E214", "robot kind"),
    "handover-point": ("E215", "handover point"),
    "fixed": ("E211", "fixed object"),
    # where a relay sets its object down: a region, or the top of a fixed object
    "surface": ("E212", "region or fixed object"),
}

#: sort a predicate asks for -> the sorts of names it accepts there
ACCEPTS = {"surface": ("region", "fixed")}

#: problem section keyword -> sort of the names it declares
SECTION_SORT = {
    "robots": "robot",
    "fixed": "fixed",
    "regions": "region",
    "movable": "movable",
    "handover-points": "handover-point",
}


def _article(noun: str) -> str:
    return ("an " if noun[0] in "aeiou" else "a ") + noun


class Checker:
    """Checks the definitions of one file; collects diagnostics in ``self.diags``."""

    def __init__(self, file: str) -> None:
        self.file = file
        self.diags: list[Diagnostic] = []
        self.props = PropReader(self.diags, file)
        # names of each sort, for suggestions: built once per name table, not once per misspelt name
        self._sorted_names: dict[str, tuple[dict[str, tuple[str, Span]], frozenset[str]]] = {}
        #: where each fact of ``:init`` is first stated (checks that need the goal point there)
        self._fact_spans: dict[Fact, Span] = {}

    def err(self, code: str, message: str, span: Span) -> None:
        """Record a diagnostic."""
        self.diags.append(Diagnostic(code, message, span))

    def _once(self, sections: Iterable[Any], label: Any) -> dict[str, Any]:
        """Index sections by label, reporting a section given twice (E201); unlabelled ones may repeat."""
        seen: dict[str, Any] = {}
        for sec in sections:
            key = label(sec)
            if key is None:
                continue
            if key in seen:
                self.err("E201", f"section ':{key}' given twice (first at {seen[key].span})", sec.span)
            else:
                seen[key] = sec
        return seen

    # ------------------------------------------------------------ domains
    def domain(self, d: ast.DomainDef) -> Domain:
        """A checked :class:`~mrgc.language.model.Domain` (diagnostics recorded, not raised)."""
        secs = self._once(d.sections, _domain_label)
        reqs = self._requirements(secs["requirements"]) if "requirements" in secs else ()
        kinds: dict[str, RobotKind] = {}
        for sec in d.sections:
            if isinstance(sec, ast.RobotKindDecl):
                kind = self.robot_kind(sec)
                if sec.name in kinds:
                    self.err(
                        "E200", f"robot kind '{sec.name}' declared twice (first at {kinds[sec.name].span})", sec.span
                    )
                else:
                    kinds[sec.name] = kind
        grasps, specs = self._grasps(secs["grasps"], bool(kinds)) if "grasps" in secs else ((), [])
        return Domain(d.name, reqs, tuple(kinds.values()), grasps, self.file, d.span, tuple(specs))

    def _requirements(self, req: ast.Requirements) -> tuple[str, ...]:
        """The known requirement flags, once each (E235 for the others)."""
        for flag, span in zip(req.flags, req.flag_spans or (req.span,) * len(req.flags)):
            if flag not in REQUIREMENTS:
                hint = did_you_mean(flag, REQUIREMENTS) or f" (known: {', '.join(':' + r for r in REQUIREMENTS)})"
                self.err("E235", f"unknown requirement ':{flag}'{hint}", span)
        return tuple(dict.fromkeys(f for f in req.flags if f in REQUIREMENTS))

    def _grasps(self, section: ast.Grasps, has_kinds: bool) -> tuple[tuple[str, ...], list[GraspSpec]]:
        """The declared grasp names (E200 for repeats) and the geometry of those declared with it (E243 for a
        bare name that is not built in, when the domain has robot kinds)."""
        seen: dict[str, Span] = {}
        specs: list[GraspSpec] = []
        for decl in section.decls:
            if decl.name in seen:
                self.err("E200", f"grasp '{decl.name}' declared twice (first at {seen[decl.name]})", decl.span)
                continue
            seen[decl.name] = decl.span
            if not decl.bare:
                spec = self.grasp(decl)
                if spec is not None:
                    specs.append(spec)
            elif has_kinds and decl.name not in BUILTIN_GRASPS:
                hint = did_you_mean(decl.name, BUILTIN_GRASPS) or f" (built in: {' '.join(BUILTIN_GRASPS)})"
                self.err(
                    "E243",
                    f"grasp '{decl.name}' has no geometry: it is not built in and not declared "
                    f"as ({decl.name} :approach AXIS :fingers AXIS){hint}",
                    decl.span,
                )
        return tuple(seen), specs

    def grasp(self, d: ast.Decl) -> GraspSpec | None:
        """The geometry of a declared grasp ``(NAME :approach AXIS :fingers AXIS :depth D :offset (X Y Z))``."""
        what = f"grasp '{d.name}'"
        table = self.props.table("grasp", what, d.props)
        vals = {key: self.props.read("grasp", prop) for key, prop in table.items()}
        for key in ("approach", "fingers"):
            if key not in table:
                self.err("E255", f"{what} needs ':{key}'", d.span)
        approach = cast("tuple[float, float, float] | None", vals.get("approach"))
        fingers = cast("tuple[float, float, float] | None", vals.get("fingers"))
        if (
            approach is None
            or fingers is None
            or ("depth" in table and vals["depth"] is None)
            or ("offset" in table and vals["offset"] is None)
        ):
            return None
        if sum(a * b for a, b in zip(approach, fingers)) != 0:
            span = table["fingers"].span
            self.err(
                "E241",
                f"{what}: the finger axis ({_word(table['fingers'])}) must be perpendicular to the "
                f"approach axis ({_word(table['approach'])})",
                span,
            )
            return None
        return GraspSpec(
            d.name,
            approach,
            fingers,
            vals.get("depth", DEFAULT_GRASP_DEPTH),  # type: ignore[arg-type]
            vals.get("offset", (0.0, 0.0, 0.0)),  # type: ignore[arg-type]
            span=d.span,
        )

    def robot_kind(self, k: ast.RobotKindDecl) -> RobotKind:
        """A checked robot kind: URDF and end effector (fixed base) or footprint (planar base), home, TCP, carry
        pose."""
        what = f"robot kind '{k.name}'"
        table = self.props.table("robot-kind", what, k.props)
        vals = {key: self.props.read("robot-kind", prop) for key, prop in table.items()}
        base = vals.get("base") or "fixed"
        needed = ("urdf", "end-effector") if base == "fixed" else ("footprint",)
        for key in needed:
            if key not in table:
                self.err("E255", f"{what} with a {base} base needs ':{key}'", k.span)
        return RobotKind(
            name=k.name,
            urdf=vals.get("urdf"),  # type: ignore[arg-type]
            base=str(base),
            end_effector=vals.get("end-effector"),  # type: ignore[arg-type]
            home=vals.get("home") or (),  # type: ignore[arg-type]
            footprint=vals.get("footprint"),  # type: ignore[arg-type]
            carry=vals.get("carry"),  # type: ignore[arg-type]
            reach=vals.get("reach"),  # type: ignore[arg-type]
            tcp=vals.get("tcp"),  # type: ignore[arg-type]
            gripper_opening=vals.get("gripper-opening") or DEFAULT_GRIPPER_OPENING,  # type: ignore[arg-type]
            source=self.file,
            span=k.span,
            home_span=table["home"].value.span if "home" in table else k.span,
        )

    # ------------------------------------------------------------ problems
    def problem(self, p: ast.ProblemDef, domain: Domain) -> Problem:
        """A checked :class:`~mrgc.language.model.Problem` of ``domain`` (diagnostics recorded, not raised)."""
        secs = self._once(p.sections, _problem_label)
        decls: dict[str, tuple[ast.Decl, ...]] = {
            kind: secs[kind].decls if kind in secs else () for kind in SECTION_SORT
        }
        sort_of = self._declare(decls)
        geometric = self._classify(decls)
        kinds = {k.name for k in domain.robot_kinds}
        # a geometric problem's objects may also name built-in grasps the vocabulary leaves out
        grasps = set(domain.grasps) | (set(BUILTIN_GRASPS) if geometric else set())

        robots, fixed, regions, movable, points = [], [], [], [], []
        for d in decls["robots"]:
            v = self._decl_values("robots", "robot", d)
            kind = v.get("kind")
            if kind is not None and kind not in kinds:
                span = _prop_span(d, "kind")
                self.err(
                    "E214", f"undeclared robot kind '{kind}' in domain '{domain.name}'{did_you_mean(kind, kinds)}", span
                )
            if geometric and "kind" not in v and not _has(d, "kind"):
                self.err("E260", f"robot '{d.name}' of a geometric problem needs ':kind'", d.span)
            robots.append(Robot(d.name, kind, v.get("base"), d.span))
        for d in decls["fixed"]:
            v = self._decl_values("fixed", "fixed object", d)
            fixed.append(FixedObject(d.name, v.get("shape"), v.get("pose"), d.span))
        for d in decls["regions"]:
            v = self._decl_values("regions", "region", d)
            regions.append(Region(d.name, v.get("shape"), v.get("pose"), d.span))
        point_names = [d.name for d in decls["handover-points"]]
        for d in decls["movable"]:
            v = self._decl_values("movable", "movable object", d)
            own = self._name_list(v.get("grasps"), grasps, "grasp", f"domain '{domain.name}'")
            via = self._name_list(v.get("handover"), set(point_names), "handover-point", "this problem")
            movable.append(
                MovableObject(
                    d.name,
                    v.get("shape"),
                    v.get("pose"),
                    own or domain.grasps,
                    via or tuple(dict.fromkeys(point_names)),
                    d.span,
                )
            )
        for d in decls["handover-points"]:
            v = self._decl_values("handover-points", "handover point", d)
            points.append(HandoverPoint(d.name, v.get("position"), d.span))

        obj_grasps = {m.name: set(m.grasps) for m in movable}
        init = self._facts(secs.get("init"), sort_of, grasps, obj_grasps)
        goal = self._goal(secs.get("goal"), sort_of, p)
        self._initial_regions(init, secs.get("init"), movable, geometric)
        self._relays(init, goal)

        domain_ref = secs.get("domain")
        return Problem(
            name=p.name,
            domain=domain,
            robots=tuple(robots),
            fixed=tuple(fixed),
            regions=tuple(regions),
            movable=tuple(movable),
            handover_points=tuple(points),
            init=tuple(init),
            goal=tuple(goal),
            symbolic=not geometric,
            source=self.file,
            span=domain_ref.span if domain_ref is not None else p.span,
        )

    def _declare(self, decls: dict[str, tuple[ast.Decl, ...]]) -> dict[str, tuple[str, Span]]:
        """One namespace for everything a problem declares: name -> (sort, where declared)."""
        sort_of: dict[str, tuple[str, Span]] = {}
        for kind, items in decls.items():
            for d in items:
                sort = SECTION_SORT[kind]
                if d.name in sort_of:
                    prev_sort, prev_span = sort_of[d.name]
                    self.err(
                        "E200",
                        f"'{d.name}' declared twice (first as {_article(SORTS[prev_sort][1])} at {prev_span})",
                        d.span,
                    )
                else:
                    sort_of[d.name] = (sort, d.span)
        return sort_of

    def _classify(self, decls: dict[str, tuple[ast.Decl, ...]]) -> bool:
        """Geometric iff some movable object has a shape; then report missing geometry, else mixed-in geometry."""
        geometric = any(_has(d, "shape") for d in decls["movable"])
        required = {
            "fixed": ("shape", "pose"),
            "regions": ("shape", "pose"),
            "movable": ("shape", "pose"),
            "robots": ("base",),
            "handover-points": ("position",),
        }
        for kind, items in decls.items():
            noun = SORTS[SECTION_SORT[kind]][1]
            for d in items:
                if geometric:
                    missing = [k for k in required[kind] if not _has(d, k)]
                    if missing:
                        need = " and ".join(":" + k for k in missing)
                        self.err("E262", f"{noun} '{d.name}' of a geometric problem needs {need}", d.span)
                else:
                    for prop in d.props:
                        if prop.key in GEOMETRIC_PROPS:
                            self.err(
                                "E261",
                                f"':{prop.key}' on {noun} '{d.name}' in a symbolic problem "
                                "(give the movable objects shapes to make the problem geometric)",
                                prop.span,
                            )
        return geometric

    def _decl_values(self, kind: str, noun: str, d: ast.Decl) -> dict[str, Any]:
        table = self.props.table(kind, f"{noun} '{d.name}'", d.props)
        return {key: self.props.read(kind, prop) for key, prop in table.items()}

    def _name_list(self, items: Any, known: set[str], sort: str, scope: str) -> tuple[str, ...]:
        if not items:
            return ()
        code, noun = SORTS[sort]
        out = []
        for name, span in items:
            if name not in known:
                self.err(code, f"undeclared {noun} '{name}' in {scope}{did_you_mean(name, known)}", span)
            elif name not in out:
                out.append(name)
        return tuple(out)

    # ------------------------------------------------------------ facts and goals
    def _atom(self, atom: ast.Atom, sort_of: dict[str, tuple[str, Span]], grasps: set[str]) -> Fact | None:
        sig = PREDICATES.get(atom.predicate)
        if sig is None:
            hint = by_meaning(atom.predicate, PREDICATES, PREDICATE_WORDS)
            self.err("E220", f"unknown predicate '{atom.predicate}'{hint}", atom.span)
            return None
        if len(atom.args) != len(sig):
            self.err(
                "E221",
                f"'{atom.predicate}' takes {len(sig)} arguments ({' '.join(sig)}), got {len(atom.args)}",
                atom.span,
            )
            return None
        ok = True
        spans = atom.arg_spans or (atom.span,) * len(atom.args)
        for name, want, span in zip(atom.args, sig, spans):
            ok = self._arg(name, want, span, sort_of, grasps, atom.predicate) and ok
        return Fact(atom.predicate, atom.args) if ok else None

    def _arg(
        self, name: str, want: str, span: Span, sort_of: dict[str, tuple[str, Span]], grasps: set[str], predicate: str
    ) -> bool:
        code, noun = SORTS[want]
        if want == "grasp":
            if name not in grasps:
                self.err(code, f"undeclared grasp '{name}'{did_you_mean(name, grasps)}", span)
                return False
            return True
        accepted = ACCEPTS.get(want, (want,))
        if name not in sort_of:
            cached = self._sorted_names.get(want)
            if cached is None or cached[0] is not sort_of:
                cached = (sort_of, frozenset(n for n, (s, _) in sort_of.items() if s in accepted))
                self._sorted_names[want] = cached
            self.err(code, f"undeclared {noun} '{name}'{did_you_mean(name, cached[1])}", span)
            return False
        have = sort_of[name][0]
        if have not in accepted:
            self.err(
                "E216", f"'{name}' is {_article(SORTS[have][1])}, but '{predicate}' expects {_article(noun)} here", span
            )
            return False
        return True

    def _facts(
        self,
        init: ast.Init | None,
        sort_of: dict[str, tuple[str, Span]],
        grasps: set[str],
        obj_grasps: dict[str, set[str]],
    ) -> list[Fact]:
        self._fact_spans = {}
        if init is None:
            return []
        facts: dict[Fact, None] = {}
        for atom in init.atoms:
            fact = self._atom(atom, sort_of, grasps)
            if fact is None:
                continue
            same, note = _self_referential(fact)
            if same:
                self.err("E229", f"'{fact.predicate}' relates {same} to itself{note}", atom.span)
                continue
            for obj, grasp in _grasp_uses(fact):
                if grasp not in obj_grasps.get(obj, {grasp}):
                    self.err(
                        "E227",
                        f"grasp '{grasp}' is not among the grasps of '{obj}' ({' '.join(sorted(obj_grasps[obj]))})",
                        atom.span,
                    )
            facts[fact] = None
            self._fact_spans.setdefault(fact, atom.span)
        return list(facts)

    def _goal(self, goal: ast.Goal | None, sort_of: dict[str, tuple[str, Span]], p: ast.ProblemDef) -> list[Fact]:
        if goal is None:
            self.err("E226", f"problem '{p.name}' has no (:goal ...)", p.span)
            return []
        if not goal.atoms:
            self.err("E225", "the goal is empty", goal.span)
            return []
        out: dict[str, tuple[Fact, Span]] = {}
        for atom in goal.atoms:
            if atom.predicate != "in-region":
                self.err("E223", f"goals are (in-region object region) literals, not '{atom.predicate}'", atom.span)
                continue
            if len(atom.args) == 2 and sort_of.get(atom.args[0], ("",))[0] == "fixed":
                spans = atom.arg_spans or (atom.span,)
                self.err("E222", f"'{atom.args[0]}' is a fixed object and can never be moved to a goal", spans[0])
                continue
            fact = self._atom(atom, sort_of, set())
            if fact is None:
                continue
            obj, region = fact.args
            if obj in out and out[obj][0] != fact:
                self.err(
                    "E224",
                    f"'{obj}' cannot be in both '{out[obj][0].args[1]}' and '{region}' (first goal at {out[obj][1]})",
                    atom.span,
                )
                continue
            out.setdefault(obj, (fact, atom.span))
        return [f for f, _ in out.values()]

    def _initial_regions(
        self, init: list[Fact], init_sec: ast.Init | None, movable: list[MovableObject], geometric: bool
    ) -> None:
        where: dict[str, list[str]] = {}
        attempted = {a.args[0] for a in (init_sec.atoms if init_sec else ()) if a.predicate == "in-region" and a.args}
        for f in init:
            if f.predicate == "in-region":
                where.setdefault(f.args[0], []).append(f.args[1])
        for m in movable:
            regions = where.get(m.name, [])
            if len(regions) > 1:
                span = init_sec.span if init_sec is not None else m.span
                self.err("E228", f"'{m.name}' is initially in several regions ({', '.join(regions)})", span)
            elif not regions and not geometric and m.name not in attempted:
                self.err("E228", f"'{m.name}' has no initial region: add (in-region {m.name} REGION) to :init", m.span)

    def _relays(self, init: list[Fact], goal: list[Fact]) -> None:
        """A relay sets its object down on the way, never in its goal region (E217)."""
        goal_of = {f.args[0]: f.args[1] for f in goal}
        for f in init:
            if f.predicate == "enable-relay" and goal_of.get(f.args[0]) == f.args[1]:
                self.err(
                    "E217",
                    f"'enable-relay' sets '{f.args[0]}' down in its goal region '{f.args[1]}': a relay is a "
                    "stop on the way to the goal, in another region",
                    self._fact_spans[f],
                )


def _self_referential(fact: Fact) -> tuple[str, str]:
    """What a fact wrongly relates to itself ("" if nothing), and a note: an object occluding itself, a
    handover to the same robot, a relay to the same robot with the same grasp."""
    a = fact.args
    if (
        fact.predicate in ("occludes-pick", "occludes-goal-place", "occludes-handover", "occludes-relay")
        and a[0] == a[1]
    ):
        return f"object '{a[0]}'", ""
    if fact.predicate == "enable-goal-handover" and a[3] == a[4]:
        return f"robot '{a[3]}'", ""
    if fact.predicate == "occludes-handover" and a[4] == a[5]:
        return f"robot '{a[4]}'", ""
    if fact.predicate == "enable-relay" and a[4] == a[5] and a[2] == a[3]:
        return f"robot '{a[4]}' with grasp '{a[2]}'", ": a relay back to the same robot must change the grasp"
    if fact.predicate == "occludes-relay" and a[5] == a[6] and a[3] == a[4]:
        return f"robot '{a[5]}' with grasp '{a[3]}'", ": a relay back to the same robot must change the grasp"
    return "", ""


def _grasp_uses(fact: Fact) -> list[tuple[str, str]]:
    """(object, grasp) pairs a fact asserts something about."""
    a = fact.args
    if fact.predicate == "reachable-pick":
        return [(a[0], a[1])]
    if fact.predicate == "reachable-place":
        return [(a[0], a[2])]
    if fact.predicate == "occludes-pick":
        return [(a[1], a[2])]
    if fact.predicate == "occludes-goal-place":
        return [(a[1], a[3])]
    if fact.predicate == "enable-goal-handover":
        return [(a[0], a[1]), (a[0], a[2])]
    if fact.predicate == "enable-relay":
        return [(a[0], a[2]), (a[0], a[3])]
    if fact.predicate == "occludes-relay":
        return [(a[1], a[3]), (a[1], a[4])]
    if fact.predicate == "occludes-handover":
        return [(a[1], a[2]), (a[1], a[3])]
    return []


def _word(prop: ast.Property) -> str:
    return prop.value.name if isinstance(prop.value, ast.Symbol) else "?"


def _has(d: ast.Decl, key: str) -> bool:
    return any(p.key == key for p in d.props)


def _prop_span(d: ast.Decl, key: str) -> Span:
    return next((p.value.span for p in d.props if p.key == key), d.span)


def _domain_label(sec: Any) -> str | None:
    """Label of a domain section that may appear once; None for repeatable ones (kinds, includes)."""
    if isinstance(sec, ast.Requirements):
        return "requirements"
    if isinstance(sec, ast.Grasps):
        return "grasps"
    return None


def _problem_label(sec: Any) -> str | None:
    """Label of a problem section that may appear once; None for includes."""
    if isinstance(sec, ast.DomainRef):
        return "domain"
    if isinstance(sec, ast.DeclSection):
        return sec.kind
    if isinstance(sec, ast.Init):
        return "init"
    if isinstance(sec, ast.Goal):
        return "goal"
    return None
