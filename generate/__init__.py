"""Instance generators: random, valid ``.mrg`` problems in the shipped domains, for problems nobody tuned.

- :func:`packaging`: Panda arms around a table, objects packed in a start region, bins, handover points.
- :func:`box_moving`: rooms, walls and doorways, carts, boxes to carry to another room.
- :func:`preset`: the paper's suites (PA5, PA7, PA10, PA18 with 2-6 arms, BO8) as seeded layouts.

All return the text of a self-contained file (the shipped domain inlined); the same arguments give the
same text.  ``mrgc generate KIND ...`` is the command line (:func:`generate`); docs/generators.md says
what is guaranteed.
"""

from __future__ import annotations

from mrgc.generate.box_moving import box_moving
from mrgc.generate.packaging import packaging
from mrgc.generate.presets import PRESETS, preset
from mrgc.generate.sampling import usage_error

#: kind name (as on the command line) -> generator
KINDS = {"packaging": packaging, "box-moving": box_moving}

#: the command line's counts when none is given (without --preset)
DEFAULT_COUNTS = {"robots": 2, "goals": 3, "others": 2}


def generate(
    kind: str,
    seed: int = 0,
    preset_name: str | None = None,
    robots: int | None = None,
    goals: int | None = None,
    others: int | None = None,
) -> str:
    """What ``mrgc generate KIND`` writes: a random problem of ``kind`` with the given counts (None: the
    defaults of :data:`DEFAULT_COUNTS`), or instance ``seed`` of suite ``preset_name``, whose counts are
    fixed (only ``robots``, for suites that take several).  InputError E000 for a bad combination."""
    if preset_name is None:
        counts = {"robots": robots, "goals": goals, "others": others}
        return KINDS[kind](seed=seed, **{k: DEFAULT_COUNTS[k] if v is None else v for k, v in counts.items()})
    suite = PRESETS.get(preset_name)
    if suite is not None and suite.kind != kind:
        raise usage_error(f"--preset {preset_name} is a {suite.kind} suite, not {kind}")
    for flag, value in (("--goals", goals), ("--others", others)):
        if value is not None:
            raise usage_error(f"{flag} is fixed by --preset {preset_name}")
    return preset(preset_name, seed=seed, robots=robots)


__all__ = ["DEFAULT_COUNTS", "KINDS", "PRESETS", "box_moving", "generate", "packaging", "preset"]
