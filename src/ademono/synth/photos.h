#pragma once
// Actor photos: cut-outs of the persons and cars in real photographs, for synthetic actors a
// real detector can see. The folder holds the photos and `expected_detections.json` (the layout
// `ademono detect --json` writes, e.g. ../shared/images): every person / car box above a score
// and size becomes a cut-out, segmented from its box with GrabCut (the photo's pixels, an alpha
// mask of the figure, cropped to the mask). Nothing of the photos is stored in the repository:
// the folder is read at run time.

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace ademono::synth {

struct PhotoCutout {
  cv::Mat bgr;         // CV_8UC3, the photo's pixels in the cut-out's bounding box
  cv::Mat alpha;       // CV_8UC1, 255 on the figure, 0 elsewhere
  std::string source;  // "bus.jpg#1": photo file and index of the detection in its list
  float score = 0.f;   // the reference detector's score
};

struct ActorPhotos {
  std::vector<PhotoCutout> persons;  // highest reference score first
  std::vector<PhotoCutout> cars;     // highest reference score first
  std::vector<PhotoCutout> buses;    // highest reference score first; may be empty
};

// Reads `dir`/expected_detections.json and the photos it names. Persons need a score >= 0.5 and
// a box at least 100 px tall, cars and buses a score >= 0.5 and 60 px wide (buses are optional:
// the street's crossing vehicle falls back to a car). Throws InputError (one line
// naming the file) when the folder, the JSON or a photo is missing or bad, or when no person or
// no car qualifies. Deterministic (GrabCut's k-means is seeded).
ActorPhotos LoadActorPhotos(const std::filesystem::path& dir);

// The cut-out of the box `box` of `image`: GrabCut initialised with the box, the largest
// connected component, closed; the whole box when the segmentation keeps under a quarter of it.
PhotoCutout CutOut(const cv::Mat& image, const cv::Rect& box);

}  // namespace ademono::synth
