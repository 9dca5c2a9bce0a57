"""Reading ``.mrg`` files: size and encoding guards, includes, domain lookup, and the checked result.

A problem's domain is looked up (1) among the domains of its own file, (2) in ``domain.mrg`` beside it,
(3) in the files named by ``(:include "path")`` (transitively).  Includes resolve relative to the including
file and must stay inside the folder tree of the file being checked.  Any error raises
:class:`~mrgc.errors.InputError` carrying *every* diagnostic found.

Only regular files are read: a FIFO, a device or a socket is refused (E001) without opening it for
reading, so a FIFO cannot block the command.  Geometry files are confined like includes: the mesh files of
shapes and a robot kind's ``:urdf`` must lie in the folder tree of the file being checked, in
pybullet_data (for a URDF), or under a folder given as ``allow_outside`` (``--allow-outside PATH``), else
E236.  The same folders travel with each robot kind (:attr:`~mrgc.language.model.RobotKind.roots`) so
the geometry layer confines the URDF's own mesh files the same way.
"""

from __future__ import annotations

import importlib.util
import os
from dataclasses import dataclass, field, replace

from mrgc.errors import Diagnostic, InputError, Span
from mrgc.language import ast
from mrgc.language.check import Checker
from mrgc.language.files import FileTooLarge, read_regular
from mrgc.language.model import Domain, Mesh, Problem
from mrgc.language.parser import parse_text
from mrgc.language.suggest import did_you_mean

#: files larger than this are refused with E002 (documented in docs/language.md)
MAX_BYTES = 8 * 1024 * 1024

DOMAIN_FILE = "domain.mrg"


@dataclass(frozen=True)
class MrgFile:
    """A checked ``.mrg`` file: its syntax tree, the domains it defines and its checked problems."""

    path: str
    syntax: ast.SourceFile
    domains: tuple[Domain, ...]
    problems: tuple[Problem, ...]
    text: str = field(default="", repr=False, compare=False)
    #: real paths of every .mrg file read: this one, its includes, the domain.mrg beside it
    files: tuple[str, ...] = field(default=(), repr=False, compare=False)

    def problem(self, name: str | None = None) -> Problem:
        """The problem called ``name``, or the file's only problem when ``name`` is None."""
        if name is None:
            if len(self.problems) != 1:
                found = ", ".join(p.name for p in self.problems) or "none"
                raise InputError(
                    [
                        Diagnostic(
                            "E230",
                            f"{self.path} holds {len(self.problems)} problems ({found}); name one (--problem NAME)",
                        )
                    ]
                )
            return self.problems[0]
        for p in self.problems:
            if p.name == name:
                return p
        hint = did_you_mean(name, [p.name for p in self.problems])
        raise InputError([Diagnostic("E230", f"{self.path} has no problem '{name}'{hint}")])


def read_source(path: str) -> tuple[str | None, Diagnostic | None]:
    """The text of ``path``, or the E001/E002/E003 diagnostic saying why it cannot be used."""
    try:
        data = read_regular(path, MAX_BYTES)
    except FileTooLarge as exc:
        return None, Diagnostic(
            "E002", f"'{path}' is {exc.size} bytes; the limit is {MAX_BYTES} bytes", Span(path, 1, 1, 1, 2)
        )
    except OSError as exc:
        return None, Diagnostic("E001", f"cannot read '{path}': {exc.strerror or exc}")
    return decode(data, path)


def decode(data: bytes, path: str) -> tuple[str | None, Diagnostic | None]:
    """Bytes → text, refusing oversized, NUL-holding or non-UTF-8 input with a located diagnostic."""
    if len(data) > MAX_BYTES:
        return None, Diagnostic("E002", f"input is larger than the limit of {MAX_BYTES} bytes", Span(path, 1, 1, 1, 2))
    nul = data.find(b"\0")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        return None, Diagnostic("E003", "not UTF-8 text (binary file?)", _byte_span(data, exc.start, path))
    if nul >= 0:
        return None, Diagnostic("E003", "file holds a NUL byte (binary file?)", _byte_span(data, nul, path))
    if text.startswith("\ufeff"):
        text = text[1:]
    return text, None


