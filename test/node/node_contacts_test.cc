// Acceptance 6 and the contact half of 7: resting contact forces carry the
// weight, an impact's impulse is (1 + e) m v, and contact markers draw them.
#include <gtest/gtest.h>

#include <cmath>

#include <visualization_msgs/MarkerArray.h>

#include "sim_client.h"

namespace rigid_body_sim::test {
namespace {

constexpr double kGravity = 9.81;          // m/s^2, the node's default
constexpr double kPenetrationSlop = 1e-4;  // m, the node's default solver/penetration_slop

bool Involves(const rigid_body_sim::Contact& contact, const std::string& a, const std::string& b) {
  return (contact.body_a == a && contact.body_b == b) ||
         (contact.body_a == b && contact.body_b == a);
}

class ContactsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(client_.WaitForServices(20.0));
    ASSERT_TRUE(client_.SetPaused(false));
  }
  ros::NodeHandle node_{"/rigid_body_sim"};
  SimClient client_;
  Latest<rigid_body_sim::Contacts> contacts_{node_, "contacts"};
  Latest<visualization_msgs::MarkerArray> markers_{node_, "contact_markers"};
};

TEST_F(ContactsTest, RestingContactForcesSumToTheWeight) {
  constexpr double kMass = 2.0;  // kg
  ASSERT_TRUE(
      client_.SpawnUrdf("box1", BoxUrdf(1.0, 1.0, 1.0, kMass), MakePose(0, 0, 0.55)).success);
  // Settled: below 1 mm/s.
  ASSERT_TRUE(WaitFor(
      [&] {
        const auto state = client_.GetState("box1");
        return std::hypot(state.twist.linear.x, state.twist.linear.y, state.twist.linear.z) <
                   1e-3 &&
               state.pose.position.z < 0.51;
      },
      60.0));
  const auto message = contacts_.Next(20.0);
  ASSERT_TRUE(message.has_value());
  EXPECT_EQ(message->header.frame_id, "world");
  double force = 0.0;
  int resting = 0;
  for (const auto& contact : message->contacts) {
    if (!Involves(contact, "box1/base_link", "ground")) continue;
    if (contact.type != rigid_body_sim::Contact::RESTING) continue;
    ++resting;
    force += contact.normal_force;
    EXPECT_NEAR(std::abs(contact.normal.z), 1.0, 1e-6);
    // The split impulse leaves at most the penetration slop (sim.yaml:
    // solver/penetration_slop, 1e-4 m) of a resting contact.
    EXPECT_LE(contact.depth, kPenetrationSlop + 1e-6);
  }
  EXPECT_GE(resting, 3);
  EXPECT_NEAR(force, kMass * kGravity, 0.01 * kMass * kGravity);

  // The markers of the same contacts: a point and an arrow each, green for resting.
  const auto markers = markers_.Next(20.0);
  ASSERT_TRUE(markers.has_value());
  int arrows = 0;
  for (const auto& marker : markers->markers) {
    if (marker.action != visualization_msgs::Marker::ADD) continue;
    if (marker.type != visualization_msgs::Marker::ARROW) continue;
    ++arrows;
    EXPECT_EQ(marker.header.frame_id, "world");
    EXPECT_GT(marker.color.g, marker.color.r);
  }
  EXPECT_GE(arrows, 3);
  ASSERT_TRUE(client_.Delete("box1").success);
}

TEST_F(ContactsTest, ImpactImpulseIsOnePlusRestitutionTimesMomentum) {
  constexpr double kMass = 0.5;         // kg
  constexpr double kRadius = 0.1;       // m
  constexpr double kRestitution = 0.5;  // the ground's is 0; the larger one applies
  constexpr double kDrop = 1.0;         // m from release to touching the ground
  rigid_body_sim::Spawn::Request request;
  request.name = "ball";
  request.urdf = SphereUrdf(kRadius, kMass);
  request.pose = MakePose(0, 0, kRadius + kDrop);
  request.friction = -1.0;
  request.restitution = kRestitution;
  ASSERT_TRUE(client_.Spawn(request).success);
  std::optional<rigid_body_sim::Contact> impact;
  ASSERT_TRUE(WaitFor(
      [&] {
        const auto message = contacts_.Get();
        if (!message) return false;
        for (const auto& contact : message->contacts) {
          if (Involves(contact, "ball/base_link", "ground") &&
              contact.type == rigid_body_sim::Contact::COLLIDING) {
            impact = contact;
            return true;
          }
        }
        return false;
      },
      60.0));
  const double impact_speed = std::sqrt(2.0 * kGravity * kDrop);
  EXPECT_NEAR(-impact->normal_velocity, impact_speed, 0.02 * impact_speed);
  const double expected = (1.0 + kRestitution) * kMass * std::abs(impact->normal_velocity);
  EXPECT_NEAR(impact->normal_impulse, expected, 0.02 * expected);
  ASSERT_TRUE(client_.Delete("ball").success);
}

}  // namespace
}  // namespace rigid_body_sim::test
