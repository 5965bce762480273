// The force distribution's per-step QPs (pushctl/planning/forces.py, _StepQP.solve) in one
// call: the same ProxQP calls, in the same order, as the Python loop makes through the
// bindings, without its round trip per QP (about 7500 QPs per reset of the training
// environment).
//
// ProxSuite is header-only; this file is built, like the portable bindings pushctl loads
// (pushctl/proxqp_build.py), for the baseline x86-64 instruction set, so its answers are
// the bindings' to the bit (tests/native/test_force_qps.py).

#include <proxsuite/proxqp/dense/dense.hpp>

#include <cstdint>

namespace {

using proxsuite::nullopt;
using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

}  // namespace

extern "C" {

// One QP object of n variables and m inequalities l ≤ C x ≤ u with Hessian H (n, n), made
// as _StepQP makes it (eps_abs, eps_rel 0, max_iter; init with g = 0; then warm starts from
// the previous result), solved for each of the `count` gradients (count, n) in turn. Writes
// each solve's x into x (count, n) and whether ProxQP reported it solved into solved
// (count,); the caller solves the unsolved ones again from scratch, as the Python loop
// does (those solves never touch this QP object). Matrices C-ordered float64.
void pushctl_force_qps(std::int64_t n, std::int64_t m, const double *H, const double *C,
                       const double *l, const double *u, std::int64_t count,
                       const double *gradients, double eps_abs, std::int64_t max_iter,
                       double *x, std::int8_t *solved) {
  namespace qp = proxsuite::proxqp;
  const Eigen::MatrixXd hessian = Eigen::Map<const RowMajorMatrix>(H, n, n);
  const Eigen::MatrixXd cone = Eigen::Map<const RowMajorMatrix>(C, m, n);
  const Eigen::VectorXd lower = Eigen::Map<const Eigen::VectorXd>(l, m);
  const Eigen::VectorXd upper = Eigen::Map<const Eigen::VectorXd>(u, m);
  qp::dense::QP<double> problem(n, 0, m, false, qp::HessianType::Dense,
                                qp::DenseBackend::Automatic);
  problem.settings.eps_abs = eps_abs;
  problem.settings.eps_rel = 0.0;
  problem.settings.max_iter = max_iter;
  problem.init(hessian, Eigen::VectorXd::Zero(n), nullopt, nullopt, cone, lower, upper);
  problem.settings.initial_guess = qp::InitialGuessStatus::WARM_START_WITH_PREVIOUS_RESULT;
  Eigen::VectorXd gradient(n);
  for (std::int64_t i = 0; i < count; ++i) {
    gradient = Eigen::Map<const Eigen::VectorXd>(gradients + i * n, n);
    // C, l and u are passed again as the Python loop passes them: updating g alone trips
    // an assertion inside ProxSuite 0.8.0 (and crashes its bindings) on these problems.
    problem.update(nullopt, gradient, nullopt, nullopt, cone, lower, upper);
    problem.solve();
    solved[i] = problem.results.info.status == qp::QPSolverOutput::PROXQP_SOLVED;
    Eigen::Map<Eigen::VectorXd>(x + i * n, n) = problem.results.x;
  }
}

}  // extern "C"
