// Body contacts of robot_sim's robots (BodyContacts): bodies closer than one diameter touch, and
// are counted as the MuJoCo world counts them (ContactLog: one contact until apart 0.1 s).
#include <gtest/gtest.h>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation/world/body_contacts.hpp"

namespace vf {
namespace {

TEST(BodyContacts, BodiesCloserThanADiameterTouchOnceUntilApart) {
  BodyContacts c(3, kBurgerBodyRadius);  // 0.21 m diameter
  c.setPosition(0, 0.0, 0.0);
  c.setPosition(1, 0.211, 0.0);  // a millimetre apart
  EXPECT_TRUE(c.check(0.0).empty());  // robot 2 unknown yet: ignored
  EXPECT_EQ(c.log().count(), 0);
  EXPECT_DOUBLE_EQ(c.closest(), 0.211);
  c.setPosition(1, 0.209, 0.0);
  const auto began = c.check(0.01);
  ASSERT_EQ(began.size(), 1u);
  EXPECT_EQ(began[0].first, "robot_0");
  EXPECT_EQ(began[0].second, "robot_1");
  EXPECT_TRUE(c.check(0.02).empty());  // still touching: the same contact
  c.setPosition(1, 0.5, 0.0);
  EXPECT_TRUE(c.check(0.05).empty());
  c.setPosition(1, 0.1, 0.0);
  EXPECT_TRUE(c.check(0.08).empty());  // apart for less than 0.1 s: the same contact
  c.setPosition(1, 0.5, 0.0);
  c.check(0.1);
  c.setPosition(1, 0.1, 0.0);
  EXPECT_EQ(c.check(0.3).size(), 1u);  // apart for 0.22 s: a new one
  EXPECT_EQ(c.log().count(), 2);
  EXPECT_EQ(c.log().resultLines(), "contacts: 2\nfirst_contact: \"t = 0.01 s, robot_0 and robot_1\"\n");
}

TEST(BodyContacts, OnlyOneRobotsPairs) {
  BodyContacts c(3, 0.1);
  c.setPosition(0, 0.0, 0.0);
  c.setPosition(1, 0.05, 0.0, 0.0);
  c.setPosition(2, 5.0, 0.0);
  EXPECT_TRUE(c.check(0.0, 2).empty());  // 0 and 1 touch, but robot 2 counts only its own pairs
  EXPECT_EQ(c.check(1.0, 0).size(), 1u);
  EXPECT_EQ(c.log().resultLines().rfind("contacts: 1\n", 0), 0u);
}

TEST(BodyContacts, RefusesABadRadius) {
  try {
    BodyContacts(2, 0.0);
    ADD_FAILURE() << "accepted body_radius 0";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("body_radius"), std::string::npos) << e.what();
  }
  EXPECT_THROW(BodyContacts(0, 0.1), InvalidInput);
}

}  // namespace
}  // namespace vf
