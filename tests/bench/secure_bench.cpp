// The owner's channel's cost (docs/security.md): a 640x480 range frame sent in the clear (copied
// to the socket's buffer) and through the encrypted records (sealed by the device, opened by the
// host), in one run; the session handshake and the pairing exchange. The depth is a slanted
// plane with holes, as RVL and uncompressed (the largest a frame gets). Counters: frames/s and
// bytes/s of one core.
#include <benchmark/benchmark.h>

#include <cstring>
#include <vector>

#include "smx/protocol/messages.hpp"
#include "smx/protocol/secure_pairing.hpp"
#include "smx/protocol/secure_session.hpp"

namespace {

using namespace smx;
using namespace smx::protocol;

constexpr int kWidth = 640;
constexpr int kHeight = 480;

std::vector<std::byte> rangeFrame(Compression compression) {
  std::vector<std::uint16_t> depth(static_cast<std::size_t>(kWidth) * kHeight);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const bool hole = ((x / 16) + (y / 16)) % 10 == 0;
      depth[static_cast<std::size_t>(y * kWidth + x)] =
          static_cast<std::uint16_t>(hole ? 0 : 9000 + x + y / 2);
    }
  }
  const auto plane = *algo::ConstDepthPlane::packed(depth, kWidth, kHeight);
  std::vector<std::byte> buffer(rangeFrameBound(kWidth, kHeight));
  const auto message = encodeRangeFrame({.compression = compression}, plane, buffer);
  buffer.resize(message->size());
  return buffer;
}

// One connection's session: fresh ephemeral keys on both sides, keys derived, streams started.
void startSession(SecureChannel& device, SecureChannel& host, const KeyPair& deviceId,
                  const KeyPair& hostId) {
  const KeyPair hostE = generateKeyPair();
  const KeyPair deviceE = generateKeyPair();
  device.start(
      *deriveSessionKeys(Role::kDevice, deviceE, deviceId, {hostE.publicKey, hostId.publicKey}),
      Role::kDevice);
  host.start(
      *deriveSessionKeys(Role::kHost, hostE, hostId, {deviceE.publicKey, deviceId.publicKey}),
      Role::kHost);
}

struct Pair {
  SecureChannel device;
  SecureChannel host;
  Pair() { startSession(device, host, generateKeyPair(), generateKeyPair()); }
};

// Moves what `from` has pending into `to` and reads its plaintext into `out`.
std::size_t transfer(SecureChannel& from, SecureChannel& to, std::span<std::byte> out) {
  std::size_t plain = 0;
  auto pending = from.pending();
  while (!pending.empty() || to.hasPlain()) {
    const auto space = to.writable();
    const std::size_t n = std::min(space.size(), pending.size());
    std::memcpy(space.data(), pending.data(), n);
    to.commit(n);
    pending = pending.subspan(n);
    plain += *to.read(out);
  }
  from.sent(from.pending().size());
  return plain;
}

void BM_FrameInTheClear(benchmark::State& state, Compression compression) {
  const auto frame = rangeFrame(compression);
  std::vector<std::byte> socket(frame.size());
  for (auto _ : state) {
    std::memcpy(socket.data(), frame.data(), frame.size());
    benchmark::DoNotOptimize(socket.data());
  }
  state.counters["frame_bytes"] = static_cast<double>(frame.size());
  state.counters["frames_per_s"] =
      benchmark::Counter(1.0, benchmark::Counter::kIsIterationInvariantRate);
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(frame.size()));
}

void BM_FrameEncrypted(benchmark::State& state, Compression compression) {
  const auto frame = rangeFrame(compression);
  Pair pair;
  std::vector<std::byte> received(kRecordPlainBytes);
  (void)transfer(pair.device, pair.host, received);  // header and key confirmation
  for (auto _ : state) {
    std::size_t done = 0;
    while (done < frame.size()) {
      done += pair.device.seal(std::span(frame).subspan(done));
      (void)transfer(pair.device, pair.host, received);
    }
  }
  state.counters["frame_bytes"] = static_cast<double>(frame.size());
  state.counters["frames_per_s"] =
      benchmark::Counter(1.0, benchmark::Counter::kIsIterationInvariantRate);
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(frame.size()));
}

// Both sides' work for one connection (ephemeral keys, two X25519 each, the key derivation and
// the key confirmations), without the network's round trip.
void BM_SessionHandshake(benchmark::State& state) {
  const KeyPair hostId = generateKeyPair();
  const KeyPair deviceId = generateKeyPair();
  SecureChannel device;
  SecureChannel host;
  std::array<std::byte, 64> none{};
  for (auto _ : state) {
    startSession(device, host, deviceId, hostId);
    (void)transfer(device, host, none);
    (void)transfer(host, device, none);
    if (!host.confirmed() || !device.confirmed()) {
      state.SkipWithError("the key confirmation failed");
    }
  }
}

void BM_PairingExchange(benchmark::State& state) {
  const KeyPair hostId = generateKeyPair();
  const KeyPair deviceId = generateKeyPair();
  for (auto _ : state) {
    const PakeShare h = pakeStart("12345678");
    const PakeShare d = pakeStart("12345678");
    const PairRequest request{h.element, hostId.publicKey};
    auto a = pakeFinish(h, d.element, request, d.element, deviceId.publicKey);
    auto b = pakeFinish(d, h.element, request, d.element, deviceId.publicKey);
    benchmark::DoNotOptimize(a);
    benchmark::DoNotOptimize(b);
  }
}

BENCHMARK_CAPTURE(BM_FrameInTheClear, rvl, Compression::kRvl);
BENCHMARK_CAPTURE(BM_FrameEncrypted, rvl, Compression::kRvl);
BENCHMARK_CAPTURE(BM_FrameInTheClear, raw, Compression::kNone);
BENCHMARK_CAPTURE(BM_FrameEncrypted, raw, Compression::kNone);
BENCHMARK(BM_SessionHandshake)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PairingExchange)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
