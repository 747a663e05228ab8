// `ademono map info FILE`: what a saved map holds (slam/map_io.h, docs/maps.md).
#include <filesystem>
#include <iostream>

#include "ademono/core/error.h"
#include "ademono/slam/map_io.h"
#include "command.h"

namespace ademono::cli {
namespace {

struct MapArgs {
  std::string file;
  CLI::App* info = nullptr;
};

int Run(const MapArgs& args) {
  if (args.info == nullptr || !args.info->parsed())
    throw InputError("map: a subcommand is required (info)");
  const MapFileData data = LoadMapFile(args.file);
  const uint64_t size = std::filesystem::file_size(args.file);
  std::cout << MapSummaryText(args.file, SummarizeMap(data, size));
  return 0;
}

const bool kRegistered = RegisterCommand(
    "map", "Inspect a saved map (`map info FILE`)", [](CLI::App& app) -> Runner {
      auto args = std::make_shared<MapArgs>();
      args->info =
          app.add_subcommand("info", "print the version, camera, sizes and options of a map");
      args->info->add_option("file", args->file, "map file (ademono run --save-map)")->required();
      app.require_subcommand(1);
      return [args] { return Run(*args); };
    });

}  // namespace
}  // namespace ademono::cli
