// Bundles as the device meets them: every cut and every changed byte refused for the reason its
// place in the layout gives (docs/update.md), keys, boards and versions, hostile manifests signed
// by a trusted key; and nothing extracted unless all of it holds.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "smx/update/bundle.hpp"
#include "update_fixture.hpp"

namespace smx::update {
namespace {

namespace fs = std::filesystem;

using Reasons = std::set<UpdateReason>;

const KeyPair kKey = test::testKey(1);
const KeyPair kOtherKey = test::testKey(2);

std::expected<VerifiedBundle, UpdateError> check(std::vector<std::byte> bytes,
                                                 const Expectations& expect = {"sim", {}}) {
  const std::vector<PublicKey> trusted = {kOtherKey.pub, kKey.pub};
  return verifyBundle(std::move(bytes), trusted, expect);
}

std::vector<std::byte> smallBundle() {
  auto bundle = makeBundle(kKey.secret, test::smallSpec());
  EXPECT_TRUE(bundle) << bundle.error().message;
  return bundle ? *bundle : std::vector<std::byte>{};
}

// The layout's regions, read from the header and trailer as docs/update.md describes them.
struct Regions {
  std::size_t manifestEnd;
  std::size_t payloadEnd;
  std::size_t signatureEnd;
};

std::uint64_t le(const std::vector<std::byte>& b, std::size_t at, std::size_t size) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < size; ++i) {
    v |= static_cast<std::uint64_t>(b[at + i]) << (8 * i);
  }
  return v;
}

Regions regionsOf(const std::vector<std::byte>& b) {
  const std::size_t manifestEnd = 24 + le(b, 8, 4);
  const std::size_t payloadEnd = manifestEnd + le(b, 16, 8);
  return {manifestEnd, payloadEnd, payloadEnd + le(b, b.size() - 12, 4)};
}

TEST(UpdateBundle, ASmallBundleVerifiesWithItsManifest) {
  const auto bundle = check(smallBundle());
  ASSERT_TRUE(bundle) << bundle.error().message;
  const auto& info = bundle->info();
  EXPECT_EQ(info.version, (Version{1, 4, 2}));
  EXPECT_EQ(info.boards, (std::vector<std::string>{"rpi4", "sim"}));
  EXPECT_EQ(info.keyId, kKey.pub.id);
  ASSERT_EQ(info.files.size(), 3U);
  const auto spec = test::smallSpec();
  for (std::size_t i = 0; i < spec.files.size(); ++i) {
    EXPECT_EQ(info.files[i].name, spec.files[i].name);
    EXPECT_EQ(info.files[i].mode, spec.files[i].mode);
    const auto bytes = bundle->fileBytes(info.files[i]);
    EXPECT_EQ(std::vector<std::byte>(bytes.begin(), bytes.end()), spec.files[i].bytes);
  }
}

TEST(UpdateBundle, EveryCutIsTruncated) {
  const auto whole = smallBundle();
  for (std::size_t size = 0; size < whole.size(); ++size) {
    const auto result = check({whole.begin(), whole.begin() + static_cast<std::ptrdiff_t>(size)});
    ASSERT_FALSE(result) << "cut at " << size;
    EXPECT_EQ(result.error().reason, UpdateReason::kTruncated)
        << "cut at " << size << ": " << result.error().message;
  }
}

