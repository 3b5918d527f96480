// ember: command-line front end. Subcommands live in one file each (render, tonemap, info, bench, compare,
// merge, denoise).
#include "app/commands.h"

#include "io/input_error.h"

#include <cstdio>
#include <map>

int main(int argc, char** argv) {
  CLI::App app{
      "Ember: a physically based path tracer on Embree.\n"
      "Renders analytic JSON scenes and glTF 2.0 files to linear float EXR."};
  app.set_version_flag("--version", std::string("ember ") + EMBER_VERSION);
  app.require_subcommand(1);
  std::map<CLI::App*, ember::cli::Runner> runners;
  for (auto add : {ember::cli::addRenderCommand, ember::cli::addTonemapCommand, ember::cli::addInfoCommand,
                   ember::cli::addBenchCommand, ember::cli::addCompareCommand, ember::cli::addMergeCommand,
                   ember::cli::addDenoiseCommand}) {
    const size_t before = app.get_subcommands({}).size();
    ember::cli::Runner run = add(app);
    runners[app.get_subcommands({})[before]] = std::move(run);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; any bad argument exits 2, as for bad input to `compare`.
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  try {
    for (auto& [sub, run] : runners)
      if (sub->parsed()) return run();
  } catch (const ember::InputError& e) {
    std::fprintf(stderr, "ember: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ember: error: %s\n", e.what());
    return 1;
  }
  return 1;
}
