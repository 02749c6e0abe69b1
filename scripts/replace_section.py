#!/usr/bin/env python3
"""Replace the text between <!-- BEGIN name --> and <!-- END name --> in a Markdown file.

Usage: replace_section.py FILE NAME CONTENT_FILE   (CONTENT_FILE '-' reads stdin)
Scripts that regenerate part of a shared document (docs/performance.md, docs/reproduction.md)
use this so each rewrites only its own section. Writes via a temporary file and rename.
"""
import os
import sys


def main() -> int:
    if len(sys.argv) != 4:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    path, name, content_path = sys.argv[1:]
    content = sys.stdin.read() if content_path == "-" else open(content_path).read()
    begin, end = f"<!-- BEGIN {name} -->", f"<!-- END {name} -->"
    text = open(path).read() if os.path.exists(path) else ""
    if begin in text and end in text:
        head, rest = text.split(begin, 1)
        _, tail = rest.split(end, 1)
    else:
        head, tail = text.rstrip("\n") + "\n\n", "\n"
    new = f"{head}{begin}\n{content.strip()}\n{end}{tail}"
    tmp = f"{path}.tmp-{os.getpid()}"
    with open(tmp, "w") as f:
        f.write(new)
    os.replace(tmp, path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
