"""Reading a study file (:func:`load_study`, :func:`parse_study`) and the checks of its schema
(:mod:`mrgc.bench.study` documents it and defines what a checked study is), on the composed YAML tree so
that every error is located at ``file:line:col`` (code E601), all of them reported at once.

Also the readers of the schema's small value languages: seed ranges (``"0..19"``) and memory sizes
(``"4GB"``).
"""

from __future__ import annotations

import os
import re
from dataclasses import replace
from typing import Any

from mrgc.bench.study import E_STUDY_READ, E_STUDY_SCHEMA, FACTS_CACHE, InstanceSpec, Limits, Method, Study
from mrgc.errors import Diagnostic, InputError, Span
from mrgc.language.files import FileTooLarge, read_regular

_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.+-]*$")
_RANGE = re.compile(r"^\s*(\d+)\s*\.\.\s*(\d+)\s*$")
_SIZE = re.compile(r"^\s*(\d+(?:\.\d+)?)\s*([KMGT]i?B?|)\s*$", re.IGNORECASE)
_UNITS = {"": 1.0, "k": 1 / 1024, "m": 1.0, "g": 1024.0, "t": 1024.0**2}
_MAX_BYTES = 1 << 20

STUDY_KEYS = ("study", "description", "seeds", "limits", "facts_cache", "instances", "methods")
LIMIT_KEYS = ("time", "wall", "memory")
METHOD_KEYS = ("name", "planner", "compile", "backend", "encoding", "options", "limits", "only")
FILE_KEYS = ("file", "name", "problem")
GLOB_KEYS = ("glob", "name", "problem")
GENERATE_KEYS = ("generate", "name", "seeds")  # plus the generator's own options


#: the largest seed: mrgc plan's and compile's (``mrgc.limits.BOUNDS``: CP-SAT's seed is a 32-bit integer)
MAX_SEED = 2**31 - 1


def parse_seeds(value: Any) -> tuple[int, ...] | None:
    """``3`` → (3,); ``"0..19"`` → (0, ..., 19); a list of those → their concatenation; None if malformed."""
    if isinstance(value, bool):
        return None
    if isinstance(value, int):
        return (value,) if 0 <= value <= MAX_SEED else None
    if isinstance(value, str):
        m = _RANGE.match(value)
        if not m or int(m.group(1)) > int(m.group(2)) or int(m.group(2)) > MAX_SEED:
            return None
        return tuple(range(int(m.group(1)), int(m.group(2)) + 1))
    if isinstance(value, list) and value:
        out: list[int] = []
        for v in value:
            part = parse_seeds(v) if not isinstance(v, list) else None
            if part is None:
                return None
            out += part
        return tuple(out)
    return None


def parse_megabytes(value: Any) -> float | None:
    """A memory size: a number of MiB, or ``"512MB"``, ``"4GB"``, ``"4 GiB"`` (binary units); None if malformed."""
    if isinstance(value, bool):
        return None
    if isinstance(value, (int, float)):
        return float(value) if value > 0 else None
    if isinstance(value, str):
        m = _SIZE.match(value)
        if m:
            mb = float(m.group(1)) * _UNITS[m.group(2)[:1].lower()]
            return mb if mb > 0 else None
    return None


def load_study(path: str | os.PathLike[str]) -> Study:
    """Read and check a study file; :class:`~mrgc.errors.InputError` lists every problem found (E600/E601)."""
    path = os.fspath(path)
    try:
        data = read_regular(path, _MAX_BYTES)  # non-blocking open: a FIFO is refused, not waited on
    except FileTooLarge:
        raise InputError([Diagnostic(E_STUDY_READ, f"study '{path}' is larger than {_MAX_BYTES} bytes")]) from None
    except OSError as exc:
        raise InputError([Diagnostic(E_STUDY_READ, f"cannot read study '{path}': {exc.strerror or exc}")]) from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError([Diagnostic(E_STUDY_READ, f"study '{path}' is not UTF-8 text (byte {exc.start})")]) from None
    return parse_study(text, path, files=True)


