#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "smx/protocol/secure_messages.hpp"
#include "smx/protocol/secure_session.hpp"

// Pairing (docs/security.md): the device prints a one-time code; host and device run CPace on
// ristretto255 with the code as the password, so a passive observer learns nothing and an
// active one tests one guess per attempt (no offline search), then each proves the code with a
// MAC over the transcript, which binds both long-term keys.
namespace smx::protocol {

// One side's half of the exchange: a secret scalar and the element it sends.
struct PakeShare {
  Key32 scalar{};
  Key32 element{};
};

[[nodiscard]] PakeShare pakeStart(std::string_view code);

struct PairingKeys {
  Key32 deviceProof{};
  Key32 hostProof{};
};

// Both sides derive the same proofs from their share, the peer's element and the two requests'
// fields; nullopt for an invalid peer element.
[[nodiscard]] std::optional<PairingKeys> pakeFinish(const PakeShare& mine, const Key32& peerElement,
                                                    const PairRequest& request,
                                                    const Key32& deviceElement,
                                                    const Key32& deviceIdentity);
// Constant-time comparison of two proofs.
[[nodiscard]] bool sameProof(const Key32& a, const Key32& b);

// The device's one-time code: kDigits decimal digits, valid kLifetimeNs, kAttempts tries. A new
// code can be opened at most every kReopenNs, which bounds an attacker's guesses per minute.
class PairingCode {
 public:
  static constexpr int kDigits = 8;
  static constexpr int kAttempts = 3;
  static constexpr std::int64_t kLifetimeNs = 300'000'000'000;
  static constexpr std::int64_t kReopenNs = 10'000'000'000;

  // A fresh code if none is open and the last one was opened long enough ago (the caller
  // prints it); nullopt otherwise.
  [[nodiscard]] std::optional<std::string> open(std::int64_t nowNs);
  [[nodiscard]] bool isOpen(std::int64_t nowNs) const;
  // Takes one attempt: the code to check against, or nullopt when none is open.
  [[nodiscard]] std::optional<std::string> attempt(std::int64_t nowNs);
  // The code paired a host: it is used up.
  void close();
  [[nodiscard]] int attemptsLeft() const { return attemptsLeft_; }
  [[nodiscard]] int secondsLeft(std::int64_t nowNs) const;

 private:
  std::string code_;
  std::int64_t openedNs_ = 0;
  bool everOpened_ = false;
  int attemptsLeft_ = 0;
};

}  // namespace smx::protocol
