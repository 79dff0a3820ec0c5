// ROI sets (select/roi_set.h): the JSON file round-trips, relative paths
// follow the file, every malformed file is a one-line Error naming the file
// and the place, the criteria are the enabled ROIs'.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <glm/geometric.hpp>
#include <string>

#include "core/error.h"
#include "select/roi_set.h"
#include "test_support.h"

namespace fibscope {
namespace {

std::vector<std::string> specs(const std::vector<Region>& regions) {
  std::vector<std::string> out;
  for (const Region& r : regions) out.push_back(regionSpec(r));
  return out;
}

RoiSet exampleSet(const test::TempDir& dir) {
  RoiSet set;
  set.rois = {{"CST upper", parseRegion("sphere:1,2,3,4"), RoiRole::Include, true},
              {"", parseRegion("box:-10,-10,-10,10,10,0.5"), RoiRole::Exclude, true},
              {"off", parseRegion("sphere:9,9,9,1"), RoiRole::Include, false},
              {"first", parseRegion("obox:0,0,0,10,2,4,10,20,30"), RoiRole::IncludeOrdered, true},
              {"second", parseRegion("sphere:0,30,0,5"), RoiRole::IncludeOrdered, true}};
  set.ends_only = true;
  set.min_length_mm = 20;
  set.max_length_mm = 250.5;
  set.clip_planes = {{makeClipPlane({1.1f, 2, 3}, {0, 0.6f, 0.8f}, "test"), true},
                     {makeClipPlane({0.1f, 0, 0}, {-3, 0, 0}, "test"), false}};
  set.slab = Slab{5.5f, "axial"};
  set.cut_meshes = {{{dir.file("cut.obj"), true}, true}, {{"sphere:0,0,0,30", false}, false}};
  set.anatomy = dir.file("anat/t1.nii.gz");
  return set;
}

void expectEqual(const RoiSet& a, const RoiSet& b) {
  ASSERT_EQ(a.rois.size(), b.rois.size());
  for (size_t i = 0; i < a.rois.size(); ++i) {
    EXPECT_EQ(a.rois[i].name, b.rois[i].name);
    EXPECT_EQ(regionSpec(a.rois[i].region), regionSpec(b.rois[i].region));
    EXPECT_EQ(a.rois[i].role, b.rois[i].role);
    EXPECT_EQ(a.rois[i].enabled, b.rois[i].enabled);
  }
  EXPECT_EQ(a.ends_only, b.ends_only);
  for (const auto& [x, y] : {std::pair{a.min_length_mm, b.min_length_mm}, std::pair{a.max_length_mm, b.max_length_mm}})
    EXPECT_TRUE(x == y || (std::isnan(x) && std::isnan(y))) << x << " " << y;
  ASSERT_EQ(a.clip_planes.size(), b.clip_planes.size());
  for (size_t i = 0; i < a.clip_planes.size(); ++i) {
    EXPECT_EQ(a.clip_planes[i].plane.point, b.clip_planes[i].plane.point);
    // Normalising a unit float vector again may move its last bit.
    EXPECT_LT(glm::distance(a.clip_planes[i].plane.normal, b.clip_planes[i].plane.normal), 1e-7f);
    EXPECT_EQ(a.clip_planes[i].enabled, b.clip_planes[i].enabled);
  }
  ASSERT_EQ(a.slab.has_value(), b.slab.has_value());
  if (a.slab) {
    EXPECT_EQ(a.slab->thickness_mm, b.slab->thickness_mm);
    EXPECT_EQ(a.slab->follow, b.slab->follow);
  }
  ASSERT_EQ(a.cut_meshes.size(), b.cut_meshes.size());
  for (size_t i = 0; i < a.cut_meshes.size(); ++i) {
    EXPECT_EQ(a.cut_meshes[i].cut.spec, b.cut_meshes[i].cut.spec);
    EXPECT_EQ(a.cut_meshes[i].cut.cull_inside, b.cut_meshes[i].cut.cull_inside);
    EXPECT_EQ(a.cut_meshes[i].enabled, b.cut_meshes[i].enabled);
  }
  EXPECT_EQ(a.anatomy, b.anatomy);
}

TEST(RoiSet, saveThenLoadGivesTheSameSet) {
  test::TempDir dir;
  const RoiSet set = exampleSet(dir);
  const std::string path = dir.file("set.json");
  saveRoiSet(set, path);
  const RoiSet back = loadRoiSet(path);
  expectEqual(set, back);
  // Saved again, byte for byte the same file.
  saveRoiSet(back, dir.file("again.json"));
  EXPECT_EQ(test::readBytes(dir.file("again.json")), test::readBytes(path));
  // Paths under the file's folder are written relative to it.
  const std::string text = test::readBytes(path);
  EXPECT_NE(text.find("\"mesh\": \"cut.obj\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"anatomy\": \"anat/t1.nii.gz\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"point\": [\n        1.1,\n        2.0,\n        3.0\n"), std::string::npos)
      << "floats as their shortest decimals\n"
      << text;
  // An empty set is the version alone (and empty lists).
  saveRoiSet(RoiSet{}, path);
  expectEqual(RoiSet{}, loadRoiSet(path));
  EXPECT_EQ(loadRoiSet(path).slab, std::nullopt);
}

TEST(RoiSet, relativePathsFollowTheFile) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.file("sets"));
  const std::string path = dir.file("sets/a.json");
  test::writeBytes(path, R"({"fibscope_roi_set": 1,
    "cut_meshes": [{"mesh": "m.obj", "cull": "inside"}, {"mesh": "/abs/n.obj", "cull": "outside"},
                   {"mesh": "box:0,0,0,1,1,1", "cull": "inside"}],
    "anatomy": "../t1.nii.gz"})");
  const RoiSet set = loadRoiSet(path);
  EXPECT_EQ(set.cut_meshes[0].cut.spec, dir.file("sets/m.obj"));
  EXPECT_EQ(set.cut_meshes[1].cut.spec, "/abs/n.obj");
  EXPECT_EQ(set.cut_meshes[2].cut.spec, "box:0,0,0,1,1,1") << "a built-in shape is no path";
  EXPECT_EQ(set.anatomy, dir.file("t1.nii.gz"));
  // Saved one folder up, the mesh is under it, the anatomy beside it.
  saveRoiSet(set, dir.file("b.json"));
  const std::string up = test::readBytes(dir.file("b.json"));
  EXPECT_NE(up.find("\"sets/m.obj\""), std::string::npos) << up;
  EXPECT_NE(up.find("\"anatomy\": \"t1.nii.gz\""), std::string::npos) << up;
  EXPECT_NE(up.find("\"/abs/n.obj\""), std::string::npos) << up;
  EXPECT_EQ(loadRoiSet(dir.file("b.json")).cut_meshes[0].cut.spec, dir.file("sets/m.obj"));
  // Saved in a folder they are not under: absolute.
  test::TempDir other;
  saveRoiSet(set, other.file("c.json"));
  const std::string away = test::readBytes(other.file("c.json"));
  const std::string absolute_mesh = std::filesystem::absolute(dir.file("sets/m.obj")).lexically_normal().string();
  EXPECT_NE(away.find("\"" + absolute_mesh + "\""), std::string::npos) << away;
  // Masks name a file inside their region spec.
  EXPECT_EQ(regionSpecAgainstFolder("mask:rois/cst.nii.gz", "/data/s1", true), "mask:/data/s1/rois/cst.nii.gz");
  EXPECT_EQ(regionSpecAgainstFolder("mask:/data/s1/rois/cst.nii.gz", "/data/s1", false), "mask:rois/cst.nii.gz");
  EXPECT_EQ(regionSpecAgainstFolder("mask:/elsewhere/cst.nii.gz", "/data/s1", false), "mask:/elsewhere/cst.nii.gz");
  EXPECT_EQ(regionSpecAgainstFolder("sphere:1,2,3,4", "/data/s1", true), "sphere:1,2,3,4");
  EXPECT_EQ(pathAgainstFolder("/data/s1/../s2/x.obj", "/data/s1", false), "/data/s2/x.obj");
  EXPECT_EQ(pathAgainstFolder("x.obj", "", true), "x.obj") << "a file in the current folder";
}

