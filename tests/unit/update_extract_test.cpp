// Extraction into a slot: exactly the bundle's files with their bytes and modes, nothing beside
// them, the slot appearing whole (through slot.tmp and a rename) or not at all.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "smx/update/bundle.hpp"
#include "update_fixture.hpp"

namespace smx::update {
namespace {

namespace fs = std::filesystem;

const KeyPair kKey = test::testKey(1);

class UpdateExtract : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("smx_extract_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // What the device does with a bundle: verify, and only then extract.
  std::expected<void, UpdateError> install(std::vector<std::byte> bytes, const fs::path& slot) {
    const std::vector<PublicKey> trusted = {kKey.pub};
    const auto bundle = verifyBundle(std::move(bytes), trusted, {"sim", Version{1, 0, 0}});
    if (!bundle) {
      return std::unexpected(bundle.error());
    }
    return extractBundle(*bundle, slot);
  }

  // Every entry below dir: regular files with their bytes and permission bits.
  static std::map<std::string, std::pair<std::string, unsigned>> tree(const fs::path& dir) {
    std::map<std::string, std::pair<std::string, unsigned>> files;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
      if (entry.is_directory()) {
        continue;
      }
      struct stat st {};
      ::lstat(entry.path().c_str(), &st);
      std::ifstream in(entry.path(), std::ios::binary);
      files[entry.path().lexically_relative(dir).generic_string()] = {
          std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()),
          S_ISREG(st.st_mode) ? st.st_mode & 07777U : 0xffffU};
    }
    return files;
  }

  fs::path dir_;
};

TEST_F(UpdateExtract, WritesExactlyTheFilesWithTheirBytesAndModes) {
  const auto spec = test::smallSpec();
  ASSERT_TRUE(install(*makeBundle(kKey.secret, spec), dir_ / "slot-b"));

  std::map<std::string, std::pair<std::string, unsigned>> expected;
  for (const auto& f : spec.files) {
    expected[f.name] = {std::string(reinterpret_cast<const char*>(f.bytes.data()), f.bytes.size()),
                        f.mode};
  }
  EXPECT_EQ(tree(dir_ / "slot-b"), expected);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1)
      << "only the slot is left beside it";
}

TEST_F(UpdateExtract, RefusedBundlesWriteNothing) {
  auto changed = *makeBundle(kKey.secret, test::smallSpec());
  changed[30] ^= std::byte{1};  // in the manifest
  const auto result = install(changed, dir_ / "slot-b");
  ASSERT_FALSE(result);
  EXPECT_EQ(result.error().reason, UpdateReason::kBadSignature);
  EXPECT_TRUE(fs::is_empty(dir_));
}

TEST_F(UpdateExtract, AnExistingSlotIsNotTouchedAndAStaleTemporaryIsReplaced) {
  fs::create_directories(dir_ / "slot-a");
  std::ofstream(dir_ / "slot-a" / "keep") << "old";
  const auto exists = install(*makeBundle(kKey.secret, test::smallSpec()), dir_ / "slot-a");
  ASSERT_FALSE(exists);
  EXPECT_EQ(exists.error().reason, UpdateReason::kExists);
  EXPECT_EQ(tree(dir_ / "slot-a").size(), 1U);

  // What an extraction killed half way leaves behind.
  fs::create_directories(dir_ / "slot-b.tmp" / "bin");
  std::ofstream(dir_ / "slot-b.tmp" / "bin" / "half") << "half";
  ASSERT_TRUE(install(*makeBundle(kKey.secret, test::smallSpec()), dir_ / "slot-b"));
  EXPECT_FALSE(fs::exists(dir_ / "slot-b.tmp"));
  EXPECT_FALSE(fs::exists(dir_ / "slot-b" / "bin" / "half"));
  EXPECT_EQ(tree(dir_ / "slot-b").size(), test::smallSpec().files.size());
}

}  // namespace
}  // namespace smx::update
