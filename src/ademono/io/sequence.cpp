#include "ademono/io/sequence.h"

#include "ademono/core/error.h"
#include "ademono/io/file_sequence.h"

namespace fs = std::filesystem;

namespace ademono {

std::unique_ptr<Sequence> OpenSequence(const std::string& spec,
                                       const std::optional<fs::path>& camera_yaml) {
  const size_t colon = spec.find(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == spec.size()) {
    throw InputError("sequence '" + spec +
                     "': expected KIND:PATH with KIND one of tum, kitti, euroc, 7scenes, folder, "
                     "video, camera");
  }
  const std::string kind = spec.substr(0, colon);
  const fs::path path = spec.substr(colon + 1);
  if (camera_yaml) RequireFile(*camera_yaml);
  if (kind == "7scenes") return OpenSevenScenes(path, camera_yaml);
  if (kind == "tum") return OpenTum(path, camera_yaml);
  if (kind == "kitti") return OpenKitti(path, camera_yaml);
  if (kind == "euroc") return OpenEuroc(path, camera_yaml);
  if (kind == "folder") return OpenImageFolder(path, camera_yaml);
  if (kind == "video") return OpenVideo(path, camera_yaml);
  if (kind == "camera") return OpenCamera(path.string(), camera_yaml);
  throw InputError("sequence '" + spec + "': unknown kind '" + kind +
                   "' (expected tum, kitti, euroc, 7scenes, folder, video or camera)");
}

}  // namespace ademono
