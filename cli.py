"""The ``mrgc`` command: a thin layer over the Python API.

Exit codes (docs/errors.md): 0 ok; 1 infeasible (no skeleton under the facts) / ``fmt --check`` found
unformatted files / ``validate`` found the plan invalid; 2 input error (bad file, bad plan file or bad
command line); 3 time limit; 4 missing backend; 5 ``plan``: every skeleton tried, none grounded into a valid
plan; 70 internal error; 130 interrupted (SIGINT), 143 terminated (SIGTERM).  No input produces a Python traceback:
unexpected exceptions are reported in one line with exit code 70.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
from typing import TYPE_CHECKING, Callable, Sequence

from mrgc import __version__
from mrgc.errors import Diagnostic, InputError, MrgcError

if TYPE_CHECKING:
    from mrgc.language.loader import MrgFile
    from mrgc.language.model import Problem

EXIT_OK = 0
EXIT_NO_PLAN = 1
EXIT_INPUT = 2
EXIT_TIME_LIMIT = 3
EXIT_MISSING_BACKEND = 4
EXIT_INTERNAL = 70
EXIT_INTERRUPTED = 130


class _Parser(argparse.ArgumentParser):
    """argparse whose usage errors are one ``error[E000]`` line and exit code 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        print(f"mrgc: error[E000]: {message}", file=sys.stderr)
        raise SystemExit(EXIT_INPUT)


def _report(exc: InputError) -> None:
    for d in exc.diagnostics:  # errors raised past the loader (geometry) carry no source text: read it
        if d.span is not None and d.span.file not in exc.sources and os.path.isfile(d.span.file):
            try:
                with open(d.span.file, encoding="utf-8") as fh:
                    exc.sources[d.span.file] = fh.read()
            except (OSError, UnicodeDecodeError):
                pass
    print(exc.render(), file=sys.stderr)
    n = len(exc.diagnostics)
    if n > 1:
        print(f"{n} errors", file=sys.stderr)


def _warn(mf: "MrgFile") -> None:
    """Print the warnings of a checked file's problems (grasps no robot can open wide enough for)."""
    from mrgc.geometry.grasps import grasp_warnings

    for p in mf.problems:
        for d in grasp_warnings(p):
            print(d.render(mf.text if d.span is not None and d.span.file == mf.path else None), file=sys.stderr)


# ---------------------------------------------------------------- commands
def cmd_check(args: argparse.Namespace) -> int:
    from mrgc.language.loader import parse_file

    status = EXIT_OK
    for path in args.files:
        try:
            mf = parse_file(path)
        except InputError as exc:
            _report(exc)
            status = EXIT_INPUT
            continue
        _warn(mf)
        parts = [f"{len(mf.domains)} domain{'s' * (len(mf.domains) != 1)}"]
        for p in mf.problems:
            kind = "symbolic" if p.symbolic else "geometric"
            parts.append(
                f"problem {p.name} ({kind}: {len(p.robots)} robots, {len(p.movable)} movable, "
                f"{len(p.regions)} regions, {len(p.goal)} goals, {len(p.init)} facts)"
            )
        if not args.quiet:
            print(f"{path}: ok: " + "; ".join(parts))
    return status


def cmd_fmt(args: argparse.Namespace) -> int:
    from mrgc.language.loader import read_source
    from mrgc.language.parser import parse_text
    from mrgc.language.printer import format_source

    if not (args.check or args.write) and len(args.files) != 1:
        raise InputError([Diagnostic("E000", "fmt prints one file; use --check or --write for several")])
    status = EXIT_OK
    for path in args.files:
        text, diag = read_source(path)
        if diag is None:
            assert text is not None
            tree = parse_text(text, path)
            if isinstance(tree, Diagnostic):
                diag = tree
        if diag is not None:
            _report(InputError([diag], {path: text} if text is not None else {}))
            status = EXIT_INPUT
            continue
        assert text is not None and not isinstance(tree, Diagnostic)
        pretty = format_source(tree, text)
        if args.check:
            if pretty != text:
                print(f"{path}: would reformat", file=sys.stderr)
                status = status or EXIT_NO_PLAN
        elif args.write:
            if pretty != text:
                tmp = path + ".mrgc-tmp"
                with open(tmp, "w", encoding="utf-8") as fh:
                    fh.write(pretty)
                os.replace(tmp, path)
                print(f"{path}: reformatted")
        else:
            sys.stdout.write(pretty)
    return status


