#include "smx/algo/stripe_code.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <set>
#include <utility>

namespace smx::algo::stripe {
namespace {

using C = Colour;
using T = Transition;

std::array<Colour, kWindowStripes> windowAt(int i) {
  std::array<Colour, kWindowStripes> w{};
  std::copy_n(kSequence.begin() + i, kWindowStripes, w.begin());
  return w;
}

// The paper's classes written out by hand (not derived from the code under test): +XY is X→Y.
const std::map<std::pair<C, C>, T> kExpectedClass = {
    {{C::kRed, C::kGreen}, T::kPlusRG},  {{C::kGreen, C::kRed}, T::kMinusRG},
    {{C::kGreen, C::kBlue}, T::kPlusGB}, {{C::kBlue, C::kGreen}, T::kMinusGB},
    {{C::kBlue, C::kRed}, T::kPlusBR},   {{C::kRed, C::kBlue}, T::kMinusBR},
};

std::array<Transition, kWindowTransitions> transitionsOf(const std::array<Colour, 7>& w) {
  std::array<Transition, kWindowTransitions> t{};
  for (std::size_t j = 0; j < t.size(); ++j) {
    t[j] = kExpectedClass.at({w[j], w[j + 1]});
  }
  return t;
}

TEST(StripeCode, SequenceHas198StripesAndNoEqualNeighbours) {
  ASSERT_EQ(kSequence.size(), 198U);
  for (std::size_t i = 0; i + 1 < kSequence.size(); ++i) {
    EXPECT_NE(kSequence[i], kSequence[i + 1]) << "stripes " << i << " and " << i + 1;
  }
}

TEST(StripeCode, Every7StripeWindowIsUniqueAndAll192Occur) {
  std::set<std::array<Colour, kWindowStripes>> windows;
  for (int i = 0; i + kWindowStripes <= kStripes; ++i) {
    windows.insert(windowAt(i));
  }
  EXPECT_EQ(windows.size(), 192U);
}

TEST(StripeCode, WindowTableRoundTripsEveryWindow) {
  for (int i = 0; i + kWindowStripes <= kStripes; ++i) {
    const auto w = windowAt(i);
    EXPECT_EQ(decodeWindow(std::span<const Colour, 7>(w)), i) << "colour window at " << i;
    const auto t = transitionsOf(w);
    EXPECT_EQ(decodeWindow(std::span<const Transition, 6>(t)), i) << "transitions at " << i;
  }
}

TEST(StripeCode, TransitionClassesMatchPaper) {
  for (const auto& [colours, cls] : kExpectedClass) {
    EXPECT_EQ(transitionBetween(colours.first, colours.second), cls);
    EXPECT_EQ(from(cls), colours.first);
    EXPECT_EQ(to(cls), colours.second);
  }
  // Paper §4.1 grouping by the colour after the boundary.
  EXPECT_EQ(colourAfter(T::kPlusBR), C::kRed);
  EXPECT_EQ(colourAfter(T::kMinusRG), C::kRed);
  EXPECT_EQ(colourAfter(T::kPlusRG), C::kGreen);
  EXPECT_EQ(colourAfter(T::kMinusGB), C::kGreen);
  EXPECT_EQ(colourAfter(T::kPlusGB), C::kBlue);
  EXPECT_EQ(colourAfter(T::kMinusBR), C::kBlue);
  int plus = 0;
  for (int i = 0; i < kTransitions; ++i) {
    plus += isPlus(static_cast<T>(i)) ? 1 : 0;
  }
  EXPECT_EQ(plus, 3);
  EXPECT_TRUE(isPlus(T::kPlusRG) && isPlus(T::kPlusGB) && isPlus(T::kPlusBR));
}

TEST(StripeCode, ReversedReadFlipsEveryTransitionSign) {
  EXPECT_EQ(reversed(T::kPlusRG), T::kMinusRG);
  EXPECT_EQ(reversed(T::kMinusRG), T::kPlusRG);
  EXPECT_EQ(reversed(T::kPlusGB), T::kMinusGB);
  EXPECT_EQ(reversed(T::kMinusGB), T::kPlusGB);
  EXPECT_EQ(reversed(T::kPlusBR), T::kMinusBR);
  EXPECT_EQ(reversed(T::kMinusBR), T::kPlusBR);
}

// Documents what the decoder must know: a window read against the axis is a *valid* window of
// the sequence (all 192 codes occur), so a reversed read decodes silently to another index.
// Only palindromic windows map to themselves.
TEST(StripeCode, ReversedWindowsDecodeToValidButWrongIndices) {
  int palindromes = 0;
  int wrong = 0;
  for (int i = 0; i + kWindowStripes <= kStripes; ++i) {
    auto w = windowAt(i);
    const bool palindrome = std::equal(w.begin(), w.end(), w.rbegin());
    std::reverse(w.begin(), w.end());
    const int j = decodeWindow(std::span<const Colour, 7>(w));
    ASSERT_GE(j, 0) << "reversed window " << i << " is not in the table";
    if (palindrome) {
      ++palindromes;
      EXPECT_EQ(j, i);
    } else {
      ++wrong;
      EXPECT_NE(j, i);
    }
  }
  // Palindromes of 7 stripes: free choice of stripes 0..3 with neighbours differing: 3·2·2·2.
  EXPECT_EQ(palindromes, 24);
  EXPECT_EQ(wrong, 192 - 24);
}

TEST(StripeCode, RejectsEqualNeighboursAndBrokenChains) {
  const std::array<Colour, 7> equal = {C::kRed, C::kGreen, C::kGreen, C::kBlue,
                                       C::kRed, C::kGreen, C::kBlue};
  EXPECT_EQ(decodeWindow(std::span<const Colour, 7>(equal)), -1);
  // R→G then B→R: the second boundary does not start where the first ended.
  const std::array<Transition, 6> broken = {T::kPlusRG, T::kPlusBR, T::kPlusRG,
                                            T::kPlusGB, T::kPlusBR, T::kPlusRG};
  EXPECT_EQ(decodeWindow(std::span<const Transition, 6>(broken)), -1);
  const std::array<Colour, 7> outOfRange = {C::kRed,  static_cast<C>(3), C::kRed,  C::kGreen,
                                            C::kBlue, C::kRed,           C::kGreen};
  EXPECT_EQ(decodeWindow(std::span<const Colour, 7>(outOfRange)), -1);
}

}  // namespace
}  // namespace smx::algo::stripe
