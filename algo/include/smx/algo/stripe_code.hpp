#pragma once

#include <array>
#include <cstdint>
#include <span>

// The colour-stripe permutation code of the paper's §4.1: N = 3 colours (R, G, B), adjacent
// stripes always differ, every window of k = 7 consecutive stripes is unique. A window is fixed
// by its first colour and its 6 transitions, each +1 or −1 (mod 3), so there are 3·2^6 = 192
// windows and the longest sequence has 192 + 6 = 198 stripes. It is built at compile time as an
// Eulerian circuit of the graph whose nodes are 6-stripe windows and whose edges are 7-stripe
// windows (every node has in- and out-degree 2). The sequence uses *every* possible window once.
//
// Reading direction: a window read against the encoding axis is the reversed colour list, which
// is also a valid window of the sequence (all 192 are). The decoder cannot detect a reversed read
// from the code itself — it must know the axis sign (from the rig) and pass boundaries in +axis
// order. Reversal also flips every transition's sign (+RG ↔ −RG); see reversed(Transition).
namespace smx::algo::stripe {

enum class Colour : std::uint8_t { kRed = 0, kGreen = 1, kBlue = 2 };

inline constexpr int kColours = 3;
inline constexpr int kWindowStripes = 7;
inline constexpr int kWindowTransitions = kWindowStripes - 1;
inline constexpr int kWindows = 192;
inline constexpr int kStripes = kWindows + kWindowTransitions;  // 198

// A boundary seen along the encoding axis, from one colour to the next. +XY means X→Y (a +1 step,
// R→G→B→R), −XY means Y→X. In the derivative image the "to" channel rises and the "from" channel
// falls.
enum class Transition : std::uint8_t {
  kPlusRG,   // R→G
  kMinusRG,  // G→R
  kPlusGB,   // G→B
  kMinusGB,  // B→G
  kPlusBR,   // B→R
  kMinusBR,  // R→B
};
inline constexpr int kTransitions = 6;

[[nodiscard]] constexpr Colour colourFromIndex(int i) {
  return static_cast<Colour>(i % kColours);
}
[[nodiscard]] constexpr int indexOf(Colour c) {
  return static_cast<int>(c);
}

[[nodiscard]] constexpr bool isPlus(Transition t) {
  return static_cast<int>(t) % 2 == 0;
}

[[nodiscard]] constexpr Colour from(Transition t) {
  constexpr std::array<Colour, kTransitions> kFrom = {Colour::kRed,  Colour::kGreen, Colour::kGreen,
                                                      Colour::kBlue, Colour::kBlue,  Colour::kRed};
  return kFrom[static_cast<std::size_t>(t)];
}

[[nodiscard]] constexpr Colour to(Transition t) {
  constexpr std::array<Colour, kTransitions> kTo = {Colour::kGreen, Colour::kRed, Colour::kBlue,
                                                    Colour::kGreen, Colour::kRed, Colour::kBlue};
  return kTo[static_cast<std::size_t>(t)];
}

// The paper's grouping "by the colour after the boundary": R = {+BR, −RG}, G = {+RG, −GB},
// B = {+GB, −BR}.
[[nodiscard]] constexpr Colour colourAfter(Transition t) {
  return to(t);
}

// The transition a→b; a and b must differ.
[[nodiscard]] constexpr Transition transitionBetween(Colour a, Colour b) {
  const int ia = indexOf(a);
  const bool plus = (ia + 1) % kColours == indexOf(b);
  // +XY with X = a for plus steps; −XY with Y = a for minus steps (XY is the +1 pair).
  const int pair = plus ? ia : indexOf(b);
  return static_cast<Transition>(pair * 2 + (plus ? 0 : 1));
}

// The same boundary read in the opposite direction: b→a.
[[nodiscard]] constexpr Transition reversed(Transition t) {
  return transitionBetween(to(t), from(t));
}

// Window code: first colour · 64 + transition bits (bit j set when transition j is a +1 step).
[[nodiscard]] constexpr int windowCode(Colour first, int plusBits) {
  return indexOf(first) * (1 << kWindowTransitions) + plusBits;
}

namespace detail {

// Colour index after a step: bit 1 is +1 (mod 3), bit 0 is −1 (i.e. +2).
constexpr std::size_t step(std::size_t colour, std::size_t bit) {
  return (colour + (bit != 0 ? 1 : 2)) % kColours;
}

// Hierholzer's algorithm over the 96 six-stripe nodes; node id = first colour · 32 + 5 step bits.
// Out-edges are tried +1 first, so the sequence is deterministic and starts R, G, B, R, G, B.
constexpr std::array<Colour, kStripes> buildSequence() {
  constexpr std::size_t kNodeBits = kWindowTransitions - 1;
  constexpr std::size_t kBitsMask = (std::size_t{1} << kNodeBits) - 1;
  constexpr std::size_t kNodes = std::size_t{kColours} << kNodeBits;
  std::array<std::size_t, kNodes> edgesTaken{};
  std::array<std::size_t, kWindows + 1> stack{};
  std::array<std::size_t, kWindows + 1> circuit{};
  std::size_t stackSize = 0;
  std::size_t circuitSize = 0;
  stack[stackSize++] = kBitsMask;  // first colour R, five +1 steps: R G B R G B
  while (stackSize > 0) {
    const std::size_t node = stack[stackSize - 1];
    if (edgesTaken[node] < 2) {
      const std::size_t bit = edgesTaken[node] == 0 ? 1 : 0;
      ++edgesTaken[node];
      const std::size_t nextFirst = step(node >> kNodeBits, node & 1);
      const std::size_t nextBits = ((node & kBitsMask) >> 1) | (bit << (kNodeBits - 1));
      stack[stackSize++] = (nextFirst << kNodeBits) | nextBits;
    } else {
      circuit[circuitSize++] = node;
      --stackSize;
    }
  }
  // circuit holds the node path reversed; expand it into stripes.
  std::array<Colour, kStripes> seq{};
  std::size_t n = 0;
  const std::size_t firstNode = circuit[circuitSize - 1];
  std::size_t colour = firstNode >> kNodeBits;
  seq[n++] = static_cast<Colour>(colour);
  for (std::size_t j = 0; j < kNodeBits; ++j) {
    colour = step(colour, (firstNode >> j) & 1);
    seq[n++] = static_cast<Colour>(colour);
  }
  for (std::size_t i = circuitSize - 1; i-- > 0;) {
    colour = step(colour, (circuit[i] >> (kNodeBits - 1)) & 1);
    seq[n++] = static_cast<Colour>(colour);
  }
  return seq;
}

constexpr std::array<std::int16_t, kWindows> buildWindowIndex(
    const std::array<Colour, kStripes>& seq) {
  std::array<std::int16_t, kWindows> table{};
  for (auto& entry : table) {
    entry = -1;
  }
  for (std::size_t i = 0; i + kWindowTransitions < kStripes; ++i) {
    int bits = 0;
    for (std::size_t j = 0; j < kWindowTransitions; ++j) {
      if ((indexOf(seq[i + j]) + 1) % kColours == indexOf(seq[i + j + 1])) {
        bits |= 1 << j;
      }
    }
    table[static_cast<std::size_t>(windowCode(seq[i], bits))] = static_cast<std::int16_t>(i);
  }
  return table;
}

}  // namespace detail

// The projected stripe colours, index 0 first along +axis.
inline constexpr std::array<Colour, kStripes> kSequence = detail::buildSequence();

// Window code → index of the window's first stripe (−1 for a code that does not occur; with the
// full-length sequence every code occurs).
inline constexpr std::array<std::int16_t, kWindows> kWindowIndex =
    detail::buildWindowIndex(kSequence);

// Decodes 6 consecutive boundaries read along +axis into the index of the stripe before the first
// of them (boundary j then lies between stripes i+j and i+j+1). Returns −1 when the boundaries do
// not chain (to of one ≠ from of the next).
[[nodiscard]] int decodeWindow(std::span<const Transition, kWindowTransitions> boundaries);

// The same for 7 stripe colours; −1 when two neighbours are equal.
[[nodiscard]] int decodeWindow(std::span<const Colour, kWindowStripes> colours);

}  // namespace smx::algo::stripe