def _load_problem(path: str, name: str | None) -> "Problem":
    from mrgc.language.loader import parse_file

    return parse_file(path).problem(name)


def cmd_compile(args: argparse.Namespace) -> int:
    import json

    from mrgc.planner.skeletons import compile_problem, export_model, problem_facts

    problem = _load_problem(args.file, args.problem)
    if args.skeletons < 1:
        raise InputError([Diagnostic("E000", "--skeletons must be at least 1")])
    facts, facts_seconds = problem_facts(problem, seed=args.seed)  # once, for the skeletons and the export
    result = compile_problem(problem, backend=args.backend, encoding=args.encoding, skeletons=args.skeletons,
                             max_makespan=args.max_makespan, time_limit=args.time_limit, facts=facts,
                             seed=args.seed)
    result.stats["facts_seconds"] = round(facts_seconds, 6)
    if args.emit:
        horizon = result.skeletons[0].makespan if result.skeletons else None
        export_model(problem, args.emit, backend=args.backend, encoding=args.encoding, horizon=horizon, facts=facts)
    if args.format == "json":
        print(json.dumps(result.to_json(), indent=2))
    else:
        n = len(result.skeletons)
        print(f"problem {result.problem}: backend {result.backend}, encoding {result.encoding}: "
              f"{result.status}, {n} skeleton{'s' * (n != 1)} "
              f"({result.stats.get('objects', 0)} objects, {result.stats.get('actions', 0)} actions in the task graph, "
              f"{result.stats.get('total_seconds', 0):.3f} s"
              + (f"; phase 1: {result.stats['facts']} facts in {result.stats['facts_seconds']:.2f} s"
                 if result.stats.get("facts_seconds") else "") + ")")
        for i, sk in enumerate(result.skeletons, 1):
            print(f"skeleton {i}: makespan {sk.makespan}, moves {len(sk.moved)} ({' '.join(sk.moved)})")
            for line in sk.describe():
                print("  " + line)
        for reason in result.reasons:
            print(f"  reason: {reason}")
        if args.emit:
            print(f"model written to {args.emit}")
    if result.skeletons:
        return EXIT_OK
    return {"infeasible": EXIT_NO_PLAN, "time limit": EXIT_TIME_LIMIT}.get(result.status, EXIT_INTERNAL)


def cmd_facts(args: argparse.Namespace) -> int:
    import json

    from mrgc.language.edit import facts_document
    from mrgc.language.loader import parse_file
    from mrgc.planner.phase1 import compute_problem_facts

    mf = parse_file(args.file)
    problem = mf.problem(args.problem)
    result = compute_problem_facts(problem, seed=args.seed, workers=args.workers)
    header = (f"facts of problem {problem.name} computed by mrgc {__version__} (seed {args.seed}) from "
              f"{os.path.basename(args.file)}: {len(result.facts)} facts in {result.stats['seconds']:.2f} s")
    text = facts_document(mf.syntax, problem.name, problem.domain.name, problem.domain.source, result.facts,
                          args.file, args.output, header)
    if args.output:
        tmp = args.output + ".mrgc-tmp"
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.replace(tmp, args.output)
        print(f"{args.output}: {len(result.facts)} facts ({result.stats['seconds']:.2f} s, "
              f"{int(result.stats['ik_solves'])} IK solves, {int(result.stats['workers'])} workers)")
        if args.stats:
            print(json.dumps(result.stats, indent=2))
    else:
        sys.stdout.write(text)
    return EXIT_OK


def _progress(message: str) -> "contextlib.AbstractContextManager[object]":
    """A rich spinner on a terminal (stderr), nothing otherwise (logs and pipes stay clean)."""
    if not sys.stderr.isatty():
        return contextlib.nullcontext()
    from rich.console import Console

    return Console(stderr=True).status(message)