TEST(RoiSet, malformedFilesAreOneLineErrorsNamingFileAndPlace) {
  test::TempDir dir;
  const std::string path = dir.file("bad.json");
  const std::string v = R"("fibscope_roi_set": 1)";
  const std::string deep = "{" + v + R"(, "rois": [[[[[[[[[[1]]]]]]]]]]})";
  const std::pair<std::string, std::string> cases[] = {
      {"{}", "missing \"fibscope_roi_set\""},
      {R"({"fibscope_roi_set": 2})", "fibscope_roi_set: version 2 (this fibscope reads version 1)"},
      {R"({"fibscope_roi_set": "1"})", "fibscope_roi_set: version \"1\""},
      {R"({"fibscope_roi_set": 1.0})", "fibscope_roi_set: version 1.0"},
      {"{" + v + R"(, "colour": 3})", "unknown key \"colour\""},
      {"{" + v + R"(, "rois": [{"region": "sphere:0,0,0,1"}, {"region": "box:0,0,0,1,1,1"},
                               {"region": "sphere:0,0,0,1", "colour": "red"}]})",
       "rois[2]: unknown key \"colour\""},
      {"{" + v + R"(, "rois": [{"region": "sphere:0,0,0,1", "enabled": "yes"}]})",
       "rois[0].enabled: expected true or false, found a string"},
      {"{" + v + R"(, "rois": [{"region": "sphere:0,0,0,1"}, {"region": "sphere:1,2"}]})",
       "rois[1].region: sphere:1,2: expected a sphere"},
      {"{" + v + R"(, "rois": [{"region": "sphere:0,0,0,1"}, {"region": 5}]})",
       "rois[1].region: expected a string, found a number"},
      {"{" + v + R"(, "rois": [{"name": "a"}]})", "rois[0]: missing key \"region\""},
      {"{" + v + R"(, "rois": [{"region": "sphere:0,0,0,1", "role": "maybe"}]})", "rois[0].role: expected"},
      {"{" + v + R"(, "rois": {"region": "sphere:0,0,0,1"}})", "rois: expected an array, found an object"},
      {"{" + v + R"(, "rois": [3]})", "rois[0]: expected an object, found a number"},
      {"{" + v + R"(, "ends_only": 1})", "ends_only: expected true or false, found a number"},
      {"{" + v + R"(, "min_length_mm": -1})", "min_length_mm: a length must be >= 0 mm"},
      {"{" + v + R"(, "max_length_mm": null})", "max_length_mm: expected a number, found null"},
      {"{" + v + R"(, "min_length_mm": 50, "max_length_mm": 40})", "min_length_mm: above max_length_mm (50 > 40)"},
      {"{" + v + R"(, "clip_planes": [{"point": [0,0,0], "normal": [0,0,0]}]})",
       "clip_planes[0]: a clip plane's normal must be non-zero"},
      {"{" + v + R"(, "clip_planes": [{"point": [0,0], "normal": [0,0,1]}]})",
       "clip_planes[0].point: expected [x, y, z]"},
      {"{" + v + R"(, "clip_planes": [{"point": [0,0,"a"], "normal": [0,0,1]}]})",
       "clip_planes[0].point[2]: expected a number, found a string"},
      {"{" + v + R"(, "clip_planes": [{"point": [0,0,0]}]})", "clip_planes[0]: missing key \"normal\""},
      {"{" + v + R"(, "clip_planes": [)" +
           [] {
             std::string planes;
             for (int i = 0; i < 7; ++i)
               planes += std::string(i ? "," : "") + R"({"point": [0,0,0], "normal": [0,0,1]})";
             return planes;
           }() +
           "]}",
       "clip_planes: 7 enabled (at most 6 at once)"},
      {"{" + v + R"(, "slab": {"thickness_mm": 0}})", "slab.thickness_mm: a slab's thickness must be > 0 mm"},
      {"{" + v + R"(, "slab": {"thickness_mm": 2, "follow": "up"}})", "slab.follow: expected"},
      {"{" + v + R"(, "slab": 5})", "slab: expected an object, found a number"},
      {"{" + v + R"(, "cut_meshes": [{"mesh": "a.obj", "cull": "both"}]})", "cut_meshes[0].cull: expected"},
      {"{" + v + R"(, "cut_meshes": [{"mesh": "a.obj"}]})", "cut_meshes[0]: missing key \"cull\""},
      {"{" + v + R"(, "cut_meshes": [{"mesh": "box:1,2", "cull": "inside"}]})", "cut_meshes[0].mesh: box:1,2: "},
      {"{" + v + R"(, "anatomy": ""})", "anatomy: empty"},
      {"{" + v + R"(, "ends_only": true, "ends_only": false})", "repeated key \"ends_only\""},
      {"{" + v + ", ", "invalid JSON: "},
      {"", "invalid JSON: "},
      {"{" + v + R"(, "min_length_mm": 1e999})", "invalid JSON: number overflow"},  // escaped as a crash once
      {"[1]", "expected a JSON object, found an array"},
      {deep, "JSON nests deeper than 8 levels"},
  };
  for (const auto& [text, expected] : cases) {
    SCOPED_TRACE(text);
    test::writeBytes(path, text);
    const std::string message = test::errorOf([&] { loadRoiSet(path); });
    EXPECT_EQ(message.rfind(path + ": " + expected, 0), 0u) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  const std::string missing = test::errorOf([&] { loadRoiSet(dir.file("none.json")); });
  EXPECT_EQ(missing, dir.file("none.json") + ": no such file");
}

