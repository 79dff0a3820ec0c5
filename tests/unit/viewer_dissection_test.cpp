// The viewer's dissection without a GPU: the state's edits, the criteria and
// the frame's clip planes it gives, ROI set files through the state, the
// geometry the mouse and the panel use, and the scripts and mouse bindings
// that drive it.
#include <gtest/gtest.h>

#include <GLFW/glfw3.h>

#include <cmath>
#include <glm/glm.hpp>
#include <string>
#include <tuple>
#include <vector>

#include "app/viewer/dissection.h"
#include "app/viewer/viewer_input.h"
#include "app/viewer/viewer_script.h"
#include "core/error.h"
#include "render/camera.h"
#include "select/roi_set.h"
#include "test_support.h"

namespace fibscope {
namespace {

void edit(DissectionState& d, RenderSettings& s, const DissectionEdit& e) { applyDissectionEdit(d, s, e); }

std::vector<std::string> specs(const std::vector<Region>& regions) {
  std::vector<std::string> out;
  for (const Region& r : regions) out.push_back(regionSpec(r));
  return out;
}

// --- the state and what it gives the filter and the frame -----------------

TEST(ViewerDissection, enabledRoisBecomeTheCriteriaInTheirOrderPerRole) {
  DissectionState d;
  RenderSettings s;
  edit(d, s, RoiAddEdit{"a", RoiRole::Include, parseRegion("sphere:1,2,3,4")});
  edit(d, s, RoiAddEdit{"b", RoiRole::Exclude, parseRegion("box:0,0,0,1,1,1")});
  edit(d, s, RoiAddEdit{"c", RoiRole::IncludeOrdered, parseRegion("sphere:5,5,5,1")});
  edit(d, s, RoiAddEdit{"d", RoiRole::Include, parseRegion("sphere:9,9,9,2")});
  edit(d, s, RoiAddEdit{"e", RoiRole::IncludeOrdered, parseRegion("sphere:6,6,6,1")});
  EXPECT_EQ(d.selected, 4);  // the ROI added last
  edit(d, s, RoiEnableEdit{"a", false});
  edit(d, s, EndsOnlyEdit{true});
  edit(d, s, LengthEdit{20, NAN});

  const FilterCriteria c = dissectionCriteria(d);
  EXPECT_EQ(specs(c.include), std::vector<std::string>{"sphere:9,9,9,2"});  // a is off
  EXPECT_EQ(specs(c.exclude), std::vector<std::string>{"box:0,0,0,1,1,1"});
  EXPECT_EQ(specs(c.include_ordered), (std::vector<std::string>{"sphere:5,5,5,1", "sphere:6,6,6,1"}));
  EXPECT_TRUE(c.ends_only);
  EXPECT_EQ(c.min_length_mm, 20);
  EXPECT_TRUE(std::isnan(c.max_length_mm));

  edit(d, s, RoiEnableEdit{"a", true});
  EXPECT_EQ(specs(dissectionCriteria(d).include), (std::vector<std::string>{"sphere:1,2,3,4", "sphere:9,9,9,2"}));
}

TEST(ViewerDissection, badEditsAreOneLineErrorsThatChangeNothing) {
  DissectionState d;
  RenderSettings s;
  edit(d, s, RoiAddEdit{"a", RoiRole::Include, parseRegion("sphere:1,2,3,4")});
  edit(d, s, LengthEdit{10, 100});
  const std::string before = roiSetJson(roiSetToSave(d, s), "x.json");
  const std::vector<DissectionEdit> bad = {
      RoiAddEdit{"a", RoiRole::Exclude, parseRegion("sphere:0,0,0,1")},  // the name is taken
      RoiRemoveEdit{"nope"},
      RoiEnableEdit{"nope", false},
      LengthEdit{50, 40},
      LengthEdit{-1, NAN},
      SlabEdit{-2},
      SlabEdit{NAN}};
  for (const DissectionEdit& e : bad) {
    const std::string message = test::errorOf([&] { edit(d, s, e); });
    EXPECT_FALSE(message.empty());
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(roiSetJson(roiSetToSave(d, s), "x.json"), before) << message;
  }
  d.selected = -1;
  EXPECT_NE(test::errorOf([&] { edit(d, s, RoiRemoveEdit{}); }).find("no ROI is selected"), std::string::npos);
}

TEST(ViewerDissection, removingFollowsTheSelection) {
  DissectionState d;
  RenderSettings s;
  for (const char* name : {"a", "b", "c"}) edit(d, s, RoiAddEdit{name, RoiRole::Include, parseRegion("1,2,3,4")});
  d.selected = 2;
  edit(d, s, RoiRemoveEdit{"a"});
  EXPECT_EQ(d.selected, 1);  // still c
  EXPECT_EQ(d.set.rois[size_t(d.selected)].name, "c");
  edit(d, s, RoiRemoveEdit{});  // the selected one
  EXPECT_EQ(d.selected, -1);
  ASSERT_EQ(d.set.rois.size(), 1u);
  EXPECT_EQ(d.set.rois[0].name, "b");
  EXPECT_EQ(uniqueRoiName(d.set, "b"), "b-1");
  d.set.rois[0].name = "sphere-1";
  EXPECT_EQ(uniqueRoiName(d.set, "sphere"), "sphere-2");
}

// n.p + d of a frame's world plane.
double side(const std::array<double, 4>& plane, const glm::dvec3& p) {
  return plane[0] * p.x + plane[1] * p.y + plane[2] * p.z + plane[3];
}

TEST(ViewerDissection, enabledClipPlanesKeepTheSideTheirNormalPointsTo) {
  DissectionState d;
  RenderSettings s;
  edit(d, s, ClipPlaneAddEdit{makeClipPlane({10, 0, 0}, {2, 0, 0}, "t")});
  edit(d, s, ClipPlaneAddEdit{makeClipPlane({0, 5, 5}, {0, -1, -1}, "t")});
  d.set.clip_planes.push_back(RoiClipPlane{makeClipPlane({0, 0, 0}, {0, 0, 1}, "t"), false});  // off
  RenderSettings frame;
  EXPECT_EQ(addDissectionCuts(d.set, frame), 0u);
  ASSERT_EQ(frame.clip_planes.size(), 2u);
  // x >= 10 kept: (11, 0, 0) on the kept side, (9, 0, 0) cut, the plane's point on it.
  EXPECT_NEAR(side(frame.clip_planes[0], {11, 0, 0}), 1.0, 1e-9);
  EXPECT_NEAR(side(frame.clip_planes[0], {9, 3, -7}), -1.0, 1e-9);
  EXPECT_NEAR(side(frame.clip_planes[0], {10, 40, 2}), 0.0, 1e-9);
  // y + z <= 10 kept.
  EXPECT_GT(side(frame.clip_planes[1], {0, 0, 0}), 0);
  EXPECT_LT(side(frame.clip_planes[1], {0, 6, 6}), 0);
  EXPECT_NEAR(side(frame.clip_planes[1], {0, 5, 5}), 0.0, 1e-6);
}

TEST(ViewerDissection, atMostSixPlanesReachTheFrame) {
  DissectionState d;
  RenderSettings s;
  for (int i = 0; i < 6; ++i) edit(d, s, ClipPlaneAddEdit{makeClipPlane({float(i), 0, 0}, {1, 0, 0}, "t")});
  EXPECT_NE(test::errorOf([&] {
              edit(d, s, ClipPlaneAddEdit{makeClipPlane({0, 0, 0}, {0, 1, 0}, "t")});
            }).find("at most 6"),
            std::string::npos);
  EXPECT_EQ(d.set.clip_planes.size(), 6u);
  RenderSettings frame;
  frame.clip_planes.push_back({0, 0, 1, 0});  // one there already
  EXPECT_EQ(addDissectionCuts(d.set, frame), 1u);
  EXPECT_EQ(frame.clip_planes.size(), 6u);
  edit(d, s, ClipPlaneClearEdit{});
  EXPECT_TRUE(d.set.clip_planes.empty());
}

TEST(ViewerDissection, commandLinePlanesBecomeTheSamePlanesOfTheState) {
  const std::vector<std::array<double, 4>> given = {{0, 0, 1, -4}, {0.6, 0.8, 0, 3}, {-1, 0, 0, 0}};
  DissectionState d;
  d.set.clip_planes = clipPlanesFromSettings(given);
  RenderSettings frame;
  addDissectionCuts(d.set, frame);
  ASSERT_EQ(frame.clip_planes.size(), given.size());
  for (size_t i = 0; i < given.size(); ++i)
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(frame.clip_planes[i][k], given[i][k], 1e-6) << i << " " << k;
}

TEST(ViewerDissection, slabIsTheSettingsAndTravelsWithTheSet) {
  DissectionState d;
  RenderSettings s;
  edit(d, s, SlabEdit{12.5f});
  EXPECT_EQ(s.slab_mm, 12.5f);
  edit(d, s, RoiAddEdit{"cst", RoiRole::IncludeOrdered, parseRegion("obox:1,2,3,4,5,6,10,20,30")});
  edit(d, s, ClipPlaneAddEdit{makeClipPlane({1, 2, 3}, {0, 1, 0}, "t")});
  d.set.cut_meshes.push_back(RoiCutMesh{MeshCut{"sphere:0,0,0,30", true}, true});  // kept, not drawn

  test::TempDir dir;
  const std::string path = dir.file("set.json");
  saveRoiSet(roiSetToSave(d, s), path);
  const RoiSet back = loadRoiSet(path);
  ASSERT_TRUE(back.slab.has_value());
  EXPECT_EQ(back.slab->thickness_mm, 12.5f);
  ASSERT_EQ(back.rois.size(), 1u);
  EXPECT_EQ(back.rois[0].name, "cst");
  EXPECT_EQ(back.rois[0].role, RoiRole::IncludeOrdered);
  EXPECT_EQ(regionSpec(back.rois[0].region), "obox:1,2,3,4,5,6,10,20,30");
  EXPECT_EQ(back.cut_meshes.size(), 1u);

  DissectionState other;
  RenderSettings other_settings;
  loadRoiSetIntoState(back, other, other_settings);
  EXPECT_EQ(other_settings.slab_mm, 12.5f);
  EXPECT_EQ(roiSetJson(roiSetToSave(other, other_settings), path), roiSetJson(roiSetToSave(d, s), path));

  edit(other, other_settings, SlabEdit{0});
  EXPECT_FALSE(roiSetToSave(other, other_settings).slab.has_value());
}

// --- geometry of placing and moving ROIs ----------------------------------

Camera testCamera() {
  Camera c;
  c.eye = {30, -200, 40};
  c.target = {5, 10, -3};
  c.up = {0, 0, 1};
  c.fov_y_deg = 35;
  c.near_mm = 10;
  c.far_mm = 600;
  c.width = 640;
  c.height = 400;
  return c;
}

// Window pixel of a world point (camera.h's conventions).
glm::dvec2 toWindow(const Camera& camera, const glm::dvec3& p) {
  const std::array<double, 16> m = viewProjectionD(camera);
  const double x = m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12];
  const double y = m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13];
  const double w = m[3] * p.x + m[7] * p.y + m[11] * p.z + m[15];
  return {(x / w + 1) * camera.width / 2, (y / w + 1) * camera.height / 2};
}

