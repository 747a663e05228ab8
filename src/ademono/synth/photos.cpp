#include "ademono/synth/photos.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "ademono/core/error.h"
#include "ademono/core/file_util.h"

namespace fs = std::filesystem;

namespace ademono::synth {

PhotoCutout CutOut(const cv::Mat& image, const cv::Rect& box_in) {
  const cv::Rect bounds(0, 0, image.cols, image.rows);
  const cv::Rect box = box_in & bounds;
  if (box.width < 4 || box.height < 4) throw std::invalid_argument("cut-out box too small");
  // Context around the box for GrabCut's background model.
  const int mx = box.width / 5 + 2, my = box.height / 10 + 2;
  const cv::Rect roi = cv::Rect(box.x - mx, box.y - my, box.width + 2 * mx, box.height + 2 * my) &
                       bounds;
  cv::Mat crop = image(roi).clone();
  cv::Rect rect(box.x - roi.x, box.y - roi.y, box.width, box.height);
  // GrabCut needs background pixels outside the rectangle: keep a one-pixel frame.
  rect &= cv::Rect(1, 1, crop.cols - 2, crop.rows - 2);
  cv::Mat mask(crop.size(), CV_8UC1, cv::Scalar(cv::GC_BGD));
  cv::Mat bgd, fgd;
  // GrabCut seeds its GMMs with k-means on cv::theRNG(): a fixed state makes it deterministic.
  const uint64_t saved = cv::theRNG().state;
  cv::theRNG().state = 0x5EED5EEDull;
  cv::grabCut(crop, mask, rect, bgd, fgd, 4, cv::GC_INIT_WITH_RECT);
  cv::theRNG().state = saved;
  cv::Mat fg = (mask == cv::GC_FGD) | (mask == cv::GC_PR_FGD);
  // The figure is the largest connected part; close small gaps in it.
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(fg, labels, stats, centroids, 8, CV_32S);
  int best = 0, best_area = 0;
  for (int i = 1; i < n; ++i) {
    if (stats.at<int>(i, cv::CC_STAT_AREA) > best_area) {
      best_area = stats.at<int>(i, cv::CC_STAT_AREA);
      best = i;
    }
  }
  cv::Mat alpha;
  if (best_area < rect.area() / 4) {
    alpha = cv::Mat::zeros(crop.size(), CV_8UC1);
    alpha(rect).setTo(255);
  } else {
    alpha = (labels == best);
    cv::morphologyEx(alpha, alpha, cv::MORPH_CLOSE,
                     cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(7, 7)));
  }
  const cv::Rect tight = cv::boundingRect(alpha);
  PhotoCutout cutout;
  cutout.bgr = crop(tight).clone();
  cutout.alpha = alpha(tight).clone();
  return cutout;
}

ActorPhotos LoadActorPhotos(const fs::path& dir) {
  if (!fs::is_directory(dir))
    ThrowInputError(dir, "actor photos folder not found (expected photos and "
                         "expected_detections.json, e.g. ../shared/images)");
  const fs::path json_path = dir / "expected_detections.json";
  RequireFile(json_path);
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(ReadTextFile(json_path));
  } catch (const nlohmann::json::exception& e) {
    ThrowInputError(json_path, std::string("invalid JSON: ") + e.what());
  }
  if (!json.contains("images") || !json["images"].is_object())
    ThrowInputError(json_path, "no \"images\" object");
  struct Candidate {
    std::string file;
    size_t index;
    int class_id;
    float score;
    cv::Rect box;
  };
  std::vector<Candidate> candidates;
  try {
    for (const auto& [file, entry] : json["images"].items()) {
      const auto& detections = entry.at("detections");
      for (size_t i = 0; i < detections.size(); ++i) {
        const auto& d = detections[i];
        const int class_id = d.at("class_id").get<int>();
        const float score = d.at("score").get<float>();
        const auto& b = d.at("box_xywh");
        const cv::Rect box(static_cast<int>(std::lround(b.at(0).get<double>())),
                           static_cast<int>(std::lround(b.at(1).get<double>())),
                           static_cast<int>(std::lround(b.at(2).get<double>())),
                           static_cast<int>(std::lround(b.at(3).get<double>())));
        const bool person = class_id == 0 && score >= 0.5f && box.height >= 100;
        const bool car = class_id == 2 && score >= 0.5f && box.width >= 60;
        const bool bus = class_id == 5 && score >= 0.5f && box.width >= 60;
        if (person || car || bus) candidates.push_back({file, i, class_id, score, box});
      }
    }
  } catch (const nlohmann::json::exception& e) {
    ThrowInputError(json_path, std::string("bad detection entry: ") + e.what());
  }
  // Surest first (a figure cut by the photo's border scores low); ties by name.
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) {
                     if (a.score != b.score) return a.score > b.score;
                     return std::tie(a.file, a.index) < std::tie(b.file, b.index);
                   });
  ActorPhotos photos;
  std::map<std::string, cv::Mat> images;
  for (const Candidate& c : candidates) {
    cv::Mat& image = images[c.file];
    if (image.empty()) image = ReadImage(dir / c.file, cv::IMREAD_COLOR);
    const cv::Rect inside = c.box & cv::Rect(0, 0, image.cols, image.rows);
    if (inside.width < 8 || inside.height < 8) continue;
    PhotoCutout cutout = CutOut(image, inside);
    cutout.source = c.file + "#" + std::to_string(c.index + 1);
    cutout.score = c.score;
    (c.class_id == 0 ? photos.persons : c.class_id == 2 ? photos.cars : photos.buses)
        .push_back(std::move(cutout));
  }
  if (photos.persons.empty())
    ThrowInputError(json_path, "no person box to cut out (score >= 0.5, >= 100 px tall)");
  if (photos.cars.empty())
    ThrowInputError(json_path, "no car box to cut out (score >= 0.5, >= 60 px wide)");
  return photos;
}

}  // namespace ademono::synth
