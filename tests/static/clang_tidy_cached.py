#!/usr/bin/env python3
"""Runs clang-tidy on translation units of a compilation database, skipping a unit whose last
analysis found nothing and whose inputs have not changed since.

A unit's inputs are hashed into its cache key:
  - the text of every file it includes, comments and all (so that a NOLINT removed from a header
    is seen): read from the files its build's dependency file lists (OBJECT.d, written by the
    compiler beside the object) when that file is newer than each file it lists; otherwise its
    preprocessed text (clang -E -C), which costs a second or more per unit. The source and build
    folders' paths are replaced by placeholders so that a clone elsewhere shares the cache;
  - its compile command (flags decide which compiler warnings clang-tidy reports) and its path
    relative to the source folder (HeaderFilterRegex matches paths);
  - the text of every .clang-tidy file of the source tree, the extra arguments, and the
    clang-tidy and clang versions.
Only clean results are stored: a unit with a finding is analysed again on every run and fails
every run until the finding is fixed.

A list of keys known clean (--known-clean, tests/static/tidy-clean.txt in the repository) is a
second, read-only cache that travels with the sources: CI on a fresh machine analyses only the
units whose inputs differ from those of a clean analysis recorded in the list. The list is
written by --record-known-clean after a run without findings (cmake --build --preset host
--target record_tidy_clean); a stale entry only costs an analysis, never hides a finding.

Usage: clang_tidy_cached.py --clang-tidy BIN --clang BIN --build DIR --source-root DIR
                            [--cache DIR] [--jobs N] [--extra-arg ARG ...]
                            [--known-clean LIST] [--record-known-clean LIST] FILE...
The cache defaults to $SMX_TIDY_CACHE, else $XDG_CACHE_HOME/stripemux/clang-tidy, else
~/.cache/stripemux/clang-tidy. Exit status: 0 when no unit has a finding, 1 otherwise, 2 on a
usage error (an unknown file, a missing tool).
"""
import argparse
import concurrent.futures
import hashlib
import json
import os
import pathlib
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

KEY_FORMAT = b"stripemux-tidy-cache/2\n"