TEST(ViewerDissection, draggedRoiFollowsTheCursorInTheViewPlane) {
  const Camera camera = testCamera();
  const glm::dvec3 eye(camera.eye[0], camera.eye[1], camera.eye[2]);
  const glm::dvec3 forward = glm::normalize(glm::dvec3(camera.target[0], camera.target[1], camera.target[2]) - eye);
  for (const glm::dvec3& at : {glm::dvec3(5, 10, -3), glm::dvec3(-20, 40, 15), glm::dvec3(12, -90, 0)}) {
    for (const glm::dvec2& drag : {glm::dvec2(25, 0), glm::dvec2(0, -17), glm::dvec2(-8, 31)}) {
      const glm::dvec3 delta = viewPlaneDrag(camera, at, drag.x, drag.y);
      EXPECT_NEAR(glm::dot(delta, forward), 0.0, 1e-9);  // in the plane facing the viewer
      const glm::dvec2 moved = toWindow(camera, at + delta) - toWindow(camera, at);
      EXPECT_NEAR(moved.x, drag.x, 1e-6);
      EXPECT_NEAR(moved.y, drag.y, 1e-6);
    }
  }
}

TEST(ViewerDissection, clipPlaneAtTheFocalPointKeepsTheViewersSide) {
  const Camera camera = testCamera();
  const ClipPlane p = planeFacingViewer(camera);
  const glm::dvec3 target(camera.target[0], camera.target[1], camera.target[2]);
  const glm::dvec3 eye(camera.eye[0], camera.eye[1], camera.eye[2]);
  EXPECT_NEAR(glm::length(glm::dvec3(p.point) - target), 0.0, 1e-5);
  EXPECT_TRUE(planeKeeps(p, glm::vec3(0.5 * (eye + target))));      // between the viewer and the focal point
  EXPECT_FALSE(planeKeeps(p, glm::vec3(target + (target - eye))));  // behind it
}

