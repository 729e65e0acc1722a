#!/usr/bin/env python3
# SPDX-License-Identifier: LGPL-2.1-or-later
"""Plot the paper's Fig. 4 from the CSV that `benchmarks/run cluster` writes
(busy solver servers over 40 s of a straight stroke, StVK, cloud 2.5 cm):

    python3 doc/images/cluster_fig4.py cluster-fig4.csv doc/images/cluster-fig4.png

The CSV has one row per change of the busy count:
state_times (paper|palpate), servers (0 = unlimited), time_s, busy.
Needs Python 3 with matplotlib (Debian: python3-matplotlib)."""
import csv, sys
from collections import defaultdict

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

if len(sys.argv) != 3:
    sys.exit(__doc__)
series = defaultdict(lambda: ([], []))
with open(sys.argv[1]) as f:
    for row in csv.DictReader(f):
        key = (row["state_times"], int(row["servers"]))
        series[key][0].append(float(row["time_s"]))
        series[key][1].append(int(row["busy"]))

END = 40.0  # s, the paper's plot
fig, ax = plt.subplots(figsize=(8, 4))
ax.axvspan(15, 33, color="0.92", label="HIP moving (5.25 mm/s)")
styles = {"paper": ("C0", "state time 1.0 s (paper)"),
          "palpate": ("C3", "state time measured here")}
for (times, n), (t, b) in sorted(series.items(), key=lambda s: (s[0][0] != "paper", s[0][1] == 0)):
    colour, what = styles[times]
    label = f"{what}, {'unlimited servers' if n == 0 else f'{n} servers'}"
    # Hold the last count to the end of the plot.
    t, b = t + [END], b + [b[-1]]
    ax.step(t, b, where="post", color=colour, lw=1.0 if n == 0 else 1.6,
            ls=":" if n == 0 else "-", label=label)
ax.set_xlim(0, END)
ax.set_ylim(bottom=0)
ax.set_xlabel("time [s]")
ax.set_ylabel("busy solver servers")
ax.set_title("Busy servers, St.Venant-Kirchhoff, cloud 2.5 cm, 5 mm grid "
             "(simulated; cf. the paper's Fig. 4)", fontsize=10)
ax.legend(fontsize=8, loc="upper right")
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=110)
