"""The commands of ``mrgc`` (all but the command groups of ``render/`` and ``bench/``) and their parser: a
thin layer over the Python API.

:mod:`mrgc.cli` adds render's and bench's commands to :func:`build_parser` and runs the result (``main``).
``mrgc.bench`` reads this parser rather than the CLI's: the options ``mrgc plan`` and ``mrgc compile`` take
are the options a study's method may give, and a study's generated instances are ``mrgc generate`` run in
the same process.  (``mrgc.bench`` cannot import :mod:`mrgc.cli`, which registers bench's commands: that
would be an import cycle.)  Exit codes: the table of :mod:`mrgc.exits`.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
from typing import TYPE_CHECKING, Any, Callable, Iterator, Sequence

from mrgc import __version__
from mrgc.errors import Diagnostic, InputError
from mrgc.exits import ExitCode
from mrgc.language.files import add_allow_outside
from mrgc.limits import BOUNDS, count, number
from mrgc.planner.defaults import DEFAULT_BACKEND, DEFAULT_ENCODING, DEFAULT_PLANNER, DEFAULT_TIME_LIMIT

if TYPE_CHECKING:
    from mrgc.language.loader import MrgFile
    from mrgc.planner.summary import FactsSummary


class _Parser(argparse.ArgumentParser):
    """argparse whose usage errors are one ``error[E000]`` line and exit code 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        print(f"mrgc: error[E000]: {message}", file=sys.stderr)
        raise SystemExit(ExitCode.INPUT)


def report_input_error(exc: InputError) -> None:
    """Print an input error's diagnostics with their source lines (and how many there are, if several)."""
    from mrgc.language.files import read_regular

    for d in exc.diagnostics:  # errors raised past the loader (geometry) carry no source text: read it
        if d.span is not None and d.span.file not in exc.sources and os.path.isfile(d.span.file):
            try:
                exc.sources[d.span.file] = read_regular(d.span.file, 8 << 20).decode("utf-8")
            except (OSError, UnicodeDecodeError):
                pass
    print(exc.render(), file=sys.stderr)
    n = len(exc.diagnostics)
    if n > 1:
        print(f"{n} errors", file=sys.stderr)


def _warn(path: str, text: str, warnings: Sequence[Diagnostic]) -> None:
    """Print the warnings about a checked file (``path``, whose ``text`` shows the source lines)."""
    for d in warnings:
        print(d.render(text if d.span is not None and d.span.file == path else None), file=sys.stderr)


# ---------------------------------------------------------------- commands
def cmd_check(args: argparse.Namespace) -> int:
    """``mrgc check``: check every file (and its layout); exit 2 when any has an error."""
    from mrgc.api import check

    status = ExitCode.OK
    for path in args.files:
        try:
            report = check(path, allow_outside=getattr(args, "allow_outside", None) or ())
        except InputError as exc:
            report_input_error(exc)
            status = ExitCode.INPUT
            continue
        mf = report.file
        _warn(mf.path, mf.text, report.warnings)
        parts = [f"{len(mf.domains)} domain{'s' * (len(mf.domains) != 1)}"] if mf.domains or not mf.problems else []
        own = {(d.name, d.source) for d in mf.domains}
        # the domains its problems used from another file, each once (each problem loads its own copy)
        used = {(p.domain.name, p.domain.source): p.domain for p in mf.problems}
        for d in (d for key, d in used.items() if key not in own):
            parts.append(f"domain {d.name} from {_shown_path(d.source)}")
        for p in mf.problems:
            kind = "symbolic" if p.symbolic else "geometric"
            counts = (
                (len(p.robots), "robot"),
                (len(p.regions), "region"),
                (len(p.goal), "goal"),
                (len(p.init), "fact"),
            )
            robots, regions, goals, facts = (f"{n} {word}{'s' * (n != 1)}" for n, word in counts)
            parts.append(f"problem {p.name} ({kind}: {robots}, {len(p.movable)} movable, {regions}, {goals}, {facts})")
        if not args.quiet:
            for note in report.notes:
                print(note)
            print(f"{path}: ok: " + "; ".join(parts))
    return status


def _shown_path(path: str) -> str:
    """``path`` relative to the current folder when it lies below it, else as it is."""
    rel = os.path.relpath(path) if path else path
    return rel if path and not rel.startswith("..") else path


