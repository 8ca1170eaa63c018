#!/usr/bin/env python3
"""Every path a document names must exist: the links and repository paths of README.md,
docs/*.md and the other Markdown files of the source tree.

Checked, in each Markdown file:
  - links [text](target): a relative target must exist (relative to the file); a #fragment on a
    Markdown target must be one of its headings (GitHub's anchors);
  - repository paths in the text, such as `algo/src/frame/demux.cpp` or docs/demux.md: any word
    that starts with a top-level folder of the repository (algo/, hal/, docs/, ...) must exist
    relative to the repository's root. Globs (demux_*.cpp) must match at least one file.
Not checked: web links, paths under build/ (build outputs), placeholders (<name>, NN, ...).

  check_doc_paths.py ROOT          check the tree at ROOT; exit 1 naming every broken path
  check_doc_paths.py --self-test   prove the checker finds each kind of broken path
"""
import glob
import os
import re
import sys
import tempfile

TOP_FOLDERS = ("algo", "hal", "firmware", "boards", "toolchains", "tests", "tools", "docs",
               "packaging", "cmake", ".ci")
SKIPPED_DIRS = {"build", ".git", "corpus", "node_modules"}

LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
REPO_PATH = re.compile(r"(?<![\w./~-])((?:%s)/[\w./*+-]*)" % "|".join(re.escape(t) for t in TOP_FOLDERS))
PLACEHOLDER = re.compile(r"<[^>]*>|\.\.\.|…|\{|\}|NN|\bDIR\b|\bX\b|\bN\b")


def markdown_files(root):
    for folder, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs if d not in SKIPPED_DIRS and not d.startswith("build"))
        for name in sorted(files):
            if name.endswith(".md"):
                yield os.path.join(folder, name)


def anchor(heading):
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r"`|\*\*?|_", lambda m: "_" if m.group(0) == "_" else "", heading.strip())
    text = text.lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors_of(path):
    result = set()
    in_code = False
    with open(path, encoding="utf-8") as f:
        for line in f:
            if line.startswith("```"):
                in_code = not in_code
            elif not in_code and line.startswith("#"):
                result.add(anchor(line.lstrip("#")))
    return result


def exists(path):
    if "*" in path:
        return bool(glob.glob(path))
    return os.path.exists(path)


def check_file(root, md):
    problems = []
    rel = os.path.relpath(md, root)
    here = os.path.dirname(md)
    with open(md, encoding="utf-8") as f:
        lines = f.read().split("\n")
    for number, line in enumerate(lines, 1):
        where = f"{rel}:{number}"
        for target in LINK.findall(line):
            if re.match(r"^[a-z]+:", target):
                continue
            path, _, fragment = target.partition("#")
            full = os.path.normpath(os.path.join(here, path)) if path else md
            if path and not exists(full):
                problems.append(f"{where}: link to {target}: no such file")
            elif fragment and full.endswith(".md") and fragment not in anchors_of(full):
                problems.append(f"{where}: link to {target}: no heading #{fragment} there")
        for match in REPO_PATH.finditer(line):
            path = match.group(1).rstrip(".,:;")
            if PLACEHOLDER.search(line[match.start():match.end() + 1]):
                continue
            if not exists(os.path.join(root, path)) and not exists(os.path.join(here, path)):
                problems.append(f"{where}: {path}: no such file or folder")
    return problems


def check(root):
    problems = []
    for md in markdown_files(root):
        problems += check_file(root, md)
    return problems


def self_test():
    with tempfile.TemporaryDirectory() as root:
        os.makedirs(os.path.join(root, "docs"))
        os.makedirs(os.path.join(root, "algo/src"))
        open(os.path.join(root, "algo/src/kernel.cpp"), "w").close()
        with open(os.path.join(root, "docs/a.md"), "w") as f:
            f.write("# Title\n\n## Some section\n")
        cases = {
            "good": ("See [a](a.md#some-section), `algo/src/kernel.cpp`, algo/src/*.cpp, "
                     "[web](https://example.org/x), `build/host/x`, `docs/<name>.md`.\n", 0),
            "missing link": ("[b](b.md)\n", 1),
            "missing anchor": ("[a](a.md#other)\n", 1),
            "missing path": ("The kernel is in `algo/src/moved.cpp`.\n", 1),
            "missing glob": ("Kernels: algo/src/demux_*.cpp\n", 1),
        }
        failures = []
        for name, (text, expected) in cases.items():
            with open(os.path.join(root, "docs/case.md"), "w") as f:
                f.write(text)
            found = len(check_file(root, os.path.join(root, "docs/case.md")))
            if found != expected:
                failures.append(f"{name}: {found} problems found, {expected} expected")
        for failure in failures:
            print("self-test:", failure)
        return 1 if failures else 0


def main():
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    problems = check(os.path.abspath(sys.argv[1]))
    for problem in problems:
        print(problem)
    if problems:
        print(f"{len(problems)} broken paths in the documentation")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
