// fibscope command line: wires the subcommands together.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "app/commands.h"
#include "core/error.h"
#include "core/interrupt_cleanup.h"

int main(int argc, char** argv) {
  // Before any thread: an interrupted command removes its temporary outputs.
  fibscope::installInterruptCleanup();
  CLI::App app{"fibscope: real-time whole-brain tractogram viewer and tools"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "fibscope 0.1.0");
  fibscope::addInfoCommand(app);
  fibscope::addConvertCommand(app);
  fibscope::addFilterCommand(app);
  fibscope::addPhantomCommand(app);
  fibscope::addCompressCommand(app);
  fibscope::addDecompressCommand(app);
  fibscope::addGpuInfoCommand(app);
  fibscope::addRenderCommand(app);
  fibscope::addBenchCommand(app);
  fibscope::addViewCommand(app);
  fibscope::addBundleCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  } catch (const fibscope::Error& e) {
    std::fprintf(stderr, "fibscope: error: %s\n", e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "fibscope: error: out of memory\n");
    return 2;
  }
  return 0;
}
