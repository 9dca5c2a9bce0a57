"""Instances: a study's ``instances:`` entries expanded into checked problem files with content hashes.

- ``file:`` is one instance, ``glob:`` one per match (sorted), both relative to the study file's folder;
- ``generate:`` runs ``mrgc generate KIND --option value ... --seed S`` (the command line's own parser
  and code, :mod:`mrgc.commands`, in this process) once per generator seed and writes
  ``WORK/instances/SET/SET-sS.mrg``, rewriting the file only when its text changed.  The generator is
  deterministic, so a study regenerates the same files on every machine.

Every instance is parsed and checked once here (a bad file is reported before any run starts, exit 2),
which also gives the robots' base types for the path-length measure.  An instance's **content hash** is
the sha256 of its file and of the file defining its domain when that is another file (``domain.mrg``
beside it): the results database keys runs by it, so an edited instance is a new instance.
"""

from __future__ import annotations

import contextlib
import glob as globbing
import hashlib
import io
import os
import re
from dataclasses import dataclass

from mrgc.bench.runner import read_text as _read
from mrgc.bench.study import InstanceSpec, Study
from mrgc.errors import Diagnostic, InputError, MrgcError

#: diagnostic code: an instance entry names no usable file or its generator call is rejected
E_INSTANCE = "E602"


@dataclass(frozen=True)
class Instance:
    """One problem file of a study.  ``set`` is its instance set (the entry's name, the report's row
    label) and ``set_index`` that entry's position in the study; ``bases`` maps each robot to its kind's
    base type (``fixed`` arm, ``planar`` base, ``""`` in a symbolic problem); ``files`` are the texts a
    remote worker needs (the file itself and a domain file beside it), by base name."""

    name: str
    set: str
    set_index: int
    path: str
    problem: str | None
    sha256: str
    bases: tuple[tuple[str, str], ...]
    files: tuple[tuple[str, str], ...]


def expand_instances(study: Study, work: str) -> list[Instance]:
    """Every instance of ``study`` in study order, generating files under ``work/instances``.

    :class:`~mrgc.errors.InputError` (E602 located in the study, or the ``.mrg`` file's own diagnostics)
    if an entry yields no usable file."""
    out: list[Instance] = []
    diags: list[Diagnostic] = []
    seen_names: dict[str, str] = {}
    seen_hash: dict[str, str] = {}
    for index, spec in enumerate(study.instances):
        try:
            files = _files(study, spec, work)
        except InputError as exc:
            diags += exc.diagnostics
            continue
        for name, path in files:
            inst = _instance(name, spec, index, path)
            clash = seen_names.get(inst.name) or seen_hash.get(inst.sha256)
            if clash is not None:
                what = "name" if inst.name in seen_names else "content"
                diags.append(
                    Diagnostic(
                        E_INSTANCE,
                        f"instance '{inst.name}' ({path}) has the same {what} as "
                        f"instance '{clash}': each run is keyed by the instance's content",
                        spec.span,
                    )
                )
                continue
            seen_names[inst.name] = inst.name
            seen_hash[inst.sha256] = inst.name
            out.append(inst)
    if diags:
        raise InputError(diags, {study.path: study.text})
    return out


def _files(study: Study, spec: InstanceSpec, work: str) -> list[tuple[str, str]]:
    """(instance name, path) of the entry's files."""
    if spec.kind != "generate":
        return instance_files(spec, study.folder)
    return _generated(spec, os.path.join(work, "instances", spec.name))


