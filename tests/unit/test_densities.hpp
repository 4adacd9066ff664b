// Shared by the unit tests: a built-in density by name.
#pragma once

#include <gtest/gtest.h>

#include "protocol/density.hpp"

namespace beamcast::testing_support {

inline Density named(const char* name) {
  Density d;
  EXPECT_TRUE(density_from_name(name, &d)) << name;
  return d;
}

}  // namespace beamcast::testing_support
