// Map files (ParseMapFile, then RestoreMap into a map with a keyframe database). The CRC-32 in
// the header stops almost every mutation before the decoder, so an input that does not start
// with the magic is taken as a payload and wrapped in a valid header: the cereal decoder, the
// length guards, Validate and RestoreMap see arbitrary bytes too.
#include <zlib.h>

#include "ademono/slam/map_io.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ademono;
  std::string bytes(reinterpret_cast<const char*>(data), size);
  if (bytes.compare(0, 8, std::string("ADEMAP\r\n", 8)) != 0) {
    const std::string payload = bytes;
    std::string header("ADEMAP\r\n", 8);
    auto put = [&header](uint64_t v, int n) {
      for (int i = 0; i < n; ++i) header.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
    };
    put(kMapFormatVersion, 4);
    put(payload.size(), 8);
    put(crc32(crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(payload.data()),
              static_cast<uInt>(payload.size())),
        4);
    bytes = header + payload;
  }
  fuzz::ExpectOnlyInputError([&] {
    const MapFileData map_data = ParseMapFile(bytes, "fuzz.map");
    KeyFrameDatabase database;
    Map map;
    map.SetKeyFrameDatabase(&database);
    MutexLock lock(map.mutex);
    RestoreMap(map_data, std::make_shared<ScalePyramid>(ScalePyramid::Make(8, 1.2f)), map, "fuzz.map");
    // The options text is parsed for the map's scale (map info, loading): never more than an
    // answer, whatever it holds.
    fuzz::g_sink = static_cast<double>(map.NumKeyFrames() + map.NumMapPoints()) +
                   (MapHasMetricScale(map_data) ? 1.0 : 0.0);
  });
  return 0;
}
