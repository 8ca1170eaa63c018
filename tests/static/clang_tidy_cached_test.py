#!/usr/bin/env python3
"""The clang-tidy cache never hides a finding: a unit with a finding fails on every run, and any
change to what clang-tidy reads (a header, a NOLINT comment, the configuration, the flags) is
analysed again; an unchanged unit, also in a clone at another path, is not.

Usage: clang_tidy_cached_test.py CLANG_TIDY CLANG SOURCE_ROOT
"""
import json
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

    def run_cached(self, tree=None, options=()):
        tree = tree or self.tree
        result = subprocess.run(
            [sys.executable, str(SCRIPT), "--clang-tidy", CLANG_TIDY, "--clang", CLANG,
             "--build", str(tree / "build"), "--source-root", str(tree),
             "--cache", str(self.cache), "--extra-arg=-std=c++2b", *options, "algo/unit.cpp"],
            capture_output=True, text=True)
        return result.returncode, result.stdout + result.stderr

    def set_helper(self, text):
        (self.tree / "algo" / "helper.hpp").write_text(text)

    def assert_status(self, status, tree=None, options=()):
        code, output = self.run_cached(tree, options)
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


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    CLANG_TIDY, CLANG = sys.argv[1], sys.argv[2]
    SOURCE_ROOT = pathlib.Path(sys.argv[3])
    unittest.main(argv=sys.argv[:1], verbosity=2)
