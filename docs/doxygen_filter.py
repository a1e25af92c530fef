#!/usr/bin/env python3
"""Doxygen's input filter for softsight's public headers (docs/Doxyfile.in, target `docs`).

The headers document themselves in plain // comments, written for people reading the header;
Doxygen only takes ///. This turns, line for line (so Doxygen's line numbers stay the file's):
  - the comment that opens a file into the file's description (its `#pragma once` becomes \\file);
  - a comment on its own line into the documentation of what follows it;
  - a comment after a member or an enumerator (`int x = 0;  // ...`, `kFound,  // ...`), and the
    lines that continue it in the same column, into that member's documentation (///<).
Comments inside function bodies become documentation too; Doxygen ignores them there.
  doxygen_filter.py HEADER   (prints the filtered header)
"""

import re
import sys

LINE = re.compile(r"^(\s*)//(?!/)(.*)$")
# Characters Doxygen reads as commands or HTML in a comment ("<name>_x", "%04d", "#include",
# "\\xNN"): the comments mean them literally.
SPECIAL = re.compile(r"([\\@<>#%&$])")


def text(comment):
    return SPECIAL.sub(r"\\\1", comment)
TRAILING = re.compile(r"^(\s*\S.*?[;,])(\s+)//(?!/)(.*)$")


def filtered(lines):
    out = []
    in_file_comment = True  # The comment lines at the top of the file, before `#pragma once`.
    trailing_column = None  # Column of the // of a member's comment, for its continuation lines.
    for line in lines:
        if in_file_comment:
            match = LINE.match(line)
            if match and not match.group(1):
                out.append("///" + text(match.group(2)))
                continue
            in_file_comment = False
            if line.strip() == "#pragma once" and out:
                out.append("/// \\file")
                continue
        match = LINE.match(line)
        if match:
            if trailing_column is not None and len(match.group(1)) == trailing_column:
                out.append(match.group(1) + "///<" + text(match.group(2)))
                continue
            trailing_column = None
            out.append(match.group(1) + "///" + text(match.group(2)))
            continue
        trailing_column = None
        match = TRAILING.match(line)
        if match and match.group(1).count('"') % 2 == 0:
            trailing_column = len(match.group(1)) + len(match.group(2))
            out.append(match.group(1) + match.group(2) + "///<" + text(match.group(3)))
            continue
        out.append(line)
    return out


def main():
    with open(sys.argv[1], encoding="utf-8") as header:
        lines = header.read().split("\n")
    sys.stdout.write("\n".join(filtered(lines)))


if __name__ == "__main__":
    main()
