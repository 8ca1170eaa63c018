// Pairing: the right code gives both sides the same proofs, a wrong one different proofs; the
// device's code expires, is single use and is void after three attempts.
#include "smx/protocol/secure_pairing.hpp"

#include <gtest/gtest.h>

#include <set>

#include "smx/protocol/secure_keys.hpp"

namespace smx::protocol {
namespace {

struct PairRun {
  std::optional<PairingKeys> host;
  std::optional<PairingKeys> device;
};

PairRun pair(std::string_view hostCode, std::string_view deviceCode) {
  const KeyPair hostId = generateKeyPair();
  const KeyPair deviceId = generateKeyPair();
  const PakeShare hostShare = pakeStart(hostCode);
  const PakeShare deviceShare = pakeStart(deviceCode);
  const PairRequest request{hostShare.element, hostId.publicKey};
  return {
      pakeFinish(hostShare, deviceShare.element, request, deviceShare.element, deviceId.publicKey),
      pakeFinish(deviceShare, hostShare.element, request, deviceShare.element, deviceId.publicKey)};
}

TEST(SecurePairing, TheRightCodeGivesTheSameProofs) {
  const PairRun run = pair("12345678", "12345678");
  ASSERT_TRUE(run.host && run.device);
  EXPECT_TRUE(sameProof(run.host->deviceProof, run.device->deviceProof));
  EXPECT_TRUE(sameProof(run.host->hostProof, run.device->hostProof));
  EXPECT_FALSE(sameProof(run.host->hostProof, run.host->deviceProof));
}

TEST(SecurePairing, AWrongCodeGivesOtherProofs) {
  const PairRun run = pair("12345678", "12345679");
  ASSERT_TRUE(run.host && run.device);
  EXPECT_FALSE(sameProof(run.host->deviceProof, run.device->deviceProof));
  EXPECT_FALSE(sameProof(run.host->hostProof, run.device->hostProof));
}

TEST(SecurePairing, AnInvalidElementIsRefused) {
  const PakeShare share = pakeStart("00000000");
  const PairRequest request{share.element, generateKeyPair().publicKey};
  Key32 bad{};
  bad.fill(std::byte{0xFF});
  EXPECT_FALSE(pakeFinish(share, bad, request, share.element, request.identity));
  EXPECT_FALSE(pakeFinish(share, Key32{}, request, share.element, request.identity));
}

TEST(SecurePairing, CodesAreEightDigitsAndSingleUse) {
  PairingCode code;
  std::int64_t now = 1'000;
  const auto first = code.open(now);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->size(), 8U);
  EXPECT_EQ(first->find_first_not_of("0123456789"), std::string::npos);
  EXPECT_FALSE(code.open(now)) << "one code at a time";
  EXPECT_EQ(code.attempt(now), first);
  code.close();
  EXPECT_FALSE(code.attempt(now)) << "used up";
}

TEST(SecurePairing, CodesExpire) {
  PairingCode code;
  ASSERT_TRUE(code.open(0));
  EXPECT_EQ(code.secondsLeft(0), 300);
  EXPECT_FALSE(code.attempt(PairingCode::kLifetimeNs));
  EXPECT_TRUE(code.open(PairingCode::kLifetimeNs)) << "a new code after expiry";
}

TEST(SecurePairing, ThreeAttemptsThenANewCodeAfterAPause) {
  PairingCode code;
  const auto opened = code.open(0);
  ASSERT_TRUE(opened);
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(code.attempt(1)) << i;
  }
  EXPECT_FALSE(code.attempt(1));
  EXPECT_FALSE(code.isOpen(1));
  EXPECT_FALSE(code.open(PairingCode::kReopenNs - 1)) << "codes are rate limited";
  EXPECT_TRUE(code.open(PairingCode::kReopenNs));
}

TEST(SecureKeys, PublicKeyLinesRoundTripAndBadOnesAreRefused) {
  const KeyPair pair = generateKeyPair();
  const std::string line = formatPublicKey(pair.publicKey, "laptop");
  const auto back = parsePublicKey(line);
  ASSERT_TRUE(back);
  EXPECT_EQ(*back, pair.publicKey);
  EXPECT_EQ(fingerprint(pair.publicKey).size(), 16U);
  EXPECT_FALSE(parsePublicKey("smx-x25519 1234\n"));
  EXPECT_FALSE(parsePublicKey("ssh-ed25519 " + std::string(64, 'a')));
  EXPECT_FALSE(parsePublicKey("smx-x25519 " + std::string(64, 'g')));
  EXPECT_FALSE(parsePublicKey("smx-x25519 " + std::string(65, 'a')));
}

TEST(SecureKeys, IdentityIsCreatedOnceWithOwnerOnlyMode) {
  const auto dir = std::filesystem::temp_directory_path() / "smx_secure_identity";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const auto made = loadOrCreateIdentity(dir / "identity.key");
  ASSERT_TRUE(made) << made.error();
  EXPECT_EQ(
      std::filesystem::status(dir / "identity.key").permissions() & std::filesystem::perms::all,
      std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  const auto again = loadOrCreateIdentity(dir / "identity.key");
  ASSERT_TRUE(again);
  EXPECT_EQ(again->publicKey, made->publicKey);
  EXPECT_EQ(publicKeyOf(again->secretKey), made->publicKey);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace smx::protocol
