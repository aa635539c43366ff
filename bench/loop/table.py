#!/usr/bin/env python3
"""The loop benchmark's table (bench/loop/run.sh): per run length and request, the median wall
time over the repeats, its ratio to `reprocess` of the same run (the plain least-squares fold of
the same rows), and per request the growth from the shortest to the longest run against the
growth of the run itself. A request that failed in any repeat is marked and left out of the
median."""
import csv
import statistics
import sys
from collections import defaultdict

REQUESTS = ["ingest", "reprocess", "residual", "trace", "consistency", "iv", "simex"]


def main(path):
    seconds = defaultdict(list)
    failed = defaultdict(int)
    with open(path, newline="") as f:
        for row in csv.DictReader(f, delimiter="\t"):
            key = (int(row["duration_s"]), row["request"])
            if row["exit"] == "0":
                seconds[key].append(float(row["seconds"]))
            else:
                failed[key] += 1
    durations = sorted({d for d, _ in list(seconds) + list(failed)})
    median = {k: statistics.median(v) for k, v in seconds.items() if v}
    print("request       " + "".join(f"{d:>9} s run     " for d in durations) + "  growth / run growth")
    for r in REQUESTS:
        cells = []
        for d in durations:
            m = median.get((d, r))
            base = median.get((d, "reprocess"))
            if m is None:
                cells.append(f"{'failed' if failed.get((d, r)) else '-':>19}")
            elif r in ("ingest", "reprocess") or not base:
                cells.append(f"{m:>9.2f} s         ")
            else:
                cells.append(f"{m:>9.2f} s {m / base:>5.0f}x  ")
            if failed.get((d, r)) and m is not None:
                cells[-1] = cells[-1].rstrip() + f" ({failed[(d, r)]} failed)"
        growth = ""
        first, last = durations[0], durations[-1]
        if len(durations) > 1 and (first, r) in median and (last, r) in median:
            growth = f"{median[(last, r)] / median[(first, r)]:.1f} / {last / first:.1f}"
        print(f"{r:<14}" + "".join(cells) + "  " + growth)
    print("ratios: to reprocess of the same run and model, measured beside it; medians of the repeats")


if __name__ == "__main__":
    main(sys.argv[1])
