// The slots of a state directory: the boot record's text, the active link, slot contents, the
// trusted keys, and the atomic writer's steps. The truth is the file system as read here
// (readlink, the files' bytes) and hand-written JSON, not the library's own readers.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "smx/update/file_io.hpp"
#include "smx/update/slots.hpp"
#include "update_fixture.hpp"

namespace smx::update {
namespace {

namespace fs = std::filesystem;

const KeyPair kKey = test::testKey(3);

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void writeText(const fs::path& file, const std::string& text) {
  std::ofstream(file, std::ios::binary) << text;
}

class UpdateSlots : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("smx_slots_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static VerifiedBundle verified(const BundleSpec& spec) {
    const auto bytes = makeBundle(kKey.secret, spec);
    EXPECT_TRUE(bytes.has_value());
    const std::vector<PublicKey> trusted = {kKey.pub};
    auto bundle = verifyBundle(*bytes, trusted, {"sim", std::nullopt});
    EXPECT_TRUE(bundle.has_value()) << bundle.error().message;
    return std::move(*bundle);
  }

  fs::path dir_;
};

TEST_F(UpdateSlots, AHandWrittenBootRecordIsRead) {
  writeText(dir_ / "boot.json", R"({"format": "stripemux-boot/1", "previous": "a",
    "pending": "b", "tries": 1, "marked_good": false, "outcome": "rolled back",
    "reason": "the firmware exited", "version": "0.2.0"})");
  const auto record = readBootRecord(dir_);
  ASSERT_TRUE(record.has_value()) << record.error().message;
  EXPECT_EQ(record->previous, "a");
  EXPECT_EQ(record->pending, "b");
  EXPECT_EQ(record->tries, 1);
  EXPECT_FALSE(record->markedGood);
  EXPECT_EQ(record->outcome, UpdateOutcome::kRolledBack);
  EXPECT_EQ(record->reason, "the firmware exited");
  EXPECT_EQ(record->version, "0.2.0");
}

TEST_F(UpdateSlots, NoBootRecordIsTheFactoryState) {
  const auto record = readBootRecord(dir_);
  ASSERT_TRUE(record.has_value());
  EXPECT_TRUE(record->pending.empty());
  EXPECT_TRUE(record->markedGood);
  EXPECT_EQ(record->outcome, UpdateOutcome::kNone);
}

TEST_F(UpdateSlots, AWrittenRecordIsReadBackAndLeavesNoTemporary) {
  const BootRecord record{"b", "a", 1, false, UpdateOutcome::kInstalled, "", "1.2.3"};
  ASSERT_TRUE(writeBootRecord(dir_, record).has_value());
  EXPECT_EQ(readBootRecord(dir_).value(), record);
  EXPECT_FALSE(fs::exists(dir_ / "boot.json.tmp"));
}

TEST_F(UpdateSlots, BadBootRecordFieldsAreNamed) {
  const std::string head = R"({"format": "stripemux-boot/1", "previous": "", )";
  const std::string tail =
      R"(, "marked_good": true, "outcome": "none", "reason": "", "version": ""})";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {head + R"("pending": "../x", "tries": 0)" + tail, "pending"},
      {head + R"("pending": "", "tries": -1)" + tail, "tries"},
      {head + R"("pending": "", "tries": 101)" + tail, "tries"},
      {R"({"format": "other", "previous": "", "pending": ""})", "format"},
      {"not json", "not a JSON object"},
  };
  for (const auto& [text, field] : cases) {
    const auto record = parseBootRecord(text);
    ASSERT_FALSE(record.has_value()) << text;
    EXPECT_NE(record.error().message.find(field), std::string::npos) << record.error().message;
  }
}

TEST_F(UpdateSlots, TheActiveLinkIsSwitchedAndRemoved) {
  EXPECT_EQ(activeSlot(dir_).value(), std::nullopt);
  ASSERT_TRUE(switchActive(dir_, "b").has_value());
  EXPECT_EQ(fs::read_symlink(dir_ / "active"), fs::path("slots/b"));
  EXPECT_EQ(activeSlot(dir_).value(), std::optional<std::string>("b"));
  ASSERT_TRUE(switchActive(dir_, "a").has_value());
  EXPECT_EQ(fs::read_symlink(dir_ / "active"), fs::path("slots/a"));
  EXPECT_FALSE(fs::exists(fs::symlink_status(dir_ / "active.tmp")));
  ASSERT_TRUE(switchActive(dir_, std::nullopt).has_value());
  EXPECT_FALSE(fs::exists(fs::symlink_status(dir_ / "active")));
  EXPECT_FALSE(switchActive(dir_, "../etc").has_value());
}

