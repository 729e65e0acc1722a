#!/usr/bin/env python3
# SPDX-License-Identifier: LGPL-2.1-or-later
# Copyright (C) 2026 the palpate authors
#
#   tests/check_function_length.py SOURCE_DIR
#
# Drivers read like their algorithm (issue 28, doc/architecture.md): no
# function in source/ is longer than 100 lines, at any depth (a member of a
# class in a .cc, a function in a nested namespace), unless the comment
# right above it says why it is one piece ("One function on purpose"); and
# at most 5 functions say so, so that the exception stays one. Exits 1 and
# names the functions otherwise.
#
# The code is clang-formatted, so a function body opens with a line that is
# exactly its indentation and "{" after its signature, and closes with the
# same indentation and "}".
import glob
import os
import re
import sys

LIMIT = 100
MAX_ON_PURPOSE = 5
MARK = 'One function on purpose'


def comment_above(lines, k):
    """The comment block (and template line) above the signature at k."""
    above = []
    j = k - 1
    while j >= 0 and (lines[j].strip().startswith('//') or
                      lines[j].strip().startswith('*') or
                      lines[j].strip().startswith('/*') or
                      lines[j].strip().startswith('template')
                      or lines[j].strip() in ('bool', 'void')
                      or re.match(r'^ *[\w:<>, ]+$', lines[j])
                      and lines[j].strip() != ''):
        above.append(lines[j])
        j -= 1
    return above


root = sys.argv[1] if len(sys.argv) > 1 else '.'
too_long = []
on_purpose = []
for path in sorted(glob.glob(os.path.join(root, 'source', '**', '*.cc'),
                             recursive=True)):
    lines = open(path, encoding='utf-8').read().split('\n')
    i = 1
    while i < len(lines):
        m = re.match(r'^( *)\{$', lines[i])
        signature = lines[i - 1].strip()
        if m and (re.search(r'(\)|const|noexcept|override)$', signature)
                  or signature.startswith(':')
                  or signature.startswith(',')):
            indent = m.group(1)
            end = i + 1
            while end < len(lines) and not re.match(
                    '^' + indent + r'\}[;,)]*$', lines[end]):
                end += 1
            length = end - i - 1
            k = i - 1
            while k > 0 and '(' not in lines[k]:
                k -= 1
            where = '%s:%d: %s (%d lines)' % (os.path.relpath(
                path, root), k + 1, lines[k].strip(), length)
            if any(MARK in a for a in comment_above(lines, k)):
                on_purpose.append(where)
            elif length > LIMIT:
                too_long.append(where)
            i = end
        i += 1
bad = False
if too_long:
    print('Functions longer than %d lines without a comment that says why '
          '("%s"): split them into named steps '
          '(doc/architecture.md, "Drivers"):' % (LIMIT, MARK))
    for f in too_long:
        print('  ' + f)
    bad = True
if len(on_purpose) > MAX_ON_PURPOSE:
    print('%d functions say "%s", more than %d: split some of them into '
          'named steps:' % (len(on_purpose), MARK, MAX_ON_PURPOSE))
    for f in on_purpose:
        print('  ' + f)
    bad = True
if bad:
    sys.exit(1)
print('every function in source/ is at most %d lines, or says why not '
      '(%d do, at most %d may)' % (LIMIT, len(on_purpose), MAX_ON_PURPOSE))
