#!/usr/bin/env python3
"""Every link of the README and the manual resolves.

For README.md and every doc/*.md: each Markdown link or image target that is
not a web address must name a file of the repository (relative to the page
that links it), and an anchor (#section) must be a heading of the target
page, in GitHub's anchor form (lower case, punctuation dropped, spaces to
hyphens). Also: the README stays a front page (at most 250 lines), and every
doc/*.md chapter is linked from the manual's index, doc/README.md.

Usage: doc_links.py SOURCE_DIR
"""
import glob
import os
import re
import sys

LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")


def anchor(heading):
    text = heading.strip().lower()
    text = re.sub(r"[^\w\- ]", "", text, flags=re.UNICODE)
    return text.replace(" ", "-")


def anchors(path):
    found = set()
    in_code = False
    with open(path, encoding="utf-8") as f:
        for line in f:
            if line.startswith("```"):
                in_code = not in_code
            if not in_code and line.startswith("#"):
                found.add(anchor(line.lstrip("#")))
    return found


def links(path):
    in_code = False
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            if line.startswith("```"):
                in_code = not in_code
                continue
            if in_code:
                continue
            for target in LINK.findall(line):
                yield number, target


def main():
    root = os.path.abspath(sys.argv[1])
    pages = [os.path.join(root, "README.md")] + sorted(
        glob.glob(os.path.join(root, "doc", "*.md")))
    failures = []
    n_links = 0
    for page in pages:
        for number, target in links(page):
            n_links += 1
            where = "%s:%d: '%s'" % (os.path.relpath(page, root), number,
                                     target)
            if re.match(r"^[a-z]+://", target) or target.startswith("mailto:"):
                continue
            file_part, _, section = target.partition("#")
            resolved = os.path.normpath(
                os.path.join(os.path.dirname(page), file_part)) \
                if file_part else page
            if not os.path.exists(resolved):
                failures.append(where + " names no file")
                continue
            if section and resolved.endswith(".md") and \
                    section not in anchors(resolved):
                failures.append(where + " names no heading of " +
                                os.path.relpath(resolved, root))
    with open(os.path.join(root, "README.md"), encoding="utf-8") as f:
        n_lines = sum(1 for _ in f)
    if n_lines > 250:
        failures.append("README.md has %d lines (a front page: at most 250)"
                        % n_lines)
    index = os.path.join(root, "doc", "README.md")
    linked = {os.path.normpath(os.path.join(os.path.dirname(index), t))
              for _, t in links(index)}
    for page in pages[1:]:
        if page != index and page not in linked:
            failures.append("doc/README.md does not link %s"
                            % os.path.relpath(page, root))
    for failure in failures:
        print("FAIL " + failure)
    print("%d links in %d pages, %d failures; README.md %d lines"
          % (n_links, len(pages), len(failures), n_lines))
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
