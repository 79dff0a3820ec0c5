#include <gtest/gtest.h>

#include "core/tractogram.h"
#include "test_support.h"

namespace fibscope {

TEST(Tractogram, appendKeepsOffsetsAndData) {
  Tractogram a = test::smallTractogram(5, 1, true);
  Tractogram b = test::smallTractogram(7, 2, true);
  Tractogram all = a;
  all.append(b);
  EXPECT_EQ(all.validate(), "");
  EXPECT_EQ(all.streamlineCount(), 12u);
  EXPECT_EQ(all.pointCount(), a.pointCount() + b.pointCount());
  EXPECT_EQ(all.point(a.pointCount())[0], b.point(0)[0]);
  EXPECT_EQ(all.per_streamline[0].values[5], b.per_streamline[0].values[0]);
}

TEST(Tractogram, validateReportsBadSizes) {
  Tractogram t = test::smallTractogram(3, 1, true);
  t.per_point[0].values.pop_back();
  EXPECT_NE(t.validate().find("per-point array 'fa'"), std::string::npos);
  t = test::smallTractogram(3);
  t.positions.pop_back();
  EXPECT_NE(t.validate().find("positions hold"), std::string::npos);
}

}  // namespace fibscope
