// The fiber filter (select/fiber_filter.h): regions, tckedit's rules on
// hand-made streamlines, and `fibscope filter` against MRtrix3's tckedit on
// tractograms of a real tracker (iFOD1 and SD_Stream, 0.1 mm): the same
// streamlines kept, in the same order, for spheres, ends-only, ordered
// includes, excludes, length limits and NIfTI masks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"
#include "io/reader.h"
#include "io/writer.h"
#include "select/filter_run.h"
#include "select/fiber_filter.h"
#include "select/region.h"
#include "test_support.h"

namespace fibscope {
namespace {

bool inside(const Region& r, float x, float y, float z) {
  const float p[3] = {x, y, z};
  return regionContains(r, p);
}

TEST(Region, spheresBoxesAndOrientedBoxesContainTheirPoints) {
  const Region sphere = parseRegion("sphere:1,2,3,2");
  EXPECT_TRUE(inside(sphere, 1, 2, 3));
  EXPECT_TRUE(inside(sphere, 3, 2, 3));  // on the boundary
  EXPECT_FALSE(inside(sphere, 3.001f, 2, 3));
  EXPECT_TRUE(inside(parseRegion("1,2,3,2"), 1, 3.9f, 3)) << "tckedit's plain X,Y,Z,R";
  const Region box = parseRegion("box:4,0,0,0,2,-1");  // corners in any order
  EXPECT_TRUE(inside(box, 2, 1, -0.5f));
  EXPECT_TRUE(inside(box, 4, 2, 0));
  EXPECT_FALSE(inside(box, 2, 1, 0.01f));
  // 10 x 2 x 2 box turned 90 degrees about z: its long side along y.
  const Region obox = parseRegion("obox:0,0,0,10,2,2,0,0,90");
  EXPECT_TRUE(inside(obox, 0, 4.9f, 0));
  EXPECT_FALSE(inside(obox, 4.9f, 0, 0));
  EXPECT_TRUE(inside(obox, 0.9f, -4.9f, 0.9f));
  // Round trip through the spec text.
  for (const std::string spec : {"sphere:1,2,3,2", "box:0,0,-1,4,2,0", "obox:1,2,3,10,2,4,10,20,30"}) {
    const Region back = parseRegion(regionSpec(parseRegion(spec)));
    EXPECT_EQ(regionSpec(back), regionSpec(parseRegion(spec)));
  }
}

TEST(Region, malformedSpecsAreOneLineErrorsNamingTheSpec) {
  for (const std::string spec : {"sphere:1,2,3", "sphere:1,2,3,0", "sphere:1,2,3,-1", "sphere:a,b,c,d", "box:1,2,3",
                                 "obox:0,0,0,1,1,0,0,0,0", "cube:1,2,3,4", "", "1,2,3,nan", "1,2,3,4,",
                                 // beyond kMaxRegionMm, or a size float rounds to 0: corners and squared
                                 // distances would be infinite in float (found by fuzz_specs)
                                 "box:-4e125,-5,5,5,5,5", "sphere:0,0,0,1e-50", "sphere:2e6,0,0,1",
                                 "obox:0,0,0,1,1,3e38,0,0,0", "obox:0,0,0,1,1,1e-46,0,0,0"}) {
    SCOPED_TRACE(spec);
    const std::string message = test::errorOf([&] { parseRegion(spec); });
    EXPECT_EQ(message.rfind(spec + ": ", 0), 0u) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  // The largest accepted: 1 km from the origin.
  EXPECT_NO_THROW(parseRegion("box:-1e6,-1e6,-1e6,1e6,1e6,1e6"));
  EXPECT_NO_THROW(parseRegion("obox:1e6,0,0,1e6,1,1,1e9,0,0"));  // any angle
}

// A streamline along x from x0 to x1 at y, z, 1 mm steps.
std::vector<float> lineX(float x0, float x1, float y = 0, float z = 0) {
  std::vector<float> xyz;
  const int steps = int(std::lround(std::fabs(x1 - x0)));
  for (int i = 0; i <= steps; ++i) {
    xyz.push_back(x0 + (x1 - x0) * float(i) / float(steps));
    xyz.push_back(y);
    xyz.push_back(z);
  }
  return xyz;
}

FilterVerdict verdict(const FilterCriteria& c, const std::vector<float>& xyz, float step = NAN) {
  return FiberFilter(c, step).evaluate(xyz.data(), xyz.size() / 3);
}

TEST(FiberFilter, includeExcludeEndsOnlyAndLengthAsTckedit) {
  FilterCriteria c;
  c.include = {parseRegion("sphere:0,0,0,1"), parseRegion("sphere:10,0,0,1")};
  EXPECT_TRUE(verdict(c, lineX(-5, 15)).kept());
  const FilterVerdict missed = verdict(c, lineX(-5, 5));
  EXPECT_EQ(missed.reason, FilterReason::Include);
  EXPECT_EQ(missed.region, 1u);
  c.exclude = {parseRegion("box:4,-1,-1,6,1,1")};
  const FilterVerdict excluded = verdict(c, lineX(-5, 15));
  EXPECT_EQ(excluded.reason, FilterReason::Exclude);
  EXPECT_EQ(excluded.region, 0u);
  // Ends only: the middle vertices no longer count, either way.
  c.ends_only = true;
  EXPECT_EQ(verdict(c, lineX(0, 10)).reason, FilterReason::Kept);
  EXPECT_EQ(verdict(c, lineX(-5, 15)).reason, FilterReason::Include);
  // Lengths: the float sum of the segments, with tckedit's margin of a
  // tenth of the header's step.
  FilterCriteria len;
  len.min_length_mm = 10;
  EXPECT_TRUE(verdict(len, lineX(0, 10)).kept());
  EXPECT_EQ(verdict(len, lineX(0, 9)).reason, FilterReason::Length);
  EXPECT_TRUE(verdict(len, lineX(0, 9.95f), 1.0f).kept()) << "within 0.1 x step of the limit";
  len.max_length_mm = 12;
  EXPECT_EQ(verdict(len, lineX(0, 13)).reason, FilterReason::Length);
  // No points: no length (NaN), dropped whatever the limits, as tckedit.
  EXPECT_EQ(FiberFilter(FilterCriteria{}).evaluate(nullptr, 0).reason, FilterReason::Length);
  EXPECT_THROW(FiberFilter(FilterCriteria{{}, {}, {}, false, 5, 4}), Error);
}

TEST(FiberFilter, distanceToAZoneIsTheNearestVertexsAndAThreshold) {
  // A line along x at y = 0, z = 0, vertices every 1 mm from 0 to 10.
  const std::vector<float> line = lineX(0, 10);
  const size_t n = line.size() / 3;
  FilterCriteria c;
  c.distance_zone = SphereRegion{{5.5f, 3, 4}, 0};  // a point: nearest vertices x = 5, 6 at sqrt(0.25 + 25)
  const FiberFilter measure(c);
  EXPECT_TRUE(measure.evaluate(line.data(), n).kept()) << "no threshold: nothing dropped";
  EXPECT_NEAR(measure.zoneDistance(line.data(), n), std::sqrt(25.25), 1e-5);
  c.max_distance_mm = 5.03;
  EXPECT_TRUE(FiberFilter(c).evaluate(line.data(), n).kept());
  c.max_distance_mm = 5.02;
  EXPECT_EQ(FiberFilter(c).evaluate(line.data(), n).reason, FilterReason::Distance);
  // A sphere: from its surface; a box: 0 inside, else to its faces; every
  // vertex counts, ends only or not.
  c.distance_zone = parseRegion("sphere:5,0,7,2");
  c.max_distance_mm = 5.0;
  c.ends_only = true;
  EXPECT_NEAR(FiberFilter(c).zoneDistance(line.data(), n), 5.0, 1e-5);
  EXPECT_TRUE(FiberFilter(c).evaluate(line.data(), n).kept()) << "a middle vertex is 5 mm from the surface";
  c.distance_zone = parseRegion("box:3,-1,-1,4,1,1");
  c.max_distance_mm = 0;
  EXPECT_EQ(FiberFilter(c).zoneDistance(line.data(), n), 0.0f);
  EXPECT_TRUE(FiberFilter(c).evaluate(line.data(), n).kept());
  c.distance_zone = parseRegion("box:3,2,-1,4,3,1");
  c.max_distance_mm = 1.9;
  EXPECT_NEAR(FiberFilter(c).zoneDistance(line.data(), n), 2.0, 1e-6);
  EXPECT_EQ(FiberFilter(c).evaluate(line.data(), n).reason, FilterReason::Distance);
}

TEST(FiberFilter, orderedIncludesMustBeEnteredInTheirOrder) {
  FilterCriteria c;
  c.include_ordered = {parseRegion("sphere:0,0,0,1.5"), parseRegion("sphere:5,0,0,1.5"),
                       parseRegion("sphere:10,0,0,1.5")};
  EXPECT_TRUE(verdict(c, lineX(-3, 13)).kept());             // A, B, C (several vertices in each)
  EXPECT_FALSE(verdict(c, lineX(13, -3)).kept());            // C first
  EXPECT_EQ(verdict(c, lineX(-3, 7)).reason, FilterReason::IncludeOrdered);  // C never entered
  // A, B, back to A: out of order.
  std::vector<float> back = lineX(-3, 6);
  const std::vector<float> again = lineX(5, 0);
  back.insert(back.end(), again.begin() + 3, again.end());
  const std::vector<float> on = lineX(1, 13);
  back.insert(back.end(), on.begin(), on.end());
  EXPECT_FALSE(verdict(c, back).kept());
}

// --- against MRtrix3's tckedit ---------------------------------------------

class FilterAgainstTckedit : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir();
    const auto r = test::runCommand(test::toolPath("mrtrix_fod_tractograms.sh") + " " + dir_->path() + " 300");
    status_ = r.exit_code;
    output_ = r.output;
    if (status_ != 0) return;
    // Masks over the same field (the script has checked that nibabel is there).
    const auto m = test::runCommand("/usr/bin/python3 " + test::toolPath("nifti_make.py") + " masks " + dir_->path());
    status_ = m.exit_code == 0 ? 0 : 1;
    output_ += m.output;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override {
    if (status_ == 77) GTEST_SKIP() << "MRtrix3 or nibabel missing: " << output_;
    ASSERT_EQ(status_, 0) << output_;
  }
  static test::TempDir* dir_;
  static int status_;
  static std::string output_;
};
test::TempDir* FilterAgainstTckedit::dir_ = nullptr;
int FilterAgainstTckedit::status_ = 0;
std::string FilterAgainstTckedit::output_;

TEST_F(FilterAgainstTckedit, keepsTheSameStreamlinesInTheSameOrder) {
  // The synthetic field's fibers wind around the z axis in a hollow
  // cylinder of radius 15 to 40 mm (tests/tools/mrtrix_fod_tractograms.sh).
  struct Case {
    std::string tckedit, fibscope;
  };
  const std::vector<Case> cases = {
      {"-include 25,0,0,6", "--include 25,0,0,6"},
      {"-include 25,0,0,6 -include 0,25,0,6", "--include sphere:25,0,0,6 --include sphere:0,25,0,6"},
      {"-include 25,0,0,8 -exclude 0,-25,0,8", "--include 25,0,0,8 --exclude 0,-25,0,8"},
      {"-include 25,0,0,8 -ends_only", "--include 25,0,0,8 --ends-only"},
      {"-exclude 0,30,0,10 -ends_only", "--exclude 0,30,0,10 --ends-only"},
      {"-include_ordered 25,0,0,8 -include_ordered 0,25,0,8",
       "--include-ordered 25,0,0,8 --include-ordered 0,25,0,8"},
      {"-minlength 40", "--min-length 40"},
      {"-maxlength 60 -minlength 20", "--max-length 60 --min-length 20"},
      {"-minlength 30 -include 0,-25,0,10", "--min-length 30 --include 0,-25,0,10"},
  };
  for (const std::string input : {"ifod1.tck", "sdstream.tck"}) {
    for (const Case& c : cases) {
      SCOPED_TRACE(input + ": " + c.fibscope);
      const std::string in = dir_->file(input), want = dir_->file("want.tck"), got = dir_->file("got.tck");
      // One thread: tckedit then keeps the input's order.
      const auto t = test::runCommand("tckedit -quiet -force -nthreads 0 " + in + " " + want + " " + c.tckedit);
      ASSERT_EQ(t.exit_code, 0) << t.output;
      const auto f = test::runFibscope("filter --force " + in + " " + got + " " + c.fibscope);
      ASSERT_EQ(f.exit_code, 0) << f.output;
      const Tractogram a = readTractogram(want), b = readTractogram(got);
      ASSERT_EQ(b.streamlineCount(), a.streamlineCount()) << f.output;
      EXPECT_EQ(b.offsets, a.offsets);
      EXPECT_EQ(b.positions, a.positions);
    }
  }
}

TEST_F(FilterAgainstTckedit, masksKeepTheSameStreamlinesInTheSameOrder) {
  // tests/tools/nifti_make.py masks: blob.nii a ball of 8 mm about (25,0,0)
  // (RAS, 2 mm); oblique.nii one of 7 mm about (0,25,0) (rotated, permuted
  // and flipped axes, anisotropic voxels); float.nii float32 bumps of +1
  // about (0,-25,0) and -1 about (-25,0,0) (tckedit keeps |value| >= 0.5);
  // blob_gz.nii.gz gzipped, LAS, int16 scaled by 0.01.
  const auto m = [&](const std::string& name) { return dir_->file(name); };
  struct Case {
    std::string tckedit, fibscope;
  };
  const std::vector<Case> cases = {
      {"-include " + m("blob.nii"), "--include mask:" + m("blob.nii")},
      {"-include " + m("oblique.nii"), "--include mask:" + m("oblique.nii")},
      {"-exclude " + m("oblique.nii"), "--exclude mask:" + m("oblique.nii")},
      {"-include " + m("float.nii"), "--include mask:" + m("float.nii")},
      {"-include " + m("float.nii") + " -ends_only", "--include mask:" + m("float.nii") + " --ends-only"},
      {"-exclude " + m("blob_gz.nii.gz") + " -ends_only", "--exclude mask:" + m("blob_gz.nii.gz") + " --ends-only"},
      {"-include " + m("blob_gz.nii.gz") + " -include 0,25,0,8",
       "--include mask:" + m("blob_gz.nii.gz") + " --include sphere:0,25,0,8"},
      {"-include " + m("oblique.nii") + " -exclude " + m("float.nii"),
       "--include mask:" + m("oblique.nii") + " --exclude mask:" + m("float.nii")},
      {"-include_ordered " + m("blob.nii") + " -include_ordered " + m("oblique.nii"),
       "--include-ordered mask:" + m("blob.nii") + " --include-ordered mask:" + m("oblique.nii")},
  };
  for (const std::string input : {"ifod1.tck", "sdstream.tck"}) {
    for (const Case& c : cases) {
      SCOPED_TRACE(input + ": " + c.fibscope);
      const std::string in = dir_->file(input), want = dir_->file("want.tck"), got = dir_->file("got.tck");
      const auto t = test::runCommand("tckedit -quiet -force -nthreads 0 " + in + " " + want + " " + c.tckedit);
      ASSERT_EQ(t.exit_code, 0) << t.output;
      const auto f = test::runFibscope("filter --force " + in + " " + got + " " + c.fibscope);
      ASSERT_EQ(f.exit_code, 0) << f.output;
      const Tractogram all = readTractogram(in), a = readTractogram(want), b = readTractogram(got);
      // Every case keeps some streamlines and drops others.
      EXPECT_GT(a.streamlineCount(), 0u);
      EXPECT_LT(a.streamlineCount(), all.streamlineCount());
      ASSERT_EQ(b.streamlineCount(), a.streamlineCount()) << f.output;
      EXPECT_EQ(b.offsets, a.offsets);
      EXPECT_EQ(b.positions, a.positions);
    }
  }
}

TEST(FilterCommand, badCriteriaAreOneLineErrorsAndWriteNothing) {
  test::TempDir dir;
  const std::string in = dir.file("in.tck"), out = dir.file("out.tck");
  ASSERT_EQ(test::runFibscope("phantom " + in + " -n 20").exit_code, 0);
  for (const std::string options : {"--include sphere:1,2,3", "--exclude cube:1,2,3,4", "--include 1,2,3,0",
                                    "--min-length -3", "--min-length 50 --max-length 40", "--include-ordered box:1"}) {
    SCOPED_TRACE(options);
    const auto r = test::runFibscope("filter " + in + " " + out + " " + options);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out));
  }
  const auto missing = test::runFibscope("filter " + dir.file("none.tck") + " " + out + " --include 0,0,0,10");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.output.find(dir.file("none.tck")), std::string::npos) << missing.output;
}

