// SPDX-License-Identifier: MIT
#include "plan.hpp"

namespace msgraphs::sim::building {

const char* ToString(RoomUse use) {
  switch (use) {
    case RoomUse::kCorridor:
      return "corridor";
    case RoomUse::kOffice:
      return "office";
    case RoomUse::kClassroom:
      return "classroom";
    case RoomUse::kMeeting:
      return "meeting";
    case RoomUse::kOpenPlan:
      return "open_plan";
    case RoomUse::kPatient:
      return "patient";
    case RoomUse::kBath:
      return "bath";
    case RoomUse::kNurseStation:
      return "nurse_station";
    case RoomUse::kHall:
      return "hall";
    case RoomUse::kStorage:
      return "storage";
    case RoomUse::kLobby:
      return "lobby";
    case RoomUse::kLiving:
      return "living";
    case RoomUse::kBedroom:
      return "bedroom";
    case RoomUse::kKitchen:
      return "kitchen";
    case RoomUse::kWc:
      return "wc";
    case RoomUse::kHallway:
      return "hallway";
    case RoomUse::kBare:
      return "bare";
  }
  return "room";
}

}  // namespace msgraphs::sim::building
