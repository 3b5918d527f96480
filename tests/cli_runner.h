// Runs the ember binary as a user would, capturing its exit code and stderr.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace ember::test {

struct CliResult {
  int exitCode = -1;
  std::string output;  // stdout and stderr together
};

inline CliResult runEmber(const std::string& args) {
  const std::string log =
      (std::filesystem::temp_directory_path() / ("ember_cli_" + std::to_string(::getpid()) + ".log"))
          .string();
  const std::string cmd = std::string("'") + EMBER_BINARY + "' " + args + " >'" + log + "' 2>&1";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::ifstream in(log);
  std::stringstream ss;
  ss << in.rdbuf();
  r.output = ss.str();
  std::filesystem::remove(log);
  return r;
}

// A fresh empty folder under the system temp directory, removed by the destructor.
struct TempDir {
  std::filesystem::path path;
  TempDir() {
    static int counter = 0;
    path = std::filesystem::temp_directory_path() /
           ("ember_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
  std::string write(const std::string& name, const std::string& content) const {
    std::ofstream(file(name), std::ios::binary) << content;
    return file(name);
  }
};

}  // namespace ember::test
