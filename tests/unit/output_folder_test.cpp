// The host tool's one way to write files, and its one way to print outside text.
#include "output_folder.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "cli_harness.hpp"
#include "terminal_text.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

std::string contents(const fs::path& file) {
  std::ifstream in(file);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class OutputFolderTest : public test::CliTest {};

// Names that are paths, empty, hidden, or carry control characters are refused, and nothing
// is written for them.
TEST_F(OutputFolderTest, OnlyPlainNamesAreWritten) {
  auto out = OutputFolder::create(dir_ / "out");
  ASSERT_TRUE(out.has_value()) << out.error();
  const std::string names[] = {"../x.txt",
                               "/tmp/x.txt",
                               "a/b.txt",
                               "",
                               ".hidden",
                               "x\n.txt",
                               std::string("x.txt\0.png", 10),
                               "x..txt",
                               std::string(129, 'a')};
  for (const auto& name : names) {
    const auto written = out->writeText(name, "text");
    EXPECT_FALSE(written.has_value()) << name;
  }
  ASSERT_TRUE(out->commit().has_value());
  EXPECT_TRUE(fs::is_empty(dir_ / "out"));
  EXPECT_FALSE(fs::exists(dir_ / "x.txt"));
  EXPECT_FALSE(fs::exists(dir_ / "out" / "x.txt"));
}

// A file appears under its name only at commit; until then an older file is untouched.
TEST_F(OutputFolderTest, FilesAppearAtCommit) {
  fs::create_directories(dir_ / "out");
  std::ofstream(dir_ / "out" / "a.txt") << "old";
  auto out = OutputFolder::create(dir_ / "out");
  ASSERT_TRUE(out.has_value());
  ASSERT_TRUE(out->writeText("a.txt", "new").has_value());
  ASSERT_TRUE(out->writeText("b.txt", "b").has_value());
  EXPECT_EQ(contents(dir_ / "out" / "a.txt"), "old");
  EXPECT_FALSE(fs::exists(dir_ / "out" / "b.txt"));
  ASSERT_TRUE(out->commit().has_value());
  EXPECT_EQ(contents(dir_ / "out" / "a.txt"), "new");
  EXPECT_EQ(contents(dir_ / "out" / "b.txt"), "b");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_ / "out"), fs::directory_iterator()), 2);
}

// Dropped without commit: its temporary files go, and so do the folders it created, but not a
// folder that existed or one that holds other files.
TEST_F(OutputFolderTest, DroppedWithoutCommitLeavesWhatExisted) {
  {
    auto out = OutputFolder::create(dir_ / "new" / "deeper");
    ASSERT_TRUE(out.has_value());
    ASSERT_TRUE(out->writeText("a.txt", "a").has_value());
  }
  EXPECT_FALSE(fs::exists(dir_ / "new"));
  fs::create_directories(dir_ / "old");
  std::ofstream(dir_ / "old" / "keep.txt") << "keep";
  {
    auto out = OutputFolder::create(dir_ / "old");
    ASSERT_TRUE(out.has_value());
    ASSERT_TRUE(out->writeText("keep.txt", "replaced").has_value());
  }
  EXPECT_EQ(contents(dir_ / "old" / "keep.txt"), "keep");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_ / "old"), fs::directory_iterator()), 1);
}

// A writer's failure names the final file, not the temporary one.
TEST_F(OutputFolderTest, ErrorsNameTheFinalFile) {
  auto out = OutputFolder::create(dir_ / "out");
  ASSERT_TRUE(out.has_value());
  const auto written =
      out->write("a.png", [](const fs::path& file) -> std::expected<void, std::string> {
        return std::unexpected(file.string() + ": write failed");
      });
  ASSERT_FALSE(written.has_value());
  EXPECT_EQ(written.error(), (dir_ / "out" / "a.png").string() + ": write failed");
}

TEST(TerminalText, ControlsAndBrokenUtf8AreShownAsEscapes) {
  EXPECT_EQ(printable("plain text, ümlaut, 日本"), "plain text, ümlaut, 日本");
  EXPECT_EQ(printable("a\x1b[2Jb"), "a\\x1b[2Jb");
  EXPECT_EQ(printable("\x1b]0;title\x07"), "\\x1b]0;title\\x07");
  EXPECT_EQ(printable("\r\n\t\x7f"), "\\x0d\\x0a\\x09\\x7f");
  EXPECT_EQ(printable("\xc2\x9b"
                      "31m"),
            "\\xc2\\x9b31m");                      // C1 CSI as UTF-8
  EXPECT_EQ(printable("\x9b"), "\\x9b");           // C1 CSI as one byte
  EXPECT_EQ(printable("\xe2\x82"), "\\xe2\\x82");  // cut sequence
  EXPECT_EQ(printable("\xc0\xaf"), "\\xc0\\xaf");  // overlong '/'
  EXPECT_EQ(printable(std::string("a\0b", 3)), "a\\x00b");
}

}  // namespace
}  // namespace smx::host
