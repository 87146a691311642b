// test_pch.hpp - the tests' precompiled header (tests/CMakeLists.txt, ODO_TEST_PCH): GoogleTest,
// Eigen and the standard headers most test files include. Not included by any file: CMake builds
// it once and adds it to every test target's compile.
// Through a PCH, GCC 12 reports its -Warray-bounds false positive inside libstdc++ (its bug
// 105329) for `std::string(...) + "..."` in a test; the headers' text does not (TESTING.md).
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>
