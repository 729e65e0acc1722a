#!/usr/bin/env python3
# SPDX-License-Identifier: LGPL-2.1-or-later
"""Pareto plot of a study: force error against time.

    palpate study SCENE.prm                    # writes output/study-SCENE.csv
    /usr/bin/python3 doc/images/accuracy_pareto.py output/study-SCENE.csv out.png
    benchmarks/run accuracy                    # writes accuracy-stvk.csv, accuracy-mr.csv
    /usr/bin/python3 doc/images/accuracy_pareto.py accuracy-stvk.csv accuracy-mr.csv \\
        doc/images/accuracy-pareto.png

One panel per CSV (material): every grid-knob setting as a point, p95
relative force error (log) against the implied straight-line HIP speed
(the cost side: faster is cheaper), trilinear and Hermite marked, the
3.5 % threshold drawn, the recommended setting circled and the Pareto
front (no other setting both faster and more accurate) joined.
"""
import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

args = sys.argv[1:]
if len(args) < 2:
    sys.exit("usage: accuracy_pareto.py STUDY.csv [STUDY2.csv ...] OUT.png")
sources, target = [Path(a) for a in args[:-1]], Path(args[-1])
names = {"stvk": "St.Venant-Kirchhoff", "nh": "neo-Hookean",
         "mooney-rivlin": "Mooney-Rivlin"}
fig, axes = plt.subplots(1, len(sources), figsize=(6.5 * len(sources), 5),
                         squeeze=False)
for ax, source in zip(axes[0], sources):
    rows = [r for r in csv.DictReader(source.open())
            if r["interpolation"] != "direct"
            and int(r["covered"]) >= 0.95 * int(r["samples"])]
    material = rows[0]["material"] if rows else "?"
    style = {"trilinear": dict(marker="s", c="tab:blue"),
             "Hermite": dict(marker="o", c="tab:orange")}
    for scheme, st in style.items():
        pts = [r for r in rows if r["interpolation"] == scheme]
        ax.scatter([float(r["speed_mm_s"]) for r in pts],
                   [max(float(r["err_p95_pct"]), 1e-3) for r in pts],
                   label=scheme, s=36, **st)
        for r in pts:
            label = {"grid": "h ", "tolerance": "tol ", "increment": "inc ",
                     "combined": "h, tol "}.get(r["knob"], "") + r["value"]
            ax.annotate(label, (float(r["speed_mm_s"]),
                                     max(float(r["err_p95_pct"]), 1e-3)),
                        fontsize=7, xytext=(4, 3),
                        textcoords="offset points")
    # Pareto front: sort by speed, keep points more accurate than every
    # faster one.
    pts = sorted(rows, key=lambda r: -float(r["speed_mm_s"]))
    front, best = [], float("inf")
    for r in pts:
        e = max(float(r["err_p95_pct"]), 1e-3)
        if e < best:
            front.append((float(r["speed_mm_s"]), e))
            best = e
    ax.plot(*zip(*front), c="0.5", lw=1, ls="--", label="Pareto front")
    ax.axhline(3.5, c="r", lw=1, label="3.5 % (half the force JND)")
    for r in rows:
        if r["recommended"] == "yes":
            ax.scatter([float(r["speed_mm_s"])],
                       [max(float(r["err_p95_pct"]), 1e-3)], s=250,
                       facecolors="none", edgecolors="g", lw=2,
                       label="recommended")
    ax.set_yscale("log")
    ax.set_xlabel("implied straight-line HIP speed, 2 workers (mm/s)")
    ax.set_ylabel("p95 relative force error (%)")
    ax.set_title(names.get(material, material))
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=8, loc="lower right")
fig.tight_layout()
# The Software text chunk marks the file as this plot's: palpate study
# overwrites a PNG beside its CSV only if it carries it.
fig.savefig(target, dpi=110, metadata={"Software": "palpate study"})
print("wrote", target)
