#!/usr/bin/env python3
# SPDX-License-Identifier: LGPL-2.1-or-later
"""Plot the state time against the unknowns from the CSV that
`benchmarks/run organ-speed --scaling --csv FILE` writes:

    /usr/bin/python3 doc/images/organ-speed.py scaling.csv doc/images/organ-speed.png

One line per lever configuration (the unchanged solver, and every lever on),
log-log, with the least-squares exponent of state time ~ unknowns^p, and the
issue's targets (30 ms at 1,500 nodes, 100 ms at 4,000 nodes) as marks.
Several CSV files may be given before the PNG (e.g. a run of the unchanged
solver with OPENBLAS_CORETYPE=Prescott, the BLAS kernels palpate used
before it chose them: its lines are labelled so).
Needs matplotlib (Debian: python3-matplotlib)."""
import csv, math, sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

if len(sys.argv) < 3:
    sys.exit(__doc__)
rows = []
for name in sys.argv[1:-1]:
    for r in csv.DictReader(open(name)):
        if "prescott" in name.lower():
            r["lever"] += " (generic Prescott BLAS kernels)"
        rows.append(r)
names = {"unchanged": "unchanged solver",
         "+single precision": "every lever on"}
fig, ax = plt.subplots(figsize=(6.5, 4.5))
for lever in dict.fromkeys(r["lever"] for r in rows):
    s = sorted((r for r in rows if r["lever"] == lever), key=lambda r: int(r["unknowns"]))
    n = [int(r["unknowns"]) for r in s]
    t = [float(r["state_ms"]) for r in s]
    x = [math.log(v) for v in n]
    y = [math.log(v) for v in t]
    mx, my = sum(x) / len(x), sum(y) / len(y)
    p = sum((a - mx) * (b - my) for a, b in zip(x, y)) / sum((a - mx) ** 2 for a in x)
    label = names.get(lever, lever)
    if lever.startswith("unchanged ("):
        label = "unchanged solver, generic (Prescott) BLAS kernels"
    ax.loglog(n, t, "o-", label="%s: ~ unknowns^%.2f" % (label, p))
    for r, a, b in zip(s, n, t):
        ax.annotate("%s nodes" % r["nodes"], (a, b), fontsize=7,
                    textcoords="offset points", xytext=(4, -10))
# The targets, at the unknowns of Mooney-Rivlin P1-P1 (4.3 per node).
ax.plot([1500 * 4.33], [30], "v", color="grey", label="target 30 ms (1,500 nodes)")
ax.plot([4000 * 4.33], [100], "v", color="black", label="target 100 ms (4,000 nodes)")
ax.set_xlabel("unknowns (Mooney-Rivlin P1-P1 with contact multipliers)")
ax.set_ylabel("median state from a neighbour, one core (ms)")
ax.set_title("Liver + 1 cm sphere: cost of a state against the mesh")
ax.legend(fontsize=7.5, loc="upper left")
fig.tight_layout()
fig.savefig(sys.argv[-1], dpi=110)