def cmd_plan(args: argparse.Namespace) -> int:
    from mrgc.planner.outcome import EXIT_CODES, PlanStatus
    from mrgc.planner.baselines import plan_with
    from mrgc.planner.plan import file_sha256

    if args.skeletons < 1 or not args.time_limit > 0 or args.time_limit == float("inf") or (
            args.max_makespan is not None and args.max_makespan < 1):
        raise InputError([Diagnostic("E000", "--skeletons and --max-makespan must be at least 1, "
                                     "--time-limit positive and finite")])
    problem = _load_problem(args.file, args.problem)
    log = (lambda line: print(line, file=sys.stderr, flush=True)) if args.verbose else None
    with _progress(f"planning {problem.name} (phase 1, then the tree search; at most {args.time_limit:g} s)"):
        plan = plan_with(args.planner, problem, args.file, file_sha256(args.file), __version__, backend=args.backend,
                         encoding=args.encoding, seed=args.seed, time_limit=args.time_limit, c=args.c,
                         alpha=args.alpha, skeletons=args.skeletons, max_makespan=args.max_makespan,
                         anytime=args.anytime, log=log)
    status = PlanStatus(plan.status)
    out = sys.stderr if not args.output or status is PlanStatus.INTERRUPTED else sys.stdout
    if status is not PlanStatus.INTERRUPTED:  # an interrupted run writes no result, only what it had
        text = plan.dumps()
        if args.output:
            tmp = args.output + ".mrgc-tmp"
            with open(tmp, "w", encoding="utf-8") as fh:
                fh.write(text)
            os.replace(tmp, args.output)
        else:
            sys.stdout.write(text)
    else:
        print(f"mrgc: {'terminated (SIGTERM)' if _SIGNALLED else 'interrupted'}; no plan file written. "
              "The search so far:", file=out)
    for line in plan.summary():
        print(line, file=out)
    st = plan.stats
    print(f"  {st.get('seconds', 0):.2f} s: facts {st.get('facts_seconds', 0):.2f} s, skeletons "
          f"{st.get('skeleton_seconds', 0):.2f} s, grounding {st.get('grounding_seconds', 0):.2f} s; "
          f"{st.get('skeletons', 0)} skeletons, {st.get('groundings', 0)} grounded, {st.get('nodes', 0)} nodes",
          file=out)
    if plan.validation:
        print(f"  validated: {plan.validation['plans_checked']} complete plan(s) replayed by the validator, "
              f"the returned one valid", file=out)
    if status is PlanStatus.INTERRUPTED and _SIGNALLED:
        return EXIT_TERMINATED
    return EXIT_CODES[status]


def cmd_validate(args: argparse.Namespace) -> int:
    import json

    from mrgc.language.loader import parse_file
    from mrgc.planner.validate import load_plan, validate

    mf = parse_file(args.file)
    plan = load_plan(args.plan)
    name = args.problem
    if name is None and len(mf.problems) > 1 and any(p.name == plan["problem"] for p in mf.problems):
        name = plan["problem"]  # a file of several problems: the one the plan names
    report = validate(mf.problem(name), plan, args.file)
    if args.format == "json":
        print(json.dumps(report.to_json(), indent=2))
    else:
        for line in report.lines():
            print(line)
    return EXIT_OK if report.ok else EXIT_NO_PLAN


def cmd_generate(args: argparse.Namespace) -> int:
    from mrgc.generate import generate
    from mrgc.generate.document import domain_path

    text = generate(args.kind, seed=args.seed, preset_name=args.preset, robots=args.robots, goals=args.goals,
                    others=args.others)
    if not args.output:
        sys.stdout.write(text)
        return EXIT_OK
    if os.path.exists(args.output) and os.path.samefile(args.output, domain_path(args.kind)):
        raise InputError([Diagnostic("E000", f"will not overwrite the domain the generator reads: {args.output}")])
    folder = os.path.dirname(os.path.abspath(args.output))
    import tempfile

    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(prefix=".mrgc-generate-", suffix=".tmp", dir=folder)
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.replace(tmp, args.output)
    except OSError as exc:
        raise InputError([Diagnostic("E000", f"cannot write {args.output}: {exc.strerror or exc}")]) from None
    finally:
        if tmp is not None and os.path.exists(tmp):
            os.unlink(tmp)
    print(f"{args.output}: {args.kind} problem written")
    return EXIT_OK


