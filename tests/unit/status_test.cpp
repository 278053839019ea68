#include <gtest/gtest.h>

#include "core/status.h"

namespace bb {
namespace {

TEST(Status, ExpectedCarriesValueOrOneError) {
    Expected<int> good = 3;
    ASSERT_TRUE(good);
    EXPECT_EQ(*good, 3);
    Expected<int> bad = Expected<int>::failure("no such file");
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error(), "no such file");
    EXPECT_FALSE(bad.status().isOk());
}

}  // namespace
}  // namespace bb