TEST(ViewerDissection, movedAndScaledRegionsKeepTheirKindAndCentre) {
  const glm::dvec3 delta(3, -4, 5);
  const float inside_after[3] = {4, -2, 8};  // (1, 2, 3) + delta
  // Each reaches 1 mm from its centre (1, 2, 3) along x (the box turned about x).
  for (const std::string spec : {"sphere:1,2,3,1", "box:0,1,2,2,3,4", "obox:1,2,3,2,2,2,30,0,0"}) {
    SCOPED_TRACE(spec);
    const Region r = parseRegion(spec);
    const Region moved = movedRegion(r, delta);
    EXPECT_EQ(moved.index(), r.index());
    EXPECT_NEAR(glm::length(*regionCenter(moved) - (*regionCenter(r) + delta)), 0.0, 1e-6);
    EXPECT_TRUE(regionContains(moved, inside_after));
    const float old_centre[3] = {1, 2, 3};
    EXPECT_FALSE(regionContains(moved, old_centre));

    // Twice the size: a point 1.6 x the old reach along x is inside.
    const Region big = scaledRegion(r, 2.0);
    EXPECT_NEAR(glm::length(*regionCenter(big) - *regionCenter(r)), 0.0, 1e-9);
    const float near_edge[3] = {1 + 0.9f, 2, 3}, farther[3] = {1 + 1.6f, 2, 3};
    EXPECT_TRUE(regionContains(r, near_edge));
    EXPECT_FALSE(regionContains(r, farther));
    EXPECT_TRUE(regionContains(big, farther));
  }
}

