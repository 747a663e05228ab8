#include "ademono/optimize/schur_lm.h"

#include <ceres/sphere_manifold.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

#include "ademono/optimize/residuals.h"
#include "ademono/optimize/trust_region.h"

namespace ademono::internal {
namespace {

constexpr int kMaxInvalidSteps = 5;  // Ceres' max_num_consecutive_invalid_steps

using Mat63 = Eigen::Matrix<double, 6, 3>;
static_assert(sizeof(Mat63) == 18 * sizeof(double), "a vector of them is one array of doubles");
using Mat66 = Eigen::Matrix<double, 6, 6>;

enum class Kind { kMono, kStereo, kPlane };

// One residual block and where its parameters sit: free blocks of the reduced system (cameras,
// then solved normals), free points, or -1 when held.
struct Row {
  Kind kind = Kind::kMono;
  size_t model = 0;  // index into mono_/stereo_ or problem.plane_distances
  size_t camera = 0;
  size_t point = 0;
  int normal = -1;  // solved normal's slot
  int camera_block = -1;
  int normal_block = -1;
  int point_block = -1;
  int camera_slot = -1;  // position of camera_block among its point's coupled blocks
  int normal_slot_in_point = -1;
  int Dim() const { return kind == Kind::kMono ? 2 : kind == Kind::kStereo ? 3 : 1; }
};

// A row linearised: the robustified residual and Jacobians (Dim() rows, row-major).
struct Linearised {
  double r[3];
  double camera[18];
  double point[9];
  double normal[2];
};

struct Block {
  int offset = 0;      // in the reduced system
  int size = 0;        // 6 for a camera, 2 for a normal (its tangent space)
  size_t storage = 0;  // of its values in the camera array (normals live behind the cameras)
};

// Huber with Ceres' corrector: rho(s) and sqrt(rho'), which scales residual and Jacobian.
struct Robust {
  double rho;
  double factor;
};
Robust Huber(double s, double a2) {
  double rho1 = 1.0;
  const double rho = HuberRho(s, a2, &rho1);
  return {rho, std::sqrt(rho1)};
}

class SchurLm {
 public:
  SchurLm(const BundleAdjustmentProblem& problem, const std::vector<bool>& skip,
          std::vector<double>& cameras, std::vector<double>& points, double* normals,
          const std::vector<size_t>& normal_slot)
      : problem_(problem), cameras_(cameras), points_(points) {
    normals_offset_ = static_cast<size_t>(normals - cameras.data());
    Build(skip, normal_slot);
  }

  bool Empty() const { return num_projections_ == 0; }
  bool Run(int max_iterations);

 private:
  void Build(const std::vector<bool>& skip, const std::vector<size_t>& normal_slot);
  template <int kDim>
  double EvaluateProjectionRow(const Row& row, const ProjectionResidual<kDim>& model,
                               const double* cameras, const double* points, Linearised* out) const;
  double EvaluatePlaneRow(const Row& row, const double* cameras, const double* points,
                          Linearised* out) const;
  // Half the sum of rho over the rows (Ceres' cost); linearises into lin_ when asked.
  double Evaluate(const std::vector<double>& cameras, const std::vector<double>& points,
                  bool linearise);
  void BuildNormalEquations();
  template <int kDim>
  void AccumulateRow(const Row& row, const Linearised& l);
  // The damped step for `radius`; false when a system is not positive definite.
  bool ComputeStep(double radius);
  double ModelCostChange() const;
  void Candidate();
  double GradientMaxNorm() const;
  double FreeNorm(const std::vector<double>& cameras, const std::vector<double>& points) const;
  double Damping(double h, double scale, double radius) const {
    const double d = std::clamp(scale * scale * h, kLmMinDiagonal, kLmMaxDiagonal);
    return d / (scale * scale * radius);
  }

