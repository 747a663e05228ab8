#pragma once
// Two-view monocular initialisation (ORB-SLAM's Initializer): from pixel matches between two
// frames of one calibrated camera, a homography and a fundamental matrix are estimated by RANSAC
// on the same minimal sets, each scored by its symmetric transfer error, and the model is chosen
// by the ratio of scores R_H = S_H / (S_H + S_F) (planar or low-parallax scenes: homography;
// general scenes: fundamental). The chosen model is decomposed into its motion hypotheses (8
// for H as Faugeras, 4 for F through the essential matrix) and the one that triangulates most
// matches in front of both cameras with enough parallax wins, if it wins clearly.
//
// The result is up to scale: |t| = 1. Deterministic for a given seed.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ademono/core/geometry.h"

namespace ademono {

template <typename Options>
class OptionsTable;

struct TwoViewOptions {
  // ORB-SLAM's 200 left seq-a uninitialised on some draws (configs/network_indoor.yaml).
  int ransac_iterations = 1000;
  double sigma_px = 1.0;  // keypoint position sigma at level 0 (chi2 thresholds scale with it)
  // R_H above this: the homography (ORB-SLAM2: 0.40).
  double homography_ratio = 0.40;
  double min_parallax_deg = 1.0;  // of the reconstruction (its 50th-smallest parallax)
  int min_triangulated = 50;      // matches triangulated by the winning hypothesis
  // The winning hypothesis must triangulate at least this share of the model's inliers.
  double min_triangulated_ratio = 0.9;
  // The map is made only when the translation's direction is known to within this standard
  // deviation (TranslationDirectionSigmaDeg, after the two views' bundle adjustment): beyond
  // ORB-SLAM's parallax test, which low-parallax views with a narrow field pass with a wrong
  // motion (7-Scenes seq-a frames 0-20: 1 deg of parallax, sigma 6 deg, the direction 108 deg off).
  double max_direction_sigma_deg = 2.0;
  // RANSAC's minimal sets (`run --seed` sets it with filter.seed): without depth it is the only
  // draw in a run, so it is what re-draws a geometric-only run.
  uint64_t seed = 0;
  // The homography's and the fundamental's RANSAC on two threads (ORB-SLAM's): the same result as
  // one after the other, in about half the time while the map does not yet exist.
  bool parallel = true;
  void Check() const;  // throws std::invalid_argument
  static const OptionsTable<TwoViewOptions>& Table();
  bool operator==(const TwoViewOptions&) const = default;
};

enum class TwoViewModel { kNone, kHomography, kFundamental };
const char* TwoViewModelName(TwoViewModel model);  // "none" | "homography" | "fundamental"

struct TwoViewResult {
  bool valid = false;
  std::string failure;  // why not, when !valid
  TwoViewModel model = TwoViewModel::kNone;
  double score_homography = 0, score_fundamental = 0;
  double homography_ratio = 0;          // S_H / (S_H + S_F)
  Eigen::Matrix3d H21 = Eigen::Matrix3d::Zero();  // x2 ~ H21 x1 (pixels)
  Eigen::Matrix3d F21 = Eigen::Matrix3d::Zero();  // x2^T F21 x1 = 0 (pixels)
  Rigid3d cam2_from_cam1 = Rigid3d::Identity();   // |translation| = 1
  // Per match: triangulated (in front of both cameras, parallax, reprojection) and its position
  // in camera 1's frame (zero otherwise).
  std::vector<uint8_t> triangulated;
  std::vector<Eigen::Vector3d> points_cam1;
  int num_triangulated = 0;
  double parallax_deg = 0;  // the reconstruction's parallax (the 50th-smallest, as ORB-SLAM)
};

// `pixels1[i]` in view 1 matches `pixels2[i]` in view 2 (undistorted pixels); `K` the camera
// matrix of both views. Needs at least 8 matches.
TwoViewResult InitializeTwoView(const Eigen::Matrix3d& K,
                                const std::vector<Eigen::Vector2d>& pixels1,
                                const std::vector<Eigen::Vector2d>& pixels2,
                                const TwoViewOptions& options = {});

// How well two views fix the direction of their translation: the standard deviation (degrees)
// of the translation's direction, the largest over its two degrees of freedom, from the
// reprojection residuals' information (keypoint sigma `sigma_px`) with every point marginalised
// (the Schur complement of the two-view bundle adjustment at this solution). Small parallax
// against a narrow field of view leaves rotation and translation interchangeable (the
// bas-relief ambiguity): this number then grows, while the parallax and the count of triangulated
// points may still look fine. `points_cam1` in camera 1's frame, observed at `pixels1`/`pixels2`.
double TranslationDirectionSigmaDeg(const Eigen::Matrix3d& K, const Rigid3d& cam2_from_cam1,
                                    const std::vector<Eigen::Vector3d>& points_cam1,
                                    const std::vector<Eigen::Vector2d>& pixels1,
                                    const std::vector<Eigen::Vector2d>& pixels2,
                                    double sigma_px = 1.0);

// The model estimators, exposed for tests: normalised DLT from >= 4 (H) or >= 8 (F, rank 2
// enforced) matches, in pixels.
Eigen::Matrix3d HomographyDlt(const std::vector<Eigen::Vector2d>& pixels1,
                              const std::vector<Eigen::Vector2d>& pixels2);
Eigen::Matrix3d FundamentalEightPoint(const std::vector<Eigen::Vector2d>& pixels1,
                                      const std::vector<Eigen::Vector2d>& pixels2);

}  // namespace ademono