TEST(UpdateBundle, EveryChangedByteIsRefusedForItsRegion) {
  const auto whole = smallBundle();
  const Regions r = regionsOf(whole);
  ASSERT_EQ(r.signatureEnd + 12, whole.size());
  const Reasons sizes = {UpdateReason::kTruncated, UpdateReason::kMalformed,
                         UpdateReason::kTooLarge};
  const Reasons signature = {UpdateReason::kMalformed, UpdateReason::kBadSignature,
                             UpdateReason::kUnknownKey};
  for (const std::byte mask : {std::byte{0x01}, std::byte{0xff}}) {
    for (std::size_t at = 0; at < whole.size(); ++at) {
      auto changed = whole;
      changed[at] ^= mask;
      const auto result = check(changed);
      ASSERT_FALSE(result) << "byte " << at;
      const auto reason = result.error().reason;
      if (at < 24 || at >= r.signatureEnd) {
        EXPECT_TRUE(sizes.contains(reason))
            << "header/trailer byte " << at << ": " << result.error().message;
      } else if (at < r.payloadEnd) {
        // The manifest and files are only read once the signature over them holds.
        EXPECT_EQ(reason, UpdateReason::kBadSignature) << "signed byte " << at;
      } else {
        EXPECT_TRUE(signature.contains(reason))
            << "signature byte " << at << ": " << result.error().message;
      }
    }
  }
}

TEST(UpdateBundle, KeysBoardsAndVersions) {
  const std::vector<PublicKey> onlyOther = {kOtherKey.pub};
  const auto unknown = verifyBundle(smallBundle(), onlyOther, {});
  ASSERT_FALSE(unknown);
  EXPECT_EQ(unknown.error().reason, UpdateReason::kUnknownKey);

  const auto board = check(smallBundle(), {"qemu", {}});
  ASSERT_FALSE(board);
  EXPECT_EQ(board.error().reason, UpdateReason::kWrongBoard);
  EXPECT_NE(board.error().message.find("qemu"), std::string::npos);

  EXPECT_TRUE(check(smallBundle(), {"rpi4", Version{1, 4, 2}}));  // the same version again
  EXPECT_TRUE(check(smallBundle(), {"rpi4", Version{0, 9, 9}}));
  for (const Version newer : {Version{1, 4, 3}, Version{1, 5, 0}, Version{2, 0, 0}}) {
    const auto down = check(smallBundle(), {"sim", newer});
    ASSERT_FALSE(down);
    EXPECT_EQ(down.error().reason, UpdateReason::kDowngrade);
  }
  auto spec = test::smallSpec();
  spec.allowDowngrade = true;
  const auto allowed = check(*makeBundle(kKey.secret, spec), {"sim", Version{2, 0, 0}});
  ASSERT_TRUE(allowed) << allowed.error().message;
  EXPECT_TRUE(allowed->info().allowDowngrade);
}

// A manifest with one file named `name`, its size and hash right, signed by the trusted key.
std::vector<std::byte> signedWithName(const std::string& name) {
  const auto payload = test::bytesOf("x");
  // BLAKE2b-256("x"), from Python's hashlib.blake2b(b"x", digest_size=32).
  const std::string manifest =
      R"({"format": "stripemux-bundle/1", "version": "1.0.0", "boards": ["sim"],
          "allow_downgrade": false, "files": [{"name": ")" +
      name +
      R"(", "size": 1, "mode": "0644",
          "blake2b": "d161d71145abeec5ef15abcf0459cec60a27321e2f0ac0ef7ace5254f5944476"}]})";
  return sealBundle(kKey.secret, manifest, payload);
}

TEST(UpdateBundle, HostileNamesSignedByATrustedKeyAreRefused) {
  const auto plain = check(signedWithName("bin/x"));
  ASSERT_TRUE(plain) << plain.error().message;  // so that what follows fails for the name alone
  const std::vector<std::string> names = {"../x",        "bin/../../x",
                                          "/etc/passwd", "bin//x",
                                          "bin/",        "",
                                          ".",           "bin/./x",
                                          "a\\\\b",      "a b",
                                          "bin/\\u00e9", "bin/x\\u0000y",
                                          "..",          std::string(256, 'a')};
  for (const auto& name : names) {
    const auto result = check(signedWithName(name));
    ASSERT_FALSE(result) << name;
    EXPECT_EQ(result.error().reason, UpdateReason::kBadName)
        << name << ": " << result.error().message;
  }
}

