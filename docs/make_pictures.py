"""Make every picture of the documentation from the shipped files: docs/img/*.

    python docs/make_pictures.py             # all pictures (plans pa5 and the tutorial's problem first)
    python docs/make_pictures.py tutorial    # only the tutorial's

Nothing in docs/img is drawn by hand: each file below is written by one mrgc command run here, from
domains/ and docs/tutorial/, with fixed seeds (the planner is deterministic, so the same files come out).
Run from anywhere; plans and facts go to a temporary folder.
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
IMG = ROOT / "docs" / "img"
TUTORIAL = ROOT / "docs" / "tutorial"

#: picture -> the commands that make it ({tmp}: the temporary folder, {img}: docs/img)
PICTURES: dict[str, list[list[str]]] = {
    "tutorial-scene.png": [
        ["render", "{tutorial}/two-arms.mrg", "-o", "{img}/tutorial-scene.png", "--size", "480x360"]
    ],
    "tutorial-reach.png": [
        ["render", "{tutorial}/two-arms.mrg", "--reach", "-o", "{img}/tutorial-reach.png", "--size", "760x560"]
    ],
    "tutorial-cmtg.svg": [
        ["facts", "{tutorial}/two-arms.mrg", "-o", "{tmp}/two-arms.facts.mrg"],
        ["graph", "{tmp}/two-arms.facts.mrg", "-o", "{img}/tutorial-cmtg.svg", "--skeleton", "1"],
    ],
    "tutorial-replay.gif": [
        ["plan", "{tmp}/two-arms.facts.mrg", "-o", "{tmp}/two-arms.plan.json"],
        [
            "render",
            "{tmp}/two-arms.facts.mrg",
            "{tmp}/two-arms.plan.json",
            "-o",
            "{img}/tutorial-replay.gif",
            "--size",
            "360x270",
            "--fps",
            "8",
        ],
    ],
    "tutorial-sheet.png": [
        [
            "render",
            "{tmp}/two-arms.facts.mrg",
            "{tmp}/two-arms.plan.json",
            "-o",
            "{img}/tutorial-sheet.png",
            "--size",
            "240x180",
        ]
    ],
    "tutorial-gantt.svg": [
        ["render", "{tmp}/two-arms.facts.mrg", "{tmp}/two-arms.plan.json", "-o", "{img}/tutorial-gantt.svg"]
    ],
    "pa5.gif": [
        ["plan", "{domains}/packaging/pa5.mrg", "-o", "{tmp}/pa5.plan.json"],
        [
            "render",
            "{domains}/packaging/pa5.mrg",
            "{tmp}/pa5.plan.json",
            "-o",
            "{img}/pa5.gif",
            "--size",
            "400x300",
            "--fps",
            "10",
        ],
    ],
}
#: the README's GIF must stay small
MAX_README_GIF = 2 * 2**20


def main(argv: list[str]) -> int:
    from mrgc import cli

    only = [name for name in PICTURES if not argv or any(name.startswith(a) for a in argv)]
    IMG.mkdir(exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="mrgc-pictures-") as tmp:
        where = {"tmp": tmp, "img": str(IMG), "tutorial": str(TUTORIAL), "domains": str(ROOT / "domains")}
        for name in only:
            for command in PICTURES[name]:
                args = [a.format(**where) for a in command]
                print(
                    "mrgc " + " ".join(os.path.relpath(a, ROOT) if a.startswith("/") else a for a in args), flush=True
                )
                code = cli.main(args)
                if code != 0:
                    print(f"failed with exit code {code}", file=sys.stderr)
                    return code
    gif = IMG / "pa5.gif"
    if gif.exists() and gif.stat().st_size > MAX_README_GIF:
        print(f"{gif} is {gif.stat().st_size} bytes, more than {MAX_README_GIF}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