TEST(ViewerDissection, panelOrientedBoxIsTheBoxItsSpecNames) {
  const OrientedBoxRegion o = orientedBox({1, 2, 3}, {4, 5, 6}, {10, -20, 30});
  const OrientedBoxRegion p = std::get<OrientedBoxRegion>(parseRegion("obox:1,2,3,4,5,6,10,-20,30"));
  for (int k = 0; k < 3; ++k) {
    EXPECT_DOUBLE_EQ(o.half[k], p.half[k]);
    for (int j = 0; j < 3; ++j) EXPECT_DOUBLE_EQ(o.axes[k][j], p.axes[k][j]);
  }
  EXPECT_THROW(orientedBox({0, 0, 0}, {1, 0, 1}, {0, 0, 0}), Error);
}

TEST(ViewerDissection, defaultRadiusFollowsTheScene) {
  Bounds brain;
  brain.min = {-70, -85, -60};
  brain.max = {70, 85, 60};
  EXPECT_NEAR(defaultRoiRadius(brain), 0.03 * std::sqrt(140.0 * 140 + 170 * 170 + 120 * 120), 1e-9);
  EXPECT_EQ(defaultRoiRadius(Bounds{}), 0.5);  // an empty scene: still a usable sphere
  const SphereRegion s = sphereAt({1, 2, 3}, 7.5);
  EXPECT_EQ(regionSpec(s), "sphere:1,2,3,7.5");
  EXPECT_EQ(regionSpec(boxAt({1, 2, 3}, 2)), "box:-1,0,1,3,4,5");
}

// --- scripts and the mouse -------------------------------------------------

