"""Instance generators: random, valid ``.mrg`` problems in the shipped domains, for problems nobody tuned.

- :func:`packaging`: Panda arms around a table, objects packed in a start region, bins, handover points.
- :func:`box_moving`: rooms, walls and doorways, carts, boxes to carry to another room.

Both return the text of a self-contained file (the shipped domain inlined); the same arguments give the
same text.  ``mrgc generate KIND ...`` is the command line; docs/generators.md says what is guaranteed.
"""

from mrgc.generate.box_moving import box_moving
from mrgc.generate.packaging import packaging

#: kind name (as on the command line) -> generator
KINDS = {"packaging": packaging, "box-moving": box_moving}

__all__ = ["KINDS", "box_moving", "packaging"]
