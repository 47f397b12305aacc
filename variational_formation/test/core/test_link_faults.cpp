// LinkFaults: seeded software fault injection (loss, delay, jitter) on received messages.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/agents/link_faults.hpp"
#include "variational_formation_core/common/standard_normal.hpp"

namespace vf {
namespace {

TEST(Random, UniformUnitUsesTheStandardSequenceOfMt19937_64) {
  // The C++ standard fixes the 10000th output of a default-seeded mt19937_64.
  std::mt19937_64 engine;
  engine.discard(9999);
  EXPECT_EQ(uniformUnit(engine), static_cast<double>(9981545732273789042ULL >> 11) * std::ldexp(1.0, -53));
}

TEST(LinkFaults, SameSeedSameFaultsOtherSeedOtherFaults) {
  const LinkFaultSettings settings{0.05, 0.02, 0.2};
  LinkFaults<int> a(settings, 7), b(settings, 7), c(settings, 8);
  int differences = 0;
  for (int m = 0; m < 1000; ++m) {
    const double now = 0.001 * m;
    const auto da = a.offer(m, now), db = b.offer(m, now), dc = c.offer(m, now);
    ASSERT_EQ(da, db);
    differences += da != dc;
  }
  EXPECT_GT(differences, 500);
}

TEST(LinkFaults, LossFractionIsWithinTheBinomialBound) {
  const long n = 20000;
  for (double p : {0.0, 0.2, 0.5, 1.0}) {
    LinkFaults<int> link({0.0, 0.0, p}, 3);
    for (long m = 0; m < n; ++m) link.offer(0, 0.0);
    const double fraction = static_cast<double>(link.lost()) / static_cast<double>(n);
    // 5 standard deviations of a binomial fraction: fails by chance with probability < 1e-6.
    EXPECT_LE(std::abs(fraction - p), 5.0 * std::sqrt(p * (1.0 - p) / static_cast<double>(n))) << p;
    EXPECT_EQ(link.offered(), n);
    EXPECT_EQ(static_cast<long>(link.pending()) + link.lost(), n);
  }
}

TEST(LinkFaults, DelaysStayWithinDelayPlusMinusJitterClampedAtZero) {
  const long n = 20000;
  for (const LinkFaultSettings& s : {LinkFaultSettings{0.05, 0.02, 0.0}, LinkFaultSettings{0.01, 0.02, 0.3},
                                     LinkFaultSettings{0.03, 0.0, 0.0}}) {
    LinkFaults<int> link(s, 5);
    double lo = HUGE_VAL, hi = -HUGE_VAL, sum = 0.0;
    long delivered = 0, zero = 0;
    for (long m = 0; m < n; ++m) {
      const double now = 10.0 + 0.01 * static_cast<double>(m);
      const auto due = link.offer(0, now);
      if (!due) continue;
      const double delay = *due - now;
      lo = std::min(lo, delay);
      hi = std::max(hi, delay);
      sum += delay;
      zero += *due == now;
      ++delivered;
    }
    const double tol = 1e-12;  // now + delay - now rounds at the level of 10 ulp(10 s)
    EXPECT_GE(lo, std::max(0.0, s.delay - s.jitter) - tol);
    EXPECT_LE(hi, s.delay + s.jitter + tol);
    // The spread fills the interval: u is uniform on [-1, 1).
    EXPECT_LE(lo, std::max(0.0, s.delay - s.jitter) + 0.001 * s.jitter + tol);
    EXPECT_GE(hi, s.delay + s.jitter - 0.001 * s.jitter - tol);
    if (s.delay >= s.jitter) {
      // Mean delay: 5 standard deviations of the mean of uniform(-jitter, jitter).
      EXPECT_NEAR(sum / delivered, s.delay, 5.0 * s.jitter / std::sqrt(3.0 * delivered) + tol);
    } else {
      // P(delay + jitter u <= 0) = (1 - delay/jitter) / 2, here 0.25.
      const double p = 0.5 * (1.0 - s.delay / s.jitter);
      EXPECT_NEAR(static_cast<double>(zero) / delivered, p, 5.0 * std::sqrt(p * (1 - p) / delivered));
    }
  }
}

TEST(LinkFaults, MessagesComeOutWhenDueInDeliveryOrder) {
  LinkFaults<int> link({0.05, 0.04, 0.1}, 9);
  std::vector<std::pair<double, int>> expected;  // (due, message)
  for (int m = 0; m < 500; ++m) {
    const auto due = link.offer(m, 0.01 * m);
    if (due) expected.emplace_back(*due, m);
  }
  std::stable_sort(expected.begin(), expected.end(),
                   [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<int> got;
  for (double now = 0.0; link.pending() > 0; now += 0.003) {
    const double next = link.nextDue();
    const std::vector<int> due = link.takeDue(now);
    if (!due.empty()) {
      EXPECT_LE(next, now);
    }
    if (link.pending() > 0) {
      EXPECT_GT(link.nextDue(), now);
    }
    got.insert(got.end(), due.begin(), due.end());
  }
  ASSERT_EQ(got.size(), expected.size());
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], expected[i].second) << i;
  // With jitter some messages overtake others; without it, ties keep the order offered.
  LinkFaults<int> fifo({0.02, 0.0, 0.0}, 1);
  for (int m = 0; m < 5; ++m) fifo.offer(m, 1.0);
  EXPECT_TRUE(fifo.takeDue(1.019).empty());
  EXPECT_EQ(fifo.takeDue(1.02), (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_TRUE(std::isinf(fifo.nextDue()));
}

TEST(LinkFaults, NoFaultsDeliverEverythingAtOnce) {
  LinkFaults<int> link({}, 0);
  EXPECT_TRUE(link.model().transparent());
  for (int m = 0; m < 100; ++m) {
    ASSERT_EQ(link.offer(m, 2.5), 2.5);
    ASSERT_EQ(link.takeDue(2.5), std::vector<int>{m});
  }
}

TEST(LinkFaults, BadSettingsAreRejectedWithOneLineNamingTheParameter) {
  const auto message = [](const LinkFaultSettings& s) {
    try {
      LinkFaults<int> link(s, 0);
    } catch (const InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message({-0.01, 0.0, 0.0}), "delay: must be finite and >= 0 s, got -0.01");
  EXPECT_EQ(message({0.0, -1.0, 0.0}), "jitter: must be finite and >= 0 s, got -1");
  EXPECT_EQ(message({0.0, 0.0, 1.5}), "loss: must be finite and in [0, 1], got 1.5");
  EXPECT_EQ(message({0.0, 0.0, -0.2}), "loss: must be finite and in [0, 1], got -0.2");
  EXPECT_EQ(message({std::nan(""), 0.0, 0.0}), "delay: must be finite and >= 0 s, got nan");
  EXPECT_EQ(message({0.0, HUGE_VAL, 0.0}), "jitter: must be finite and >= 0 s, got inf");
  EXPECT_EQ(message({0.0, 0.0, std::nan("")}), "loss: must be finite and in [0, 1], got nan");
  EXPECT_EQ(message({0.05, 0.02, 0.2}), "accepted");
  EXPECT_EQ(message({0.0, 0.0, 1.0}), "accepted");
}

}  // namespace
}  // namespace vf
