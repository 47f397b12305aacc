// RecordLedger: each (agent, step) state is new exactly once; repeats are compared bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/agents/record_ledger.hpp"

namespace vf {
namespace {

using Arrival = RecordLedger::Arrival;

std::vector<double> q(long step, int agent) { return {0.1 * step + agent, -0.5 * step, 1.0 / (step + 1)}; }

TEST(StepSet, HoldsEveryStepAddedInAnyOrderAndCountsEachOnce) {
  std::mt19937_64 engine(11);
  std::vector<long> arrivals;
  for (long k = 0; k < 500; ++k) arrivals.insert(arrivals.end(), static_cast<std::size_t>(1 + k % 3), k);
  std::shuffle(arrivals.begin(), arrivals.end(), engine);
  StepSet s;
  long added = 0;
  for (long k : arrivals) added += s.add(k);
  EXPECT_EQ(added, 500);
  EXPECT_EQ(s.next, 500);
  EXPECT_TRUE(s.ahead.empty());
  EXPECT_TRUE(s.holds(499));
  EXPECT_FALSE(s.holds(500));
}

TEST(RecordLedger, EachStateIsNewOnceAndItsRepeatsAreIdentical) {
  // Two agents, steps 0..299, each arriving one to three times in a shuffled order, as the topic
  // and a fetched history would deliver them; keep covers the whole run.
  std::mt19937_64 engine(5);
  std::vector<std::pair<int, long>> arrivals;
  for (int i = 0; i < 2; ++i)
    for (long k = 0; k < 300; ++k) arrivals.insert(arrivals.end(), static_cast<std::size_t>(1 + (k + i) % 3), {i, k});
  std::shuffle(arrivals.begin(), arrivals.end(), engine);
  RecordLedger ledger(2, 1000);
  long fresh = 0, identical = 0;
  for (const auto& [i, k] : arrivals) {
    const Arrival a = ledger.addState(i, k, q(k, i), q(k - 1, i));
    fresh += a == Arrival::New;
    identical += a == Arrival::Identical;
    ASSERT_TRUE(a == Arrival::New || a == Arrival::Identical);
  }
  EXPECT_EQ(fresh, 600);
  EXPECT_EQ(identical, static_cast<long>(arrivals.size()) - 600);
  EXPECT_EQ(ledger.statesBelow(0), 300);
  EXPECT_EQ(ledger.statesBelow(1), 300);
}

TEST(RecordLedger, ARepeatDifferingInOneBitOfEitherPositionDiffers) {
  RecordLedger ledger(1, 10);
  ASSERT_EQ(ledger.addState(0, 7, q(7, 0), q(6, 0)), Arrival::New);
  for (std::size_t c = 0; c < 6; ++c) {
    std::vector<double> position = q(7, 0), previous = q(6, 0);
    double& x = c < 3 ? position[c] : previous[c - 3];
    x = std::nextafter(x, 1e300);
    EXPECT_EQ(ledger.addState(0, 7, position, previous), Arrival::Differs) << "coordinate " << c;
  }
  // 0.0 and -0.0 are equal numbers with different bits: a recomputed step would not change the sign.
  ASSERT_EQ(ledger.addState(0, 8, {0.0, 1.0}, {0.0, 1.0}), Arrival::New);
  EXPECT_EQ(ledger.addState(0, 8, {-0.0, 1.0}, {0.0, 1.0}), Arrival::Differs);
  EXPECT_EQ(ledger.addState(0, 8, {0.0, 1.0}, {0.0, 1.0}), Arrival::Identical);
}

TEST(RecordLedger, KeepsTheNewestStepsOnly) {
  const long keep = 16;
  RecordLedger ledger(1, keep);
  for (long k = 0; k < 100; ++k) ASSERT_EQ(ledger.addState(0, k, q(k, 0), q(k - 1, 0)), Arrival::New);
  // Steps 84..99 are kept and compared; older repeats cannot be compared.
  EXPECT_EQ(ledger.addState(0, 100 - keep, q(0, 0), q(0, 0)), Arrival::Differs);
  EXPECT_EQ(ledger.addState(0, 99, q(99, 0), q(98, 0)), Arrival::Identical);
  EXPECT_EQ(ledger.addState(0, 99 - keep, q(0, 0), q(0, 0)), Arrival::Unchecked);
  // A step older than the kept ones arriving for the first time is still new, and not kept.
  RecordLedger gaps(1, keep);
  ASSERT_EQ(gaps.addState(0, 50, q(50, 0), q(49, 0)), Arrival::New);
  EXPECT_EQ(gaps.addState(0, 3, q(3, 0), q(2, 0)), Arrival::New);
  EXPECT_EQ(gaps.addState(0, 3, q(0, 0), q(0, 0)), Arrival::Unchecked);
  EXPECT_EQ(gaps.statesBelow(0), 0);
  EXPECT_TRUE(gaps.holdsState(0, 3));
}

TEST(RecordLedger, RejectsBadInputWithAnError) {
  EXPECT_THROW(RecordLedger(0, 10), InvalidInput);
  EXPECT_THROW(RecordLedger(2, 0), InvalidInput);
  RecordLedger ledger(2, 10);
  EXPECT_THROW(ledger.addState(2, 0, {0.0, 0.0}, {0.0, 0.0}), InvalidInput);
  EXPECT_THROW(ledger.addState(-1, 0, {0.0, 0.0}, {0.0, 0.0}), InvalidInput);
  EXPECT_THROW(ledger.addState(0, -1, {0.0, 0.0}, {0.0, 0.0}), InvalidInput);
  EXPECT_THROW(ledger.addState(0, 0, {}, {}), InvalidInput);
  EXPECT_THROW(ledger.addState(0, 0, {0.0, 0.0, 0.0, 0.0}, {0.0, 0.0, 0.0, 0.0}), InvalidInput);
  EXPECT_THROW(ledger.addState(0, 0, {0.0, 0.0}, {0.0, 0.0, 0.0}), InvalidInput);
  // A rejected state leaves no trace.
  EXPECT_EQ(ledger.addState(0, 0, {1.0, 2.0}, {1.0, 2.0}), Arrival::New);
}

}  // namespace
}  // namespace vf
