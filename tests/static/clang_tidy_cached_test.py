#!/usr/bin/env python3
"""The clang-tidy cache never hides a finding: a unit with a finding fails on every run, and any
change to what clang-tidy reads (a header, a NOLINT comment, the configuration, the flags) is
analysed again; an unchanged unit, also in a clone at another path, is not. A built unit is keyed
by the files its dependency file lists, without preprocessing, unless one was edited after it.

Usage: clang_tidy_cached_test.py CLANG_TIDY CLANG SOURCE_ROOT
"""
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import unittest

CLANG_TIDY, CLANG, SOURCE_ROOT = (None, None, None)
SCRIPT = pathlib.Path(__file__).with_name("clang_tidy_cached.py")

UNIT = """#include "helper.hpp"

namespace fixture {
int twice(int value) { return helper(value) * 2; }
}  // namespace fixture
"""
CLEAN_HELPER = """#pragma once
namespace fixture {
inline int helper(int value) { return value + 1; }
}  // namespace fixture
"""
# google-readability-casting, in a header the configuration's HeaderFilterRegex covers.
CAST_HELPER = """#pragma once
namespace fixture {
inline int helper(int value) { return (int)(value * 1.5); }
}  // namespace fixture
"""
SUPPRESSED_HELPER = CAST_HELPER.replace("1.5); }", "1.5); }  // NOLINT")