def cmd_fmt(args: argparse.Namespace) -> int:
    """``mrgc fmt``: print, check (``--check``), diff (``--diff``) or rewrite (``--write``) the canonical form."""
    from mrgc.language.loader import read_source
    from mrgc.language.parser import parse_text
    from mrgc.language.printer import format_source

    if not (args.check or args.write or args.diff) and len(args.files) != 1:
        raise InputError([Diagnostic("E000", "fmt prints one file; use --check, --diff or --write for several")])
    status = ExitCode.OK
    for path in args.files:
        text, diag = read_source(path)
        if diag is None:
            assert text is not None
            tree = parse_text(text, path)
            if isinstance(tree, Diagnostic):
                diag = tree
        if diag is not None:
            report_input_error(InputError([diag], {path: text} if text is not None else {}))
            status = ExitCode.INPUT
            continue
        assert text is not None and not isinstance(tree, Diagnostic)
        pretty = format_source(tree, text)
        if args.check or args.diff:
            if pretty != text:
                sys.stdout.write(_unified_diff(path, text, pretty))
                if args.check:
                    print(f"{path}: would reformat", file=sys.stderr)
                    status = status or ExitCode.NO_PLAN
        elif args.write:
            if pretty != text:
                write_text(path, pretty, option="fmt --write")
                print(f"{path}: reformatted")
        else:
            sys.stdout.write(pretty)
    return status


def _unified_diff(path: str, text: str, pretty: str) -> str:
    """What ``fmt --diff`` / ``--check`` print: a unified diff from ``text`` to its canonical form, ``patch
    -p0`` applicable (every line ends with a newline; a missing final newline is shown as patch does)."""
    import difflib

    def lines(s: str) -> list[str]:
        out = s.splitlines(keepends=True)
        if out and not out[-1].endswith("\n"):
            out[-1] += "\n\\ No newline at end of file\n"
        return out

    return "".join(difflib.unified_diff(lines(text), lines(pretty), fromfile=path, tofile=path))


def _load(args: argparse.Namespace) -> "MrgFile":
    """The checked file of a command's FILE argument, with its ``--allow-outside`` folders."""
    from mrgc.language.loader import parse_file

    return parse_file(args.file, **_outside(args))


def _outside(args: argparse.Namespace) -> dict[str, tuple[str, ...]]:
    """``parse_file``'s ``allow_outside`` keyword from ``--allow-outside`` (none when not given)."""
    folders = getattr(args, "allow_outside", None)
    return {"allow_outside": tuple(folders)} if folders else {}


def inputs_of(mf: "MrgFile") -> list[str]:
    """Every file a command reads for ``mf``: .mrg files (the problem, its domain, includes), the meshes
    its shapes name, and the URDFs of its robot kinds (an output may be none of them)."""
    from mrgc.language.loader import urdf_candidates
    from mrgc.language.model import Mesh

    files = list(mf.files)
    for p in mf.problems:
        shapes = [o.shape for o in p.bodies] + [k.footprint for k in p.domain.robot_kinds]
        files.extend(s.path for s in shapes if isinstance(s, Mesh))
        for kind in p.domain.robot_kinds:
            if kind.urdf is not None:
                base = os.path.dirname(os.path.abspath(kind.source)) if kind.source else ""
                files.extend(c for c, _ in urdf_candidates(kind.urdf, base))
    return files


def write_text(path: str, text: str, inputs: Sequence[str] = (), option: str = "-o") -> None:
    """Write a command's output file safely (see :mod:`mrgc.outputs`)."""
    from mrgc import outputs

    outputs.write_text(path, text, inputs, option=option)


def check_output(path: str | None, inputs: Sequence[str] = (), option: str = "-o") -> None:
    """Refuse an unusable output path before any work is done (see :mod:`mrgc.outputs`)."""
    if path is not None:
        from mrgc import outputs

        outputs.check_output(path, inputs, option=option)


