#pragma once

#include <filesystem>

namespace smx::test {

// The source tree the tests read their data from (boards/, tests/unit/testdata/, ...). Compiled
// into this one function so that the compiler cache of every other test file does not depend on
// where the tree is checked out.
const std::filesystem::path& sourceDir();

}  // namespace smx::test