TEST(ViewerScript, parsesTheDissectionCommands) {
  const auto steps = parseScript(
      "roi-add cst include sphere:1,2,3,4\n"
      "roi-add no exclude box:0,0,0,1,1,1\n"
      "roi-add o1 include_ordered 1,1,1,2\n"
      "roi-remove no\n"
      "roi-enable cst off\n"
      "ends-only on\n"
      "length 20 -\n"
      "clip-plane-add 0,0,10,0,0,-1\n"
      "clip-plane-clear\n"
      "slab 5.5\n"
      "dropped dim\n"
      "roi-save set.json\n"
      "roi-load set.json\n"
      "export-kept kept.trk\n"
      "expect-kept 12\n"
      "roi-place 30 40.5\n",
      "d.txt");
  ASSERT_EQ(steps.size(), 17u);  // export-kept is followed by its wait
  auto edit_of = [&](size_t i) { return std::get<DissectionAction>(std::get<ViewerAction>(steps[i].command)).edit; };
  const auto add = std::get<RoiAddEdit>(edit_of(0));
  EXPECT_EQ(add.name, "cst");
  EXPECT_EQ(add.role, RoiRole::Include);
  EXPECT_EQ(regionSpec(add.region), "sphere:1,2,3,4");
  EXPECT_EQ(std::get<RoiAddEdit>(edit_of(1)).role, RoiRole::Exclude);
  EXPECT_EQ(std::get<RoiAddEdit>(edit_of(2)).role, RoiRole::IncludeOrdered);
  EXPECT_EQ(std::get<RoiRemoveEdit>(edit_of(3)).name, "no");
  EXPECT_FALSE(std::get<RoiEnableEdit>(edit_of(4)).enabled);
  EXPECT_TRUE(std::get<EndsOnlyEdit>(edit_of(5)).on);
  const auto length = std::get<LengthEdit>(edit_of(6));
  EXPECT_EQ(length.min_mm, 20);
  EXPECT_TRUE(std::isnan(length.max_mm));
  const auto plane = std::get<ClipPlaneAddEdit>(edit_of(7)).plane;
  EXPECT_EQ(plane.point.z, 10);
  EXPECT_EQ(plane.normal.z, -1);
  EXPECT_TRUE(std::holds_alternative<ClipPlaneClearEdit>(edit_of(8)));
  EXPECT_EQ(std::get<SlabEdit>(edit_of(9)).thickness_mm, 5.5f);
  EXPECT_TRUE(std::get<DroppedEdit>(edit_of(10)).dim);
  const auto& save = std::get<RoiSetFileAction>(std::get<ViewerAction>(steps[11].command));
  EXPECT_TRUE(save.save);
  EXPECT_EQ(save.path, "set.json");
  EXPECT_FALSE(std::get<RoiSetFileAction>(std::get<ViewerAction>(steps[12].command)).save);
  EXPECT_EQ(std::get<ExportKeptAction>(std::get<ViewerAction>(steps[13].command)).path, "kept.trk");
  EXPECT_TRUE(std::holds_alternative<WaitExported>(steps[14].command));
  EXPECT_EQ(steps[14].line, 14);
  const auto& expect = std::get<ExpectKeptAction>(std::get<ViewerAction>(steps[15].command));
  EXPECT_EQ(expect.count, 12u);
  EXPECT_EQ(expect.where, "d.txt:15");
  const auto& place = std::get<RoiPlaceAction>(std::get<ViewerAction>(steps[16].command));
  EXPECT_EQ(place.x, 30);
  EXPECT_EQ(place.y, 40.5);
}

