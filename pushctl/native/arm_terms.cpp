// The arm's terms of one step (ArmModel.compute) called from compiled code: a C entry point
// around Pinocchio's own algorithms, so that numba kernels reach them without a Python call.
//
// Only the calls are compiled here: with PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION defined,
// Pinocchio's headers declare computeAllTerms and getFrameJacobian for double extern, so
// this file links to the instances in the installed libpinocchio_default, the same machine
// code the Python bindings run: every number is the bindings' to the bit
// (tests/native/test_arm_terms.py checks it). The model arrives
// as Pinocchio's own text serialisation of the Python model (ArmModel.model.saveToString).
//
// Built by `python -m pushctl.native.build` (the Makefile's install does it); without
// it the project runs the same calls from Python (pushctl/arm/model.py).

#include <pinocchio/algorithm/compute-all-terms.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/serialization.hpp>

#include <cstdint>
#include <string>

namespace {

using pinocchio::Data;
using pinocchio::FrameIndex;
using pinocchio::Model;
using ConstVectorRef = Eigen::Ref<const Eigen::VectorXd>;
using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using Jacobian6 = Eigen::Matrix<double, 6, Eigen::Dynamic>;

struct Arm {
  Model model;
  Data data;
};

// One frame's world placement and Jacobian (rows [linear; angular], world-aligned axes),
// written to C-ordered arrays: position (3,), rotation (3, 3), jacobian (rows, nv) of the
// Jacobian's first `rows` rows. getFrameJacobian places the frame first (data.oMf).
void write_frame(Arm &arm, FrameIndex frame, int rows, double *position, double *rotation,
                 double *jacobian) {
  const int nv = arm.model.nv;
  const Jacobian6 full =
      pinocchio::getFrameJacobian(arm.model, arm.data, frame, pinocchio::LOCAL_WORLD_ALIGNED);
  Eigen::Map<RowMajorMatrix>(jacobian, rows, nv) = full.topRows(rows);
  const auto &placement = arm.data.oMf[frame];
  Eigen::Map<Eigen::Vector3d> translation_out(position);
  translation_out = placement.translation();
  if (rotation != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> rotation_out(rotation);
    rotation_out = placement.rotation();
  }
}

}  // namespace

extern "C" {

// A model from its text serialisation; nullptr if it does not load.
void *pushctl_arm_create(const char *text, std::int64_t size) {
  try {
    auto *arm = new Arm;
    arm->model.loadFromString(std::string(text, static_cast<std::size_t>(size)));
    arm->data = Data(arm->model);
    return arm;
  } catch (...) {
    return nullptr;
  }
}

void pushctl_arm_free(void *handle) { delete static_cast<Arm *>(handle); }

// ArmModel.compute's pass: computeAllTerms at (q, v), M's strict lower triangle copied from
// its upper one (as the Python bindings return M), then the k prong frames (positions and
// the linear rows of their Jacobians), the pusher frame and, if `nominal` >= 0, the nominal
// pusher frame. Shapes: q (nq,), v (nv,), prongs (k,), M (nv, nv), nle and g (nv,),
// prong_positions (k, 3), prong_jacobians (k, 3, nv), pusher_* and nominal_* (3,), (3, 3),
// (6, nv); all C-ordered float64 (the nominal ones unused when nominal < 0).
void pushctl_arm_terms(void *handle, const double *q, const double *v, std::int64_t k,
                       const std::int64_t *prongs, std::int64_t pusher, std::int64_t nominal,
                       double *M, double *nle, double *g, double *prong_positions,
                       double *prong_jacobians, double *pusher_position,
                       double *pusher_rotation, double *pusher_jacobian,
                       double *nominal_position, double *nominal_rotation,
                       double *nominal_jacobian) {
  Arm &arm = *static_cast<Arm *>(handle);
  const int nq = arm.model.nq, nv = arm.model.nv;
  const Eigen::Map<const Eigen::VectorXd> q_map(q, nq), v_map(v, nv);
  pinocchio::computeAllTerms(arm.model, arm.data, ConstVectorRef(q_map), ConstVectorRef(v_map));
  Eigen::MatrixXd &mass = arm.data.M;
  mass.triangularView<Eigen::StrictlyLower>() =
      mass.transpose().triangularView<Eigen::StrictlyLower>();
  Eigen::Map<RowMajorMatrix>(M, nv, nv) = mass;
  Eigen::Map<Eigen::VectorXd>(nle, nv) = arm.data.nle;
  Eigen::Map<Eigen::VectorXd>(g, nv) = arm.data.g;
  for (std::int64_t i = 0; i < k; ++i) {
    write_frame(arm, static_cast<FrameIndex>(prongs[i]), 3, prong_positions + 3 * i, nullptr,
                prong_jacobians + 3 * nv * i);
  }
  write_frame(arm, static_cast<FrameIndex>(pusher), 6, pusher_position, pusher_rotation,
              pusher_jacobian);
  if (nominal >= 0) {
    write_frame(arm, static_cast<FrameIndex>(nominal), 6, nominal_position, nominal_rotation,
                nominal_jacobian);
  }
}

// ArmModel.integrate: the configuration reached from q (nq,) moving at v (nv,) [rad/s] for
// h [s], into q_out (nq,): Pinocchio's integrate of v·h (the product formed first, as the
// Python path forms it), so joints whose configuration is not a vector (a continuous joint's
// cos/sin) integrate on their manifold.
void pushctl_arm_integrate(void *handle, const double *q, const double *v, double h,
                           double *q_out) {
  const Arm &arm = *static_cast<Arm *>(handle);
  const int nq = arm.model.nq, nv = arm.model.nv;
  const Eigen::Map<const Eigen::VectorXd> q_map(q, nq), v_map(v, nv);
  const Eigen::VectorXd step = v_map * h;
  Eigen::Map<Eigen::VectorXd> out(q_out, nq);
  out = pinocchio::integrate(arm.model, q_map, step);
}

}  // extern "C"
