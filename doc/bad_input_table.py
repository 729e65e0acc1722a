#!/usr/bin/env python3
# SPDX-License-Identifier: LGPL-2.1-or-later
"""Write the table of doc/bad-input.md from tests/app/bad_input.output.

The test runs the real palpate program on every bad input and records what
the user sees; this script turns that record into the table, so the page
shows exactly what the test checks:

    python3 doc/bad_input_table.py > /tmp/table.md

and paste the table between the markers of doc/bad-input.md (or run with
--update to replace it in place).
"""
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUTPUT = ROOT / "tests" / "app" / "bad_input.output"
PAGE = ROOT / "doc" / "bad-input.md"
BEGIN, END = "<!-- table begin -->", "<!-- table end -->"


def cases(text):
    """(what, exit status, message lines) for every case of the test."""
    for block in re.split(r"^DEAL::=== ", text, flags=re.M)[1:]:
        head, _, rest = block.partition("\n")
        what, _, status = head.rpartition(": exit status ")
        lines = [l.removeprefix("DEAL::") for l in rest.splitlines()]
        yield what, int(status), lines


def cell(s):
    return s.replace("|", "\\|").replace("`", "'")


def table(text):
    rows = ["| # | Input | Exit | What the user sees |", "|---|---|---|---|"]
    for n, (what, status, lines) in enumerate(cases(text), 1):
        fields = {}
        for line in lines:
            m = re.match(r"\s*(entry|problem|fix):\s+(.*)", line)
            if m:
                fields[m.group(1)] = m.group(2)
        if status == 0:
            seen = "accepted: the scene runs (its report is in the test output)"
        else:
            # Lines before the error (a sphere's offer tried by a solve) are
            # progress, shown before it.
            head = next((i for i, l in enumerate(lines)
                         if l.startswith("palpate: the input has a problem, ")), 0)
            before = " ".join(l for l in lines[:head] if l.strip())
            where = lines[head].removeprefix("palpate: the input has a problem, ") if lines else ""
            seen = (f"(first: {before}) " if before else "") + f"{where}; **{fields.get('entry', '')}**: {fields.get('problem', '')}. *Fix:* {fields.get('fix', '')}"
        rows.append(f"| {n} | {cell(what)} | {status} | {cell(seen)} |")
    return "\n".join(rows) + "\n"


def main():
    t = table(OUTPUT.read_text())
    if "--update" in sys.argv:
        page = PAGE.read_text()
        start, stop = page.index(BEGIN) + len(BEGIN), page.index(END)
        PAGE.write_text(page[:start] + "\n" + t + page[stop:])
    else:
        sys.stdout.write(t)


if __name__ == "__main__":
    main()
