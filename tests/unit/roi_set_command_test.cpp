// `fibscope filter --roi-set`: a set's criteria keep what the same criteria
// on the command line keep (the output files byte for byte), mixed with
// command-line ones as documented; a bad set is one line naming the file,
// exit status 2 and no output.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "io/reader.h"
#include "test_support.h"

namespace fibscope {
namespace {

TEST(RoiSetCommand, filterWithASetWritesWhatTheSameOptionsWrite) {
  test::TempDir dir;
  const std::string in = dir.file("in.tck");
  ASSERT_EQ(test::runFibscope("phantom " + in + " -n 300 --seed 3").exit_code, 0);
  test::writeBytes(dir.file("set.json"), R"({"fibscope_roi_set": 1,
    "rois": [{"name": "middle", "region": "sphere:0,0,0,30", "role": "include"},
             {"name": "right", "region": "box:20,-50,-50,50,50,50", "role": "exclude"},
             {"name": "ignored", "region": "sphere:0,0,0,1", "enabled": false}],
    "min_length_mm": 40,
    "clip_planes": [{"point": [0,0,0], "normal": [0,0,1]}]})");
  const auto with_set =
      test::runFibscope("filter " + in + " " + dir.file("set.tck") + " --roi-set " + dir.file("set.json"));
  ASSERT_EQ(with_set.exit_code, 0) << with_set.output;
  EXPECT_NE(with_set.output.find("--roi-set exclude ROI 'right'"), std::string::npos) << with_set.output;
  const auto with_options = test::runFibscope("filter " + in + " " + dir.file("options.tck") +
                                              " --include sphere:0,0,0,30 --exclude box:20,-50,-50,50,50,50"
                                              " --min-length 40");
  ASSERT_EQ(with_options.exit_code, 0) << with_options.output;
  EXPECT_EQ(test::readBytes(dir.file("set.tck")), test::readBytes(dir.file("options.tck")));
  const size_t kept = readTractogram(dir.file("set.tck")).streamlineCount();
  EXPECT_GT(kept, 5u);
  EXPECT_LT(kept, 295u);

  // Mixed: the set's regions and the command line's together; the command
  // line's length limit replaces the set's.
  test::writeBytes(dir.file("half.json"), R"({"fibscope_roi_set": 1, "min_length_mm": 10,
    "rois": [{"region": "sphere:0,0,0,30"}]})");
  const auto mixed = test::runFibscope("filter " + in + " " + dir.file("mixed.tck") + " --roi-set " +
                                       dir.file("half.json") + " --exclude box:20,-50,-50,50,50,50 --min-length 40");
  ASSERT_EQ(mixed.exit_code, 0) << mixed.output;
  EXPECT_EQ(test::readBytes(dir.file("mixed.tck")), test::readBytes(dir.file("options.tck")));
}

TEST(RoiSetCommand, aBadSetIsOneLineNamingTheFileAndWritesNothing) {
  test::TempDir dir;
  const std::string in = dir.file("in.tck"), out = dir.file("out.tck");
  ASSERT_EQ(test::runFibscope("phantom " + in + " -n 20").exit_code, 0);
  for (const std::string& text : {std::string(R"({"fibscope_roi_set": 1, "rois": [{"region": "cube:1"}]})"),
                                  std::string(R"({"fibscope_roi_set": 1, "colour": 1})"), std::string("{")}) {
    SCOPED_TRACE(text);
    test::writeBytes(dir.file("bad.json"), text);
    const auto r = test::runFibscope("filter " + in + " " + out + " --roi-set " + dir.file("bad.json"));
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_NE(r.output.find(dir.file("bad.json") + ": "), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out));
  }
  const auto missing = test::runFibscope("filter " + in + " " + out + " --roi-set " + dir.file("none.json"));
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.output.find(dir.file("none.json") + ": no such file"), std::string::npos) << missing.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace fibscope