TEST(FilterCommand, keepsDataArraysAndReportsWhatEachCriterionDropped) {
  test::TempDir dir;
  const std::string in = dir.file("in.trx"), out = dir.file("out.trx");
  writeTractogram(in, test::smallTractogram(300, 5, /*with_data=*/true), TractogramHeader{});
  const auto r = test::runFibscope("filter " + in + " " + out + " --include sphere:0,0,0,30 --exclude box:20,-50,-50,50,50,50");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("missed --include sphere:0,0,0,30"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("entered --exclude box:20,-50,-50,50,50,50"), std::string::npos) << r.output;
  // The kept ones are exactly those the filter keeps, with their data.
  const Tractogram all = readTractogram(in), kept = readTractogram(out);
  FilterCriteria c;
  c.include = {parseRegion("sphere:0,0,0,30")};
  c.exclude = {parseRegion("box:20,-50,-50,50,50,50")};
  const FiberFilter filter(c);
  Tractogram want;
  want.per_streamline = {{"weight", 1, "float32", {}}};
  want.per_point = {{"fa", 1, "float32", {}}};
  std::vector<uint8_t> keep;
  for (size_t s = 0; s < all.streamlineCount(); ++s)
    keep.push_back(filter.evaluate(all.point(all.offsets[s]), all.pointsIn(s)).kept());
  ASSERT_GT(std::count(keep.begin(), keep.end(), 1), 5);
  ASSERT_LT(std::count(keep.begin(), keep.end(), 1), 295);
  appendKeptStreamlines(all, keep, want);
  EXPECT_EQ(kept.offsets, want.offsets);
  EXPECT_EQ(kept.positions, want.positions);
  ASSERT_EQ(kept.per_streamline.size(), 1u);
  EXPECT_EQ(kept.per_streamline[0].values, want.per_streamline[0].values);
  ASSERT_EQ(kept.per_point.size(), 1u);
  EXPECT_EQ(kept.per_point[0].values, want.per_point[0].values);
}

