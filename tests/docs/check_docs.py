#!/usr/bin/env python3
"""Check that the docs stay references.

Usage: check_docs.py SOURCE_DIR

Fails (exit 1), naming file and line, when
- README.md has more than 100 lines, or
- a doc directly in docs/ (not docs/results/, not docs/decisions/) carries
  an issue reference, a change tag, a date, a commit hash or a session's history.
Measured figures with their dates belong in docs/results/, decisions with their
arguments in docs/decisions/; those two folders are not checked here.
"""
import pathlib
import re
import sys

README_MAX_LINES = 100

CHECKS = [
    ("issue reference", re.compile(r"\bissues?\s+(?:#\s*)?\d+\b", re.IGNORECASE)),
    # "#12" standing alone, as issues and pull requests are written; a chunk's
    # sequence number ("through #38", "from #0", "run#5") is not one.
    ("issue reference",
     re.compile(r"(?:^|(?<=[\s(\[]))(?<!through )(?<!from )(?<!chunk )(?<!chunks )#\d+\b")),
    ("change tag", re.compile(r"\*(?:added|changed|made explicit)\*", re.IGNORECASE)),
    ("date", re.compile(r"\b20\d\d-\d\d-\d\d\b")),
    ("commit hash", re.compile(r"\bcommits?\s+`?[0-9a-f]{7,40}\b", re.IGNORECASE)),
    ("commit hash", re.compile(r"`[0-9a-f]{7,40}`")),
    ("session history", re.compile(r"before this session|last session", re.IGNORECASE)),
]


def check_reference(path, rel, problems):
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        for what, pattern in CHECKS:
            match = pattern.search(line)
            if match:
                problems.append(f"{rel}:{number}: {what}: '{match.group(0)}'")


def main(argv):
    if len(argv) != 2:
        print("usage: check_docs.py SOURCE_DIR", file=sys.stderr)
        return 2
    root = pathlib.Path(argv[1])
    problems = []

    readme = root / "README.md"
    if not readme.is_file():
        problems.append("README.md: missing")
    else:
        lines = len(readme.read_text(encoding="utf-8").splitlines())
        print(f"README.md: {lines} lines (at most {README_MAX_LINES})")
        if lines > README_MAX_LINES:
            problems.append(f"README.md:{lines}: {lines} lines, more than {README_MAX_LINES}")

    references = sorted((root / "docs").glob("*.md"))
    if not references:
        problems.append("docs/: no *.md found")
    for path in references:
        check_reference(path, path.relative_to(root), problems)
    print(f"docs/*.md checked for issue numbers, change tags, dates, commit hashes "
          f"and session history: {', '.join(p.name for p in references)}")
    print("not checked: docs/results/ (dated measurements), docs/decisions/ (decisions)")

    if problems:
        for problem in problems:
            print(problem, file=sys.stderr)
        print(f"check_docs: {len(problems)} problem(s)", file=sys.stderr)
        return 1
    print("check_docs: ok")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
