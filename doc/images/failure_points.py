#!/usr/bin/env python3
# SPDX-License-Identifier: LGPL-2.1-or-later
"""Map where the failure points lie: doc/images/failure-points.png.

    benchmarks/run failure-points            # writes failure-points.csv here
    /usr/bin/python3 doc/images/failure_points.py failure-points.csv

One panel per material and probe: every target of the survey in the
active node's displacement space, seen from the side (x: left-right,
z: up-down, cm; the probe pushes into the liver towards -z), marked by
outcome: converged, no equilibrium found on the path, solver-caused.
"""
import csv
import sys
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

source = Path(sys.argv[1] if len(sys.argv) > 1 else "failure-points.csv")
target = Path(__file__).resolve().parent / "failure-points.png"
rows = defaultdict(list)
for r in csv.DictReader(source.open()):
    rows[(r["material"], float(r["probe_mm"]))].append(r)

names = {"stvk": "St.Venant-Kirchhoff", "nh": "neo-Hookean", "mr": "Mooney-Rivlin"}
keys = sorted(rows, key=lambda k: (["stvk", "nh", "mr"].index(k[0]), k[1]))
materials = [m for m in ["stvk", "nh", "mr"] if any(k[0] == m for k in keys)]
probes = sorted({k[1] for k in keys})
fig, axes = plt.subplots(len(probes), len(materials),
                         figsize=(4 * len(materials), 4 * len(probes)),
                         squeeze=False, sharex=True, sharey=True)
style = {"converged": dict(c="0.8", s=4, marker="o", label="converged"),
         "no-equilibrium": dict(c="k", s=10, marker="x",
                                label="no equilibrium found on the path"),
         "solver": dict(c="r", s=30, marker="*", label="solver-caused")}
for (material, probe), points in rows.items():
    ax = axes[probes.index(probe)][materials.index(material)]
    for outcome, st in style.items():
        sel = [p for p in points if p["outcome"] == outcome]
        ax.scatter([100 * float(p["x"]) for p in sel],
                   [100 * float(p["z"]) for p in sel], **st)
    failed = sum(p["outcome"] != "converged" for p in points)
    ax.set_title(f"{names[material]}, "
                 f"{'point probe' if probe == 0 else f'tip {probe:g} mm'}\n"
                 f"{100 * failed / len(points):.1f} % failure points")
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
for ax in axes[-1]:
    ax.set_xlabel("x (cm)")
for row in axes:
    row[0].set_ylabel("z (cm): push into the liver is down")
axes[0][0].legend(loc="lower left", fontsize=8)
fig.suptitle("Failure points of the 10 cm state space, liver501 "
             "(benchmarks/run failure-points)")
fig.tight_layout()
fig.savefig(target, dpi=80)
print(f"wrote {target}")
