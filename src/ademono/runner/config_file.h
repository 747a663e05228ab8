#pragma once
// A run's config file with its `--set SECTION.KEY=VALUE` overrides applied, before the strict
// option readers see it: shared by `ademono run` / `ablate` (apps/ademono/run_options) and by
// `ademono batch`, which checks each variant's overrides before it starts anything.

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <string>
#include <vector>

namespace ademono {

// The YAML of `path` (an empty node for an empty path); InputError naming the file when invalid.
// `overrides` ("section.key=value", value in YAML) replace keys of the file; InputError naming the
// override when one is malformed.
YAML::Node LoadConfigWithOverrides(const std::filesystem::path& path,
                                   const std::vector<std::string>& overrides = {});

}  // namespace ademono