def _byte_span(data: bytes, offset: int, path: str) -> Span:
    before = data[:offset]
    line = before.count(b"\n") + 1
    col = len(before) - (before.rfind(b"\n") + 1) + 1
    return Span(path, line, col, line, col + 1)


def shown(path: str) -> str:
    """``path`` as diagnostics show it: relative to the working folder when inside it."""
    try:
        rel = os.path.relpath(path)
    except ValueError:  # another drive (Windows)
        return path
    return path if rel.startswith("..") else rel


class _Loader:
    """Parses a root file and everything it includes, once each, and resolves domains."""

    def __init__(self, root_dir: str) -> None:
        self.root_dir = os.path.realpath(root_dir)
        self.diags: list[Diagnostic] = []
        self.sources: dict[str, str] = {}
        self.trees: dict[str, ast.SourceFile | None] = {}
        self.domains: dict[str, list[Domain]] = {}  # file -> its checked domains
        self.includes: dict[str, list[str]] = {}  # file -> files it includes
        self.files: list[str] = []  # real paths of the files read, in order

    def dir_of(self, path: str) -> str:
        """The folder relative paths in ``path`` resolve against (the root folder for in-memory text)."""
        return os.path.dirname(os.path.abspath(path)) if os.path.isfile(path) else self.root_dir

    # ------------------------------------------------------------ files
    def parse(self, path: str, text: str | None = None) -> ast.SourceFile | None:
        key = os.path.realpath(path) if text is None else path
        if key in self.trees:
            return self.trees[key]
        self.trees[key] = None
        if text is None:
            self.files.append(key)
            text, diag = read_source(path)
            if diag is not None:
                self.diags.append(diag)
                return None
        assert text is not None
        self.sources[path] = text
        result = parse_text(text, path)
        if isinstance(result, Diagnostic):
            self.diags.append(result)
            return None
        self.trees[key] = result
        checker = Checker(path)
        self.domains[key] = [checker.domain(d) for d in result.definitions if isinstance(d, ast.DomainDef)]
        self._duplicates(result)
        self.diags.extend(checker.diags)
        return result

    def _duplicates(self, tree: ast.SourceFile) -> None:
        seen: dict[tuple[str, str], Span] = {}
        for d in tree.definitions:
            what = "domain" if isinstance(d, ast.DomainDef) else "problem"
            if (what, d.name) in seen:
                self.diags.append(
                    Diagnostic(
                        "E200",
                        f"{what} '{d.name}' defined twice in this file (first at {seen[(what, d.name)]})",
                        d.span,
                    )
                )
            seen.setdefault((what, d.name), d.span)

    def follow_includes(self, path: str, tree: ast.SourceFile, stack: tuple[str, ...]) -> list[str]:
        """Files ``path`` includes, directly or not, in order; reports cycles, escapes and missing files."""
        key = os.path.realpath(path) if os.path.exists(path) else path
        if key in self.includes:
            return self.includes[key]
        out: list[str] = []
        self.includes[key] = out
        base = self.dir_of(path)
        for inc in _includes(tree):
            target = os.path.normpath(os.path.join(base, inc.path))
            try:
                real = os.path.realpath(target)
            except (OSError, ValueError) as exc:  # e.g. a NUL character in the path
                self.diags.append(Diagnostic("E234", f"include path {inc.path!r} is not usable: {exc}", inc.span))
                continue
            if os.path.commonpath([self.root_dir, real]) != self.root_dir:
                self.diags.append(
                    Diagnostic(
                        "E233", f"include '{inc.path}' leaves the folder tree of {shown(self.root_dir)}", inc.span
                    )
                )
                continue
            if real in stack or real == key:
                chain = " -> ".join(os.path.basename(s) for s in (*stack, real))
                self.diags.append(Diagnostic("E232", f"include cycle: {chain}", inc.span))
                continue
            if not os.path.isfile(real):
                what = "is not a regular file" if os.path.exists(real) else "not found"
                self.diags.append(
                    Diagnostic("E234", f"included file '{inc.path}' {what} (looked for {shown(target)})", inc.span)
                )
                continue
            sub = self.parse(shown(target))
            if real not in out:
                out.append(real)
            if sub is not None:
                for f in self.follow_includes(target, sub, (*stack, real)):
                    if f not in out:
                        out.append(f)
        return out

    # ------------------------------------------------------------ domain lookup
    def find_domain(self, path: str, key: str, tree: ast.SourceFile, ref: ast.DomainRef) -> Domain | None:
        own = [d for d in self.domains.get(key, []) if d.name == ref.name]
        if own:
            return own[0]  # a second definition in one file is already E200
        levels: list[list[Domain]] = []
        beside = os.path.join(self.dir_of(path), DOMAIN_FILE)
        if os.path.isfile(beside) and os.path.realpath(beside) != os.path.realpath(path):
            btree = self.parse(shown(beside))
            if btree is not None:
                bkey = os.path.realpath(beside)
                found = [d for d in self.domains.get(bkey, []) if d.name == ref.name]
                if not found:  # domain.mrg may itself include the domain
                    found = self._in_files(self.follow_includes(beside, btree, (bkey,)), ref.name)
                levels.append(found)
        levels.append(self._in_files(self.follow_includes(path, tree, (key,)), ref.name))
        for found in levels:
            if len(found) > 1:
                where = ", ".join(str(d.span) for d in found)
                self.diags.append(
                    Diagnostic("E231", f"domain '{ref.name}' is defined in several places ({where})", ref.span)
                )
                return None
            if found:
                return found[0]
        known = sorted({d.name for ds in self.domains.values() for d in ds})
        self.diags.append(
            Diagnostic(
                "E230",
                f"domain '{ref.name}' not found in this file, {DOMAIN_FILE} beside "
                f"it, or its includes{did_you_mean(ref.name, known)}",
                ref.span,
            )
        )
        return None

    def _in_files(self, files: list[str], name: str) -> list[Domain]:
        return [d for f in files for d in self.domains.get(f, []) if d.name == name]


