#include <gtest/gtest.h>
TEST(PatternLibraryTest, Placeholder) { SUCCEED(); }
