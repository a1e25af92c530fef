// main() of every test executable: GoogleTest's, plus SOFTSIGHT_TEST_EXCLUDE, a list of test
// patterns in --gtest_filter's syntax ("Suite.*:Other.Test") left out of whatever the command
// line selects. ctest runs a whole suite per process (cmake/discover_test_suites.cmake), so a
// run that must skip single tests (scripts/test-sanitize.sh leaves the long accuracy sweeps to
// the plain suite) says so here rather than by ctest's -E on test names.
#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  const char* exclude = std::getenv("SOFTSIGHT_TEST_EXCLUDE");
  if (exclude != nullptr && *exclude != '\0') {
    std::string filter = GTEST_FLAG_GET(filter);
    // A filter is "positive[-negative]": the exclusions join the negative part.
    filter += filter.find('-') == std::string::npos ? "-" : ":";
    filter += exclude;
    GTEST_FLAG_SET(filter, filter);
  }
  return RUN_ALL_TESTS();
}
