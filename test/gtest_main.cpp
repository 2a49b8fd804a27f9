#include <gtest/gtest.h>

// Debian's catkin_add_gtest links gtest without gtest_main, so the core test binary brings its own.
int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
