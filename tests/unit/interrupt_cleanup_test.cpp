// An interrupted command leaves nothing beside its target
// (core/interrupt_cleanup.h): the registry's removal on its own, and
// `convert` and `compress` stopped by SIGINT / SIGTERM while they write.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "core/interrupt_cleanup.h"
#include "test_support.h"

extern char** environ;

namespace fibscope {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> namesIn(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(InterruptCleanup, removesRegisteredFilesDirectoriesAndTheirLibrariesTemporaries) {
  test::TempDir dir;
  const std::string file = dir.file(".out.tck.tmp-1-0"), folder = dir.file(".out.trx.tmpdir-1-0");
  const std::string zip = dir.file(".out.trx.tmp-1-1");
  test::writeBytes(file, "partial");
  fs::create_directories(folder + "/dps");
  test::writeBytes(folder + "/dps/weight.float32", "1234");
  test::writeBytes(zip + ".AbC123", "libzip's own temporary");
  test::writeBytes(dir.file("kept.tck"), "not registered");
  registerTemporaryPath(file);
  registerTemporaryPath(folder);
  registerTemporaryPath(zip);
  registerTemporaryPath(dir.file("gone-already"));
  unregisterTemporaryPath(dir.file("gone-already"));
  EXPECT_EQ(removeTemporaryPathsForInterrupt(), 2u);  // the zip itself never existed
  EXPECT_EQ(namesIn(dir.path()), std::vector<std::string>{"kept.tck"});
  EXPECT_EQ(removeTemporaryPathsForInterrupt(), 0u) << "the list is emptied";
}

// Starts fibscope with `args`, waits until a temporary output appears in
// `dir` (a name starting with '.'), sends `sig`, and returns the wait
// status; -1 when the command ended before a temporary was seen.
int interruptWhileWriting(const std::vector<std::string>& args, const std::string& dir, int sig) {
  std::vector<std::string> argv_strings = {FIBSCOPE_EXE};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_strings) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawn(&pid, FIBSCOPE_EXE, nullptr, nullptr, argv.data(), environ) != 0) return -2;
  int status = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    if (waitpid(pid, &status, WNOHANG) == pid) return -1;
    bool writing = false;
    for (const std::string& name : namesIn(dir)) writing |= name.front() == '.';
    if (writing) {
      kill(pid, sig);
      waitpid(pid, &status, 0);
      return status;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  kill(pid, SIGKILL);
  waitpid(pid, &status, 0);
  return -3;
}

TEST(InterruptCleanup, anInterruptedConvertOrCompressLeavesNothingBesideTheTarget) {
  test::TempDir in_dir;
  // Large enough that writing takes a while (tens of MB at 0.2 mm steps).
  const std::string input = in_dir.file("in.tck");
  ASSERT_EQ(test::runFibscope("phantom " + input + " -n 4000 --step 0.2 --seed 3").exit_code, 0);
  struct Case {
    std::vector<std::string> args;  // the output goes to "out_dir/" + output
    std::string output;
    int sig;
  };
  const std::vector<Case> cases = {{{"convert"}, "out.trk", SIGINT},
                                   {{"convert"}, "out.trx", SIGTERM},
                                   {{"convert", "--trx-directory"}, "out.trx", SIGINT},
                                   {{"compress"}, "out.fbl", SIGTERM}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args[0] + " -> " + c.output);
    test::TempDir out_dir;
    std::vector<std::string> args = c.args;
    args.insert(args.begin() + 1, input);
    args.insert(args.begin() + 2, out_dir.file(c.output));
    const int status = interruptWhileWriting(args, out_dir.path(), c.sig);
    ASSERT_GE(status, 0) << (status == -1 ? "finished before a temporary output was seen" : "could not run it");
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == c.sig) << "status " << status;
    EXPECT_TRUE(namesIn(out_dir.path()).empty()) << namesIn(out_dir.path()).front();
  }
}

}  // namespace
}  // namespace fibscope
