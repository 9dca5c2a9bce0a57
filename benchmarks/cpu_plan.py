"""`mrgc plan` with its clock in CPU seconds of the planning process: the time limit, the log's times and the
plan's statistics count what this process computed, not the wall clock (phase 1's worker processes are not
counted).  On a machine others load, a comparison of two trees then does not depend on how busy it was (the
same seed gives the same plan under both clocks; only where the limit cuts differs).

    python benchmarks/cpu_plan.py FILE --seed 0 --time-limit 120 -o plan.json   # the options of mrgc plan

benchmarks/generated.py --cpu-time runs every plan this way.
"""

from __future__ import annotations

import sys
import time

if __name__ == "__main__":
    time.perf_counter = time.process_time  # every deadline and timing of the planner reads this clock
    from mrgc.cli import main

    sys.exit(main(["plan", *sys.argv[1:]]))
