#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "cli.hpp"

// In-process runs of the `stripemux` command line for tests, and a fixture with a scratch folder
// named after the test.
namespace smx::test {

struct CliRun {
  int code;
  std::string out;
  std::string err;
};

inline CliRun runCli(const std::vector<std::string>& args) {
  std::ostringstream out;
  std::ostringstream err;
  const int code = host::runCli(args, {out, err});
  return {code, out.str(), err.str()};
}

// The text of `file` with the first occurrence of `from` replaced by `to` (unchanged for an
// empty `from`): one field of a shipped rig or board made wrong.
inline std::string textWith(const std::filesystem::path& file, const std::string& from,
                            const std::string& to) {
  std::ifstream in(file);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test bug: " << from << " not in " << file;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        std::filesystem::temp_directory_path() /
        ("smx_cli_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::filesystem::path writeFile(const std::string& name, const std::string& text) {
    auto path = dir_ / name;
    std::ofstream(path) << text;
    return path;
  }

  std::filesystem::path dir_;
};

}  // namespace smx::test
