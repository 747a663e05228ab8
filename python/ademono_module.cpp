// The Python module `ademono`: sequences, the SLAM system, depth models and detectors, trajectory
// evaluation and synthetic sequences, over numpy arrays. See docs/python.md.
//
// Images are numpy uint8 arrays HxWx3 in BGR order (as cv2 reads them) or HxW grey; depth maps
// float32 HxW in metres (0 = invalid); poses 4x4 float64 matrices. Every array is copied in and
// out, so Python never sees memory the library may free. InputError (bad file, bad input) becomes
// ademono.InputError with the same one-line message; other bad arguments raise ValueError. Long
// calls (tracking, inference, evaluation, rendering) release the GIL.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <yaml-cpp/yaml.h>

#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ademono/core/camera.h"
#include "ademono/core/error.h"
#include "ademono/depth/onnx_depth.h"
#include "ademono/depth/sensor_depth.h"
#include "ademono/detect/detection_io.h"
#include "ademono/detect/detector_factory.h"
#include "ademono/detect/yolo_detector.h"
#include "ademono/eval/trajectory_eval.h"
#include "ademono/io/sequence.h"
#include "ademono/io/trajectory.h"
#include "ademono/live/live_server.h"
#include "ademono/runner/live_feed.h"
#include "ademono/slam/system.h"
#include "ademono/synth/camera_motion.h"
#include "ademono/synth/generator.h"

namespace py = pybind11;
namespace fs = std::filesystem;

namespace ademono {
namespace {

// ---- numpy <-> cv::Mat / Eigen (copies) ----

py::array MatToArray(const cv::Mat& mat) {
  if (mat.empty()) return py::array();
  const cv::Mat m = mat.isContinuous() ? mat : mat.clone();
  std::vector<py::ssize_t> shape{m.rows, m.cols};
  if (m.channels() > 1) shape.push_back(m.channels());
  switch (m.depth()) {
    case CV_8U: {
      py::array_t<uint8_t> out(shape);
      std::memcpy(out.mutable_data(), m.data, m.total() * m.elemSize());
      return out;
    }
    case CV_32F: {
      py::array_t<float> out(shape);
      std::memcpy(out.mutable_data(), m.data, m.total() * m.elemSize());
      return out;
    }
    case CV_32S: {
      py::array_t<int32_t> out(shape);
      std::memcpy(out.mutable_data(), m.data, m.total() * m.elemSize());
      return out;
    }
    default:
      throw std::invalid_argument("unsupported image type");
  }
}

// uint8 HxW or HxWx3 (BGR) -> CV_8UC1 / CV_8UC3.
cv::Mat ImageFromArray(const py::array& array, const char* what) {
  const auto a = py::array_t<uint8_t, py::array::c_style>::ensure(array);
  if (!a || !(a.ndim() == 2 || (a.ndim() == 3 && (a.shape(2) == 3 || a.shape(2) == 1))) ||
      a.shape(0) == 0 || a.shape(1) == 0) {
    throw std::invalid_argument(std::string(what) +
                                ": expected a uint8 array of shape (H, W) or (H, W, 3), BGR");
  }
  const int channels = a.ndim() == 3 ? static_cast<int>(a.shape(2)) : 1;
  cv::Mat mat(static_cast<int>(a.shape(0)), static_cast<int>(a.shape(1)), CV_8UC(channels));
  std::memcpy(mat.data, a.data(), mat.total() * mat.elemSize());
  return mat;
}

// float HxW metres -> CV_32FC1.
cv::Mat DepthFromArray(const py::array& array) {
  const auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!a || a.ndim() != 2) {
    throw std::invalid_argument("depth: expected a float array of shape (H, W) in metres");
  }
  cv::Mat mat(static_cast<int>(a.shape(0)), static_cast<int>(a.shape(1)), CV_32FC1);
  std::memcpy(mat.data, a.data(), mat.total() * mat.elemSize());
  return mat;
}

py::array_t<double> Matrix4ToArray(const Eigen::Matrix4d& m) {
  py::array_t<double> out({4, 4});
  auto r = out.mutable_unchecked<2>();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r(i, j) = m(i, j);
  return out;
}

py::object PoseOrNone(const std::optional<Rigid3d>& pose) {
  if (!pose) return py::none();
  return Matrix4ToArray(pose->matrix());
}

// (N, 4, 4) array of poses.
py::array_t<double> PosesToArray(const std::vector<Eigen::Matrix4d>& poses) {
  py::array_t<double> out({static_cast<py::ssize_t>(poses.size()), py::ssize_t{4}, py::ssize_t{4}});
  auto r = out.mutable_unchecked<3>();
  for (size_t k = 0; k < poses.size(); ++k)
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) r(static_cast<py::ssize_t>(k), i, j) = poses[k](i, j);
  return out;
}