def parse_study(text: str, path: str = "<study>", files: bool = False) -> Study:
    """Check the text of a study file named ``path`` (relative paths in it resolve against its folder);
    ``files``: also that every ``file:`` exists and every ``glob:`` matches a problem file (E602), as
    :func:`load_study` asks, so that a study's every error is reported at once."""
    import yaml

    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        span = Span(path, mark.line + 1, mark.column + 1, mark.line + 1, mark.column + 2) if mark else None
        raise InputError(
            [Diagnostic(E_STUDY_READ, f"study is not YAML: {exc.problem or exc}", span)], {path: text}
        ) from None
    except yaml.YAMLError as exc:
        raise InputError([Diagnostic(E_STUDY_READ, f"study is not YAML: {exc}")], {path: text}) from None
    reader = Reader(path, files)
    study = reader.study(root)
    if reader.diags or study is None:
        diags = reader.diags or [Diagnostic(E_STUDY_SCHEMA, "the study is empty", Span(path, 1, 1, 1, 2))]
        raise InputError(diags, {path: text})
    return replace(study, text=text)


class Reader:
    """Walks the composed YAML tree, collecting a located diagnostic per problem."""

    def __init__(self, path: str, files: bool = False) -> None:
        self.path = path
        self.files = files  # also look for the instance files and globs (a study read from its file)
        self.diags: list[Diagnostic] = []
        self.set_names: list[str] = []

    def span(self, node: Any) -> Span:
        """The node's place in the study file."""
        s, e = node.start_mark, node.end_mark
        return Span(self.path, s.line + 1, s.column + 1, e.line + 1, e.column + 1)

    def error(self, node: Any, message: str) -> None:
        """Record a problem located at ``node``."""
        self.diags.append(Diagnostic(E_STUDY_SCHEMA, message, self.span(node)))

    def value(self, node: Any) -> Any:
        """The node's plain-data value (None, with an error, for anything a safe loader refuses)."""
        from yaml.constructor import ConstructorError, SafeConstructor

        try:
            return SafeConstructor().construct_object(node, deep=True)
        except ConstructorError as exc:
            self.error(node, f"not plain data: {exc.problem}")
            return None

    def mapping(self, node: Any, what: str, keys: tuple[str, ...] | None) -> dict[str, tuple[Any, Any]] | None:
        """key -> (key node, value node), after checking the node is a mapping of known, unique keys."""
        import yaml

        if not isinstance(node, yaml.MappingNode):
            self.error(node, f"{what} must be a mapping (key: value)")
            return None
        out: dict[str, tuple[Any, Any]] = {}
        for k, v in node.value:
            key = k.value if isinstance(k, yaml.ScalarNode) else None
            if not isinstance(key, str):
                self.error(k, f"{what}: keys must be names")
                continue
            if key in out:
                self.error(k, f"{what}: duplicate key '{key}'")
                continue
            if keys is not None and key not in keys:
                from mrgc.language.suggest import did_you_mean

                self.error(k, f"{what}: unknown key '{key}'{did_you_mean(key, keys)} (known: {', '.join(keys)})")
                continue
            out[key] = (k, v)
        return out

    def scalar(self, node: Any, what: str, types: tuple[type, ...]) -> Any:
        """The node's value if it is of one of ``types`` (a bool counts only where bool is listed)."""
        value = self.value(node)
        if value is None or not isinstance(value, types) or (isinstance(value, bool) and bool not in types):
            want = (
                "true or false"
                if types == (bool,)
                else "a number"
                if float in types
                else "a name"
                if str in types and int in types
                else "text"
            )
            self.error(node, f"{what} must be {want}")
            return None
        return value

    def name(self, node: Any, what: str) -> str | None:
        """A name (letters, digits, ``_ . + -``), or None with an error."""
        value = self.scalar(node, what, (str, int))
        if value is None:
            return None
        value = str(value)
        if not _NAME.match(value):
            self.error(node, f"{what} '{value}' is not a name (letters, digits, _ . + -; a letter or digit first)")
            return None
        return value

    def seeds(self, node: Any, what: str) -> tuple[int, ...] | None:
        """A list of distinct seeds (:func:`parse_seeds`), or None with an error."""
        seeds = parse_seeds(self.value(node))
        if seeds is None:
            self.error(node, f"{what} must be a seed (0 to {MAX_SEED:,}), a range 'a..b' (a <= b) or a list of those")
        elif len(set(seeds)) != len(seeds):
            self.error(node, f"{what} repeat a seed")
            return None
        return seeds

    def study(self, root: Any) -> Study | None:
        """The study of the document ``root``; None when it is empty or has an error."""
        if root is None:
            return None
        top = self.mapping(root, "the study", STUDY_KEYS)
        if top is None:
            return None
        for key in ("study", "instances", "methods"):
            if key not in top:
                self.diags.append(Diagnostic(E_STUDY_SCHEMA, f"the study lacks '{key}'", self.span(root)))
        name = self.name(top["study"][1], "study") if "study" in top else None
        description = self.scalar(top["description"][1], "description", (str,)) if "description" in top else ""
        seeds = self.seeds(top["seeds"][1], "seeds") if "seeds" in top else (0,)
        limits = self.limits(top["limits"][1], Limits()) if "limits" in top else Limits()
        facts_cache = self.facts_cache(top["facts_cache"][1]) if "facts_cache" in top else "own"
        instances = self.instances(top["instances"][1]) if "instances" in top else []
        self.set_names = [i.name for i in instances]
        methods = self.methods(top["methods"][1], limits or Limits()) if "methods" in top else []
        self.later(instances, methods)  # with the rest: every error of a study at once
        if name is None or seeds is None or limits is None or self.diags:
            return None
        return Study(
            name, self.path, "", tuple(instances), tuple(methods), seeds, limits, description or "", facts_cache
        )

    def later(self, instances: list[InstanceSpec], methods: list[Method]) -> None:
        """The errors of what parsed that the run would find before its first run: an instance file that
        does not exist or a glob that matches none (E602), a method's unknown backend, encoding or option
        and a bad option value (E601): found here, they come with the rest, not in later rounds."""
        from mrgc.bench.instances import instance_files
        from mrgc.bench.methods import check_methods

        folder = os.path.dirname(os.path.abspath(self.path))
        for spec in instances if self.files else ():
            if spec.kind != "generate":
                try:
                    instance_files(spec, folder)
                except InputError as exc:
                    self.diags += exc.diagnostics
        partial = Study("study", self.path, "", tuple(instances), tuple(methods), (0,), Limits())
        self.diags += check_methods(partial)[0]

    def facts_cache(self, node: Any) -> str:
        """The study's ``facts_cache`` (a key of :data:`~mrgc.bench.study.FACTS_CACHE`), "own" with an error
        when it is another value."""
        value = self.value(node)
        if value not in FACTS_CACHE:
            self.error(node, f"facts_cache must be one of {', '.join(FACTS_CACHE)}")
            return "own"
        return str(value)

    def limits(self, node: Any, base: Limits) -> Limits | None:
        """``base`` with the limits the node gives; None when it is not a mapping."""
        m = self.mapping(node, "limits", LIMIT_KEYS)
        if m is None:
            return None
        out = base
        for key in ("time", "wall"):
            if key in m:
                t = self.scalar(m[key][1], f"limits: {key} (seconds)", (int, float))
                if t is not None and not 0 < t < float("inf"):
                    self.error(m[key][1], f"limits: {key} must be positive and finite (seconds)")
                elif t is not None:
                    out = replace(out, **{key: float(t)})
        if "memory" in m:
            mb = parse_megabytes(self.value(m["memory"][1]))
            if mb is None:
                self.error(m["memory"][1], "limits: memory must be a size such as 4GB, 512MB or a number of MiB")
            else:
                out = replace(out, memory_mb=mb)
        return out

    def sequence(self, node: Any, what: str) -> list[Any]:
        """The items of a non-empty list node (none, with an error, for anything else)."""
        import yaml

        if not isinstance(node, yaml.SequenceNode) or not node.value:
            self.error(node, f"{what} must be a non-empty list")
            return []
        return list(node.value)

    def instances(self, node: Any) -> list[InstanceSpec]:
        """The entries of ``instances``, set names unique."""
        out: list[InstanceSpec] = []
        names: dict[str, Any] = {}
        for item in self.sequence(node, "instances"):
            spec = self.instance(item)
            if spec is None:
                continue
            if spec.name in names:
                self.error(item, f"instances: two entries are named '{spec.name}' (give one a name: ...)")
                continue
            names[spec.name] = item
            out.append(spec)
        return out

    def instance(self, node: Any) -> InstanceSpec | None:
        """One entry of ``instances`` (a file, a glob or a generator call), or None with errors."""
        m = self.mapping(node, "an instance", None)
        if m is None:
            return None
        kinds = [k for k in ("file", "glob", "generate") if k in m]
        if len(kinds) != 1:
            self.error(node, "an instance has exactly one of file:, glob: or generate:")
            return None
        kind = kinds[0]
        if kind != "generate":
            self.file_keys(m, kind)
        source = self.scalar(m[kind][1], kind, (str,))
        if source is None:
            return None
        name = self.name(m["name"][1], "name") if "name" in m else _default_name(kind, source)
        problem = self.name(m["problem"][1], "problem") if "problem" in m else None
        if name is None or not _NAME.match(name):
            if "name" not in m:
                self.error(node, f"cannot name this instance after '{source}': give it a name:")
            return None
        span = self.span(node)
        if kind != "generate":
            return InstanceSpec(kind, name, source, problem, span=span)
        seeds = self.seeds(m["seeds"][1], "seeds") if "seeds" in m else (0,)
        options = self.options(m, "generator option", GENERATE_KEYS)
        if seeds is None:
            return None
        return InstanceSpec("generate", name, source, None, tuple(options), seeds, span)

    def file_keys(self, m: dict[str, tuple[Any, Any]], kind: str) -> None:
        """An error per key a ``file:`` or ``glob:`` instance (``kind``) does not know."""
        allowed = FILE_KEYS if kind == "file" else GLOB_KEYS
        for key, (knode, _) in m.items():
            if key not in allowed:
                from mrgc.language.suggest import did_you_mean

                self.error(
                    knode,
                    f"a {kind} instance: unknown key '{key}'{did_you_mean(key, allowed)} (known: {', '.join(allowed)})",
                )

    def options(self, m: dict[str, tuple[Any, Any]], what: str, skip: tuple[str, ...] = ()) -> list[tuple[str, Any]]:
        """(key, value) of the mapping's entries but those in ``skip``; an error (``what 'key' must be ...``)
        for each value that is not a number, a word or true/false."""
        out: list[tuple[str, Any]] = []
        for key, (_, vnode) in m.items():
            if key in skip:
                continue
            value = self.value(vnode)
            if value is None or isinstance(value, (list, dict)):
                self.error(vnode, f"{what} '{key}' must be a number, a word or true/false")
                continue
            out.append((key, value))
        return out

    def methods(self, node: Any, limits: Limits) -> list[Method]:
        """The entries of ``methods``, names unique; ``limits`` are the study's."""
        out: list[Method] = []
        names: set[str] = set()
        for item in self.sequence(node, "methods"):
            method = self.method(item, limits)
            if method is None:
                continue
            if method.name in names:
                self.error(item, f"methods: two methods are named '{method.name}'")
                continue
            names.add(method.name)
            out.append(method)
        return out

    def method(self, node: Any, limits: Limits) -> Method | None:
        """One entry of ``methods``, or None with errors; its limits default to ``limits``."""
        m = self.mapping(node, "a method", METHOD_KEYS)
        if m is None:
            return None
        if "name" not in m:
            self.error(node, "a method lacks 'name'")
            return None
        name = self.name(m["name"][1], "name")
        compile_only = bool(self.scalar(m["compile"][1], "compile", (bool,))) if "compile" in m else False
        planner = self.name(m["planner"][1], "planner") if "planner" in m else "mcts"
        if compile_only and "planner" in m:
            self.error(m["planner"][0], "a compile: true method generates skeletons only: it has no planner")
        backend = self.name(m["backend"][1], "backend") if "backend" in m else None
        encoding = self.name(m["encoding"][1], "encoding") if "encoding" in m else None
        options: list[tuple[str, Any]] = []
        if "options" in m:
            options = self.options(self.mapping(m["options"][1], "options", None) or {}, "option")
        own = self.limits(m["limits"][1], limits) if "limits" in m else limits
        only: list[str] = []
        if "only" in m:
            for item in self.sequence(m["only"][1], "only (instance set names)"):
                set_name = self.name(item, "only")
                if set_name is not None and set_name not in self.set_names:
                    from mrgc.language.suggest import did_you_mean

                    self.error(item, f"only: no instance set '{set_name}'{did_you_mean(set_name, self.set_names)}")
                elif set_name is not None:
                    only.append(set_name)
        if name is None or planner is None or own is None:
            return None
        return Method(name, planner, compile_only, backend, encoding, tuple(options), own, tuple(only), self.span(node))


def _default_name(kind: str, source: str) -> str:
    """The instance set's name when the entry gives none: the file's stem, the glob's pattern made a name
    (``glob`` if nothing is left), the generator's kind."""
    if kind == "file":
        return os.path.splitext(os.path.basename(source))[0]
    if kind == "glob":
        return re.sub(r"[^A-Za-z0-9_.+-]+", "-", source).strip("-.") or "glob"
    return source