TEST(ViewerScript, malformedDissectionLinesNameTheFileAndLine) {
  for (const std::string bad : {"roi-add a include",
                                "roi-add a inside sphere:1,2,3,4",
                                "roi-add a include sphere:1,2,3",
                                "roi-add a include cube:1",
                                "roi-remove",
                                "roi-enable a maybe",
                                "ends-only yes",
                                "length 5",
                                "length 50 40",
                                "length -1 -",
                                "length x -",
                                "clip-plane-add 0,0,0,0,0,0",
                                "clip-plane-add 1,2,3",
                                "clip-plane-clear now",
                                "slab -1",
                                "slab 5000",
                                "dropped fade",
                                "roi-save set.txt",
                                "roi-load",
                                "export-kept kept.vtk",
                                "export-kept",
                                "expect-kept -3",
                                "expect-kept 2.5",
                                "roi-place 1",
                                "roi-place -1 2",
                                "roi-place a b",
                                "cut-mesh-add box:0,0,0,1,1,1",
                                "cut-mesh-add box:0,0,0,1,1:inside",
                                "cut-mesh-add sphere:0,0,0,1:around",
                                "cut-mesh-add",
                                "cut-mesh-clear all"}) {
    SCOPED_TRACE(bad);
    try {
      parseScript("wait 1\n" + bad + "\n", "session.txt");
      ADD_FAILURE() << "no error";
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind("session.txt:2: ", 0), 0u) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
}

TEST(ViewerScript, exportKeptHoldsTheScriptUntilWritten) {
  ScriptRunner runner(parseScript("export-kept a.tck\nexpect-kept 3\nquit\n", "s"));
  const auto first = runner.nextFrame(false, /*exporting=*/false);  // the export is started this frame
  ASSERT_EQ(first.size(), 1u);
  EXPECT_TRUE(std::holds_alternative<ExportKeptAction>(first[0]));
  EXPECT_TRUE(runner.nextFrame(false, /*exporting=*/true).empty());
  EXPECT_TRUE(runner.nextFrame(false, true).empty());
  EXPECT_FALSE(runner.finished());
  const auto rest = runner.nextFrame(false, false);
  ASSERT_EQ(rest.size(), 2u);
  EXPECT_TRUE(std::holds_alternative<ExpectKeptAction>(rest[0]));
  EXPECT_TRUE(runner.finished());
}

InputEvent at(double x, double y) {
  InputEvent e;
  e.type = InputEvent::Type::CursorMoved;
  e.x = x;
  e.y = y;
  return e;
}
InputEvent rightButton(bool pressed) {
  InputEvent e;
  e.type = InputEvent::Type::MouseButton;
  e.button = InputEvent::kRight;
  e.pressed = pressed;
  return e;
}

TEST(ViewerDissection, cutMeshesAreEditsUpToFourEnabledAndTravelWithTheSet) {
  DissectionState d;
  RenderSettings s;
  const auto steps = parseScript("cut-mesh-add box:0,0,0,10,10,10:outside\ncut-mesh-add mesh:a.obj:inside\n"
                                 "cut-mesh-clear\n", "s");
  ASSERT_EQ(steps.size(), 3u);
  const auto& add = std::get<CutMeshAddEdit>(std::get<DissectionAction>(std::get<ViewerAction>(steps[0].command)).edit);
  EXPECT_EQ(add.cut.spec, "box:0,0,0,10,10,10");
  EXPECT_FALSE(add.cut.cull_inside);
  const auto& file = std::get<CutMeshAddEdit>(std::get<DissectionAction>(std::get<ViewerAction>(steps[1].command)).edit);
  EXPECT_EQ(file.cut.spec, "mesh:a.obj");  // an OBJ path, ':' and all
  EXPECT_TRUE(file.cut.cull_inside);
  EXPECT_TRUE(std::holds_alternative<CutMeshClearEdit>(
      std::get<DissectionAction>(std::get<ViewerAction>(steps[2].command)).edit));

  for (int i = 0; i < 4; ++i) edit(d, s, CutMeshAddEdit{MeshCut{"sphere:0,0,0," + std::to_string(i + 1), i % 2 == 0}});
  EXPECT_THROW(edit(d, s, CutMeshAddEdit{MeshCut{"sphere:0,0,0,9", true}}), Error);
  EXPECT_EQ(d.set.cut_meshes.size(), 4u);
  d.set.cut_meshes[0].enabled = false;  // a disabled one leaves room
  edit(d, s, CutMeshAddEdit{MeshCut{"sphere:0,0,0,9", true}});
  EXPECT_EQ(enabledCutMeshes(d.set), 4u);

  test::TempDir dir;
  saveRoiSet(roiSetToSave(d, s), dir.file("set.json"));
  edit(d, s, CutMeshClearEdit{});
  EXPECT_TRUE(d.set.cut_meshes.empty());
  loadRoiSetIntoState(loadRoiSet(dir.file("set.json")), d, s);
  ASSERT_EQ(d.set.cut_meshes.size(), 5u);
  EXPECT_FALSE(d.set.cut_meshes[0].enabled);
  EXPECT_EQ(d.set.cut_meshes[1].cut.spec, "sphere:0,0,0,2");
  EXPECT_FALSE(d.set.cut_meshes[1].cut.cull_inside);
  // Five enabled: refused, the state kept.
  RoiSet five = d.set;
  five.cut_meshes[0].enabled = true;
  EXPECT_THROW(loadRoiSetIntoState(five, d, s), Error);
  EXPECT_FALSE(d.set.cut_meshes[0].enabled);
}

TEST(ViewerDissection, cutSizeFollowsTheScene) {
  Bounds b;
  b.min = {0, 0, 0};
  b.max = {100, 0, 0};
  EXPECT_DOUBLE_EQ(defaultCutSize(b), 15.0);
  b.max = {0, 0, 0};
  EXPECT_DOUBLE_EQ(defaultCutSize(b), 1.0);
}

TEST(ViewerInput, droppedObjBecomesACutHidingItsOutsideOtherFilesOpen) {
  InputMapper m;
  InputEvent drop;
  drop.type = InputEvent::Type::Drop;
  drop.paths = {"/data/thalamus.OBJ", "/data/sub.tck"};
  const auto a = m.map(drop, false, false);
  ASSERT_EQ(a.size(), 2u);
  const auto& cut = std::get<CutMeshAddEdit>(std::get<DissectionAction>(a[0]).edit).cut;
  EXPECT_EQ(cut.spec, "/data/thalamus.OBJ");
  EXPECT_FALSE(cut.cull_inside);
  EXPECT_EQ(std::get<OpenAction>(a[1]).path, "/data/sub.tck");
  EXPECT_FALSE(isObjPath("obj"));
  EXPECT_TRUE(isObjPath("a.obj"));
}

TEST(ViewerInput, rightClickPlacesASphereAtThePress) {
  InputMapper m;
  m.map(at(70, 40), false, false);
  EXPECT_TRUE(m.map(rightButton(true), false, false).empty());
  EXPECT_TRUE(m.map(at(72, 41), false, false).empty());  // within the slop: nothing moves yet
  const auto a = m.map(rightButton(false), false, false);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(std::get<RoiPlaceAction>(a[0]).x, 70);
  EXPECT_EQ(std::get<RoiPlaceAction>(a[0]).y, 40);
  m.map(rightButton(true), /*want_mouse=*/true, false);  // on a panel
  EXPECT_TRUE(m.map(rightButton(false), true, false).empty());
}

TEST(ViewerInput, rightDragMovesTheSelectedRoiByTheWholeWay) {
  InputMapper m;
  m.map(at(70, 40), false, false);
  m.map(rightButton(true), false, false);
  EXPECT_TRUE(m.map(at(72, 40), false, false).empty());
  auto a = m.map(at(76, 38), false, false);  // out of the slop: the motion since the press
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(std::get<RoiDragAction>(a[0]).dx, 6);
  EXPECT_EQ(std::get<RoiDragAction>(a[0]).dy, -2);
  a = m.map(at(80, 45), false, false);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(std::get<RoiDragAction>(a[0]).dx, 4);
  EXPECT_EQ(std::get<RoiDragAction>(a[0]).dy, 7);
  EXPECT_TRUE(m.map(rightButton(false), false, false).empty());  // a drag places nothing
  EXPECT_TRUE(m.map(at(90, 45), false, false).empty());
}

TEST(ViewerInput, shiftWheelAndBracketsResizeDeleteRemoves) {
  InputMapper m;
  InputEvent wheel;
  wheel.type = InputEvent::Type::Scroll;
  wheel.y = -2;
  wheel.shift = true;
  auto a = m.map(wheel, false, false);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(std::get<RoiResizeAction>(a[0]).steps, -2);
  for (const auto& [k, steps] : {std::pair{GLFW_KEY_RIGHT_BRACKET, 1.0}, std::pair{GLFW_KEY_LEFT_BRACKET, -1.0}}) {
    InputEvent e;
    e.type = InputEvent::Type::Key;
    e.key = k;
    e.pressed = true;
    a = m.map(e, false, false);
    ASSERT_EQ(a.size(), 1u);
    EXPECT_EQ(std::get<RoiResizeAction>(a[0]).steps, steps);
  }
  InputEvent del;
  del.type = InputEvent::Type::Key;
  del.key = GLFW_KEY_DELETE;
  del.pressed = true;
  a = m.map(del, false, false);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_TRUE(std::get<RoiRemoveEdit>(std::get<DissectionAction>(a[0]).edit).name.empty());  // the selected one
  EXPECT_TRUE(m.map(del, false, /*want_keyboard=*/true).empty());                            // typing in a panel
}

}  // namespace
}  // namespace fibscope