  const BundleAdjustmentProblem& problem_;
  std::vector<double>& cameras_;
  std::vector<double>& points_;
  size_t normals_offset_ = 0;
  std::vector<ProjectionResidual<2>> mono_;
  std::vector<ProjectionResidual<3>> stereo_;
  size_t num_projections_ = 0;
  std::vector<Row> rows_;
  std::vector<size_t> used_cameras_;
  std::vector<CameraRotation> rotations_;  // per camera, at the point being evaluated
  std::vector<Block> blocks_;
  int reduced_size_ = 0;
  std::vector<size_t> free_points_;       // point index of each free point
  std::vector<size_t> point_slot_begin_;  // CSR: the blocks each free point couples to
  std::vector<int> point_slots_;

  // Linearisation and normal equations at the current point.
  std::vector<Linearised> lin_;
  Eigen::MatrixXd hff_;
  Eigen::VectorXd gf_;
  std::vector<Eigen::Matrix3d> hpp_;
  std::vector<Eigen::Vector3d> gp_;
  // Per point slot: W^T = J_block^T J_point, stored 6x3 column-major so that its products
  // vectorise (a normal's in the first 2 rows).
  std::vector<Mat63> wt_;
  Eigen::VectorXd scale_f_;
  std::vector<Eigen::Vector3d> scale_p_;
  bool scaled_ = false;

