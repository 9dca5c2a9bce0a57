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
    "E104": "unclosed parenthesis",
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
    "E229": "fact relates a thing to itself",
    "E217": "relay into the object's goal region",
    # domains and includes
    "E230": "missing domain",
    "E231": "ambiguous domain",
    "E232": "include cycle",
    "E233": "include leaves the problem's folder tree",
    "E234": "included file not found",
    "E235": "unknown requirement",
    "E236": "geometry file outside the problem's folder tree",
    # grasps
    "E240": "unknown axis",
    "E241": "grasp axes not perpendicular",
    "E242": "negative grasp depth",
    "E243": "grasp without geometry",
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
    "E259": "number out of range",
    # symbolic vs geometric
    "E260": "robot of a geometric problem lacks a kind",
    "E261": "symbolic problem mixes in geometry",
    "E262": "geometric declaration lacks its shape or pose",
    # the start layout of a geometric problem (geometry/layout.py)
    "E263": "home configuration that does not fit the arm",
    "E264": "movable objects overlap at the start",
    "E265": "movable object overlaps a fixed object at the start",
    "E266": "robot overlaps an object at the start",
    "E267": "mesh with no triangle",
    "E268": "mesh not centred on its origin",
    "E269": "region that is not a box",
    # warnings (the file is accepted)
    "W270": "grasp wider than the gripper",
    "W271": "object in no region",
    "W272": "region outside every robot's workspace",
    "W273": "no tool centre point",
    "W274": "every configuration of an arm collides",
    "W275": "an arm's home configuration collides",
    "W276": "IK finds no solution for an arm",
    "W277": "region floor that holds nothing up",
    "W278": "object no robot can carry",
    "W279": "goal object too tall for its goal region",
}

#: codes that are warnings: reported, but the input is accepted (exit code 0)
WARNINGS = frozenset(c for c in CODES if c.startswith("W"))

#: codes the CLI itself uses (not produced by the front end)
CLI_CODES: dict[str, str] = {
    "E000": "bad command line",
    "E005": "output file is an input of the command",
    "E006": "output file cannot be written",
    "E070": "internal error",
    "E300": "backend cannot export this format",
    "E301": "unknown backend",
    "E302": "backend does not support the encoding",
    "E303": "unknown encoding",
    "E304": "nothing to export: the goals hold at the start",
    "E400": "robot URDF not found or unreadable",
    "E401": "end-effector link not in the URDF",
    "E402": "geometry asked of a symbolic problem",
    "E403": "mesh file unreadable or invalid",
    "E500": "plan file cannot be read",
    "E501": "plan file is not JSON",
    "E502": "plan does not follow the plan schema",
    "E503": "unsupported plan schema version",
    "E510": "plan does not fit the problem",
    "E504": "plan file beyond a reading limit",
    "E600": "study file cannot be read or is not YAML",
    "E601": "study does not follow the study schema",
    "E602": "study instance not found or not generated",
    "E603": "results database cannot be used",
}

