// `fibscope bundle IN OUT`: GPU fiber bundling (FiberVisualizer section 7,
// src/bundling) of any supported tractogram, written in the format of OUT's
// extension (.tck .trk .trx; .fbl through the compressor) with the input's
// fibers, offsets and data arrays; --report prints the displacement and
// ink figures.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <string>

#include "app/bundle_output.h"
#include "app/commands.h"
#include "app/open_input.h"
#include "bundling/bundle_params.h"
#include "bundling/bundle_quality.h"
#include "bundling/bundle_setup.h"
#include "bundling/gpu/gpu_bundler.h"
#include "codec/compressor.h"
#include "core/error.h"
#include "core/output_file.h"
#include "core/progress.h"
#include "gpu/vulkan_context.h"
#include "io/reader.h"
#include "io/writer.h"

namespace fibscope {

void addBundleCommand(CLI::App& app) {
  struct Options {
    std::string input, output, mode = "isotropic", device;
    bool force = false, report = false;
    BundleParams params;
  };
  auto opt = std::make_shared<Options>();
  BundleParams& p = opt->params;
  CLI::App* cmd = app.add_subcommand("bundle", "Bundle fibers on the GPU (density, constrained advection, smoothing)");
  cmd->add_option("input", opt->input, "Input tractogram (.tck .trk .trk.gz .tt.gz .trx .vtk .vtp .fbl)")->required();
  cmd->add_option("output", opt->output, "Output tractogram (.tck .trk .trx .fbl)")->required();
  cmd->add_option("--radius", p.radius, "Kernel radius R of the first iteration, voxels")->capture_default_str();
  cmd->add_option("--iterations", p.iterations, "Iterations")->capture_default_str();
  cmd->add_option("--radius-decay", p.radius_decay, "R is multiplied by this after each iteration")
      ->capture_default_str();
  cmd->add_option("--voxel", p.voxel_mm, "Voxel size, mm (default: 0.003 of the box's largest side)");
  cmd->add_option("--step", p.step_mm, "Resampling interval, mm (default: 0.01 of the box's z extent)");
  cmd->add_option("--smoothing", p.smoothing, "Smoothing weight phi")->capture_default_str();
  cmd->add_option("--smoothing-length", p.smoothing_length, "Smoothing window L, multiples of R")
      ->capture_default_str();
  cmd->add_option("--relaxation", p.relaxation, "Relaxation alpha (1: fully bundled, 0: original)")
      ->capture_default_str();
  cmd->add_option("--advection", p.advection, "Advection step, multiples of R")->capture_default_str();
  cmd->add_flag("--anchor-ends", p.anchor_ends, "Keep the fibers' end points where they are");
  cmd->add_option("--anisotropy", p.anisotropy, "Anisotropic mode: kernel radius across the fiber / along it")
      ->capture_default_str();
  cmd->add_flag("--structure-aware", p.structure_aware,
                "Filter the advection by the density's structure tensor, so sheets contract across, not into strands");
  cmd->add_option("--structure-power", p.structure_power, "Structure-aware: the filter's power (1-8)")
      ->capture_default_str();
  cmd->add_option("--structure-scale", p.structure_scale, "Structure-aware: the tensor's cells, multiples of R")
      ->capture_default_str();
  cmd->add_option("--mode", opt->mode, "isotropic (the paper's) or anisotropic (a kernel elongated along each fiber)")
      ->check(CLI::IsMember({"isotropic", "anisotropic"}))
      ->capture_default_str();
  cmd->add_option("--device", opt->device, "Vulkan device whose name contains this");
  cmd->add_flag("--report", opt->report, "Print the displacement, ink, memory and GPU time per pass");
  cmd->add_flag("--force,-f", opt->force, "Overwrite the output if it exists");
  cmd->callback([opt] {
    // Refuse before reading anything: bad parameters, an existing output.
    BundleParams params = opt->params;
    params.mode = parseBundleMode(opt->mode);
    validateBundleParams(params);
    checkOverwrite(opt->output, opt->force);
    checkBundledOutputPath(opt->output);  // the writer's own extension check, before the long part

    const auto start = std::chrono::steady_clock::now();
    auto reader = openInput(opt->input);
    const TractogramHeader header = reader->header();
    const Tractogram model = readAllStreamlines(*reader);
    for (const auto& w : reader->warnings()) std::fprintf(stderr, "fibscope: warning: %s\n", w.c_str());
    BundleSetup setup;
    try {
      setup = planBundling(model, params);
    } catch (const Error& e) {
      fail(opt->input, e.what());
    }

    gpu::ContextOptions context_options;
    context_options.device_name = opt->device;
    const gpu::VulkanContext context(context_options);
    Progress progress("bundling", double(params.iterations), "iterations");
    GpuBundler bundler(context);
    bundler.load(model, setup, params);
    for (uint32_t it = 0; it < params.iterations; ++it) {
      bundler.iterate(bundleRadius(params, it));
      progress.set(double(it + 1));
    }
    Tractogram bundled = model;
    bundled.positions = bundler.finish(model);
    progress.finish();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    for (const auto& w : writeBundledTractogram(opt->output, bundled, header, opt->force))
      std::fprintf(stderr, "fibscope: warning: %s\n", w.c_str());
    const BundleDisplacement d = bundleDisplacement(model, bundled.positions);
    std::printf(
        "wrote %s: %zu fibers, %zu points (%u samples, grid %u x %u x %u of %.4g mm); displacement mean %.3f mm, "
        "max %.3f mm; %.2f s\n",
        opt->output.c_str(), bundled.streamlineCount(), bundled.pointCount(), setup.sampleCount(), setup.grid.size.x,
        setup.grid.size.y, setup.grid.size.z, setup.grid.voxel, d.mean_mm, d.max_mm, seconds);
    if (!opt->report) return;
    const Camera camera = bundleInkCamera(model);
    const uint64_t ink_before = bundleInk(model, camera), ink_after = bundleInk(bundled, camera);
    std::printf("  device      %s\n", context.info().name.c_str());
    std::printf(
        "  parameters  mode %s, R %.4g voxels (%.4g mm) x %.4g per iteration, %u iterations, step %.4g mm, "
        "phi %.3g, L %.3g R, alpha %.3g, advection %.3g R%s\n",
        bundleModeName(params.mode), params.radius, params.radius * setup.grid.voxel, params.radius_decay,
        params.iterations, setup.step_mm, params.smoothing, params.smoothing_length, params.relaxation,
        params.advection, params.anchor_ends ? ", ends anchored" : "");
    if (params.mode == BundleMode::Anisotropic)
      std::printf("  anisotropy  %.3g (kernel radius across / along)\n", params.anisotropy);
    if (params.structure_aware)
      std::printf("  structure   aware: power %u, cells of %u voxels\n", params.structure_power,
                  bundleStructureCell(params));
    std::printf("  ink         %llu -> %llu px (%.1f%%) in a %u x %u coronal view\n",
                static_cast<unsigned long long>(ink_before), static_cast<unsigned long long>(ink_after),
                ink_before ? 100.0 * double(ink_after) / double(ink_before) : 0.0, camera.width, camera.height);
    std::printf("  memory      %s on the device\n", formatBytes(double(bundler.bytes())).c_str());
    double total_ms = 0;
    for (const gpu::PassTime& t : bundler.passTimes()) total_ms += t.ms;
    std::printf("  gpu time    %.2f ms in all:", total_ms);
    for (const gpu::PassTime& t : bundler.passTimes()) std::printf(" %s %.2f;", t.name.c_str(), t.ms);
    std::printf("\n");
  });
}

}  // namespace fibscope