  // The step and the candidate it leads to.
  Eigen::VectorXd step_f_;
  std::vector<Eigen::Vector3d> step_p_;
  std::vector<Eigen::Matrix3d> inverse_;
  std::vector<Mat63> vt_;  // scratch: one point's W_i^T A^-1, per slot
  std::vector<double> candidate_cameras_, candidate_points_;
};

void SchurLm::Build(const std::vector<bool>& skip, const std::vector<size_t>& normal_slot) {
  const size_t num_cameras = problem_.cameras.size();
  std::vector<bool> point_used(problem_.points.size(), false), camera_used(num_cameras, false);
  for (size_t i = 0; i < problem_.observations.size(); ++i) {
    if (skip[i]) continue;
    point_used[problem_.observations[i].point] = true;
    camera_used[problem_.observations[i].camera] = true;
  }
  auto point_free = [&](size_t p) {
    return !(p < problem_.point_fixed.size() && problem_.point_fixed[p]);
  };
  std::vector<int> camera_block(num_cameras, -1), point_block(problem_.points.size(), -1);
  for (size_t c = 0; c < num_cameras; ++c) {
    if (!camera_used[c] || problem_.cameras[c].fixed) continue;
    camera_block[c] = static_cast<int>(blocks_.size());
    blocks_.push_back({reduced_size_, 6, 6 * c});
    reduced_size_ += 6;
  }
  std::vector<int> normal_block;
  auto add_row = [&](Row row) {
    row.camera_block = camera_block[row.camera];
    if (point_free(row.point)) {
      if (point_block[row.point] < 0) {
        point_block[row.point] = static_cast<int>(free_points_.size());
        free_points_.push_back(row.point);
      }
      row.point_block = point_block[row.point];
    }
    if (row.normal >= 0) {
      if (static_cast<size_t>(row.normal) >= normal_block.size())
        normal_block.resize(row.normal + 1, -1);
      if (normal_block[row.normal] < 0) {
        normal_block[row.normal] = static_cast<int>(blocks_.size());
        const size_t storage = normals_offset_ + 3 * row.normal;
        blocks_.push_back({reduced_size_, 2, storage});
        reduced_size_ += 2;
      }
      row.normal_block = normal_block[row.normal];
    }
    // A row with nothing free is constant: Ceres drops it from the reduced program.
    if (row.camera_block < 0 && row.point_block < 0 && row.normal_block < 0) return;
    rows_.push_back(row);
  };
  for (size_t i = 0; i < problem_.observations.size(); ++i) {
    if (skip[i]) continue;
    const BaObservation& o = problem_.observations[i];
    Row row;
    row.camera = o.camera;
    row.point = o.point;
    if (o.image.HasDepth()) {
      row.kind = Kind::kStereo;
      row.model = stereo_.size();
      stereo_.emplace_back(problem_.intrinsics, o.image);
    } else {
      row.kind = Kind::kMono;
      row.model = mono_.size();
      mono_.emplace_back(problem_.intrinsics, o.image);
    }
    ++num_projections_;
    add_row(row);
  }
  for (size_t i = 0; i < problem_.plane_distances.size(); ++i) {
    const BaPlaneDistance& d = problem_.plane_distances[i];
    if (!point_used[d.point] || !camera_used[d.camera]) continue;
    Row row;
    row.kind = Kind::kPlane;
    row.model = i;
    row.camera = d.camera;
    row.point = d.point;
    if (d.plane >= 0) row.normal = static_cast<int>(normal_slot[i]);
    add_row(row);
  }

  // The rows of each free point (CSR, in row order), to number the blocks it couples to.
  const size_t num_free_points = free_points_.size();
  std::vector<size_t> point_row_begin(num_free_points + 1, 0);
  for (const Row& row : rows_)
    if (row.point_block >= 0) ++point_row_begin[row.point_block + 1];
  for (size_t p = 0; p < num_free_points; ++p) point_row_begin[p + 1] += point_row_begin[p];
  std::vector<size_t> point_rows(point_row_begin.back());
  std::vector<size_t> fill(point_row_begin.begin(), point_row_begin.end() - 1);
  for (size_t r = 0; r < rows_.size(); ++r)
    if (rows_[r].point_block >= 0) point_rows[fill[rows_[r].point_block]++] = r;
  point_slot_begin_.assign(1, 0);
  for (size_t p = 0; p < num_free_points; ++p) {
    const size_t first_slot = point_slots_.size();
    auto slot_of = [&](int block) {
      for (size_t s = first_slot; s < point_slots_.size(); ++s)
        if (point_slots_[s] == block) return static_cast<int>(s - first_slot);
      point_slots_.push_back(block);
      return static_cast<int>(point_slots_.size() - 1 - first_slot);
    };
    for (size_t k = point_row_begin[p]; k < point_row_begin[p + 1]; ++k) {
      Row& row = rows_[point_rows[k]];
      if (row.camera_block >= 0) row.camera_slot = slot_of(row.camera_block);
      if (row.normal_block >= 0) row.normal_slot_in_point = slot_of(row.normal_block);
    }
    point_slot_begin_.push_back(point_slots_.size());
  }

  std::vector<bool> camera_in_rows(num_cameras, false);
  for (const Row& row : rows_) camera_in_rows[row.camera] = true;
  for (size_t c = 0; c < num_cameras; ++c)
    if (camera_in_rows[c]) used_cameras_.push_back(c);
  rotations_.resize(num_cameras);
  lin_.resize(rows_.size());
  hpp_.resize(num_free_points);
  gp_.resize(num_free_points);
  wt_.resize(point_slots_.size());
  scale_p_.resize(num_free_points);
  step_p_.resize(num_free_points);
  inverse_.resize(num_free_points);
  size_t max_slots = 0;
  for (size_t p = 0; p < num_free_points; ++p)
    max_slots = std::max(max_slots, point_slot_begin_[p + 1] - point_slot_begin_[p]);
  vt_.resize(max_slots);
}

template <int kDim>
double SchurLm::EvaluateProjectionRow(const Row& row, const ProjectionResidual<kDim>& model,
                                      const double* cameras, const double* points,
                                      Linearised* out) const {
  const CameraRotation& rotation = rotations_[row.camera];
  const double* point = points + 3 * row.point;
  const Eigen::Vector3d q = rotation.rotation * Eigen::Map<const Eigen::Vector3d>(point);
  double r[kDim];
  ProjectRotated(model, q.data(), cameras + 6 * row.camera + 3, point, &rotation, r,
                 out != nullptr ? out->camera : nullptr, out != nullptr ? out->point : nullptr);
  double s = 0;
  for (int k = 0; k < kDim; ++k) s += r[k] * r[k];
  const Robust robust = Huber(s, kDim == 3 ? kChi2Stereo : kChi2Mono);
  if (out != nullptr) {
    for (int k = 0; k < kDim; ++k) out->r[k] = robust.factor * r[k];
    if (robust.factor != 1.0) {
      for (int k = 0; k < 6 * kDim; ++k) out->camera[k] *= robust.factor;
      for (int k = 0; k < 3 * kDim; ++k) out->point[k] *= robust.factor;
    }
  }
  return robust.rho;
}

double SchurLm::EvaluatePlaneRow(const Row& row, const double* cameras, const double* points,
                                 Linearised* out) const {
  const BaPlaneDistance& d = problem_.plane_distances[row.model];
  const double* camera = cameras + 6 * row.camera;
  const double* point = points + 3 * row.point;
  const double* normal =
      row.normal >= 0 ? cameras + normals_offset_ + 3 * row.normal : d.normal_cam.data();
  const CameraRotation& rotation = rotations_[row.camera];
  const Eigen::Vector3d q = rotation.rotation * Eigen::Map<const Eigen::Vector3d>(point);
  double along = 0;
  for (int k = 0; k < 3; ++k) along += normal[k] * (q[k] + camera[3 + k]);
  const double r = d.inv_sigma * (along - d.distance);
  const Robust robust = Huber(r * r, 1.0);  // HuberLoss(1)
  if (out == nullptr) return robust.rho;
  const double f = robust.factor;
  out->r[0] = f * r;
  const Eigen::RowVector3d n = f * d.inv_sigma * Eigen::Map<const Eigen::RowVector3d>(normal);
  Eigen::Map<Eigen::Matrix<double, 1, 6>> jc(out->camera);
  jc.leftCols<3>() = n * rotation.DerivativeAt(point, q.data());
  jc.rightCols<3>() = n;
  Eigen::Map<Eigen::RowVector3d>(out->point) = n * rotation.rotation;
  if (row.normal >= 0) {
    Eigen::Matrix<double, 3, 2, Eigen::RowMajor> plus_jacobian;
    ceres::SphereManifold<3>().PlusJacobian(normal, plus_jacobian.data());
    const Eigen::RowVector3d dr_dn =
        f * d.inv_sigma * Eigen::RowVector3d(q[0] + camera[3], q[1] + camera[4], q[2] + camera[5]);
    Eigen::Map<Eigen::RowVector2d>(out->normal) = dr_dn * plus_jacobian;
  }
  return robust.rho;
}

double SchurLm::Evaluate(const std::vector<double>& cameras, const std::vector<double>& points,
                         bool linearise) {
  // Each camera's rotation once, not once per observation (a sine and cosine each).
  for (size_t c : used_cameras_) rotations_[c] = CameraRotation(&cameras[6 * c]);
  double sum = 0;
  for (size_t r = 0; r < rows_.size(); ++r) {
    const Row& row = rows_[r];
    Linearised* out = linearise ? &lin_[r] : nullptr;
    switch (row.kind) {
      case Kind::kMono:
        sum += EvaluateProjectionRow(row, mono_[row.model], cameras.data(), points.data(), out);
        break;
      case Kind::kStereo:
        sum += EvaluateProjectionRow(row, stereo_[row.model], cameras.data(), points.data(), out);
        break;
      case Kind::kPlane:
        sum += EvaluatePlaneRow(row, cameras.data(), points.data(), out);
        break;
    }
  }
  return 0.5 * sum;
}

template <int kDim>
void SchurLm::AccumulateRow(const Row& row, const Linearised& l) {
  using RowMatrix6 = Eigen::Matrix<double, kDim, 6, Eigen::RowMajor>;
  using RowMatrix3 = Eigen::Matrix<double, kDim, 3, Eigen::RowMajor>;
  const Eigen::Map<const Eigen::Matrix<double, kDim, 1>> r(l.r);
  const Eigen::Map<const RowMatrix6> jc(l.camera);
  const Eigen::Map<const RowMatrix3> jp(l.point);
  const Eigen::Map<const Eigen::RowVector2d> jn(l.normal);
  const int oc = row.camera_block >= 0 ? blocks_[row.camera_block].offset : -1;
  const int on = row.normal_block >= 0 ? blocks_[row.normal_block].offset : -1;
  if (oc >= 0) {
    hff_.block<6, 6>(oc, oc).noalias() += jc.transpose() * jc;
    gf_.segment<6>(oc).noalias() += jc.transpose() * r;
  }
  if constexpr (kDim == 1) {  // a plane row: its normal may be free
    if (on >= 0) {
      hff_.block<2, 2>(on, on).noalias() += jn.transpose() * jn;
      gf_.segment<2>(on) += jn.transpose() * l.r[0];
      if (oc >= 0) {
        const Eigen::Matrix<double, 6, 2> cn = jc.transpose() * jn;
        hff_.block<6, 2>(oc, on) += cn;
        hff_.block<2, 6>(on, oc) += cn.transpose();
      }
    }
  }
  if (row.point_block >= 0) {
    const size_t p = row.point_block;
    hpp_[p].noalias() += jp.transpose() * jp;
    gp_[p].noalias() += jp.transpose() * r;
    const size_t first = point_slot_begin_[p];
    if (oc >= 0) wt_[first + row.camera_slot].noalias() += jc.transpose() * jp;
    if constexpr (kDim == 1) {
      if (on >= 0)
        wt_[first + row.normal_slot_in_point].topRows<2>().noalias() += jn.transpose() * jp;
    }
  }
}

void SchurLm::BuildNormalEquations() {
  hff_.setZero(reduced_size_, reduced_size_);
  gf_.setZero(reduced_size_);
  for (size_t p = 0; p < free_points_.size(); ++p) {
    hpp_[p].setZero();
    gp_[p].setZero();
  }
  // One fill over the contiguous blocks: per block it was a string store each, a quarter of this
  // function's time.
  if (!wt_.empty()) Eigen::Map<Eigen::VectorXd>(wt_[0].data(), 18 * wt_.size()).setZero();
  for (size_t i = 0; i < rows_.size(); ++i) {
    switch (rows_[i].kind) {
      case Kind::kMono:
        AccumulateRow<2>(rows_[i], lin_[i]);
        break;
      case Kind::kStereo:
        AccumulateRow<3>(rows_[i], lin_[i]);
        break;
      case Kind::kPlane:
        AccumulateRow<1>(rows_[i], lin_[i]);
        break;
    }
  }
  if (!scaled_) {  // Ceres' Jacobi scaling, from the first Jacobian's column norms
    scale_f_ = (1.0 + hff_.diagonal().array().sqrt()).inverse();
    for (size_t p = 0; p < free_points_.size(); ++p)
      scale_p_[p] = (1.0 + hpp_[p].diagonal().array().sqrt()).inverse();
    scaled_ = true;
  }
}

bool SchurLm::ComputeStep(double radius) {
  Eigen::MatrixXd reduced = hff_;
  for (int j = 0; j < reduced_size_; ++j) reduced(j, j) += Damping(hff_(j, j), scale_f_[j], radius);
  Eigen::VectorXd rhs = -gf_;
  for (size_t p = 0; p < free_points_.size(); ++p) {
    Eigen::Matrix3d a = hpp_[p];
    for (int k = 0; k < 3; ++k) a(k, k) += Damping(hpp_[p](k, k), scale_p_[p][k], radius);
    const Eigen::LLT<Eigen::Matrix3d> llt(a);
    if (llt.info() != Eigen::Success) return false;
    inverse_[p] = llt.solve(Eigen::Matrix3d::Identity());
    const Eigen::Vector3d inv_g = inverse_[p] * gp_[p];
    const size_t begin = point_slot_begin_[p], end = point_slot_begin_[p + 1];
    // W_i^T A^-1 per slot, 6x3 column-major: a block W_i^T A^-1 W_j is then three 6-vector
    // multiply-adds per column, which the compiler vectorises (through a transposed 3x6 view it
    // was scalar code: the whole local BA 1.4x slower).
    for (size_t i = begin; i < end; ++i) vt_[i - begin].noalias() = wt_[i] * inverse_[p];
    for (size_t i = begin; i < end; ++i) {
      const Block& bi = blocks_[point_slots_[i]];
      const Mat63& vi = vt_[i - begin];
      rhs.segment(bi.offset, bi.size) += (wt_[i] * inv_g).head(bi.size);
      for (size_t j = i; j < end; ++j) {
        const Block& bj = blocks_[point_slots_[j]];
        // Only the upper triangle: the Cholesky below reads nothing else.
        if (bi.size == 6 && bj.size == 6) {
          if (bi.offset <= bj.offset) {
            reduced.block<6, 6>(bi.offset, bj.offset).noalias() -= vi * wt_[j].transpose();
          } else {
            reduced.block<6, 6>(bj.offset, bi.offset).noalias() -=
                vt_[j - begin] * wt_[i].transpose();
          }
          continue;
        }
        const Mat66 m = vi * wt_[j].transpose();  // W_i^T A^-1 W_j
        if (bi.offset <= bj.offset) {
          reduced.block(bi.offset, bj.offset, bi.size, bj.size) -=
              m.topLeftCorner(bi.size, bj.size);
        } else {
          reduced.block(bj.offset, bi.offset, bj.size, bi.size) -=
              m.topLeftCorner(bi.size, bj.size).transpose();
        }
      }
    }
  }
  const Eigen::LLT<Eigen::MatrixXd, Eigen::Upper> llt(reduced);
  if (llt.info() != Eigen::Success) return false;
  step_f_ = llt.solve(rhs);
  if (!step_f_.allFinite()) return false;
  for (size_t p = 0; p < free_points_.size(); ++p) {
    Eigen::Vector3d b = -gp_[p];
    for (size_t i = point_slot_begin_[p]; i < point_slot_begin_[p + 1]; ++i) {
      const Block& bi = blocks_[point_slots_[i]];
      b.noalias() -= wt_[i].topRows(bi.size).transpose() * step_f_.segment(bi.offset, bi.size);
    }
    step_p_[p] = inverse_[p] * b;
    if (!step_p_[p].allFinite()) return false;
  }
  return true;
}

// -(r . J d + |J d|^2 / 2): the decrease the linear model predicts for the step d.
double SchurLm::ModelCostChange() const {
  double change = 0;
  for (size_t i = 0; i < rows_.size(); ++i) {
    const Row& row = rows_[i];
    const Linearised& l = lin_[i];
    const int dim = row.Dim();
    double jd[3] = {0, 0, 0};
    for (int k = 0; k < dim; ++k) {
      if (row.camera_block >= 0) {
        const double* d = step_f_.data() + blocks_[row.camera_block].offset;
        for (int c = 0; c < 6; ++c) jd[k] += l.camera[6 * k + c] * d[c];
      }
      if (row.point_block >= 0) {
        const Eigen::Vector3d& d = step_p_[row.point_block];
        for (int c = 0; c < 3; ++c) jd[k] += l.point[3 * k + c] * d[c];
      }
      if (row.normal_block >= 0) {
        const double* d = step_f_.data() + blocks_[row.normal_block].offset;
        jd[k] += l.normal[0] * d[0] + l.normal[1] * d[1];
      }
      change -= l.r[k] * jd[k] + 0.5 * jd[k] * jd[k];
    }
  }
  return change;
}

void SchurLm::Candidate() {
  candidate_cameras_ = cameras_;
  candidate_points_ = points_;
  for (const Block& b : blocks_) {
    const double* d = step_f_.data() + b.offset;
    if (b.size == 6) {
      for (int k = 0; k < 6; ++k) candidate_cameras_[b.storage + k] += d[k];
    } else {
      ceres::SphereManifold<3>().Plus(&cameras_[b.storage], d, &candidate_cameras_[b.storage]);
    }
  }
  for (size_t p = 0; p < free_points_.size(); ++p)
    for (int k = 0; k < 3; ++k) candidate_points_[3 * free_points_[p] + k] += step_p_[p][k];
}

double SchurLm::GradientMaxNorm() const {
  double norm = 0;
  for (const Block& b : blocks_) {
    if (b.size == 6) {
      norm = std::max(norm, gf_.segment<6>(b.offset).lpNorm<Eigen::Infinity>());
      continue;
    }
    // x - Plus(x, -g), as Ceres measures it on a manifold.
    const Eigen::Vector2d minus_g = -gf_.segment<2>(b.offset);
    double moved[3];
    ceres::SphereManifold<3>().Plus(&cameras_[b.storage], minus_g.data(), moved);
    for (int k = 0; k < 3; ++k) norm = std::max(norm, std::abs(cameras_[b.storage + k] - moved[k]));
  }
  for (const Eigen::Vector3d& g : gp_) norm = std::max(norm, g.lpNorm<Eigen::Infinity>());
  return norm;
}

double SchurLm::FreeNorm(const std::vector<double>& cameras,
                         const std::vector<double>& points) const {
  double sum = 0;
  for (const Block& b : blocks_) {
    const int ambient = b.size == 6 ? 6 : 3;
    for (int k = 0; k < ambient; ++k) sum += cameras[b.storage + k] * cameras[b.storage + k];
  }
  for (size_t p : free_points_)
    for (int k = 0; k < 3; ++k) sum += points[3 * p + k] * points[3 * p + k];
  return std::sqrt(sum);
}

bool SchurLm::Run(int max_iterations) {
  double cost = Evaluate(cameras_, points_, true);
  if (!std::isfinite(cost)) return false;
  BuildNormalEquations();
  if (GradientMaxNorm() <= kLmGradientTolerance) return true;
  LmTrustRegion region;
  double x_norm = FreeNorm(cameras_, points_);
  int invalid_steps = 0;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    double model_change = 0;
    const bool valid = ComputeStep(region.Radius()) && (model_change = ModelCostChange()) > 0.0;
    bool accepted = false;
    double relative_decrease = 0;
    if (!valid) {
      if (++invalid_steps >= kMaxInvalidSteps) return false;
    } else {
      invalid_steps = 0;
      Candidate();
      double step_norm = 0;
      for (size_t i = 0; i < cameras_.size(); ++i) {
        const double d = candidate_cameras_[i] - cameras_[i];
        step_norm += d * d;
      }
      for (size_t i = 0; i < points_.size(); ++i) {
        const double d = candidate_points_[i] - points_[i];
        step_norm += d * d;
      }
      if (std::sqrt(step_norm) <= kLmParameterTolerance * (x_norm + kLmParameterTolerance))
        return true;
      double candidate_cost = Evaluate(candidate_cameras_, candidate_points_, false);
      if (!std::isfinite(candidate_cost)) candidate_cost = std::numeric_limits<double>::max();
      if (std::abs(cost - candidate_cost) <= kLmFunctionTolerance * cost) return true;
      relative_decrease = (cost - candidate_cost) / model_change;
      accepted = relative_decrease > kLmMinRelativeDecrease;
      if (accepted) {
        // Copied, not swapped: the caller holds a pointer to the normals inside `cameras`.
        std::copy(candidate_cameras_.begin(), candidate_cameras_.end(), cameras_.begin());
        std::copy(candidate_points_.begin(), candidate_points_.end(), points_.begin());
        x_norm = FreeNorm(cameras_, points_);
        cost = Evaluate(cameras_, points_, true);
        BuildNormalEquations();
      }
    }
    if (accepted) {
      region.Accepted(relative_decrease);
      if (GradientMaxNorm() <= kLmGradientTolerance) return true;
    } else {
      region.Rejected();
    }
    if (region.Collapsed()) return true;
  }
  return true;
}

}  // namespace

bool SolveSchurLm(const BundleAdjustmentProblem& problem, const std::vector<bool>& skip,
                  int max_iterations, std::vector<double>& cameras, std::vector<double>& points,
                  double* normals, const std::vector<size_t>& normal_slot) {
  SchurLm solver(problem, skip, cameras, points, normals, normal_slot);
  if (solver.Empty()) return false;
  return solver.Run(max_iterations);
}

}  // namespace ademono::internal