def instance_files(spec: InstanceSpec, folder: str) -> list[tuple[str, str]]:
    """(instance name, path) of a ``file:`` or ``glob:`` entry, relative to the study's ``folder``; InputError
    E602 located at the entry when the file does not exist or the glob matches no problem file (the study
    checker asks it too, so that every error of a study is reported at once)."""

    def missing(message: str) -> InputError:
        return InputError([Diagnostic(E_INSTANCE, message, spec.span)])

    if spec.kind == "file":
        path = os.path.join(folder, spec.source)
        if not os.path.isfile(path):
            raise missing(f"instance file '{spec.source}' not found (looked for {path})")
        return [(spec.name, path)]
    if spec.kind == "glob":
        paths = sorted(
            p
            for p in globbing.glob(os.path.join(folder, spec.source), recursive=True)
            if os.path.isfile(p) and p.endswith(".mrg") and os.path.basename(p) != "domain.mrg"
        )
        if not paths:
            raise missing(f"glob '{spec.source}' matches no problem file (.mrg, domain.mrg excluded) in {folder}")
        return [(re.sub(r"[^A-Za-z0-9_.+-]", "-", os.path.splitext(os.path.basename(p))[0]), p) for p in paths]
    raise ValueError(f"not a file or glob entry: {spec.kind}")


def _generated(spec: InstanceSpec, folder: str) -> list[tuple[str, str]]:
    """(instance name, path) of a ``generate:`` entry's files, written into ``folder``."""
    os.makedirs(folder, exist_ok=True)
    out = []
    for seed in spec.seeds:
        name = f"{spec.name}-s{seed}"
        path = os.path.join(folder, name + ".mrg")
        text = generate(spec, seed)
        if _read(path) != text:
            tmp = path + ".mrgc-tmp"
            with open(tmp, "w", encoding="utf-8") as fh:
                fh.write(text)
            os.replace(tmp, path)
        out.append((name, path))
    return out


def generator_args(spec: InstanceSpec, seed: int) -> list[str]:
    """The ``mrgc generate`` arguments of a generated instance (without ``-o``)."""
    args = ["generate", spec.source]
    for key, value in spec.options:
        flag = f"-{key}" if len(key) == 1 else "--" + key.replace("_", "-")
        if isinstance(value, bool):
            args += [flag] if value else []
        else:
            args += [flag, str(value)]
    return args + ["--seed", str(seed)]


def generate(spec: InstanceSpec, seed: int) -> str:
    """The text ``mrgc generate`` prints for the entry and ``seed`` (run in this process); InputError E602
    located at the entry when the command line rejects the call."""
    from mrgc.commands import build_parser

    args = generator_args(spec, seed)
    err, out = io.StringIO(), io.StringIO()
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
            ns = build_parser().parse_args(args)
            ns.func(ns)
    except SystemExit:
        lines = [ln for ln in err.getvalue().splitlines() if "error" in ln] or err.getvalue().splitlines()[-1:]
        message = lines[-1].split("error[E000]: ", 1)[-1] if lines else "rejected"
        raise InputError([Diagnostic(E_INSTANCE, f"mrgc {' '.join(args)}: {message}", spec.span)]) from None
    except MrgcError as exc:
        raise InputError([Diagnostic(E_INSTANCE, f"mrgc {' '.join(args)}: {exc}", spec.span)]) from None
    return out.getvalue()


def _instance(name: str, spec: InstanceSpec, index: int, path: str) -> Instance:
    from mrgc.language.loader import parse_file

    problem = parse_file(path).problem(spec.problem)  # InputError with the file's diagnostics
    digest = hashlib.sha256()
    files: list[tuple[str, str]] = []
    sources = [path]
    dom = problem.domain.source
    if dom and os.path.abspath(dom) != os.path.abspath(path):
        sources.append(dom)
    for src in sources:
        with open(src, "rb") as fh:
            data = fh.read()
        digest.update(data)
        if os.path.dirname(os.path.abspath(src)) == os.path.dirname(os.path.abspath(path)):
            files.append((os.path.basename(src), data.decode("utf-8")))
    bases = tuple((r.name, problem.domain.kind(r.kind).base if r.kind else "") for r in problem.robots)
    return Instance(
        name, spec.name, index, os.path.abspath(path), spec.problem, digest.hexdigest(), bases, tuple(files)
    )
