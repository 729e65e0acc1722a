#!/usr/bin/env python3
# SPDX-License-Identifier: LGPL-2.1-or-later
"""Plot the rendered force against the direct solve along the onset sweep
(the first sweep: from 5 mm above the surface to 8 mm deep along its
normal) from the output of

    benchmarks/run contact-patch --body liver --spacing 10 --verbose > run.log
    /usr/bin/python3 doc/images/contact-patch-onset.py run.log doc/images/contact-patch-onset.png

One line per interpolation (trilinear, Hermite, contact patch) and the
direct solves; depth < 0 is above the surface. Needs matplotlib (Debian:
python3-matplotlib)."""
import math, re, sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

if len(sys.argv) != 3:
    sys.exit(__doc__)
number = r"(-?[0-9.]+(?:e[-+]?[0-9]+)?)"
vector = number + r", " + number + r", " + number
line = re.compile(r"^\s+(\w+) x " + vector + " direct " + vector +
                  " rendered " + vector + " err")
samples = {}
spacing = None
for text in open(sys.argv[1]):
    if text.startswith("  h = "):
        spacing = text.split()[2]
    m = line.match(text)
    if m:
        v = [float(g) for g in m.groups()[1:]]
        samples.setdefault(m.group(1), []).append((v[0:3], v[3:6], v[6:9]))

def onset(rows):
    """The samples of the first sweep: until consecutive samples jump."""
    out = [rows[0]]
    for r in rows[1:]:
        if math.dist(r[0], out[-1][0]) > 2e-3:
            break
        out.append(r)
    return out

names = {"trilinear": "trilinear", "hermite": "tricubic Hermite",
         "contact_patch": "contact patch"}
fig, ax = plt.subplots(figsize=(6.5, 4.5))
direct_done = False
for key, label in names.items():
    if key not in samples:
        continue
    rows = onset(samples[key])
    depth = [1e3 * math.dist(r[0], rows[0][0]) - 5 for r in rows]
    if not direct_done:
        ax.plot(depth, [math.hypot(*r[1]) for r in rows], "k-", lw=2.5,
                label="direct solve", zorder=1)
        direct_done = True
    ax.plot(depth, [math.hypot(*r[2]) for r in rows], "o-", ms=3,
            label=label, zorder=2)
ax.axvline(0, color="grey", lw=0.8, ls=":")
ax.set_xlabel("depth of the sphere along the surface normal (mm); < 0: above")
ax.set_ylabel("|force| (N)")
ax.set_title("Liver, 1 cm sphere, states " + (spacing or "?") +
             " mm apart: rendered against direct")
ax.legend()
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=110)