def cmd_compile(args: argparse.Namespace) -> int:
    """``mrgc compile``: the first skeletons of a problem (text or JSON), and with ``--emit`` its model file."""
    import json

    from mrgc import api, outputs, signals
    from mrgc.backends.registry import check_export
    from mrgc.planner.skeletons import COMPILE_EXIT_CODES, needs_facts

    mf = _load(args)
    problem = mf.problem(args.problem)
    if args.horizon is not None and not args.emit:
        raise InputError([Diagnostic("E000", "--horizon is the horizon of the model --emit writes: give --emit")])
    if args.emit:  # before any solving: a path the solver cannot write, or a format it does not write
        check_output(args.emit, inputs_of(mf), option="--emit")
        check_export(args.backend, args.emit)
    facts = None
    if needs_facts(problem):  # phase 1 once, for the skeletons and the export
        with signals.activity(f"computing the facts of {problem.name} (phase 1)"):
            found = api.compute_facts(problem, seed=args.seed)
        _warn(mf.path, mf.text, found.warnings)
        facts, facts_seconds = found.facts, float(found.stats["seconds"])
    with signals.activity(f"generating skeletons of {problem.name} with {args.backend}"):
        result = api.compile(
            problem,
            backend=args.backend,
            encoding=args.encoding,
            skeletons=args.skeletons,
            max_makespan=args.max_makespan,
            time_limit=args.time_limit,
            facts=facts,
            seed=args.seed,
        )
    if facts is not None:
        result.stats["facts_seconds"] = round(facts_seconds, 6)
    if args.emit:
        horizon = args.horizon if args.horizon is not None else api.emit_horizon(problem.name, result, args.encoding)
        with (
            signals.activity(f"writing the model to {args.emit}"),
            outputs.atomic_path(args.emit, inputs_of(mf), option="--emit") as tmp,
        ):
            horizon = api.export_model(
                problem,
                tmp,
                backend=args.backend,
                encoding=args.encoding,
                horizon=horizon,
                max_makespan=args.max_makespan,
                facts=facts,
                seed=args.seed,
            )
        result.stats["emitted_horizon"] = horizon
    if args.format == "json":
        print(json.dumps(result.to_json(), indent=2))
    else:
        n = len(result.skeletons)
        print(
            f"problem {result.problem}: backend {result.backend}, encoding {result.encoding}: "
            f"{result.status}, {n} skeleton{'s' * (n != 1)} "
            f"({result.stats.get('objects', 0)} objects, {result.stats.get('actions', 0)} actions in the task graph, "
            f"{result.stats.get('total_seconds', 0):.3f} s"
            + (
                f"; phase 1: {result.stats['facts']} facts in {result.stats['facts_seconds']:.2f} s"
                if result.stats.get("facts_seconds")
                else ""
            )
            + ")"
        )
        for i, sk in enumerate(result.skeletons, 1):
            print(f"skeleton {i}: makespan {sk.makespan}, moves {len(sk.moved)} ({' '.join(sk.moved)})")
            for line in sk.describe():
                print("  " + line)
        for reason in result.reasons:
            print(f"  reason: {reason}")
        if args.emit:
            print(f"model written to {args.emit} (horizon {result.stats['emitted_horizon']})")
    if result.skeletons:
        return ExitCode.OK
    return COMPILE_EXIT_CODES[result.status]


def cmd_facts(args: argparse.Namespace) -> int:
    """``mrgc facts``: phase 1, written as the problem with its ``:init`` completed."""
    import json

    from mrgc import signals
    from mrgc.api import compute_facts
    from mrgc.planner.phase1 import facts_file

    mf = _load(args)
    problem = mf.problem(args.problem)
    check_output(args.output, inputs_of(mf))
    if args.summary and not args.output:  # the file's own facts when it holds them, else phase 1
        from mrgc.api import facts_summary

        with signals.activity(f"summarizing the facts of {problem.name}"):
            summary = facts_summary(problem, seed=args.seed)
        _warn(mf.path, mf.text, summary.warnings)
        _print_summary(summary, args.summary)
        return ExitCode.OK
    with signals.activity(f"computing the facts of {problem.name} (phase 1)"):
        result = compute_facts(problem, seed=args.seed, workers=args.workers)
    _warn(mf.path, mf.text, result.warnings)
    if args.summary:
        from mrgc.planner.summary import summarize

        _print_summary(summarize(problem, result.facts), args.summary)
    doc = facts_file(mf, problem, result.facts, args.seed, __version__, args.output)
    if args.output:
        for asset, data in doc.assets.items():  # local meshes and URDFs the output refers to, copied beside it
            _write_asset(asset, data, inputs_of(mf))
        write_text(args.output, doc.text, inputs_of(mf))
        print(
            f"{args.output}: {len(result.facts)} facts ({int(result.stats['ik_solves'])} IK solves, "
            f"{int(result.stats['workers'])} worker{'s' * (int(result.stats['workers']) != 1)}"
            + (f"; {len(doc.assets)} mesh/URDF files copied beside it" if doc.assets else "")
            + ")"
        )
    else:
        sys.stdout.write(doc.text)
    if args.stats:
        print(json.dumps(result.stats, indent=2), file=sys.stdout if args.output else sys.stderr)
    return ExitCode.OK


