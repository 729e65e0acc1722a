#!/usr/bin/env python3
# SPDX-License-Identifier: LGPL-2.1-or-later
"""Plot the indenter's convergence study from the CSV that
`benchmarks/run convergence --csv FILE` writes:

    /usr/bin/python3 doc/images/convergence.py convergence.csv doc/images/convergence.png

Left: Hertz verification, |force error| against Hertz over the finest element
size (log-log). Right: the liver, |force error| against the reference
(extrapolated) force over the cost of a state (ms, log-log), one line per
discretisation, the 3.5 % line and the 40 ms target. Needs matplotlib
(Debian: python3-matplotlib)."""
import csv, sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

if len(sys.argv) != 4 and len(sys.argv) != 3:
    sys.exit(__doc__)
rows = list(csv.DictReader(open(sys.argv[1])))
hertz_N = 4.0 / 3.0 * 1e4 / (1 - 0.09) * 0.1 * (1e-4) ** 1.5
fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
for name in sorted({r["discretization"] for r in rows if r["case"] == "hertz"}):
    s = [r for r in rows if r["case"] == "hertz" and r["discretization"] == name]
    h = [float(r["h_mm"]) for r in s]
    e = [abs(float(r["force_N"]) - hertz_N) / hertz_N * 100 for r in s]
    a.loglog(h, e, "o-", label=name)
a.axhline(3, color="grey", ls=":", label="3 %")
a.set_xlabel("element size under the sphere (mm)")
a.set_ylabel("|F - F_Hertz| / F_Hertz (%)")
a.set_title("Hertz: block indented 0.1 mm by R = 1 cm")
a.legend()
liver = [r for r in rows if r["case"] == "liver"]
ref = min(liver, key=lambda r: float(r["h_mm"]))["extrapolated_N"]
ref = float(ref)
for name in sorted({r["discretization"] for r in liver}):
    s = [r for r in liver if r["discretization"] == name]
    t = [float(r["state_ms"]) for r in s]
    e = [max(abs(float(r["force_N"]) - ref) / ref * 100, 0.05) for r in s]
    b.loglog(t, e, "o-", label=name)
    for r, x, y in zip(s, t, e):
        b.annotate("%g mm" % float(r["h_mm"]), (x, y), fontsize=7)
b.axhline(3.5, color="grey", ls=":", label="3.5 % (half the JND)")
b.axvline(40, color="grey", ls="--", label="40 ms target")
b.set_xlabel("state from a neighbour, one core (ms)")
b.set_ylabel("|F - F_ref| / F_ref (%)")
b.set_title("Liver, 1 cm sphere pressed 1 cm: error against cost")
b.legend(fontsize=8)
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=110)