TEST(RoiSet, criteriaAreTheEnabledRoisAndCutsTheEnabledCuts) {
  test::TempDir dir;
  const RoiSet set = exampleSet(dir);
  const FilterCriteria c = filterCriteria(set);
  EXPECT_EQ(specs(c.include), (std::vector<std::string>{"sphere:1,2,3,4"}));
  EXPECT_EQ(specs(c.exclude), specs({parseRegion("box:-10,-10,-10,10,10,0.5")}));
  EXPECT_EQ(specs(c.include_ordered),
            specs({parseRegion("obox:0,0,0,10,2,4,10,20,30"), parseRegion("sphere:0,30,0,5")}));
  EXPECT_TRUE(c.ends_only);
  EXPECT_EQ(c.min_length_mm, 20);
  EXPECT_EQ(c.max_length_mm, 250.5);

  const CutSet cuts = cutSet(set);
  ASSERT_EQ(cuts.planes.size(), 1u);
  EXPECT_EQ(cuts.planes[0].point, glm::vec3(1.1f, 2, 3));
  ASSERT_EQ(cuts.meshes.size(), 1u);
  EXPECT_EQ(cuts.meshes[0].spec, dir.file("cut.obj"));
  ASSERT_TRUE(cuts.slab.has_value());
  EXPECT_EQ(cuts.slab->follow, "axial");

  // The command line's regions come after the set's; its lengths win.
  FilterCriteria cli;
  cli.include = {parseRegion("sphere:5,5,5,5")};
  cli.max_length_mm = 100;
  const FilterCriteria merged = mergeCriteria(c, cli);
  EXPECT_EQ(specs(merged.include), (std::vector<std::string>{"sphere:1,2,3,4", "sphere:5,5,5,5"}));
  EXPECT_EQ(specs(merged.exclude), specs(c.exclude));
  EXPECT_EQ(merged.min_length_mm, 20) << "not given on the command line";
  EXPECT_EQ(merged.max_length_mm, 100);
  EXPECT_TRUE(merged.ends_only);
  EXPECT_FALSE(mergeCriteria(FilterCriteria{}, FilterCriteria{}).ends_only);
}

}  // namespace
}  // namespace fibscope