std::vector<Eigen::Matrix4d> PosesFromArray(const py::handle& array, const char* what) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!a || a.ndim() != 3 || a.shape(1) != 4 || a.shape(2) != 4) {
    throw std::invalid_argument(std::string(what) + ": expected poses of shape (N, 4, 4)");
  }
  std::vector<Eigen::Matrix4d> poses(static_cast<size_t>(a.shape(0)));
  auto r = a.unchecked<3>();
  for (size_t k = 0; k < poses.size(); ++k) {
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        const double v = r(static_cast<py::ssize_t>(k), i, j);
        if (!std::isfinite(v)) {
          throw std::invalid_argument(std::string(what) + ": pose " + std::to_string(k) +
                                      " is not finite");
        }
        poses[k](i, j) = v;
      }
  }
  return poses;
}

py::tuple SeriesToTuple(const PoseSeries& s) {
  return py::make_tuple(
      py::array_t<double>(static_cast<py::ssize_t>(s.timestamps.size()), s.timestamps.data()),
      PosesToArray(s.world_from_cam));
}

py::tuple TrajectoryToTuple(const Trajectory& t) { return SeriesToTuple(ToPoseSeries(t)); }

py::object JsonToPython(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

// ---- sequences ----

struct PyFrame {
  size_t index = 0;
  double timestamp = 0;
  std::string name;
  py::object image, depth, gt_pose;
};

PyFrame ToPyFrame(const FrameData& f) {
  PyFrame p;
  p.index = f.index;
  p.timestamp = f.timestamp;
  p.name = f.name;
  p.image = MatToArray(f.image);
  p.depth = f.depth.empty() ? py::object(py::none()) : py::object(MatToArray(f.depth));
  p.gt_pose = PoseOrNone(f.world_from_cam_gt);
  return p;
}

class PySequence {
 public:
  PySequence(const std::string& spec, const std::optional<fs::path>& camera_yaml)
      : sequence_(OpenSequence(spec, camera_yaml)) {}
  size_t Size() const { return sequence_->Size(); }
  PyFrame Get(py::ssize_t i) const {
    const auto n = static_cast<py::ssize_t>(sequence_->Size());
    if (i < 0) i += n;
    if (i < 0 || i >= n) throw py::index_error("frame index out of range");
    FrameData frame;
    {
      py::gil_scoped_release release;
      frame = sequence_->Load(static_cast<size_t>(i));
    }
    return ToPyFrame(frame);
  }
  const Sequence& Get() const { return *sequence_; }

 private:
  std::unique_ptr<Sequence> sequence_;
};

// ---- the SLAM system ----


struct PyTrackResult {
  size_t index = 0;
  bool tracked = false;
  py::object cam_from_world;
  std::string state;
  bool new_keyframe = false;
  int num_keypoints = 0, num_kept = 0, num_with_depth = 0, inliers = 0;
  double depth_scale = 1.0;
  std::optional<double> scale_sigma;
  py::object keypoints;  // (N, 2) float32 pixel positions of all extracted keypoints
};

// The YAML of a config: a file path, a dict (converted through JSON, which YAML reads), or None
// for the built-in defaults.
std::pair<YAML::Node, fs::path> ConfigNode(const py::object& config) {
  if (config.is_none()) return {YAML::Node(), fs::path()};
  if (py::isinstance<py::dict>(config)) {
    const std::string text = py::module_::import("json").attr("dumps")(config).cast<std::string>();
    try {
      return {YAML::Load(text), fs::path("<config dict>")};
    } catch (const YAML::Exception& e) {
      throw InputError(std::string("<config dict>: ") + e.msg);
    }
  }
  const fs::path path = py::str(config).cast<std::string>();
  RequireFile(path);
  try {
    return {YAML::LoadFile(path.string()), path};
  } catch (const YAML::Exception& e) {
    ThrowInputError(path, std::string("invalid YAML: ") + e.msg);
  }
}

class PySystem {
 public:
  PySystem(const py::object& config, const Camera& camera, std::optional<uint64_t> seed,
           const std::optional<std::string>& live) {
    camera.Check();
    const auto [node, path] = ConfigNode(config);
    SystemOptions options = SystemOptions::FromYaml(node, path);
    if (seed) options.SetSeed(*seed);
    camera_ = camera;
    system_ = std::make_unique<System>(camera, options);
    if (live) {
      // The live view of `ademono run --live` (docs/live.md), fed after every track().
      live_ = std::make_unique<live::LiveServer>(live::ParseLiveAddress(*live));
      feed_ = std::make_unique<LiveFeed>(live_.get());
    }
  }
  ~PySystem() {
    if (live_) {
      py::gil_scoped_release release;
      live_->Stop();
    }
  }
  PySystem(const PySystem&) = delete;
  PySystem& operator=(const PySystem&) = delete;

  PyTrackResult Track(const py::array& image, const std::optional<py::array>& depth,
                      std::optional<double> timestamp,
                      const std::optional<std::vector<Detection>>& detections) {
    FrameData frame;
    frame.index = next_index_;
    frame.timestamp = timestamp ? *timestamp : static_cast<double>(next_index_);
    frame.name = "frame-" + std::to_string(next_index_);
    frame.image = ImageFromArray(image, "image");
    if (frame.image.cols != camera_.width || frame.image.rows != camera_.height) {
      throw InputError("image size " + std::to_string(frame.image.cols) + "x" +
                       std::to_string(frame.image.rows) + " differs from the camera's " +
                       std::to_string(camera_.width) + "x" + std::to_string(camera_.height));
    }
    cv::Mat depth_m;
    if (depth) {
      frame.depth = DepthFromArray(*depth);
      // Exactly what `ademono run --depth sensor` feeds the tracker (size check, invalid -> 0).
      SensorDepthProvider sensor(nullptr);
      depth_m = sensor.Depth(frame, camera_);
    }
    const std::vector<Detection> boxes = detections.value_or(std::vector<Detection>{});
    TrackResult r;
    {
      py::gil_scoped_release release;
      r = system_->TrackFrame(frame, depth_m, boxes);
      if (feed_) feed_->Frame(*system_, frame, boxes, r);
    }
    ++next_index_;
    PyTrackResult out;
    out.index = r.index;
    out.tracked = r.tracked;
    out.cam_from_world = PoseOrNone(r.cam_from_world);
    out.state = TrackingStateName(r.state);
    out.new_keyframe = r.new_keyframe;
    out.num_keypoints = r.num_keypoints;
    out.num_kept = r.num_kept;
    out.num_with_depth = r.num_with_depth;
    out.inliers = r.inliers;
    out.depth_scale = r.depth_scale;
    out.scale_sigma = r.scale_sigma;
    py::array_t<float> kp({static_cast<py::ssize_t>(r.keypoints.size()), py::ssize_t{2}});
    auto k = kp.mutable_unchecked<2>();
    for (size_t i = 0; i < r.keypoints.size(); ++i) {
      k(static_cast<py::ssize_t>(i), 0) = r.keypoints[i].pt.x;
      k(static_cast<py::ssize_t>(i), 1) = r.keypoints[i].pt.y;
    }
    out.keypoints = kp;
    return out;
  }

  void Shutdown() {
    py::gil_scoped_release release;
    system_->Shutdown();
    if (feed_ && !ended_) {
      // The final map and trajectory to the live view (as trajectory() and map_points() give).
      ended_ = true;
      feed_->End(*system_, {next_index_, static_cast<size_t>(system_->FrameTrajectory().size()),
                            system_->NumKeyFrames(), system_->NumMapPoints(), system_->NumLost(),
                            false});
    }
  }
  System& Get() { return *system_; }
  live::LiveServer& Live() {
    if (!live_) throw std::runtime_error("this System was made without live=\"[HOST:]PORT\"");
    return *live_;
  }

 private:
  Camera camera_;
  std::unique_ptr<System> system_;
  size_t next_index_ = 0;
  bool ended_ = false;
  std::unique_ptr<live::LiveServer> live_;
  std::unique_ptr<LiveFeed> feed_;
};

// ---- depth models and detectors ----

class PyDepthModel {
 public:
  PyDepthModel(const fs::path& onnx, const std::optional<fs::path>& spec, int threads) {
    OrtSessionOptions options;
    options.intra_op_threads = threads;
    options.Check();
    model_ = std::make_unique<OnnxDepthProvider>(onnx, spec, options);
  }
  py::array Predict(const py::array& image, const std::optional<Camera>& camera) const {
    const cv::Mat bgr = ImageFromArray(image, "image");
    // Without a camera: a pinhole at the image's size with a 60 degree-ish field of view; only
    // models with a canonical focal length (spec: canonical_focal) use it.
    Camera cam;
    if (camera) {
      cam = *camera;
    } else {
      cam.width = bgr.cols;
      cam.height = bgr.rows;
      cam.fx = cam.fy = std::max(bgr.cols, bgr.rows);
      cam.cx = 0.5 * (bgr.cols - 1);
      cam.cy = 0.5 * (bgr.rows - 1);
    }
    cv::Mat depth;
    {
      py::gil_scoped_release release;
      depth = model_->DepthFromImage(bgr, cam);
    }
    return MatToArray(depth);
  }
  std::string Name() const { return model_->Name(); }

 private:
  std::unique_ptr<OnnxDepthProvider> model_;
};

class PyDetector {
 public:
  PyDetector(const fs::path& onnx, const std::string& arch, float score_threshold, float nms_iou,
             const std::string& classes) {
    DetectorOptions options;
    options.score_threshold = score_threshold;
    options.nms_iou = nms_iou;
    options.class_ids = ParseClassList(classes);
    options.Check();
    detector_ = std::make_unique<YoloDetector>(onnx, ParseYoloArch(arch), options);
  }
  std::vector<Detection> Detect(const py::array& image) const {
    const cv::Mat bgr = ImageFromArray(image, "image");
    py::gil_scoped_release release;
    return detector_->DetectImage(bgr);
  }
  std::string Name() const { return detector_->Name(); }

 private:
  std::unique_ptr<YoloDetector> detector_;
};

// ---- evaluation ----

// A trajectory argument: a file path (format detected or named), a (timestamps, poses) pair, or
// an (N, 4, 4) array of poses matched by index.
PoseSeries SeriesFrom(const py::object& arg, const std::string& format, const char* what) {
  if (py::isinstance<py::str>(arg) || py::hasattr(arg, "__fspath__")) {
    const fs::path path = py::str(arg).cast<std::string>();
    const TrajectoryFormat f =
        format == "auto" ? DetectTrajectoryFormat(path) : ParseTrajectoryFormat(format);
    return ReadPoseSeries(path, f);
  }
  PoseSeries series;
  if (py::isinstance<py::tuple>(arg) && py::len(arg) == 2) {
    const auto t = py::tuple(arg);
    series.timestamps = t[0].cast<std::vector<double>>();
    series.world_from_cam = PosesFromArray(t[1], what);
    if (series.timestamps.size() != series.world_from_cam.size()) {
      throw std::invalid_argument(std::string(what) + ": " +
                                  std::to_string(series.timestamps.size()) + " timestamps for " +
                                  std::to_string(series.world_from_cam.size()) + " poses");
    }
    series.format = TrajectoryFormat::kTum;
    return series;
  }
  series.world_from_cam = PosesFromArray(arg, what);
  for (size_t i = 0; i < series.world_from_cam.size(); ++i)
    series.timestamps.push_back(static_cast<double>(i));
  series.format = TrajectoryFormat::kKitti;
  return series;
}

py::object Evaluate(const py::object& gt_arg, const py::object& est_arg, const std::string& align,
                    double max_diff, double rpe_delta, const std::string& rpe_unit,
                    bool kitti_metrics, const std::optional<std::string>& kitti_align,
                    const std::string& format) {
  EvalOptions options;
  options.alignment = ParseAlignment(align);
  options.max_diff = max_diff;
  options.rpe_delta = rpe_delta;
  options.rpe_unit = ParseDeltaUnit(rpe_unit);
  options.kitti_metrics = kitti_metrics || kitti_align.has_value();
  options.kitti_alignment =
      kitti_align ? ParseKittiAlignment(*kitti_align) : KittiAlignmentFor(options.alignment);
  options.Check();
  const PoseSeries gt = SeriesFrom(gt_arg, format, "gt");
  const PoseSeries est = SeriesFrom(est_arg, format, "est");
  // As `ademono eval`: without timestamps on either side, match by frame (by the written index
  // when a file is indexed KITTI).
  options.associate_by_timestamp = !gt.HasFrameIndices() && !est.HasFrameIndices();
  options.associate_by_frame_index =
      gt.format == TrajectoryFormat::kKittiIndexed || est.format == TrajectoryFormat::kKittiIndexed;
  if (options.associate_by_frame_index && !(gt.HasFrameIndices() && est.HasFrameIndices())) {
    throw std::invalid_argument(
        "an indexed KITTI trajectory matches poses by frame index and cannot be compared with a "
        "timestamped one");
  }
  EvalResult r;
  {
    py::gil_scoped_release release;
    r = EvaluateTrajectories(gt, est, options);
  }
  py::dict out = JsonToPython(ToJson(r));
  out["ape_errors"] =
      py::array_t<double>(static_cast<py::ssize_t>(r.ape_errors.size()), r.ape_errors.data());
  out["gt_matched"] = SeriesToTuple(r.gt_matched);
  out["est_aligned"] = SeriesToTuple(r.est_aligned);
  return out;
}

}  // namespace
}  // namespace ademono

