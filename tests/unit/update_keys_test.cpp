// Keys and signatures against minisign itself: its verifier accepts our signatures, and its keys
// and signatures read and verify here.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "smx/update/file_io.hpp"
#include "smx/update/keys.hpp"
#include "smx/update/signature.hpp"
#include "update_fixture.hpp"

namespace smx::update {
namespace {

namespace fs = std::filesystem;

class UpdateKeys : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("smx_update_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static std::string read(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  static void write(const fs::path& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
  }
  static bool haveMinisign() { return std::system("minisign -v >/dev/null 2>&1") == 0; }

  fs::path dir_;
};

TEST_F(UpdateKeys, FilesRoundTripAndTheSecretKeyIsPrivateAndNeverReplaced) {
  const KeyPair pair = generateKeyPair();
  ASSERT_TRUE(writeSecretKeyFile(dir_ / "k.key", pair.secret));
  ASSERT_TRUE(writePublicKeyFile(dir_ / "k.pub", pair.pub));

  struct stat st {};
  ASSERT_EQ(::stat((dir_ / "k.key").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777U, 0600U);
  const auto secret = readSecretKeyFile(dir_ / "k.key");
  const auto pub = readPublicKeyFile(dir_ / "k.pub");
  ASSERT_TRUE(secret) << secret.error().message;
  ASSERT_TRUE(pub) << pub.error().message;
  EXPECT_EQ(secret->key, pair.secret.key);
  EXPECT_EQ(pub->key, pair.pub.key);
  EXPECT_EQ(pub->id, pair.pub.id);

  const auto again = writeSecretKeyFile(dir_ / "k.key", generateKeyPair().secret);
  ASSERT_FALSE(again);
  EXPECT_EQ(again.error().reason, UpdateReason::kExists);
  EXPECT_EQ(readSecretKeyFile(dir_ / "k.key")->key, pair.secret.key);
}

TEST_F(UpdateKeys, ASecretKeyWithAWrongChecksumIsRefused) {
  std::string text = formatSecretKey(test::testKey(7).secret);
  const auto at = text.find('\n') + 1 + 100;  // base64 of the secret key's bytes 75..
  text[at] = text[at] == 'A' ? 'B' : 'A';
  const auto key = parseSecretKey(text, "k.key");
  ASSERT_FALSE(key);
  EXPECT_EQ(key.error().reason, UpdateReason::kMalformed);
  EXPECT_NE(key.error().message.find("k.key"), std::string::npos);
}

TEST_F(UpdateKeys, KeyIdsPrintAsMinisignPrintsThem) {
  // Ids and names from key files minisign 0.11 wrote ("minisign public key 748CD41B5481321").
  EXPECT_EQ(keyIdHex({0x21, 0x13, 0x48, 0xb5, 0x41, 0xcd, 0x48, 0x07}), "748CD41B5481321");
  EXPECT_EQ(keyIdHex({0x63, 0xc5, 0x94, 0x02, 0x44, 0x03, 0x3e, 0x00}), "3E03440294C563");
  EXPECT_EQ(keyIdHex({}), "0");
}

TEST_F(UpdateKeys, MinisignVerifiesOurSignature) {
  if (!haveMinisign()) {
    GTEST_SKIP() << "minisign is not installed (tools/install-deps installs it)";
  }
  const KeyPair pair = test::testKey(3);
  const std::string data = "firmware bytes\n";
  write(dir_ / "data", data);
  write(dir_ / "data.minisig", sign(pair.secret, asBytes(data), "stripemux-bundle/1"));
  const std::string check = "minisign -Vq -P " + publicKeyLine(pair.pub) + " -m " +
                            (dir_ / "data").string() + " >/dev/null 2>&1";
  EXPECT_EQ(std::system(check.c_str()), 0);

  // The same signature over other bytes: minisign refuses it too, so the check above can fail.
  write(dir_ / "data", data + "!");
  EXPECT_NE(std::system(check.c_str()), 0);
}

TEST_F(UpdateKeys, MinisignKeysAndSignaturesVerifyHere) {
  if (!haveMinisign()) {
    GTEST_SKIP() << "minisign is not installed (tools/install-deps installs it)";
  }
  const auto key = dir_ / "m.key";
  const auto pubPath = dir_ / "m.pub";
  const auto file = dir_ / "data";
  write(file, "signed by minisign\n");
  const std::string make = "minisign -G -W -s " + key.string() + " -p " + pubPath.string() +
                           " >/dev/null 2>&1 && minisign -S -s " + key.string() + " -m " +
                           file.string() + " -t stripemux >/dev/null 2>&1";
  ASSERT_EQ(std::system(make.c_str()), 0);

  const auto pub = readPublicKeyFile(pubPath);
  const auto secret = readSecretKeyFile(key);
  ASSERT_TRUE(pub) << pub.error().message;
  ASSERT_TRUE(secret) << secret.error().message;
  EXPECT_EQ(secret->id, pub->id);
  // minisign names its key id in the public key's comment: the same text as keyIdHex.
  EXPECT_NE(read(pubPath).find("minisign public key " + keyIdHex(pub->id)), std::string::npos);

  // Its untrusted comment is unauthenticated free text; the bundle's is fixed.
  std::string signature = read(dir_ / "data.minisig");
  signature.replace(0, signature.find('\n'), kUntrustedComment);
  const std::string data = read(file);
  const auto id = verify(asBytes(data), signature, std::span(&*pub, 1));
  ASSERT_TRUE(id) << id.error().message;
  EXPECT_EQ(*id, pub->id);

  const auto other = verify(asBytes(data + "x"), signature, std::span(&*pub, 1));
  ASSERT_FALSE(other);
  EXPECT_EQ(other.error().reason, UpdateReason::kBadSignature);
}

}  // namespace
}  // namespace smx::update
