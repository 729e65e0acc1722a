#!/usr/bin/env python3
# SPDX-License-Identifier: LGPL-2.1-or-later
# Copyright (C) 2026 the palpate authors
#
#   tests/check_function_length.py SOURCE_DIR
#
# Drivers read like their algorithm (issue 28, doc/architecture.md): no
# function in source/ is longer than 150 lines, unless the comment right
# above it says why it is one piece ("One function on purpose"). Exits 1
# and names the functions otherwise.
#
# The code is clang-formatted, so a function body opens with a line that is
# exactly its indentation and "{" after its signature, and closes with the
# same indentation and "}".
import glob
import os
import re
import sys

LIMIT = 150
root = sys.argv[1] if len(sys.argv) > 1 else '.'
found = []
for path in sorted(glob.glob(os.path.join(root, 'source', '**', '*.cc'),
                             recursive=True)):
    lines = open(path, encoding='utf-8').read().split('\n')
    i = 1
    while i < len(lines):
        m = re.match(r'^( *)\{$', lines[i])
        signature = lines[i - 1].strip()
        if m and len(m.group(1)) <= 4 and (
                re.search(r'(\)|const|noexcept|override)$', signature)
                or signature.startswith(':') or signature.startswith(',')):
            indent = m.group(1)
            end = i + 1
            while end < len(lines) and not re.match(
                    '^' + indent + r'\}[;,)]*$', lines[end]):
                end += 1
            length = end - i - 1
            if length > LIMIT:
                # The comment block above the signature.
                k = i - 1
                while k > 0 and '(' not in lines[k]:
                    k -= 1
                name = lines[k].strip()
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
                if not any('One function on purpose' in a for a in above):
                    found.append('%s:%d: %s (%d lines)' %
                                 (os.path.relpath(path, root), k + 1, name,
                                  length))
            i = end
        i += 1
if found:
    print('Functions longer than %d lines without a comment that says why '
          '("One function on purpose"): split them into named steps '
          '(doc/architecture.md, "Drivers"):' % LIMIT)
    for f in found:
        print('  ' + f)
    sys.exit(1)
print('every function in source/ is at most %d lines, or says why not' % LIMIT)