def _print_summary(summary: "FactsSummary", form: str) -> None:
    """``mrgc facts --summary``: the summary as text or JSON on standard output."""
    import json

    sys.stdout.write(json.dumps(summary.to_json(), indent=2) + "\n" if form == "json" else summary.text())


def _write_asset(path: str, data: bytes, inputs: Sequence[str]) -> None:
    from mrgc import outputs

    os.makedirs(os.path.dirname(path), exist_ok=True)
    try:
        with open(path, "rb") as fh:
            if fh.read(len(data) + 1) == data:
                return  # already there (a previous run)
    except OSError:
        pass
    outputs.write_bytes(path, data, inputs)


def _progress(message: str) -> "contextlib.AbstractContextManager[object]":
    """A rich spinner on a terminal (stderr), nothing otherwise (logs and pipes stay clean)."""
    if not sys.stderr.isatty():
        return contextlib.nullcontext()
    from rich.console import Console

    return Console(stderr=True).status(message)


@contextlib.contextmanager
def _start_up_frozen() -> Iterator[None]:
    """Leave the objects that exist when a planning run starts out of the cyclic garbage collector's passes
    until it ends (``gc.freeze()``, then ``gc.unfreeze()``).

    They are the modules, the parsed problem and the command line: they outlive the run, so the collector's
    full passes (and those of phase 1's forked workers, which inherit the frozen set) need not walk them
    again and again; about 22,000 of a PA5 run's 42,000 tracked objects, whose one full pass cost 11-21 ms
    of its CPU.  Objects made during the run are collected as before, and a caller that plans in-process gets
    its objects back at the end (nothing is kept from the collector for good).  Measured on the PA5 presets
    (each instance run before, after, after, before): median CPU 2.5 % lower, the same plans; with the exit
    left without its collection too (:mod:`mrgc.cli`), 7 % (docs/benchmarks.md, "Session 28")."""
    import gc

    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


#: the timing and counting statistics ``mrgc plan -v`` prints, each when the method recorded it (mcts: skeletons,
#: grounding, nodes; ap1: grounding, nodes; ap2: task plans, grounding)
_SECONDS = (("skeleton_seconds", "skeletons"), ("task_seconds", "task plans"), ("grounding_seconds", "grounding"))
_COUNTS = (("skeletons", "skeletons"), ("task_plans", "task plans"), ("groundings", "grounded"), ("nodes", "nodes"))


def _timing_line(st: dict[str, Any]) -> str:
    """``mrgc plan``'s line of times and counts, from the statistics the planning method recorded."""
    times = [f"facts {st.get('facts_seconds', 0):.2f} s"]
    times += [f"{label} {st[key]:.2f} s" for key, label in _SECONDS if key in st]
    counts = [f"{st[key]} {label}" for key, label in _COUNTS if key in st]
    return f"  {st.get('seconds', 0):.2f} s: {', '.join(times)}" + (f"; {', '.join(counts)}" if counts else "")


def cmd_plan(args: argparse.Namespace) -> int:
    """``mrgc plan``: plan end to end and write the plan; the exit code is the plan's status's."""
    from mrgc import api, signals
    from mrgc.planner.outcome import EXIT_CODES, PlanStatus

    mf = _load(args)
    problem = mf.problem(args.problem)
    check_output(args.output, inputs_of(mf))
    log = (lambda line: print(line, file=sys.stderr, flush=True)) if args.verbose else None
    with (
        _progress(f"planning {problem.name} (phase 1, then the tree search; at most {args.time_limit:g} s)"),
        signals.activity(f"planning {problem.name}"),
        _start_up_frozen(),
    ):
        plan = api.plan(
            problem,
            planner=args.planner,
            seed=args.seed,
            time_limit=args.time_limit,
            log=log,
            motions=args.motions,
            **planner_options(args),
        )
    status = PlanStatus(plan.status)
    # a signal ends the run as interrupted even where the search did not see it (never a verdict, never a file)
    interrupted = status is PlanStatus.INTERRUPTED or signals.received() is not None
    out = sys.stderr if not args.output or interrupted else sys.stdout
    if not interrupted:  # an interrupted run writes no result, only what it had
        text = plan.dumps()
        if args.output:
            write_text(args.output, text, inputs_of(mf))
        else:
            sys.stdout.write(text)
    else:
        print(f"mrgc: {signals.describe()}; no plan file written. The search so far:", file=out)
    for line in plan.summary():
        print(line, file=out)
    print(_timing_line(plan.stats), file=out)
    if plan.validation:
        print(
            f"  validated: {plan.validation['plans_checked']} complete plan(s) replayed by the validator, "
            f"the returned one valid",
            file=out,
        )
    if interrupted:
        return signals.exit_code()
    return EXIT_CODES[status]


