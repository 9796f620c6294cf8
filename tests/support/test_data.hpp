// SPDX-License-Identifier: MIT
// Locating the public data set (../shared/data by default, the CMake cache variable
// MSGRAPHS_DATA_DIR). Tests labelled `external` call MSGRAPHS_REQUIRE_DATA first: it skips the
// test, with the reason, when the file is absent.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace msgraphs::test {

inline std::filesystem::path DataDir() {
  const char* dir = std::getenv("MSGRAPHS_DATA_DIR");
  return dir != nullptr ? std::filesystem::path(dir) : std::filesystem::path();
}

}  // namespace msgraphs::test

#define MSGRAPHS_REQUIRE_DATA(relative_path, out_path)                                       \
  do {                                                                                       \
    const auto msgraphs_dir_ = ::msgraphs::test::DataDir();                                  \
    if (msgraphs_dir_.empty()) GTEST_SKIP() << "MSGRAPHS_DATA_DIR is not set";               \
    out_path = msgraphs_dir_ / (relative_path);                                              \
    if (!std::filesystem::exists(out_path))                                                  \
      GTEST_SKIP() << "external data absent: " << out_path.string()                          \
                   << " (set the CMake cache variable MSGRAPHS_DATA_DIR)";                   \
  } while (0)
