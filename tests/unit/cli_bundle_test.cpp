// stripemux keygen, bundle and verify-bundle end to end in-process: the owner's key, a bundle of
// a firmware tree, and the device's verdict with the documented exit codes (docs/cli.md).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "cli_harness.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

using test::runCli;

class CliBundle : public test::CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    fs::create_directories(dir_ / "fw/bin");
    fs::create_directories(dir_ / "fw/boards/sim");
    fs::create_directories(dir_ / "fw/boards/rpi4");
    std::ofstream(dir_ / "fw/bin/stripemuxd") << "#!/bin/sh\n";
    fs::permissions(dir_ / "fw/bin/stripemuxd", fs::perms::owner_exec, fs::perm_options::add);
    std::ofstream(dir_ / "fw/boards/sim/board.json") << "{}\n";
    std::ofstream(dir_ / "fw/boards/rpi4/board.json") << "{}\n";
    key_ = (dir_ / "owner").string();
    ASSERT_EQ(runCli({"keygen", "--out", key_}).code, kExitOk);
  }

  test::CliRun bundle(const std::string& version) {
    return runCli({"bundle", "--key", key_ + ".key", "--firmware", (dir_ / "fw").string(), "--out",
                   (dir_ / "fw.bundle").string(), "--version", version});
  }
  test::CliRun verifyFor(const std::string& board, const std::string& installed) {
    return runCli({"verify-bundle", "--pub", key_ + ".pub", "--board", board, "--installed",
                   installed, (dir_ / "fw.bundle").string()});
  }

  std::string key_;
};

TEST_F(CliBundle, KeygenWritesAPrivateKeyAndNeverReplacesIt) {
  struct stat st {};
  ASSERT_EQ(::stat((key_ + ".key").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777U, 0600U);
  const auto again = runCli({"keygen", "--out", key_});
  EXPECT_EQ(again.code, kExitBadInput);
  EXPECT_NE(again.err.find("exists already"), std::string::npos);
}

TEST_F(CliBundle, ABundleOfTheTreeVerifiesForItsBoardsAndVersions) {
  const auto made = bundle("2.1.0");
  ASSERT_EQ(made.code, kExitOk) << made.err;
  EXPECT_NE(made.out.find("3 files"), std::string::npos) << made.out;
  EXPECT_NE(made.out.find("boards rpi4, sim"), std::string::npos) << made.out;

  const auto ok = verifyFor("rpi4", "2.0.9");
  EXPECT_EQ(ok.code, kExitOk) << ok.err;
  const auto board = verifyFor("qemu", "2.0.9");
  EXPECT_EQ(board.code, kExitBadInput);
  EXPECT_NE(board.err.find("wrong board"), std::string::npos) << board.err;
  const auto down = verifyFor("sim", "2.1.1");
  EXPECT_EQ(down.code, kExitBadInput);
  EXPECT_NE(down.err.find("downgrade"), std::string::npos) << down.err;
}

TEST_F(CliBundle, SymlinksInTheTreeAreRefusedNamingThem) {
  fs::create_symlink("/etc/passwd", dir_ / "fw/bin/passwd");
  const auto made = bundle("1.0.0");
  EXPECT_EQ(made.code, kExitBadInput);
  EXPECT_NE(made.err.find("bin/passwd"), std::string::npos) << made.err;
  EXPECT_FALSE(fs::exists(dir_ / "fw.bundle"));
}

}  // namespace
}  // namespace smx::host
