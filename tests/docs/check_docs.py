#!/usr/bin/env python3
"""DocsTest — the docs of a clone stand on their own.

Checks, over the source tree (build folders, node_modules and tests/models left out):
  1. every relative Markdown link `[text](path#anchor)` in a .md file names a file or folder that
     exists, and its #anchor (if any) a heading of that Markdown file (GitHub's slugs);
  2. every "SPEC §N" citation (in code, shaders, scripts and docs) names a section `## N.` of
     docs/spec.md, the product's own specification;
  3. the README stays a user's guide: at most README_MAX_LINES lines.
Prints one line per failure and a closing "N passed, N failed" line; exits 1 on any failure.
Usage: check_docs.py SOURCE_DIR
"""
import os
import re
import sys

README_MAX_LINES = 300
SKIP_DIRS = {".git", "node_modules", "out", "editor-screenshots"}
TEXT_EXT = {".md", ".cpp", ".hpp", ".h", ".c", ".txt", ".cmake", ".sh", ".py", ".js", ".mjs",
            ".json", ".yaml", ".yml", ".vert", ".frag", ".glsl", ".html", ".css", ""}


def walk(root):
    for base, dirs, files in os.walk(root):
        rel = os.path.relpath(base, root)
        dirs[:] = [d for d in dirs if d not in SKIP_DIRS and not d.startswith("build")
                   and os.path.join(rel, d) != os.path.join("tests", "models")]
        for f in files:
            yield os.path.join(base, f)


def slug(heading):
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces to hyphens."""
    s = heading.strip().lower()
    s = re.sub(r"[`*_]", "", s)
    s = re.sub(r"[^\w\- ]", "", s, flags=re.UNICODE)
    return s.replace(" ", "-")


def anchors(md_path, cache={}):
    if md_path not in cache:
        found, counts = set(), {}
        in_code = False
        with open(md_path, encoding="utf-8") as f:
            for line in f:
                if line.startswith("```"):
                    in_code = not in_code
                    continue
                m = None if in_code else re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
                if m:
                    s = slug(m.group(1))
                    n = counts.get(s, 0)
                    counts[s] = n + 1
                    found.add(s if n == 0 else f"{s}-{n}")
        cache[md_path] = found
    return cache[md_path]


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else ".")
    failures, checks = [], 0
    spec = os.path.join(root, "docs", "spec.md")
    sections = set()
    if os.path.isfile(spec):
        with open(spec, encoding="utf-8") as f:
            for line in f:
                m = re.match(r"^## (\d+[a-z]?)\.\s", line)
                if m:
                    sections.add(m.group(1))
    checks += 1
    if len(sections) < 9:
        failures.append(f"docs/spec.md: expected sections 1–8 and 2b, found {sorted(sections)}")

    link = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)\)|!\[[^\]]*\]\(([^)\s]+)\)")
    cite = re.compile(r"SPEC §\s?(\d+[a-z]?)")
    citations = 0
    for path in walk(root):
        ext = os.path.splitext(path)[1]
        if ext not in TEXT_EXT:
            continue
        rel = os.path.relpath(path, root)
        try:
            with open(path, encoding="utf-8") as f:
                text = f.read()
        except (UnicodeDecodeError, OSError):
            continue
        for n, line in enumerate(text.splitlines(), 1):
            for m in cite.finditer(line):
                citations += 1
                if m.group(1) not in sections:
                    failures.append(f"{rel}:{n}: 'SPEC §{m.group(1)}' names no section of docs/spec.md")
        if ext != ".md":
            continue
        in_code = False
        for n, line in enumerate(text.splitlines(), 1):
            if line.startswith("```"):
                in_code = not in_code
            if in_code:
                continue
            for m in link.finditer(line):
                target = m.group(1) or m.group(2)
                if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # http:, mailto:, …
                    continue
                checks += 1
                file_part, _, anchor = target.partition("#")
                dest = path if not file_part else os.path.normpath(os.path.join(os.path.dirname(path), file_part))
                if not os.path.exists(dest):
                    failures.append(f"{rel}:{n}: link to {target}: {os.path.relpath(dest, root)} does not exist")
                elif anchor and dest.endswith(".md") and anchor not in anchors(dest):
                    failures.append(f"{rel}:{n}: link to {target}: no heading '#{anchor}' there")
    checks += citations
    if citations < 100:
        failures.append(f"only {citations} SPEC § citations found: is the walk missing the sources?")

    checks += 1
    with open(os.path.join(root, "README.md"), encoding="utf-8") as f:
        lines = sum(1 for _ in f)
    if lines > README_MAX_LINES:
        failures.append(f"README.md has {lines} lines (at most {README_MAX_LINES}): move reference material to docs/")

    for f in failures:
        print("FAIL", f)
    print(f"docs: {checks - len(failures)} passed, {len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