def cmd_validate(args: argparse.Namespace) -> int:
    """``mrgc validate``: the independent validator's report on a plan; exit 1 when the plan is invalid."""
    import json

    from mrgc.api import validate
    from mrgc.planfile.reader import load_plan

    report = validate(
        args.file, load_plan(args.plan), name=args.problem, allow_outside=getattr(args, "allow_outside", None) or ()
    )
    if args.format == "json":
        print(json.dumps(report.to_json(), indent=2))
    else:
        for line in report.lines():
            print(line)
    return ExitCode.OK if report.ok else ExitCode.NO_PLAN


def cmd_generate(args: argparse.Namespace) -> int:
    """``mrgc generate``: a random problem of a domain, checked before it is written."""
    from mrgc.generate import generate
    from mrgc.generate.document import domain_path

    text = generate(
        args.kind, seed=args.seed, preset_name=args.preset, robots=args.robots, goals=args.goals, others=args.others
    )
    if not args.output:
        sys.stdout.write(text)
        return ExitCode.OK
    write_text(args.output, text, [domain_path(args.kind)])
    print(f"{args.output}: {args.kind} problem written")
    return ExitCode.OK


def cmd_backends(args: argparse.Namespace) -> int:
    """``mrgc backends``: the registered solver backends and what they translate natively."""
    import json

    from mrgc.api import backends
    from mrgc.backends.registry import feature_table

    rows = backends()
    if args.format == "json":
        print(json.dumps([r.to_json() for r in rows], indent=2))
        return ExitCode.OK
    for r in rows:
        state = f"installed ({r.library} {r.version})" if r.installed else f"missing: pip install {r.library}"
        print(f"{r.name:6} {r.title}: {state}; encodings: {', '.join(r.encodings)}")
    print()
    print(feature_table())
    return ExitCode.OK


# ---------------------------------------------------------------- wiring
def add_seed(p: argparse.ArgumentParser, metavar: str | None = None) -> None:
    """``--seed`` (bounded, see mrgc.limits)."""
    p.add_argument("--seed", type=count("--seed"), default=0, metavar=metavar)


def add_no_cache(p: argparse.ArgumentParser) -> None:
    """``--no-cache``: neither read nor write the facts cache (mrgc.planner.facts_cache)."""
    p.add_argument(
        "--no-cache",
        action="store_true",
        help="compute phase 1 even when the facts cache holds its facts, and do not store them",
    )


def add_planner_options(p: argparse.ArgumentParser) -> None:
    """The options the planning methods declare (:mod:`mrgc.planner.registry`), each once, for the methods
    that declare it; an option not given is not passed (its method's default applies, and another method
    refuses it only when it is given)."""
    from mrgc.planner.registry import declared_options

    for owners in declared_options().values():
        option = owners[0][1]
        if not option.cli:
            continue
        methods = ", ".join(m for m, _ in owners)
        shown = f"{option.default:g}" if isinstance(option.default, float) else str(option.default)
        default = "" if option.default in (None, False) else f"; default {shown}"
        text = f"{option.help} ({methods}{default})"
        if option.kind == "flag":
            p.add_argument(option.flag, dest=option.name, action="store_true", default=argparse.SUPPRESS, help=text)
            continue
        parse: Callable[[str], Any] = str
        low, high = BOUNDS.get(option.flag, option.bounds)  # mrgc.limits.BOUNDS' row for the flag first
        if option.kind == "count":
            parse = count(option.flag, int(low), int(high))
        elif option.kind == "number":
            parse = number(option.flag, low, high)
        p.add_argument(
            option.flag,
            dest=option.name,
            type=parse,
            metavar=option.metavar,
            choices=option.choices,
            default=argparse.SUPPRESS,
            help=text,
        )