TEST_F(UpdateSlots, ALinkElsewhereIsRefused) {
  fs::create_symlink("/etc", dir_ / "active");
  EXPECT_FALSE(activeSlot(dir_).has_value());
}

TEST_F(UpdateSlots, TheInactiveSlotIsTheOther) {
  EXPECT_EQ(inactiveSlot(std::nullopt), "a");
  EXPECT_EQ(inactiveSlot("a"), "b");
  EXPECT_EQ(inactiveSlot("b"), "a");
}

TEST_F(UpdateSlots, ASlotHoldsTheBundleAndItsManifestAndReplacesAStaleOne) {
  fs::create_directories(dir_ / "slots" / "b");
  writeText(dir_ / "slots" / "b" / "stale", "left by an earlier update");
  ASSERT_TRUE(writeSlot(dir_, "b", verified(test::smallSpec())).has_value());
  EXPECT_FALSE(fs::exists(dir_ / "slots" / "b" / "stale"));
  EXPECT_EQ(readText(dir_ / "slots" / "b" / "bin" / "stripemuxd"), "#!/bin/sh\necho firmware\n");
  EXPECT_NE(readText(dir_ / "slots" / "b" / "slot.json").find("\"1.4.2\""), std::string::npos);
  const auto manifest = readSlotManifest(dir_, "b");
  ASSERT_TRUE(manifest.has_value()) << manifest.error().message;
  EXPECT_EQ(manifest->version, (Version{1, 4, 2}));
  EXPECT_EQ(manifest->boards, (std::vector<std::string>{"rpi4", "sim"}));
  EXPECT_FALSE(readSlotManifest(dir_, "a").has_value());
}

TEST_F(UpdateSlots, ABundleCannotOverwriteTheSlotManifest) {
  BundleSpec spec = test::smallSpec();
  spec.files.push_back({"slot.json", 0644, test::bytesOf("{\"version\": \"9.9.9\"}")});
  const auto written = writeSlot(dir_, "a", verified(spec));
  ASSERT_FALSE(written.has_value());
  EXPECT_EQ(written.error().reason, UpdateReason::kBadName);
  EXPECT_FALSE(fs::exists(dir_ / "slots" / "a"));
}

TEST_F(UpdateSlots, TrustedKeysAreThePubFilesOfKeys) {
  EXPECT_TRUE(readTrustedKeys(dir_).value().empty());
  fs::create_directories(dir_ / "keys");
  const KeyPair other = test::testKey(4);
  writeText(dir_ / "keys" / "a.pub", formatPublicKey(kKey.pub));
  writeText(dir_ / "keys" / "b.pub", formatPublicKey(other.pub));
  writeText(dir_ / "keys" / "notes.txt", "not a key");
  const auto keys = readTrustedKeys(dir_);
  ASSERT_TRUE(keys.has_value());
  ASSERT_EQ(keys->size(), 2U);
  EXPECT_EQ((*keys)[0].key, kKey.pub.key);
  EXPECT_EQ((*keys)[1].key, other.pub.key);
  writeText(dir_ / "keys" / "c.pub", "garbage");
  const auto broken = readTrustedKeys(dir_);
  ASSERT_FALSE(broken.has_value());
  EXPECT_NE(broken.error().message.find("c.pub"), std::string::npos) << broken.error().message;
}

// The hook sees every step in order; until the rename the old file is the file.
TEST_F(UpdateSlots, TheAtomicWriterTellsItsStepsAndKeepsTheOldFileUntilTheRename) {
  const fs::path file = dir_ / "config.json";
  writeText(file, "old");
  std::vector<std::string> steps;
  std::vector<std::string> seen;
  const auto written = writeFileAtomic(file, asBytes(std::string("new")), 0644, Replace::kAllow,
                                       [&](std::string_view step) {
                                         steps.emplace_back(step);
                                         seen.push_back(readText(file));
                                       });
  ASSERT_TRUE(written.has_value());
  const std::vector<std::string> expected(std::begin(kAtomicWriteSteps),
                                          std::end(kAtomicWriteSteps));
  EXPECT_EQ(steps, (std::vector<std::string>{"temp-created", "temp-written", "temp-synced",
                                             "renamed", "dir-synced"}));
  EXPECT_EQ(steps, expected);
  EXPECT_EQ(seen, (std::vector<std::string>{"old", "old", "old", "new", "new"}));
  EXPECT_EQ(tempPathOf(file), fs::path(file.string() + ".tmp"));
  EXPECT_FALSE(fs::exists(tempPathOf(file)));
}

}  // namespace
}  // namespace smx::update