def default_cache():
    if os.environ.get("SMX_TIDY_CACHE"):
        return pathlib.Path(os.environ["SMX_TIDY_CACHE"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return pathlib.Path(base) / "stripemux" / "clang-tidy"


def tool_version(binary, cache):
    """What BINARY --version prints, kept in CACHE by the binary's path, size and time: each
    unit's run is a process of its own, and asking both tools costs a quarter of a second."""
    stat = pathlib.Path(shutil.which(binary) or binary).resolve().stat()
    name = hashlib.sha256(f"{binary}\0{stat.st_size}\0{stat.st_mtime_ns}".encode()).hexdigest()
    stored = cache / "versions" / name
    try:
        return stored.read_bytes()
    except OSError:
        pass
    version = subprocess.run([binary, "--version"], check=True, capture_output=True).stdout
    stored.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.NamedTemporaryFile("wb", dir=stored.parent, delete=False) as tmp:
        tmp.write(version)
    os.replace(tmp.name, stored)
    return version


def tidy_configs(source_root):
    """The text of every .clang-tidy of the tree, keyed by its path in the tree."""
    digest = hashlib.sha256()
    for path in sorted(source_root.rglob(".clang-tidy")):
        relative = path.relative_to(source_root)
        if relative.parts[0] == "build" or ".git" in relative.parts:
            continue
        digest.update(str(relative).encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.digest()


def command_args(entry):
    if "arguments" in entry:
        return list(entry["arguments"])
    return shlex.split(entry["command"])


def preprocess_args(args, clang, extra_args):
    """The compile command turned into clang -E -C writing to standard output."""
    out = [clang]
    skip = False
    for arg in args[1:]:
        if skip:
            skip = False
            continue
        if arg == "-o":
            skip = True
            continue
        if arg == "-c" or arg.startswith("-o"):
            continue
        out.append(arg)
    return out + extra_args + ["-E", "-C", "-w", "-o", "-"]


class Unit:
    def __init__(self, path, entry, build_dir, source_root):
        self.path = path
        self.entry = entry
        self.relative = os.path.relpath(path, source_root)
        self.build_dir = build_dir
        self.source_root = source_root

    def normalise(self, data):
        # The build folder usually lies inside the source folder: replace it first.
        data = data.replace(str(self.build_dir).encode(), b"<build>")
        return data.replace(str(self.source_root).encode(), b"<source>")

    def key(self, common, clang, extra_args):
        args = command_args(self.entry)
        digest = hashlib.sha256(common)
        digest.update(self.relative.encode() + b"\0")
        digest.update(self.normalise(" ".join(args).encode()) + b"\0")
        inputs = self.included_files(args)
        if inputs is not None:
            digest.update(b"included files\0")
            for path in inputs:
                digest.update(self.normalise(str(path).encode()) + b"\0")
                digest.update(self.normalise(path.read_bytes()) + b"\0")
            return digest.hexdigest()
        result = subprocess.run(preprocess_args(args, clang, extra_args),
                                cwd=self.entry["directory"], capture_output=True)
        if result.returncode != 0:
            return None  # let clang-tidy report why it cannot parse the unit
        digest.update(b"preprocessed\0")
        digest.update(self.normalise(result.stdout))
        return digest.hexdigest()

    def included_files(self, args):
        """The files the last compile of the unit read, from its dependency file, sorted; None
        when there is none or it is older than one of them (edited since: a build is due)."""
        try:
            output = args[args.index("-o") + 1]
        except (ValueError, IndexError):
            return None
        depfile = pathlib.Path(self.entry["directory"], output + ".d")
        try:
            written = depfile.stat().st_mtime_ns
            text = depfile.read_text()
        except OSError:
            return None
        # "object: dep dep \" lines; a path's own spaces are escaped with a backslash.
        words = text.replace("\\\n", " ").replace("\\ ", "\0").split()
        paths = set()
        for word in words:
            if word.endswith(":"):
                continue
            path = pathlib.Path(self.entry["directory"], word.replace("\0", " ")).resolve()
            try:
                if path.stat().st_mtime_ns > written:
                    return None
            except OSError:
                return None
            paths.add(path)
        if pathlib.Path(self.path).resolve() not in paths:
            return None
        return sorted(paths)


def read_known_clean(path):
    """The keys of a known-clean list ("KEY PATH" per line); none for a missing list."""
    if path is None or not path.exists():
        return set()
    return {line.split(" ", 1)[0] for line in path.read_text().splitlines() if line.strip()}


def analyse(unit, options, common):
    """Returns (unit, key, status, output, seconds); status is 'cached', 'known clean', 'clean'
    or 'finding'."""
    start = time.monotonic()
    key = unit.key(common, options.clang, options.extra_arg)
    stored = options.cache / key[:2] / key[2:] if key else None
    if stored is not None and stored.exists():
        os.utime(stored)  # recently used: kept by any pruning by age
        return unit, key, "cached", "", time.monotonic() - start
    if key is not None and key in options.known:
        return unit, key, "known clean", "", time.monotonic() - start
    command = [options.clang_tidy, "-p", str(options.build), "--quiet"]
    command += ["--extra-arg=" + arg for arg in options.extra_arg] + [str(unit.path)]
    result = subprocess.run(command, cwd=options.source_root, capture_output=True, text=True)
    output = result.stdout + result.stderr
    found = result.returncode != 0 or ": warning:" in output or ": error:" in output
    if not found and stored is not None:
        stored.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile("w", dir=stored.parent, delete=False) as tmp:
            tmp.write(unit.relative + "\n")
        os.replace(tmp.name, stored)
    return unit, key, "finding" if found else "clean", output, time.monotonic() - start


def parse_args(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--clang-tidy", required=True)
    parser.add_argument("--clang", required=True, help="clang++ of the same LLVM as clang-tidy")
    parser.add_argument("--build", required=True, type=pathlib.Path,
                        help="folder of compile_commands.json")
    parser.add_argument("--source-root", required=True, type=pathlib.Path)
    parser.add_argument("--cache", type=pathlib.Path, default=default_cache())
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument("--extra-arg", action="append", default=[])
    parser.add_argument("--known-clean", type=pathlib.Path,
                        help="list of keys analysed clean elsewhere (read only)")
    parser.add_argument("--record-known-clean", type=pathlib.Path,
                        help="after a run without findings, write the units' keys here")
    parser.add_argument("files", nargs="+", type=pathlib.Path)
    options = parser.parse_args(argv)
    options.build = options.build.resolve()
    options.source_root = options.source_root.resolve()
    options.known = read_known_clean(options.known_clean)
    return options


def main(argv):
    options = parse_args(argv)
    database = json.loads((options.build / "compile_commands.json").read_text())
    entries = {}
    for entry in database:
        path = pathlib.Path(entry["directory"], entry["file"]).resolve()
        entries.setdefault(path, entry)
    units = []
    for file in options.files:
        path = (options.source_root / file).resolve()
        if path not in entries:
            print(f"clang-tidy: {file} is not in {options.build}/compile_commands.json",
                  file=sys.stderr)
            return 2
        units.append(Unit(path, entries[path], options.build, options.source_root))
    try:
        common = hashlib.sha256(KEY_FORMAT + tool_version(options.clang_tidy, options.cache) +
                                tool_version(options.clang, options.cache) +
                                tidy_configs(options.source_root) +
                                "\0".join(options.extra_arg).encode()).digest()
    except (OSError, subprocess.CalledProcessError) as error:
        print(f"clang-tidy: {error}", file=sys.stderr)
        return 2

    counts = {"cached": 0, "known clean": 0, "clean": 0, "finding": 0}
    keys = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, options.jobs)) as pool:
        jobs = [pool.submit(analyse, unit, options, common) for unit in units]
        for job in concurrent.futures.as_completed(jobs):
            unit, key, status, output, seconds = job.result()
            counts[status] += 1
            if key is not None:
                keys.append(f"{key} {unit.relative}")
            print(f"{unit.relative}: {status} ({seconds:.1f} s)")
            if status == "finding":
                print(output, end="" if output.endswith("\n") else "\n")
    print(f"clang-tidy: {len(units)} units, {counts['cached']} unchanged since a clean analysis, "
          f"{counts['known clean']} in the known-clean list, {counts['clean']} analysed clean, "
          f"{counts['finding']} with findings (cache {options.cache})")
    if counts["finding"]:
        return 1
    if options.record_known_clean is not None:
        target = options.record_known_clean
        with tempfile.NamedTemporaryFile("w", dir=target.parent, delete=False) as tmp:
            tmp.write("".join(line + "\n" for line in sorted(keys, key=lambda k: k.split(" ")[1])))
        os.replace(tmp.name, target)
        print(f"clang-tidy: {len(keys)} clean units recorded in {target}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