PYBIND11_MODULE(ademono, m) {
  using namespace ademono;
  m.doc() = "ademono: monocular SLAM with metric depth, dynamic-object removal and evaluation";
  py::register_exception<InputError>(m, "InputError", PyExc_ValueError);

  py::class_<Camera>(m, "Camera", "Pinhole camera (k1, k2, p1, p2, k3 distortion)")
      .def(py::init([](int width, int height, double fx, double fy, double cx, double cy,
                       std::array<double, 5> distortion) {
             Camera c;
             c.width = width;
             c.height = height;
             c.fx = fx;
             c.fy = fy;
             c.cx = cx;
             c.cy = cy;
             c.distortion = distortion;
             c.Check();
             return c;
           }),
           py::arg("width"), py::arg("height"), py::arg("fx"), py::arg("fy"), py::arg("cx"),
           py::arg("cy"), py::arg("distortion") = std::array<double, 5>{0, 0, 0, 0, 0})
      .def_readonly("width", &Camera::width)
      .def_readonly("height", &Camera::height)
      .def_readonly("fx", &Camera::fx)
      .def_readonly("fy", &Camera::fy)
      .def_readonly("cx", &Camera::cx)
      .def_readonly("cy", &Camera::cy)
      .def_readonly("distortion", &Camera::distortion)
      .def_property_readonly("K",
                             [](const Camera& c) {
                               const Eigen::Matrix3d k = c.K();
                               py::array_t<double> out({3, 3});
                               auto r = out.mutable_unchecked<2>();
                               for (int i = 0; i < 3; ++i)
                                 for (int j = 0; j < 3; ++j) r(i, j) = k(i, j);
                               return out;
                             })
      .def("__repr__", [](const Camera& c) {
        return "Camera(" + std::to_string(c.width) + "x" + std::to_string(c.height) +
               ", fx=" + std::to_string(c.fx) + ", fy=" + std::to_string(c.fy) + ")";
      });
  m.def("load_camera", &LoadCameraYaml, py::arg("path"), "Camera from a camera YAML file");

  py::class_<PyFrame>(m, "Frame", "One frame of a sequence")
      .def_readonly("index", &PyFrame::index)
      .def_readonly("timestamp", &PyFrame::timestamp)
      .def_readonly("name", &PyFrame::name)
      .def_readonly("image", &PyFrame::image, "uint8 (H, W, 3) BGR")
      .def_readonly("depth", &PyFrame::depth, "float32 (H, W) metres, 0 = invalid; or None")
      .def_readonly("gt_pose", &PyFrame::gt_pose, "4x4 world_from_cam ground truth, or None");

  py::class_<PySequence>(m, "Sequence", "A dataset sequence; index it or iterate over it")
      .def("__len__", &PySequence::Size)
      .def("__getitem__", py::overload_cast<py::ssize_t>(&PySequence::Get, py::const_))
      .def_property_readonly("camera", [](const PySequence& s) { return s.Get().GetCamera(); })
      .def_property_readonly("kind", [](const PySequence& s) { return s.Get().Kind(); })
      .def_property_readonly("path", [](const PySequence& s) { return s.Get().Path().string(); })
      .def_property_readonly("has_depth", [](const PySequence& s) { return s.Get().HasDepth(); })
      .def_property_readonly("has_ground_truth",
                             [](const PySequence& s) { return s.Get().HasGroundTruth(); });
  m.def(
      "open_sequence",
      [](const std::string& spec, const std::optional<fs::path>& camera) {
        return std::make_unique<PySequence>(spec, camera);
      },
      py::arg("spec"), py::arg("camera") = py::none(),
      "Opens 'tum:DIR', 'kitti:DIR', 'euroc:DIR', '7scenes:DIR', 'folder:DIR' or 'video:FILE' "
      "(folder and video need camera=CAMERA.yaml)");

  py::class_<Detection>(m, "Detection", "An object box in image pixels")
      .def(py::init([](std::array<float, 4> box, int class_id, float score,
                       const std::string& class_name) {
             Detection d;
             d.box = cv::Rect2f(box[0], box[1], box[2], box[3]);
             d.class_id = class_id;
             d.score = score;
             d.class_name = class_name;
             return d;
           }),
           py::arg("box"), py::arg("class_id"), py::arg("score") = 1.0f, py::arg("class_name") = "")
      .def_readonly("class_id", &Detection::class_id)
      .def_readonly("class_name", &Detection::class_name)
      .def_readonly("score", &Detection::score)
      .def_property_readonly("box",
                             [](const Detection& d) {
                               return py::make_tuple(d.box.x, d.box.y, d.box.width, d.box.height);
                             })
      .def("__repr__", [](const Detection& d) {
        return "Detection(" + d.class_name + ", score=" + std::to_string(d.score) + ")";
      });

  py::class_<PyTrackResult>(m, "TrackResult", "What System.track returns for one frame")
      .def_readonly("index", &PyTrackResult::index)
      .def_readonly("tracked", &PyTrackResult::tracked)
      .def_readonly("cam_from_world", &PyTrackResult::cam_from_world,
                    "4x4 camera-from-world pose, or None when not tracked")
      .def_readonly("state", &PyTrackResult::state, "'not_initialized', 'ok' or 'lost'")
      .def_readonly("new_keyframe", &PyTrackResult::new_keyframe)
      .def_readonly("num_keypoints", &PyTrackResult::num_keypoints)
      .def_readonly("num_kept", &PyTrackResult::num_kept)
      .def_readonly("num_with_depth", &PyTrackResult::num_with_depth)
      .def_readonly("inliers", &PyTrackResult::inliers)
      .def_readonly("depth_scale", &PyTrackResult::depth_scale,
                    "network depth: the factor this frame's depths were corrected by (1 otherwise)")
      .def_readonly("scale_sigma", &PyTrackResult::scale_sigma,
                    "network depth or a ground scale: the relative standard error of the run's "
                    "metric scale as this frame leaves it; None otherwise")
      .def_readonly("keypoints", &PyTrackResult::keypoints);

  py::class_<PySystem>(m, "System", "The SLAM system: call track() once per frame, in order")
      .def(py::init<const py::object&, const Camera&, std::optional<uint64_t>,
                    const std::optional<std::string>&>(),
           py::arg("config"), py::arg("camera"), py::arg("seed") = py::none(),
           py::arg("live") = py::none(),
           "config: a YAML file path (e.g. configs/7scenes.yaml), a dict of the same keys, or "
           "None for the defaults; live: \"[HOST:]PORT\" serves the run as `ademono run --live` "
           "does (Foxglove WebSocket protocol and a page at http://HOST:PORT/, docs/live.md)")
      .def_property_readonly(
          "live_url", [](PySystem& s) { return s.Live().Url(); },
          "http://HOST:PORT/ of the live view (the WebSocket is ws://HOST:PORT/)")
      .def(
          "wait_for_clients",
          [](PySystem& s, size_t clients) {
            py::gil_scoped_release release;
            s.Live().WaitForClients(clients, nullptr);
          },
          py::arg("clients") = 1,
          "Blocks until this many live clients have subscribed (as --live-wait-clients)")
      .def(
          "live_linger",
          [](PySystem& s, double seconds) {
            py::gil_scoped_release release;
            s.Live().Linger(seconds);
          },
          py::arg("seconds") = 0.0,
          "After shutdown(): serve until every live client has left, at most `seconds` once they "
          "have the final state (as --live-linger)")
      .def(
          "live_stats",
          [](PySystem& s) { return py::module_::import("json").attr("loads")(s.Live().Stats().dump()); },
          "The live view's counts: clients, messages_sent, messages_dropped, frames_skipped, ...")
      .def("track", &PySystem::Track, py::arg("image"), py::arg("depth") = py::none(),
           py::arg("timestamp") = py::none(), py::arg("detections") = py::none(),
           "image uint8 (H, W, 3) BGR; depth float32 (H, W) metres or None; timestamp in seconds "
           "(default: the frame number); detections: list of Detection")
      .def("shutdown", &PySystem::Shutdown)
      .def(
          "save_map", [](PySystem& s, const fs::path& path) { s.Get().SaveMap(path); },
          py::arg("path"),
          "Finishes local mapping and writes the map as `ademono run --save-map` (docs/maps.md)")
      .def(
          "load_map",
          [](PySystem& s, const fs::path& path, bool localize_only) {
            s.Get().LoadMap(path, localize_only);
          },
          py::arg("path"), py::arg("localize_only") = false,
          "Before the first frame: start from a saved map (relocalise in it; localize_only: "
          "never change it)")
      .def(
          "loaded_map_has_metric_scale",
          [](PySystem& s) { return s.Get().LoadedMapHasMetricScale(); },
          "False after load_map of a map built without depth (--depth none) and without a "
          "camera height, until a depth sensor gave it metres at its first tracked frame (a "
          "depth network gives it its long-run scale frame by frame)")
      .def(
          "trajectory", [](PySystem& s) { return TrajectoryToTuple(s.Get().FrameTrajectory()); },
          "(timestamps (N,), world_from_cam (N, 4, 4)) of the tracked frames")
      .def(
          "keyframes", [](PySystem& s) { return TrajectoryToTuple(s.Get().KeyFrameTrajectory()); },
          "(timestamps (N,), world_from_cam (N, 4, 4)) of the keyframes")
      .def(
          "map_points",
          [](PySystem& s) {
            const auto cloud = s.Get().MapPointCloud();
            py::array_t<double> xyz({static_cast<py::ssize_t>(cloud.size()), py::ssize_t{3}});
            py::array_t<uint8_t> rgb({static_cast<py::ssize_t>(cloud.size()), py::ssize_t{3}});
            auto x = xyz.mutable_unchecked<2>();
            auto c = rgb.mutable_unchecked<2>();
            for (size_t i = 0; i < cloud.size(); ++i) {
              const auto k = static_cast<py::ssize_t>(i);
              for (int a = 0; a < 3; ++a) {
                x(k, a) = cloud[i].position[a];
                c(k, a) = cloud[i].bgr[2 - a];
              }
            }
            return py::make_tuple(xyz, rgb);
          },
          "(positions (N, 3) metres, colours (N, 3) uint8 RGB) of the map points")
      .def(
          "write_trajectory",
          [](PySystem& s, const fs::path& path, const std::string& format) {
            WriteTrajectory(path, s.Get().FrameTrajectory(), ParseTrajectoryFormat(format));
          },
          py::arg("path"), py::arg("format") = "tum",
          "Writes the frame trajectory as `ademono run` does (tum, kitti, kitti-indexed, euroc)")
      .def_property_readonly("num_keyframes", [](PySystem& s) { return s.Get().NumKeyFrames(); })
      .def_property_readonly("num_map_points", [](PySystem& s) { return s.Get().NumMapPoints(); })
      .def_property_readonly("num_lost", [](PySystem& s) { return s.Get().NumLost(); })
      .def_property_readonly("num_tracked", [](PySystem& s) { return s.Get().NumTracked(); });

  py::class_<PyDepthModel>(m, "DepthModel", "A metric monocular depth network (ONNX)")
      .def(py::init<const fs::path&, const std::optional<fs::path>&, int>(), py::arg("onnx"),
           py::arg("spec") = py::none(), py::arg("threads") = 1)
      .def("predict", &PyDepthModel::Predict, py::arg("image"), py::arg("camera") = py::none(),
           "float32 (H, W) depth in metres at the image's size, 0 where invalid")
      .def_property_readonly("name", &PyDepthModel::Name);

  py::class_<PyDetector>(m, "Detector", "A YOLO-family object detector (ONNX)")
      .def(py::init<const fs::path&, const std::string&, float, float, const std::string&>(),
           py::arg("onnx"), py::arg("arch") = "auto", py::arg("score_threshold") = 0.3f,
           py::arg("nms_iou") = 0.45f, py::arg("classes") = "dynamic")
      .def("detect", &PyDetector::Detect, py::arg("image"),
           "Boxes in image pixels, sorted by score")
      .def_property_readonly("name", &PyDetector::Name);

  m.def(
      "read_detections",
      [](const fs::path& path) {
        py::list out;
        for (const FrameDetections& f : ReadDetectionsJsonl(path)) {
          py::dict d;
          d["frame"] = f.frame;
          d["timestamp"] = f.timestamp;
          d["name"] = f.name;
          d["detections"] = f.detections;
          out.append(d);
        }
        return out;
      },
      py::arg("path"),
      "A detections cache (JSON lines, as `ademono infer` and `ademono synth` write): one dict "
      "per frame with frame, timestamp, name and detections (list of Detection)");
  m.def(
      "read_trajectory",
      [](const fs::path& path, const std::string& format) {
        const TrajectoryFormat f =
            format == "auto" ? DetectTrajectoryFormat(path) : ParseTrajectoryFormat(format);
        const PoseSeries s = ReadPoseSeries(path, f);
        return py::make_tuple(SeriesToTuple(s)[0], SeriesToTuple(s)[1], ToString(s.format));
      },
      py::arg("path"), py::arg("format") = "auto",
      "(timestamps or frame indices (N,), world_from_cam (N, 4, 4), format used)");
  m.def("evaluate", &Evaluate, py::arg("gt"), py::arg("est"), py::arg("align") = "se3",
        py::arg("max_diff") = 0.01, py::arg("rpe_delta") = 1.0, py::arg("rpe_unit") = "frames",
        py::arg("kitti_metrics") = false, py::arg("kitti_align") = py::none(),
        py::arg("format") = "auto",
        "`ademono eval` on files (path) or arrays ((timestamps, poses) or poses (N, 4, 4) matched "
        "by index). Returns the JSON dict of `ademono eval --json` plus ape_errors, gt_matched "
        "and est_aligned");
  m.def(
      "ate",
      [](const py::object& gt, const py::object& est, const std::string& align) {
        const py::dict r =
            Evaluate(gt, est, align, 0.01, 1.0, "frames", false, std::nullopt, "auto");
        return r["ape"]["rmse"].cast<double>();
      },
      py::arg("gt"), py::arg("est"), py::arg("align") = "se3", "ATE: APE translation RMSE (m)");
  m.def(
      "rpe",
      [](const py::object& gt, const py::object& est, double delta, const std::string& unit,
         const std::string& align) {
        const py::dict r = Evaluate(gt, est, align, 0.01, delta, unit, false, std::nullopt, "auto");
        return py::dict(py::arg("trans") = py::object(r["rpe_trans"]),
                        py::arg("rot_deg") = py::object(r["rpe_rot_deg"]));
      },
      py::arg("gt"), py::arg("est"), py::arg("delta") = 1.0, py::arg("unit") = "frames",
      py::arg("align") = "se3", "RPE statistics: {'trans': {...} m, 'rot_deg': {...}}");
  m.def(
      "kitti_metrics",
      [](const py::object& gt, const py::object& est, const std::string& align) {
        const py::dict r = Evaluate(gt, est, "none", 0.01, 1.0, "frames", true, align, "auto");
        return py::object(r["kitti"]);  // an accessor would outlive `r`
      },
      py::arg("gt"), py::arg("est"), py::arg("align") = "6dof",
      "kitti-odom-eval's t_rel (%), r_rel (deg/100 m), ATE, RPE (align none|scale|6dof|7dof)");

  m.def(
      "synth",
      [](const fs::path& out, const std::string& scene, size_t frames, uint64_t seed,
         const std::optional<std::string>& motion, int persons, int width, int height, double noise,
         double blur) {
        synth::GeneratorOptions options;
        options.scene.scene = scene;
        if (motion) options.scene.motion = synth::ParseMotionKind(*motion);
        options.scene.frames = frames;
        options.scene.seed = seed;
        options.scene.persons = persons;
        options.scene.width = width;
        options.scene.height = height;
        options.noise_sigma = noise;
        options.blur_px = blur;
        options.Check();
        synth::GeneratorSummary summary;
        {
          py::gil_scoped_release release;
          summary = synth::GenerateSequence(options, out);
        }
        py::dict d;
        d["frames"] = summary.frames;
        d["detections"] = summary.detections;
        d["moving_pixel_fraction"] = summary.moving_pixel_fraction;
        d["seconds_total"] = summary.seconds_total;
        return d;
      },
      py::arg("out"), py::arg("scene") = "office", py::arg("frames") = 100, py::arg("seed") = 0,
      py::arg("motion") = py::none(), py::arg("persons") = 2, py::arg("width") = 0,
      py::arg("height") = 0, py::arg("noise") = 0.0, py::arg("blur") = 0.0,
      "Renders a synthetic sequence into `out` (TUM layout, open it with 'tum:OUT')");
}
