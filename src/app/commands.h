// The `fibscope` subcommands. Each add*Command registers its options on the
// parent CLI11 app and a callback that does the work; errors propagate as
// fibscope::Error and main() turns them into one line and exit code 2.
#pragma once

namespace CLI {
class App;
}

namespace fibscope {

void addInfoCommand(CLI::App& app);
void addConvertCommand(CLI::App& app);
void addFilterCommand(CLI::App& app);
void addPhantomCommand(CLI::App& app);
void addDecompressCommand(CLI::App& app);
void addCompressCommand(CLI::App& app);
void addGpuInfoCommand(CLI::App& app);
void addRenderCommand(CLI::App& app);
void addBenchCommand(CLI::App& app);
void addViewCommand(CLI::App& app);
void addBundleCommand(CLI::App& app);

}  // namespace fibscope