TEST(UpdateBundle, SignedButWrongManifestsAreRefusedNamingTheField) {
  const auto payload = test::bytesOf("xy");
  const std::string head =
      R"({"format": "stripemux-bundle/1", "version": "1.0.0", "boards": ["sim"],
      "allow_downgrade": false, "files": [)";
  const std::string x =
      R"({"name": "a", "size": 1, "mode": "0644", "blake2b": "d161d71145abeec5ef15abcf0459cec60a27321e2f0ac0ef7ace5254f5944476"})";
  struct Case {
    std::string manifest;
    UpdateReason reason;
    std::string names;
  };
  const std::vector<Case> cases = {
      {head + x + "," +
           R"({"name": "a", "size": 1, "mode": "0644", "blake2b": "d161d71145abeec5ef15abcf0459cec60a27321e2f0ac0ef7ace5254f5944476"}]})",
       UpdateReason::kBadName, "twice"},
      {head + x + "," +
           R"({"name": "a/b", "size": 1, "mode": "0644", "blake2b": "d161d71145abeec5ef15abcf0459cec60a27321e2f0ac0ef7ace5254f5944476"}]})",
       UpdateReason::kBadName, "file and a directory"},
      {head + x + "," +
           R"({"name": "b", "size": 1, "mode": "0644", "blake2b": "0000000000000000000000000000000000000000000000000000000000000000"}]})",
       UpdateReason::kBadHash, "b:"},
      {head + x + "]}", UpdateReason::kMalformed, "payload"},
      {head + x + "," +
           R"({"name": "b", "size": 1, "mode": "0777", "blake2b": "d161d71145abeec5ef15abcf0459cec60a27321e2f0ac0ef7ace5254f5944476"}]})",
       UpdateReason::kMalformed, "files[1].mode"},
      {head + x + "," +
           R"({"name": "b", "size": -1, "mode": "0644", "blake2b": "d161d71145abeec5ef15abcf0459cec60a27321e2f0ac0ef7ace5254f5944476"}]})",
       UpdateReason::kMalformed, "files[1].size"},
      {head + x + "," +
           R"({"name": "b", "size": 1, "mode": "0644", "owner": "root", "blake2b": "d161d71145abeec5ef15abcf0459cec60a27321e2f0ac0ef7ace5254f5944476"}]})",
       UpdateReason::kMalformed, "files[1].owner"},
      {R"({"format": "stripemux-bundle/1", "version": "1.0", "boards": ["sim"], "allow_downgrade": false, "files": []})",
       UpdateReason::kMalformed, "version"},
      {R"({"format": "stripemux-bundle/1", "version": "1.0.0", "boards": [], "allow_downgrade": false, "files": []})",
       UpdateReason::kMalformed, "boards"},
      {R"({"format": "stripemux-bundle/2", "version": "1.0.0", "boards": ["sim"], "allow_downgrade": false, "files": []})",
       UpdateReason::kMalformed, "format"},
      {"[1, 2", UpdateReason::kMalformed, "not JSON"},
  };
  for (const auto& c : cases) {
    const bool empty = c.manifest.find("\"files\": []") != std::string::npos;
    const auto result =
        check(sealBundle(kKey.secret, c.manifest, empty ? std::span<const std::byte>{} : payload));
    ASSERT_FALSE(result) << c.manifest;
    EXPECT_EQ(result.error().reason, c.reason) << result.error().message;
    EXPECT_NE(result.error().message.find(c.names), std::string::npos) << result.error().message;
  }
}

TEST(UpdateBundle, MakeBundleRefusesWhatADeviceWouldRefuse) {
  auto spec = test::smallSpec();
  spec.files.push_back({"../escape", 0644, test::bytesOf("x")});
  const auto bad = makeBundle(kKey.secret, spec);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().reason, UpdateReason::kBadName);
}

}  // namespace
}  // namespace smx::update
