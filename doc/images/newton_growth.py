#!/usr/bin/env python3
# SPDX-License-Identifier: LGPL-2.1-or-later
"""Plot how the cost of a state grows with the mesh, from the CSV that
`benchmarks/run newton --growth` writes:

    /usr/bin/python3 doc/images/newton_growth.py newton-growth.csv doc/images/newton-growth.png

Columns: mesh, nodes, unknowns, plain_ms, levers_ms. Log-log axes, with
the least-squares power law of each series. Needs matplotlib (Debian:
python3-matplotlib)."""
import csv, math, sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

if len(sys.argv) != 3:
    sys.exit(__doc__)
rows = list(csv.DictReader(open(sys.argv[1])))
n = [float(r["unknowns"]) for r in rows]


def fit(y):
    lx = [math.log(v) for v in n]
    ly = [math.log(v) for v in y]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    p = sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)
    return p, math.exp(my - p * mx)


fig, ax = plt.subplots(figsize=(7, 4.5))
for key, label, colour in (("plain_ms", "plain: a factorisation per Newton step", "C3"),
                           ("levers_ms", "factorisation reuse + second-order start", "C0")):
    y = [float(r[key]) for r in rows]
    p, c = fit(y)
    ax.loglog(n, y, "o", color=colour, label=f"{label} (p = {p:.2f})")
    xs = [min(n) * (max(n) / min(n)) ** (k / 50) for k in range(51)]
    ax.loglog(xs, [c * x ** p for x in xs], "-", color=colour, lw=1, alpha=0.6)
for r, x in zip(rows, n):
    ax.annotate(r["mesh"], (x, float(r["plain_ms"])), textcoords="offset points",
                xytext=(4, 4), fontsize=8)
ax.set_xlabel("unknowns (displacements and multipliers)")
ax.set_ylabel("median time per state (ms), one core")
ax.set_title("Cost of a state against mesh size (StVK, 5 mm grid steps)")
ax.grid(True, which="both", lw=0.3)
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=110)
