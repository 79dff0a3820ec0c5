// `fibscope bench` with the SVO streamtubes (issue 16 item 5): svo-straight
// and svo-curved as --compare entries beside a fiblet pipeline, each
// tracing its own octree of the --tubes fibers on the same frames, the
// build's sizes in the JSON; --voxel refused without an svo pipeline.
// Validation layers on; a coarse voxel keeps the build small.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "test_support.h"

namespace fibscope {
namespace {

class GpuCliBenchSvo : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto r = test::runFibscope("gpu-info");
    if (r.exit_code != 0) GTEST_SKIP() << "no usable Vulkan device: " << r.output;
  }
};

TEST_F(GpuCliBenchSvo, svoPipelinesTraceTheirOctreesOnTheSameFrames) {
  const auto r = test::runFibscope(
      "bench --validate --phantom-streamlines 30 --size 64x48 --frames 2 --warmup 0 --tubes 0-3 --tube-radius 1 "
      "--voxel 1 --compare compute/none,svo-straight,svo-curved --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  ASSERT_EQ(j["results"].size(), 3u);
  EXPECT_EQ(j["results"][0]["pipeline"], "compute/none tubes compute");  // --tubes: spline tubes there
  EXPECT_EQ(j["results"][1]["tube_method"], "svo-straight");
  EXPECT_EQ(j["results"][2]["tube_method"], "svo-curved");
  for (int i : {1, 2}) {
    EXPECT_TRUE(j["results"][i]["pass_mean_ms"].contains("svo trace")) << j["results"][i].dump();
    EXPECT_FALSE(j["results"][i]["pass_mean_ms"].contains("tube raycast")) << j["results"][i].dump();
  }
  for (const char* kind : {"svo-straight", "svo-curved"}) {
    EXPECT_GT(j["svo"][kind]["leaves"].get<uint64_t>(), 100u) << kind;
    EXPECT_EQ(j["svo"][kind]["node_bytes"].get<uint64_t>() % 8, 0u) << kind;  // 8-byte nodes
  }
  const auto bad = test::runFibscope("bench --phantom-streamlines 20 --size 32x24 --frames 1 --voxel 1");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("--voxel"), std::string::npos) << bad.output;
}

}  // namespace
}  // namespace fibscope