class _PlanParser(_Parser):
    """``mrgc plan``'s parser: the options the planning methods declare (:func:`add_planner_options`) are
    added when it is first used (to parse, or for its help), since reading them imports the methods'
    modules, which no other command needs (CLI start-up, docs/benchmarks.md)."""

    _with_methods = False

    def with_planner_options(self) -> "_PlanParser":
        """This parser with the methods' options (added once)."""
        if not self._with_methods:
            self._with_methods = True
            add_planner_options(self)
        return self

    def parse_known_args(  # type: ignore[override]
        self, args: Sequence[str] | None = None, namespace: argparse.Namespace | None = None
    ) -> tuple[argparse.Namespace, list[str]]:
        """Parse, with the methods' options."""
        return super(_PlanParser, self.with_planner_options()).parse_known_args(args, namespace)

    def format_help(self) -> str:
        """The help, with the methods' options."""
        return super(_PlanParser, self.with_planner_options()).format_help()


def planner_options(args: argparse.Namespace) -> dict[str, Any]:
    """The planner options given on the command line (see :func:`add_planner_options`)."""
    from mrgc.planner.registry import declared_options

    return {name: getattr(args, name) for name in declared_options() if hasattr(args, name)}


def build_parser() -> argparse.ArgumentParser:
    """The ``mrgc`` argument parser with the commands of this module (usage errors are one ``E000`` line,
    exit 2); :func:`mrgc.cli.build_parser` adds render's and bench's."""
    from mrgc.planner.registry import PLANNERS

    parser = _Parser(prog="mrgc", description="Multi-robot geometric task-and-motion planning compiler and solver.")
    parser.add_argument("--version", action="version", version=f"mrgc {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    p = sub.add_parser("check", help="parse and check .mrg files, reporting every error at once")
    p.add_argument("files", nargs="+", metavar="FILE")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing for files that are fine")
    add_allow_outside(p)
    p.set_defaults(func=cmd_check)

    p = sub.add_parser("fmt", help="print a .mrg file in canonical form")
    p.add_argument("files", nargs="+", metavar="FILE")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument(
        "--check",
        action="store_true",
        help="exit 1 if a file is not canonically formatted, printing the unified diff to its canonical form",
    )
    mode.add_argument(
        "--diff", action="store_true", help="print the unified diff of each file to its canonical form (exit 0)"
    )
    mode.add_argument("--write", action="store_true", help="rewrite files in place")
    p.set_defaults(func=cmd_fmt)

    p = sub.add_parser(
        "facts", help="phase 1: compute the geometric facts of a problem and write it with :init completed"
    )
    p.add_argument("file", metavar="FILE")
    p.add_argument("-o", "--output", metavar="OUT", help="write here (default: standard output)")
    p.add_argument("--problem", help="which problem of the file (default: its only one)")
    add_seed(p)
    add_no_cache(p)
    p.add_argument(
        "--workers",
        type=count("--workers"),
        default=None,
        help="processes (default: one per robot; capped at one per robot and one per core)",
    )
    p.add_argument("--stats", action="store_true", help="also print timing statistics as JSON")
    p.add_argument(
        "--summary",
        nargs="?",
        const="text",
        choices=("text", "json"),
        help="print what the facts say instead (with -o: as well): per robot what it picks, where it places, "
        "its handover and relay partners; how each goal can be delivered; what nobody reaches, with the "
        "nearest miss",
    )
    add_allow_outside(p)
    p.set_defaults(func=cmd_facts)

    p = sub.add_parser("compile", help="build the task graph and generate task skeletons with a solver backend")
    p.add_argument("file", metavar="FILE")
    p.add_argument("--problem", help="which problem of the file (default: its only one)")
    p.add_argument(
        "--backend",
        default=DEFAULT_BACKEND,
        help=f"mip | smt | pysmt | cpsat (default {DEFAULT_BACKEND}; see mrgc backends)",
    )
    p.add_argument(
        "--encoding",
        default=DEFAULT_ENCODING,
        help=f"paper | disaggregated | time-of-move (default {DEFAULT_ENCODING})",
    )
    p.add_argument(
        "--skeletons", type=count("--skeletons"), default=1, metavar="K", help="how many skeletons (default 1)"
    )
    p.add_argument(
        "--max-makespan",
        type=count("--max-makespan"),
        default=None,
        metavar="T",
        help="horizon limit (default and cap: the number of objects in the task graph)",
    )
    p.add_argument(
        "--time-limit",
        type=number("--time-limit", positive=True),
        default=None,
        metavar="S",
        help="seconds for the whole search",
    )
    add_seed(p)
    add_no_cache(p)
    add_allow_outside(p)
    p.add_argument("--emit", metavar="PATH", help="also write the model: .lp/.mps (mip), .smt2 (smt), .pbtxt (cpsat)")
    p.add_argument(
        "--horizon",
        type=count("--horizon"),
        default=None,
        metavar="T",
        help="the model --emit writes: horizon T (paper, disaggregated: exactly T steps; time-of-move: "
        "at most T); default: the first skeleton's makespan, else the horizon limit",
    )
    p.add_argument("--format", choices=["text", "json"], default="text")
    p.set_defaults(func=cmd_compile)

    sub._parser_class = _PlanParser  # the methods' options are added when this parser is first used
    p = sub.add_parser("plan", help="plan end to end: facts, skeletons, MCTS with reverse-search grounding")
    sub._parser_class = _Parser
    p.add_argument("file", metavar="FILE")
    p.add_argument("--problem", help="which problem of the file (default: its only one)")
    p.add_argument("-o", "--output", metavar="PLAN", help="write the plan JSON here (default: standard output)")
    p.add_argument(
        "--planner",
        default=DEFAULT_PLANNER,
        metavar="NAME",
        help=f"the planning method: {' | '.join(PLANNERS)} (default {DEFAULT_PLANNER}, the paper's; the baselines: "
        "docs/baselines.md)",
    )
    add_seed(p)
    add_no_cache(p)
    p.add_argument(
        "--time-limit",
        type=number("--time-limit", positive=True),
        default=DEFAULT_TIME_LIMIT,
        metavar="S",
        help=f"seconds for the whole run, phase 1 included (default {DEFAULT_TIME_LIMIT:g})",
    )
    p.add_argument(
        "--motions",
        choices=["configurations", "full"],
        default="configurations",
        help="arms' motion model: configurations (the paper's packaging model: approaches, exchanges, "
        "transfers; default) or full (every motion planned as a path; docs/validator.md)",
    )
    p.add_argument("-v", "--verbose", action="store_true", help="print a search log line per grounded skeleton")
    add_allow_outside(p)
    p.set_defaults(func=cmd_plan)

    p = sub.add_parser("validate", help="independently re-check a plan: replay it in pybullet, check every step")
    p.add_argument("file", metavar="FILE", help="the problem file the plan was made for")
    p.add_argument("plan", metavar="PLAN", help="the plan JSON (mrgc plan -o PLAN)")
    p.add_argument("--problem", help="which problem of the file (default: the one the plan names, else its only one)")
    p.add_argument("--format", choices=["text", "json"], default="text")
    add_allow_outside(p)
    p.set_defaults(func=cmd_validate)

    p = sub.add_parser("generate", help="write a random problem: packaging (arms, table, bins) or box-moving (rooms)")
    p.add_argument("kind", choices=["packaging", "box-moving"])
    p.add_argument(
        "--robots", type=int, default=None, metavar="N", help="arms 2-6 (packaging), carts 1-4 (box-moving); default 2"
    )
    p.add_argument("--goals", type=int, default=None, metavar="G", help="goal objects (default 3)")
    p.add_argument("--others", type=int, default=None, metavar="K", help="other objects (default 2)")
    p.add_argument(
        "--preset",
        metavar="NAME",
        help="a suite of the paper: pa5, pa7, pa10, pa18 (--robots 2-6) "
        "(packaging), bo8 (box-moving); fixes the counts (docs/generators.md)",
    )
    add_seed(p, "S")
    p.add_argument("-o", "--output", metavar="FILE", help="write here (default: standard output)")
    p.set_defaults(func=cmd_generate)

    p = sub.add_parser("backends", help="list solver backends: installed?, versions, encodings, features")
    p.add_argument("--format", choices=["text", "json"], default="text")
    p.set_defaults(func=cmd_backends)
    return parser


def subcommands(parser: argparse.ArgumentParser) -> "argparse._SubParsersAction[argparse.ArgumentParser]":
    """The subcommands of a parser :func:`build_parser` made: to add command groups to (:mod:`mrgc.cli`),
    or to read a command's options (:mod:`mrgc.bench.methods`)."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return action
    raise AssertionError("the parser has no subcommands")  # pragma: no cover
