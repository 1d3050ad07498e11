// Linear complementarity problems of contact: find f with
//   f >= 0,  w = A f + b >= 0,  f . w = 0
// (Baraff 1997, "Rigid Body Simulation II", section 9, eqs. (9-5)-(9-7): the
// non-penetration, repulsive and workless conditions, solved for all
// contacts at once; here in their velocity-level form over a step).
#ifndef RIGID_BODY_SIM_PHYSICS_SOLVER_LCP_H_
#define RIGID_BODY_SIM_PHYSICS_SOLVER_LCP_H_

#include <Eigen/Core>

#include "rigid_body_sim/physics/result.h"

namespace rigid_body_sim::physics {

struct LcpSolution {
  Eigen::VectorXd f;  // the unknowns (forces or impulses), >= 0
  Eigen::VectorXd w;  // A f + b, >= 0
  int pivots = 0;
};

// Exact pivoting solver (Lemke's complementary pivoting with covering vector
// d = 1), followed by one refinement of the active set by a direct solve. It
// terminates with a solution for any positive semi-definite A when one
// exists; an unbounded ray means none does, reported as an error.
Result<LcpSolution> SolveLcpLemke(const Eigen::MatrixXd& a, const Eigen::VectorXd& b);

struct PgsSettings {
  int max_iterations = 200;  // sweeps
  double tolerance = 1e-12;  // stop when no unknown changes by more than this (units of f)
};

// Projected Gauss-Seidel: f_i <- max(0, f_i - (b_i + A_i. f) / A_ii), sweeping
// until converged. `f` holds the warm start on entry. Returns the sweeps used.
// Needs A_ii > 0.
int SolveLcpPgs(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, const PgsSettings& settings,
                Eigen::VectorXd* f);

// Largest violation of the three conditions: max(-f_i, -w_i, |f_i w_i|).
double LcpViolation(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, const Eigen::VectorXd& f);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_SOLVER_LCP_H_