def _includes(tree: ast.SourceFile) -> list[ast.Include]:
    return [s for d in tree.definitions for s in d.sections if isinstance(s, ast.Include)]


def load(
    path: str, text: str | None = None, root_dir: str | None = None, allow_outside: tuple[str, ...] = ()
) -> MrgFile:
    """Parse and check ``path`` (or ``text`` under that name); raise InputError with every diagnostic.

    ``allow_outside``: folders whose files (meshes, URDFs) may be used besides the file's own tree."""
    here = os.path.dirname(os.path.abspath(path)) if text is None else os.getcwd()
    base = root_dir if root_dir is not None else here
    loader = _Loader(base)
    tree = loader.parse(path, text)
    if tree is None:
        raise InputError(loader.diags, loader.sources)
    key = os.path.realpath(path) if text is None else path
    roots = (loader.root_dir, *(os.path.realpath(p) for p in allow_outside))
    problems: list[Problem] = []
    if not tree.definitions:
        loader.diags.append(Diagnostic("E004", "the file defines no domain and no problem", Span(path, 1, 1, 1, 2)))
    loader.follow_includes(path, tree, (key,))
    for pdef in tree.definitions:
        if not isinstance(pdef, ast.ProblemDef):
            continue
        refs = [s for s in pdef.sections if isinstance(s, ast.DomainRef)]
        if not refs:
            loader.diags.append(
                Diagnostic("E230", f"problem '{pdef.name}' names no domain: add (:domain NAME)", pdef.span)
            )
            continue
        domain = loader.find_domain(path, key, tree, refs[0])
        if domain is None:
            continue
        checker = Checker(path)
        problem = checker.problem(pdef, domain)
        loader.diags.extend(checker.diags)
        loader.diags.extend(confinement(problem, roots))
        problems.append(with_roots(problem, roots))
    if loader.diags:
        ordered = sorted(loader.diags, key=lambda d: (d.span is None, d.span or Span("", 0, 0, 0, 0)))
        raise InputError(_unique(ordered), loader.sources)
    domains = tuple(loader.domains.get(key, []))
    return MrgFile(path, tree, domains, tuple(problems), loader.sources.get(path, ""), tuple(loader.files))