def cmd_backends(args: argparse.Namespace) -> int:
    import json

    from mrgc.backends.registry import describe, feature_table

    rows = describe()
    if args.format == "json":
        print(json.dumps(rows, indent=2))
        return EXIT_OK
    for r in rows:
        state = f"installed ({r['library']} {r['version']})" if r["installed"] else f"missing: pip install {r['library']}"
        print(f"{r['name']:6} {r['title']}: {state}; encodings: {', '.join(r['encodings'])}")
    print()
    print(feature_table())
    return EXIT_OK


def threading_main() -> bool:
    """Whether this is the main thread (only it may install signal handlers)."""
    import threading

    return threading.current_thread() is threading.main_thread()


# ---------------------------------------------------------------- wiring
def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="mrgc", description="Multi-robot geometric task-and-motion planning compiler and solver.")
    parser.add_argument("--version", action="version", version=f"mrgc {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    p = sub.add_parser("check", help="parse and check .mrg files, reporting every error at once")
    p.add_argument("files", nargs="+", metavar="FILE")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing for files that are fine")
    p.set_defaults(func=cmd_check)

    p = sub.add_parser("fmt", help="print a .mrg file in canonical form")
    p.add_argument("files", nargs="+", metavar="FILE")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument("--check", action="store_true", help="exit 1 if a file is not canonically formatted")
    mode.add_argument("--write", action="store_true", help="rewrite files in place")
    p.set_defaults(func=cmd_fmt)

    p = sub.add_parser("facts", help="phase 1: compute the geometric facts of a problem and write it with :init completed")
    p.add_argument("file", metavar="FILE")
    p.add_argument("-o", "--output", metavar="OUT", help="write here (default: standard output)")
    p.add_argument("--problem", help="which problem of the file (default: its only one)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--workers", type=int, default=None, help="processes (default: one per robot, at most one per core)")
    p.add_argument("--stats", action="store_true", help="also print timing statistics as JSON")
    p.set_defaults(func=cmd_facts)

    p = sub.add_parser("compile", help="build the task graph and generate task skeletons with a solver backend")
    p.add_argument("file", metavar="FILE")
    p.add_argument("--problem", help="which problem of the file (default: its only one)")
    p.add_argument("--backend", default="cpsat", help="mip | smt | pysmt | cpsat (default cpsat; see mrgc backends)")
    p.add_argument("--encoding", default="time-of-move",
                   help="paper | disaggregated | time-of-move (default time-of-move)")
    p.add_argument("--skeletons", type=int, default=1, metavar="K", help="how many skeletons (default 1)")
    p.add_argument("--max-makespan", type=int, default=None, metavar="T",
                   help="horizon limit (default: the number of objects in the task graph)")
    p.add_argument("--time-limit", type=float, default=None, metavar="S", help="seconds for the whole search")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--emit", metavar="PATH", help="also write the model: .lp/.mps (mip), .smt2 (smt), .pbtxt (cpsat)")
    p.add_argument("--format", choices=["text", "json"], default="text")
    p.set_defaults(func=cmd_compile)

    p = sub.add_parser("plan", help="plan end to end: facts, skeletons, MCTS with reverse-search grounding")
    p.add_argument("file", metavar="FILE")
    p.add_argument("--problem", help="which problem of the file (default: its only one)")
    p.add_argument("-o", "--output", metavar="PLAN", help="write the plan JSON here (default: standard output)")
    p.add_argument("--planner", default="mcts", metavar="NAME",
                   help="mcts (the paper's method, default) | ap1 (its baseline Ap1; docs/baselines.md)")
    p.add_argument("--backend", default="cpsat")
    p.add_argument("--encoding", default="time-of-move")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--time-limit", type=float, default=60.0, metavar="S")
    p.add_argument("--skeletons", type=int, default=5, metavar="K", help="skeletons per generator call (default 5)")
    p.add_argument("--max-makespan", type=int, default=None, metavar="T")
    p.add_argument("-c", type=float, default=1.0, help="PUCT exploration constant (default 1)")
    p.add_argument("--alpha", type=float, default=1.0, help="reward weight of fewer moved objects (default 1)")
    p.add_argument("--anytime", action="store_true",
                   help="keep searching after the first plan until the time limit; return the best "
                        "(makespan, then objects moved)")
    p.add_argument("-v", "--verbose", action="store_true", help="print a search log line per grounded skeleton")
    p.set_defaults(func=cmd_plan)

    p = sub.add_parser("validate", help="independently re-check a plan: replay it in pybullet, check every step")
    p.add_argument("file", metavar="FILE", help="the problem file the plan was made for")
    p.add_argument("plan", metavar="PLAN", help="the plan JSON (mrgc plan -o PLAN)")
    p.add_argument("--problem", help="which problem of the file (default: the one the plan names, else its only one)")
    p.add_argument("--format", choices=["text", "json"], default="text")
    p.set_defaults(func=cmd_validate)

    p = sub.add_parser("generate", help="write a random problem: packaging (arms, table, bins) or box-moving (rooms)")
    p.add_argument("kind", choices=["packaging", "box-moving"])
    p.add_argument("--robots", type=int, default=None, metavar="N",
                   help="arms 2-6 (packaging), carts 1-4 (box-moving); default 2")
    p.add_argument("--goals", type=int, default=None, metavar="G", help="goal objects (default 3)")
    p.add_argument("--others", type=int, default=None, metavar="K", help="other objects (default 2)")
    p.add_argument("--preset", metavar="NAME", help="a suite of the paper: pa5, pa7, pa10, pa18 (--robots 2-6) "
                   "(packaging), bo8 (box-moving); fixes the counts (docs/generators.md)")
    p.add_argument("--seed", type=int, default=0, metavar="S")
    p.add_argument("-o", "--output", metavar="FILE", help="write here (default: standard output)")
    p.set_defaults(func=cmd_generate)

    p = sub.add_parser("backends", help="list solver backends: installed?, versions, encodings, features")
    p.add_argument("--format", choices=["text", "json"], default="text")
    p.set_defaults(func=cmd_backends)

    from mrgc.render.command import add_commands as add_render_commands

    add_render_commands(sub)  # render, graph

    from mrgc.bench.command import add_bench_parser

    add_bench_parser(sub)  # bench run, bench report
    return parser


EXIT_TERMINATED = 143


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the process is (like Ctrl-C) so that every command stops the same way."""


_SIGNALLED: list[int] = []  # SIGTERM seen (a search that stops on it reports "interrupted")


def _on_sigterm(signum: int, frame: object) -> None:
    _SIGNALLED.append(signum)
    raise Terminated()


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit code (the console script exits with it)."""
    import signal

    parser = build_parser()
    try:
        if threading_main():
            signal.signal(signal.SIGTERM, _on_sigterm)
        args = parser.parse_args(argv)
        if not getattr(args, "func", None):
            parser.print_help()
            return EXIT_INPUT
        func: Callable[[argparse.Namespace], int] = args.func
        return func(args)
    except SystemExit as exc:  # argparse --help / --version / usage errors
        return exc.code if isinstance(exc.code, int) else EXIT_INPUT
    except InputError as exc:
        _report(exc)
        return exc.exit_code
    except MrgcError as exc:
        print(f"mrgc: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except Terminated:
        print("mrgc: terminated (SIGTERM)", file=sys.stderr)
        return EXIT_TERMINATED
    except KeyboardInterrupt:
        print("mrgc: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        return EXIT_OK
    except Exception as exc:  # noqa: BLE001 - the promise is: never a traceback
        print(f"mrgc: internal error[E070]: {type(exc).__name__}: {exc} "
              "(please report this with the input that caused it)", file=sys.stderr)
        return EXIT_INTERNAL


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
