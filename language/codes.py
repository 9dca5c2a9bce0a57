"""The catalogue of diagnostic codes of the ``.mrg`` front end, as data.

Each code names one check.  docs/errors.md documents every code with an example, and a golden test
(tests/golden/errors/E###.mrg) triggers each one; a test asserts the three stay in step.
"""

from __future__ import annotations

CODES: dict[str, str] = {
    # reading the file
    "E001": "file cannot be read",
    "E002": "file is larger than the size limit",
    "E003": "file is not UTF-8 text",
    "E004": "file defines nothing",
    # syntax
    "E100": "unexpected character",
    "E101": "unexpected token",
    "E102": "unexpected end of file",
    "E103": "unknown section",
    # names
    "E200": "duplicate name",
    "E201": "duplicate section",
    "E202": "duplicate property",
    "E210": "undeclared robot",
    "E211": "undeclared movable object",
    "E212": "undeclared region",
    "E213": "undeclared grasp",
    "E214": "undeclared robot kind",
    "E215": "undeclared handover point",
    "E216": "name of the wrong sort",
    # predicates and goals
    "E220": "unknown predicate",
    "E221": "wrong number of arguments",
    "E222": "goal names a fixed object",
    "E223": "goal is not an in-region literal",
    "E224": "contradictory goals",
    "E225": "empty goal",
    "E226": "missing goal",
    "E227": "grasp not allowed for this object",
    "E228": "initial region missing or ambiguous",
    # domains and includes
    "E230": "missing domain",
    "E231": "ambiguous domain",
    "E232": "include cycle",
    "E233": "include leaves the problem's folder tree",
    "E234": "included file not found",
    "E235": "unknown requirement",
    # numbers, vectors, properties
    "E250": "non-positive size",
    "E251": "non-finite number",
    "E252": "vector of the wrong length",
    "E253": "property value of the wrong type",
    "E254": "unknown property",
    "E255": "missing property",
    "E256": "unknown shape",
    "E257": "unknown base type",
    "E258": "mesh file not found",
    # symbolic vs geometric
    "E260": "robot of a geometric problem lacks a kind",
    "E261": "symbolic problem mixes in geometry",
    "E262": "geometric declaration lacks its shape or pose",
}