// A TRX input's groups name input streamlines: the output's must name the
// same streamlines at their new indices. Three groups: every even
// streamline listed backwards (its order kept), the last 50, and three the
// sphere drops (the group goes, with its data per group).
TEST(FilterCommand, trxGroupsHoldTheirKeptMembersRenumbered) {
  test::TempDir dir;
  const std::string in = dir.file("in.trx"), out = dir.file("out.trx");
  const Tractogram all = test::smallTractogram(300, 5);
  const std::string sphere = "sphere:0,0,0,30";
  FilterCriteria c;
  c.include = {parseRegion(sphere)};
  const FiberFilter filter(c);
  std::vector<uint8_t> keep;
  for (size_t s = 0; s < all.streamlineCount(); ++s)
    keep.push_back(filter.evaluate(all.point(all.offsets[s]), all.pointsIn(s)).kept());
  ASSERT_GT(std::count(keep.begin(), keep.end(), 1), 20);
  ASSERT_LT(std::count(keep.begin(), keep.end(), 1), 280);
  TractogramHeader header;
  header.format = "trx";
  Group even{"even", {}}, tail{"tail", {}}, dropped{"dropped", {}};
  for (uint32_t s = 300; s-- > 0;)
    if (s % 2 == 0) even.streamlines.push_back(s);
  for (uint32_t s = 250; s < 300; ++s) tail.streamlines.push_back(s);
  for (uint32_t s = 0; s < 300 && dropped.streamlines.size() < 3; ++s)
    if (!keep[s]) dropped.streamlines.push_back(s);
  header.groups = {even, tail, dropped};
  header.properties.push_back({"dpg/even/mean.float32", "[1.5]"});
  header.properties.push_back({"dpg/dropped/mean.float32", "[2.5]"});
  writeTractogram(in, all, header);

  const auto r = test::runFibscope("filter " + in + " " + out + " --include " + sphere);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("groups: 2 kept with their kept members renumbered, 1 dropped"), std::string::npos)
      << r.output;
  TractogramHeader got_header;
  const Tractogram got = readTractogram(out, &got_header);
  ASSERT_EQ(got_header.groups.size(), 2u);
  for (const Group& want : {even, tail}) {
    SCOPED_TRACE(want.name);
    const auto g = std::find_if(got_header.groups.begin(), got_header.groups.end(),
                                [&](const Group& x) { return x.name == want.name; });
    ASSERT_NE(g, got_header.groups.end());
    // The kept members, in the group's order; each output member's points
    // are its input streamline's.
    std::vector<uint32_t> members;
    for (const uint32_t s : want.streamlines)
      if (keep[s]) members.push_back(s);
    ASSERT_FALSE(members.empty());
    ASSERT_EQ(g->streamlines.size(), members.size());
    for (size_t k = 0; k < members.size(); ++k) {
      const uint32_t o = g->streamlines[k], s = members[k];
      ASSERT_LT(o, got.streamlineCount());
      ASSERT_EQ(got.pointsIn(o), all.pointsIn(s)) << "member " << k;
      EXPECT_TRUE(std::equal(got.point(got.offsets[o]), got.point(got.offsets[o + 1]), all.point(all.offsets[s])))
          << "member " << k << ": output streamline " << o << " is not input streamline " << s;
    }
  }
  bool even_mean = false;
  for (const auto& [key, value] : got_header.properties) {
    EXPECT_NE(key.rfind("dpg/dropped/", 0), 0u) << key;
    even_mean |= key == "dpg/even/mean.float32";
  }
  EXPECT_TRUE(even_mean) << "the kept group lost its data per group";
}

TEST(FilterRun, renumberedGroupsRankTheKeptMembersAcrossWords) {
  std::vector<uint64_t> kept(3, 0);
  for (const uint32_t s : {1u, 63u, 64u, 130u}) kept[s / 64] |= uint64_t(1) << (s % 64);
  const std::vector<Group> got =
      renumberedGroups({{"a", {130, 2, 64, 1, 500}}, {"none", {0, 65}}, {"b", {63}}}, kept);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].name, "a");
  EXPECT_EQ(got[0].streamlines, (std::vector<uint32_t>{3, 2, 0}));
  EXPECT_EQ(got[1].name, "b");
  EXPECT_EQ(got[1].streamlines, std::vector<uint32_t>{1});
}

}  // namespace
}  // namespace fibscope