namespace fibscope {
namespace {

TEST(ViewerDissection, aSetsSlabFollowsTheActiveSliceOfItsViewByTheImagesAxes) {
  // An image stored with voxel i along world S, j along R, k along A
  // (a permuted, slightly oblique sform): its axial slices are i's.
  AnatomyGrid permuted;
  glm::dmat4 m(0.0);
  m[0] = glm::dvec4(0.05, 0, 1, 0);  // column i: mostly +z
  m[1] = glm::dvec4(1, 0, 0, 0);     // column j: +x
  m[2] = glm::dvec4(0, 1, 0.05, 0);  // column k: mostly +y
  m[3] = glm::dvec4(-90, -120, -70, 1);
  permuted.voxel_to_world = m;
  permuted.world_to_voxel = glm::inverse(m);
  const AnatomyGrid ras;
  for (const auto& [view, ras_axis, permuted_axis] :
       {std::tuple{"sagittal", 0, 1}, std::tuple{"coronal", 1, 2}, std::tuple{"axial", 2, 0}}) {
    SCOPED_TRACE(view);
    EXPECT_EQ(anatomicalSliceAxis(ras, view), ras_axis);
    EXPECT_EQ(anatomicalSliceAxis(permuted, view), permuted_axis);
    EXPECT_EQ(sliceAxisView(permuted, permuted_axis), view);
    RoiSet set;
    set.slab = Slab{6.0f, view};
    DissectionState d;
    RenderSettings s;
    loadRoiSetIntoState(set, d, s, &permuted);
    EXPECT_TRUE(s.slab_follows_slice);
    EXPECT_EQ(int(s.active_slice), permuted_axis);
    EXPECT_FLOAT_EQ(s.slab_mm, 6.0f);
    // Saved again, the word comes back (through either grid's own axis).
    EXPECT_EQ(roiSetToSave(d, s, &permuted).slab->follow, view);
    loadRoiSetIntoState(set, d, s);  // no image: RAS order
    EXPECT_EQ(int(s.active_slice), ras_axis);
    EXPECT_EQ(roiSetToSave(d, s).slab->follow, view);
  }
  // A slab that follows nothing stops following.
  RoiSet plain;
  plain.slab = Slab{4.0f, ""};
  DissectionState d;
  RenderSettings s;
  s.slab_follows_slice = true;
  loadRoiSetIntoState(plain, d, s);
  EXPECT_FALSE(s.slab_follows_slice);
  EXPECT_EQ(roiSetToSave(d, s).slab->follow, "");
  EXPECT_EQ(anatomicalSliceAxis(ras, "oblique"), -1);
}

TEST(ViewerDissection, fiberScalarCommandsSetReplaceAndClearTheSetsRanges) {
  DissectionState d;
  RenderSettings s;
  const auto steps = parseScript("fiber-scalar fa 0.3 -\nfiber-scalar rgb[2] - 10\nfiber-scalar fa 0.4 0.9\n"
                                 "fiber-scalar-clear\n", "s");
  ASSERT_EQ(steps.size(), 4u);
  for (const auto& step : steps) edit(d, s, std::get<DissectionAction>(std::get<ViewerAction>(step.command)).edit);
  EXPECT_TRUE(d.set.scalar_ranges.empty());
  for (size_t i = 0; i < 3; ++i) edit(d, s, std::get<DissectionAction>(std::get<ViewerAction>(steps[i].command)).edit);
  ASSERT_EQ(d.set.scalar_ranges.size(), 2u) << "the second fa replaced the first";
  EXPECT_EQ(scalarRangeSpec(d.set.scalar_ranges[0].range), "fa:0.4:0.9");
  EXPECT_EQ(scalarRangeSpec(d.set.scalar_ranges[1].range), "rgb[2]::10");
  const FilterCriteria c = dissectionCriteria(d);
  ASSERT_EQ(c.scalar_ranges.size(), 2u);
  d.set.scalar_ranges[1].enabled = false;
  EXPECT_EQ(dissectionCriteria(d).scalar_ranges.size(), 1u);
  for (const char* bad : {"fiber-scalar fa x 1\n", "fiber-scalar fa 2 1\n", "fiber-scalar fa 1\n",
                          "fiber-scalar-clear now\n"}) {
    SCOPED_TRACE(bad);
    const std::string e = test::errorOf([&] { parseScript(bad, "s.txt"); });
    EXPECT_NE(e.find("s.txt:1: "), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  edit(d, s, FiberScalarClearEdit{});
  for (int i = 0; i < 16; ++i) edit(d, s, FiberScalarEdit{ScalarRange{"a" + std::to_string(i), 0, 0, 1}});
  EXPECT_THROW(edit(d, s, FiberScalarEdit{ScalarRange{"one-too-many", 0, 0, 1}}), Error);
}

}  // namespace
}  // namespace fibscope
