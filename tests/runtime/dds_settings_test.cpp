// SPDX-License-Identifier: MIT
#include "msgraphs/runtime/link/dds_settings.hpp"

#include <gtest/gtest.h>

#include "msgraphs/runtime/link/fleet_link.hpp"

namespace msgraphs::runtime::link {
namespace {

TEST(DdsSettings, AcceptsDefaultsAndPeers) {
  DdsSettings s;
  s.initial_peers = {"10.0.0.2", "127.0.0.1"};
  EXPECT_TRUE(Validate(s));
}

TEST(DdsSettings, RejectsBadDomainAndPeers) {
  DdsSettings s;
  s.domain_id = 233;
  EXPECT_EQ(Validate(s).error().code, Errc::kInvalidConfig);
  s.domain_id = 0;
  s.initial_peers = {"robot-two"};
  EXPECT_EQ(Validate(s).error().code, Errc::kInvalidConfig);
  s.initial_peers = {"10.0.0.256"};
  EXPECT_FALSE(Validate(s));
}

TEST(FleetLink, RefusesReservedRobotIdWithoutTouchingTheNetwork) {
  auto link = FleetLink::Create(RobotId{0}, LinkSettings{});
  ASSERT_FALSE(link);
  EXPECT_EQ(link.error().code, Errc::kInvalidConfig);
}

}  // namespace
}  // namespace msgraphs::runtime::link