def _unique(diags: list[Diagnostic]) -> list[Diagnostic]:
    return list(dict.fromkeys(diags))


# ---------------------------------------------------------------- where geometry files may come from
def pybullet_data_dir() -> str | None:
    """pybullet_data's folder, found without importing it (URDFs of robot kinds may come from there)."""
    spec = importlib.util.find_spec("pybullet_data")
    if spec is None or not spec.submodule_search_locations:
        return None
    return os.path.realpath(list(spec.submodule_search_locations)[0])


def inside(path: str, roots: tuple[str, ...]) -> bool:
    """Whether the real path of ``path`` lies in one of the folder trees ``roots`` (real paths)."""
    real = os.path.realpath(path)
    return any(os.path.commonpath([r, real]) == r for r in roots)


def urdf_candidates(urdf: str, base_dir: str) -> list[tuple[str, bool]]:
    """Where a ``:urdf`` path is looked for, in order, and whether each candidate is in pybullet_data:
    relative to the declaring file's folder, then relative to pybullet_data (never the current folder)."""
    if os.path.isabs(urdf):
        return [(urdf, False)]
    out = [(os.path.join(base_dir, urdf), False)]
    data = pybullet_data_dir()
    if data is not None:
        out.append((os.path.join(data, urdf), True))
    return out


def confinement(problem: Problem, roots: tuple[str, ...]) -> list[Diagnostic]:
    """E236 for each mesh file of a shape, and each robot kind's URDF, outside ``roots`` (URDFs may also
    come from pybullet_data)."""
    out = []
    hint = "; pass --allow-outside FOLDER to allow it"
    shown_roots = " or ".join(shown(r) for r in roots[:1])
    for obj in problem.bodies:
        if isinstance(obj.shape, Mesh) and not inside(obj.shape.path, roots):
            out.append(
                Diagnostic(
                    "E236",
                    f"mesh file '{obj.shape.path}' of '{obj.name}' is outside the folder tree of {shown_roots}{hint}",
                    obj.span,
                )
            )
    data = pybullet_data_dir()
    for kind in problem.domain.robot_kinds:
        if isinstance(kind.footprint, Mesh) and not inside(kind.footprint.path, roots):
            out.append(
                Diagnostic(
                    "E236",
                    f"mesh file '{kind.footprint.path}' of robot kind '{kind.name}' is "
                    f"outside the folder tree of {shown_roots}{hint}",
                    kind.span,
                )
            )
        if kind.urdf is None:
            continue
        base = os.path.dirname(os.path.abspath(kind.source)) if kind.source else roots[0]
        for cand, in_data in urdf_candidates(kind.urdf, base):
            if os.path.exists(cand):
                if not in_data and not inside(cand, roots + ((data,) if data else ())):
                    out.append(
                        Diagnostic(
                            "E236",
                            f"robot URDF '{kind.urdf}' of robot kind '{kind.name}' is "
                            f"outside the folder tree of {shown_roots} and pybullet_data{hint}",
                            kind.span,
                        )
                    )
                break
    return out


def with_roots(problem: Problem, roots: tuple[str, ...]) -> Problem:
    """``problem`` whose robot kinds carry the folders their URDF meshes may come from."""
    if not problem.domain.robot_kinds:
        return problem
    kinds = tuple(replace(k, roots=roots) for k in problem.domain.robot_kinds)
    return replace(problem, domain=replace(problem.domain, robot_kinds=kinds))


def parse_file(path: str | os.PathLike[str], allow_outside: tuple[str, ...] = ()) -> MrgFile:
    """Read, parse and check a ``.mrg`` file and everything it includes (``allow_outside``: folders whose
    mesh and URDF files may be used besides the file's own folder tree)."""
    return load(os.fspath(path), allow_outside=allow_outside)


def parse_string(text: str, file: str = "<string>", base_dir: str | None = None) -> MrgFile:
    """Parse and check ``text`` as if it were a file named ``file`` in ``base_dir`` (default: cwd)."""
    return load(file, text=text, root_dir=base_dir)