#: what each code means and how to fix it (docs/errors.md is generated from this and the golden files)
HELP: dict[str, str] = {
    "E000": "The command line is wrong (unknown option, missing argument). `mrgc COMMAND --help` shows usage.",
    "E005": "An output path (`-o`, `--emit`) names a file the command reads: the problem file, its domain, "
    "an include, a mesh or a URDF (also through a symlink or a hard link). Writing it would destroy the input; "
    "choose another output file.",
    "E006": "An output path that cannot be written: a folder, a FIFO or device, a file under a folder that "
    "does not exist or is not writable. Checked before any work is done. Outputs are written to a temp file "
    "in the target's folder and renamed over it (docs/cli.md).",
    "E070": "A bug in mrgc. The message names the Python exception; please report it with the input.",
    "E300": "`--emit` names a file type the backend does not write (mip: .lp .mps; smt: .smt2; cpsat: "
    ".pbtxt). The message is followed by the backend × feature table.",
    "E301": "`--backend` names no registered backend; `mrgc backends` lists them.",
    "E302": "The backend cannot run the chosen encoding.",
    "E303": "`--encoding` is one of `paper`, `disaggregated`, `time-of-move`.",
    "E304": "`compile --emit` without `--horizon` writes the model whose optimum is the first skeleton; when the "
    "goals already hold, the first skeleton is empty (makespan 0), and the `paper` and `disaggregated` encodings "
    "have no model with that optimum (their models of T steps never leave a step empty: the model of one step "
    "has no solution). Nothing is written; give `--horizon H` (the API's `horizon=H`) for the model of H steps, "
    "or use `--encoding time-of-move`, whose model of one step has the empty skeleton as its optimum.",
    "E400": "A robot kind's `:urdf` names no readable URDF (looked up beside the .mrg file, then in "
    "pybullet_data), or pybullet refuses the file (a URDF of one's own is loaded into pybullet to be checked "
    "once per version of the file; pybullet_data's own files are not, as pybullet ships them and the "
    "validator loads them anyway).",
    "E401": "A robot kind's `:end-effector` is not a link of its URDF; the message lists the links.",
    "E403": "A mesh file (of a `(mesh ...)` shape or of a URDF link) that cannot be used: not a regular file, "
    "too large, a coordinate that is not a finite number or beyond 10 km (after scaling), a face naming a "
    "vertex that does not exist. The message gives the file and line.",
    "E402": "`mrgc facts` (or another geometric command) was run on a symbolic problem, which has no geometry.",
    "E500": "`mrgc validate FILE PLAN`: the plan file does not exist, is a folder, is not UTF-8 text or cannot "
    "be read.",
    "E501": "The plan file is not JSON (empty, truncated, or not a plan at all); the message gives the line and "
    "column where reading stopped.",
    "E502": "The plan is JSON but does not follow `docs/plan.schema.json` (`mrgc-plan/1`): a required field is "
    "missing, has the wrong type, or holds an unknown value; the message names the first such field.",
    "E503": "The plan's `schema` names another plan format version than the one this mrgc reads "
    "(`mrgc-plan/1`); plan again, or validate with the mrgc that wrote it.",
    "E510": "`mrgc render FILE PLAN`: the plan names an object, robot, region or grasp the problem does not have, "
    "a planar robot with a grasp it cannot use, configurations of the wrong size, or a configuration or "
    "placement number that is not finite or beyond 10,000 (the bound on any number of a problem, E259): it was "
    "made for another problem (or edited by hand). `mrgc validate FILE PLAN` lists every difference.",
    "E504": "The plan file is larger than 32 MiB, nests arrays and objects more than 32 deep, holds an integer "
    "of more than 20 digits or a number beyond double precision (such as `1e999`). Checked before or while the "
    "JSON is parsed, so no plan can exhaust memory or recursion; a plan written by `mrgc plan` stays far "
    "within these limits.",
    "E600": "`mrgc bench run STUDY`: the study file does not exist, is not UTF-8 text, is over 1 MiB, or is "
    "not YAML; the message gives the line and column where reading stopped.",
    "E601": "The study is YAML but breaks the study schema (docs/bench.md): an unknown or missing key, a value "
    "of the wrong type, a seed range that is not `a..b`, a method option `mrgc plan`/`mrgc compile` does not "
    "have, an unknown backend or encoding. Every such error is reported at once, located in the study.",
    "E602": "An instance entry yields no usable problem file: a `file:` that does not exist, a `glob:` that "
    "matches no `.mrg` file, a `generate:` call `mrgc generate` rejects, or two instances with the same "
    "name or content. (An instance file that exists but does not check reports its own diagnostics.)",
    "E603": "`--db PATH` is not a results database of this mrgc (another SQLite file, another file, a newer "
    "schema), does not exist (`bench report`), is being written by another `mrgc bench run`, or a method's "
    "definition changed under the same name since its runs were recorded (give it a new name).",
    "E001": "The file does not exist, is a folder, or cannot be read.",
    "E002": "Files above the size limit (8 MiB) are refused before parsing, so a huge input cannot stall mrgc.",
    "E003": "The file holds bytes that are not UTF-8 text, or a NUL byte: probably not a `.mrg` file.",
    "E004": "The file holds no `(define ...)` form (it is empty or only comments).",
    "E100": "A character or word that cannot start any token here, or a string with no closing quote.",
    "E101": "A token where the grammar expects something else; the message lists what may come here.",
    "E102": "The file ends inside a form: a `(` is never closed. The error points at the `(` most likely left "
    "open (the innermost one followed by a line indented no deeper than it, else the innermost one); the note "
    "says where the file ends.",
    "E103": "A section keyword that does not exist at this place; the message suggests the closest one.",
    "E104": "A `(` is not closed before the next form starts (a section such as `(:goal`, or the next "
    "`(define`): a missing `)`. The error points at the `(` left open, chosen as for E102; the note says where "
    "the parser stopped and what it expected there.",
    "E200": "Two declarations share a name. Robots, fixed and movable objects, regions and handover points "
    "share one namespace per problem; grasps and robot kinds one per domain.",
    "E201": "A section such as `:goal`, `:init` or `:robots` appears twice in one definition.",
    "E202": "A declaration gives the same `:property` twice.",
    "E210": "A fact names a robot the problem does not declare.",
    "E211": "A fact or goal names a movable object the problem does not declare.",
    "E212": "A fact or goal names a region the problem does not declare.",
    "E213": "A grasp that is not in the domain's `(:grasps ...)` vocabulary (in a geometric problem an object's "
    "`:grasps` may also name a built-in grasp: top, top-x, side-x+, side-x-, side-y+, side-y-).",
    "E214": "A robot's `:kind` that the domain does not define with `(:robot-kind ...)`.",
    "E215": "A movable object's `:handover` list names a handover point the problem does not declare.",
    "E216": "A declared name used where another sort belongs, e.g. a robot in a movable object's place.",
    "E220": "A predicate other than the nine of the language (docs/language.md): the paper's six, `enable-relay`, "
    "`occludes-handover` and `occludes-relay`.",
    "E221": "A predicate with too few or too many arguments; the message gives its signature.",
    "E222": "A goal asks to move a fixed object, which can never move.",
    "E223": "Goals are conjunctions of `(in-region OBJECT REGION)` literals only.",
    "E224": "Two goals ask for the same object in two different regions.",
    "E225": "`(:goal (and))` asks for nothing.",
    "E226": "A problem without `(:goal ...)`.",
    "E227": "A fact uses a grasp the object's `:grasps` list does not allow.",
    "E228": "In a symbolic problem every movable object needs exactly one `(in-region OBJECT REGION)` in "
    "`:init`; in any problem at most one.",
    "E229": "An object that occludes itself, a handover from a robot to itself, or a relay "
    "`(enable-relay M Re g1 g2 R1 R2)` back to the same robot with the same grasp (R1 = R2 needs g1 != g2: a "
    "regrasp).",
    "E217": "`(enable-relay M Re g1 g2 R1 R2)` names M's goal region as Re. A relay sets a goal object down on "
    "its way to the goal, in another region, where R2 picks it up again; placing M in its goal region is "
    "`reachable-place`.",
    "E230": "A problem names no domain, or a domain that is not in the file, in `domain.mrg` beside it, "
    "or in its includes; also used when a file does not hold the problem asked for.",
    "E231": "The domain's name is defined in more than one place at the same lookup level.",
    "E232": "Files that include each other in a loop.",
    "E233": "An include path that resolves outside the folder of the file being checked.",
    "E234": "An include path that names no file.",
    "E235": "A requirement flag that mrgc does not know.",
    "E236": "A mesh file of a shape, or a robot kind's `:urdf`, that lies outside the folder tree of the file "
    "being checked (URDFs may also come from pybullet_data). Like includes, geometry files are confined so a "
    "problem file cannot make mrgc read arbitrary files; `--allow-outside FOLDER` allows a folder. The mesh "
    "files a URDF names are confined the same way when the geometry is loaded.",
    "E240": "A grasp's `:approach` and `:fingers` are axis words of the object frame: `+x -x +y -y +z -z` "
    "(`x` means `+x`).",
    "E241": "A grasp's approach axis and finger axis must be perpendicular (the fingers close across the "
    "direction the hand moves in).",
    "E242": "A grasp's `:depth` (how far the tool centre point sits inside the approached face) may be 0 but "
    "not negative.",
    "E243": "In a domain with robot kinds every grasp needs geometry: a bare name must be a built-in grasp "
    "(top, top-x, side-x+, side-x-, side-y+, side-y-), any other grasp is declared as "
    "`(NAME :approach AXIS :fingers AXIS)`. Domains without robot kinds (symbolic) accept any name.",
    "E263": "A robot kind's `:home` needs one value (radians, metres for a prismatic joint) per joint of its arm, "
    "each within its joint's limits in the URDF (a value outside them was clamped, silently, by the planner and "
    "the validator alike, so every motion started and ended elsewhere than declared): the "
    "URDF's revolute, continuous and prismatic joints from the base link to the `:end-effector` link (7 for "
    "the Franka Panda; finger joints are not part of it). Checked by `mrgc check` when the URDF can be read "
    "(otherwise `mrgc facts` reports E400/E401).",
    "E264": "Two movable objects interpenetrate (by more than 1 mm) at their start poses. Objects may touch "
    "(stand side by side or on each other); move one of them.",
    "E265": "A movable object interpenetrates a fixed object (by more than 1 mm) at its start pose, e.g. sinks "
    "into the table or stands inside a wall. An object resting on a surface only touches it.",
    "E266": "A robot at its start overlaps (by more than 1 mm) a movable or fixed object: a planar robot's "
    "`:footprint` at its `:base` pose (also another planar robot's footprint), found by `mrgc check`; an arm's "
    "links at its `:home` configuration, and an arm's mount overlapping another arm's (two arms bolted at one "
    "base), found by `mrgc facts` (and `mrgc plan`), which read the arms' meshes.",
    "E267": "A `(mesh ...)` shape's file holds no triangle (an empty file, or vertices without faces): the "
    "shape has no volume, so nothing could collide with it, grasp it or set it down. Found by `mrgc check`, "
    "which reads every mesh file of the problem (a file that cannot be read at all is E403).",
    "E268": "The mesh of a movable object, or of a planar robot kind's `:footprint`, is not centred on its "
    "origin: the centre of its bounding box lies more than 1 mm from the mesh file's origin. Grasps, "
    "placements and a cart's load take such a shape's origin as its centre (an object whose origin is on its "
    "bottom face would be set down in the air, and gripped beside its middle). Move the file's vertices by "
    "the offset the message gives; a fixed object's mesh may lie anywhere about its origin.",
    "E269": "A region of a geometric problem is a box (turned by its pose's yaw): `in-region`, phase 1's "
    "placements and the grounding's are tests against that box, so a region drawn as a cylinder, a sphere or a "
    "mesh could never hold an object (planning said no robot reaches it). Give the box objects are to stand in; "
    "a fixed object (a bin's walls, a tray) may have any shape.",
    "W271": "A warning, not an error: a movable object lies in no region at its start pose (no region holds it "
    "entirely, so `in-region` holds for none). A goal object can still be moved into its goal region; any other "
    "object can never move, so if it obstructs something, that goal cannot be reached.",
    "W272": "A warning, not an error: a region is farther from the shoulder of every arm than the arm can "
    "reach (the reach bound of its URDF), so nothing can be placed in it or picked from it. Reported by "
    "`mrgc facts` (and `mrgc plan`), which read the arms' models; problems with a planar robot never get it "
    "(planar robots drive).",
    "W273": "A warning, not an error: a fixed-base robot kind has no `:tcp` and none can be derived from its "
    "URDF (no grasp-target link fixed to the end-effector link, no gripper fingers along its z axis; "
    "docs/language.md, 'Robot kinds'), so grasps put the end-effector link's origin on the object: the "
    "fingers would reach past it into the object or the table. Give `:tcp (x y z yaw)`, the point between the "
    "fingertips relative to the end-effector link.",
    "W274": "A warning, not an error: an arm collides with a fixed object wherever it goes: of 64 configurations "
    "drawn within its joint limits, one of its links collides (touching counts) with the same fixed object in "
    "every one, so phase 1 finds it no fact at all. The line names the link, the object, how deep and the height "
    "of the link's lowest point. Typical causes: the robot's `:base` sunk into the table or standing inside a "
    "wall. The links standing on the mount (the URDF's root link and every link fixed to it) are exempt from "
    "what they stand on, whatever they are called. Reported by `mrgc check`, `mrgc facts` and `mrgc plan`.",
    "W275": "A warning, not an error: an arm's `:home` configuration collides with a fixed object (touching "
    "counts) or with the arm itself; every motion of the arm starts and ends at home, so no plan can move it, "
    "whatever the facts say. Change the kind's `:home`. Reported by `mrgc check`, `mrgc facts` and `mrgc plan` "
    "(a penetration deeper than 1 mm of an object is also E266 for `facts` and `plan`).",
    "W276": "A warning, not an error: inverse kinematics finds no configuration of an arm for any grasp of any "
    "object within its reach bound, collisions ignored: the chain from the URDF's base to the `:end-effector` "
    "link cannot put that link there. Usually `:end-effector` names the wrong link (the message says how many "
    "joints its chain has) or `:tcp` is far off. Reported by `mrgc check`, `mrgc facts` and `mrgc plan`.",
    "W278": "A warning, not an error: a movable object that no planar robot of the problem (and there is no "
    "arm) can carry with any of its side grasps: at the kind's `:carry` pose (the centre's height above the "
    "floor) it would reach more than 1 mm below the floor it drives on, or into the robot's own footprint. It "
    "can never move (phase 1 gives it no fact, the validator rejects such a carry as `carry`). Raise `:carry`'s "
    "z to at least half the object's height, or move its x forward by half its depth beyond the footprint.",
    "W279": "A warning, not an error: a goal object is taller than its goal region leaves room for. Placements "
    "rest 6 mm above the region's floor (a cart's too: touching counts as colliding, and an object in hand dips a "
    "few mm while the arm moves), and the object must lie entirely inside the region, so a 0.100 m "
    "object in a 0.105 m bin has no placement at all. Make the region taller (its height is only where objects "
    "may be, not a wall).",
    "W277": "A warning, not an error: a region's floor holds nothing up. It lies neither on the ground (z = 0, or "
    "the bottom of a table slab whose top is z = 0) nor on the top of a fixed object anywhere (at most 3 mm above "
    "it: an object is set down 6 mm above the floor and may fall at most 10 mm), so an "
    "object set down in it would fall (the validator rejects it as `floating`) and the planner finds no "
    "placement in it. Usually the region's pose is a few cm too high: its floor should lie on the table's top. "
    "A floor partly over a table holds objects up only there (their centre 5 mm inside the table's top).",
    "W270": "A warning, not an error: the object is wider along the grasp's finger axis (plus the 1 cm "
    "clearance) than a robot kind's `:gripper-opening`, so robots of that kind get no facts for this "
    "(object, grasp). `mrgc check` exits 0.",
    "E250": "Sizes (box sides, radii, heights, reach, mesh scale) must be positive.",
    "E251": "A number that overflows to infinity (such as `1e999`).",
    "E252": "A pose needs 4 numbers (x y z yaw), a position 3, a shape its own count.",
    "E253": "A property value of the wrong type, e.g. a name where a quoted path belongs.",
    "E254": "A `:property` the declaration does not take; the message suggests the closest or lists them.",
    "E255": "A required property is missing (a fixed-base robot kind needs `:urdf` and `:end-effector`, "
    "a planar one `:footprint`, a declared grasp `:approach` and `:fingers`).",
    "E256": "Shapes are `box`, `cylinder`, `sphere` and `mesh`.",
    "E257": "A robot kind's `:base` is `fixed` or `planar`.",
    "E258": "A mesh file that does not exist (paths are relative to the declaring file).",
    "E259": "A number beyond 10,000 in magnitude (metres, radians: larger values are unit mistakes and "
    "overflow the geometry), or a size below 1 micrometre.",
    "E260": "In a geometric problem every robot needs a `:kind` from the domain.",
    "E261": "A problem whose movable objects have no shapes is symbolic; it may not give shapes, poses, "
    "robot bases or handover positions to anything.",
    "E262": "A problem whose movable objects have shapes is geometric; then every object and region needs "
    "`:shape` and `:pose`, every robot `:base`, every handover point `:position`.",
}