class ClangTidyCacheTest(unittest.TestCase):
    def setUp(self):
        self.tmp = pathlib.Path(tempfile.mkdtemp(prefix="smx-tidy-cache-test-"))
        self.cache = self.tmp / "cache"
        self.tree = self.make_tree(self.tmp / "clone-a")

    def tearDown(self):
        shutil.rmtree(self.tmp)

    def make_tree(self, root, flags=""):
        (root / "algo").mkdir(parents=True)
        (root / "build").mkdir()
        shutil.copy(SOURCE_ROOT / ".clang-tidy", root / ".clang-tidy")
        (root / "algo" / "unit.cpp").write_text(UNIT)
        (root / "algo" / "helper.hpp").write_text(CLEAN_HELPER)
        self.write_database(root, flags)
        return root

    @staticmethod
    def write_database(root, flags):
        database = [{
            "directory": str(root / "build"),
            "command": f"c++ -std=c++23 {flags} -o unit.o -c {root / 'algo' / 'unit.cpp'}",
            "file": str(root / "algo" / "unit.cpp"),
        }]
        (root / "build" / "compile_commands.json").write_text(json.dumps(database))

    def compile(self, tree=None):
        """Builds the unit as the build does, writing build/unit.o.d beside the object."""
        tree = tree or self.tree
        unit = str(tree / "algo" / "unit.cpp")
        subprocess.run([CLANG, "-std=c++2b", "-MD", "-MF", "unit.o.d", "-o", "unit.o", "-c", unit],
                       cwd=tree / "build", check=True)

    def clang_that_cannot_preprocess(self):
        fake = self.tmp / "fake-clang"
        fake.write_text('#!/bin/sh\n[ "$1" = --version ] && echo "fake clang" && exit 0\nexit 1\n')
        fake.chmod(0o755)
        return str(fake)

    def run_cached(self, tree=None, options=(), clang=None):
        tree = tree or self.tree
        result = subprocess.run(
            [sys.executable, str(SCRIPT), "--clang-tidy", CLANG_TIDY, "--clang", clang or CLANG,
             "--build", str(tree / "build"), "--source-root", str(tree),
             "--cache", str(self.cache), "--extra-arg=-std=c++2b", *options, "algo/unit.cpp"],
            capture_output=True, text=True)
        return result.returncode, result.stdout + result.stderr

    def set_helper(self, text):
        (self.tree / "algo" / "helper.hpp").write_text(text)

    def assert_status(self, status, tree=None, options=(), clang=None):
        code, output = self.run_cached(tree, options, clang)
        self.assertIn(f"algo/unit.cpp: {status} (", output)
        self.assertEqual(code, 1 if status == "finding" else 0, output)
        return output

    def test_a_clean_unit_is_analysed_once(self):
        self.assert_status("clean")
        self.assert_status("cached")

    def test_a_finding_in_a_header_fails_every_run(self):
        self.assert_status("clean")
        self.set_helper(CAST_HELPER)
        output = self.assert_status("finding")
        self.assertIn("google-readability-casting", output)
        self.assert_status("finding")
        self.set_helper(CLEAN_HELPER)
        self.assert_status("cached")

    def test_removing_a_nolint_comment_is_a_change(self):
        self.set_helper(SUPPRESSED_HELPER)
        self.assert_status("clean")
        self.assert_status("cached")
        self.set_helper(CAST_HELPER)
        self.assert_status("finding")

    def test_configuration_and_flags_are_part_of_the_key(self):
        self.assert_status("clean")
        config = self.tree / ".clang-tidy"
        config.write_text(config.read_text() + "# changed\n")
        self.assert_status("clean")
        self.assert_status("cached")
        self.write_database(self.tree, "-DSMX_FIXTURE=1")
        self.assert_status("clean")

    def test_a_clone_at_another_path_shares_the_cache(self):
        self.assert_status("clean")
        other = self.make_tree(self.tmp / "clone-b")
        self.assert_status("cached", other)

    # A list recorded on one machine lets a fresh machine (an empty cache) skip the unit, until
    # anything it reads changes; a run with a finding records nothing.
    def test_a_known_clean_list_travels_with_the_sources(self):
        listed = self.tmp / "tidy-clean.txt"
        self.assert_status("clean", options=("--record-known-clean", str(listed)))
        self.assertRegex(listed.read_text(), r"^[0-9a-f]{64} algo/unit.cpp\n$")
        shutil.rmtree(self.cache)
        other = self.make_tree(self.tmp / "clone-b")
        self.assert_status("known clean", other, ("--known-clean", str(listed)))
        (other / "algo" / "helper.hpp").write_text(CAST_HELPER)
        self.assert_status("finding", other, ("--known-clean", str(listed),
                                               "--record-known-clean", str(listed)))
        self.assertRegex(listed.read_text(), r"^[0-9a-f]{64} algo/unit.cpp\n$")
        self.assert_status("finding", other, ("--known-clean", str(listed)))

    # The fake clang fails to preprocess: "cached" can only come from the dependency file's key.
    def test_a_built_unit_is_keyed_by_the_files_it_read(self):
        clang = self.clang_that_cannot_preprocess()
        self.compile()
        self.assert_status("clean", clang=clang)
        self.assert_status("cached", clang=clang)
        self.set_helper(SUPPRESSED_HELPER)
        self.compile()
        self.assert_status("clean", clang=clang)
        self.assert_status("cached", clang=clang)
        self.set_helper(CAST_HELPER)
        self.compile()
        self.assert_status("finding", clang=clang)
        self.assert_status("finding", clang=clang)

    def test_a_built_clone_at_another_path_shares_the_cache(self):
        clang = self.clang_that_cannot_preprocess()
        self.compile()
        self.assert_status("clean", clang=clang)
        other = self.make_tree(self.tmp / "clone-b")
        self.compile(other)
        self.assert_status("cached", other, clang=clang)

    # Edited since the build, the unit includes a file its dependency file does not list: a key
    # from the list would not see that file change.
    def test_a_unit_edited_after_the_build_is_preprocessed(self):
        self.compile()
        unit = self.tree / "algo" / "unit.cpp"
        other = self.tree / "algo" / "other.hpp"
        other.write_text(CLEAN_HELPER.replace("helper", "other"))
        unit.write_text('#include "other.hpp"\n' + UNIT)
        later = (self.tree / "build" / "unit.o.d").stat().st_mtime_ns + 1_000_000_000
        os.utime(unit, ns=(later, later))
        self.assert_status("clean")
        other.write_text(CAST_HELPER.replace("helper", "other"))
        self.assert_status("finding")

if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    CLANG_TIDY, CLANG = sys.argv[1], sys.argv[2]
    SOURCE_ROOT = pathlib.Path(sys.argv[3])
    unittest.main(argv=sys.argv[:1], verbosity=2)
