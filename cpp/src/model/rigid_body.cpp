#include "mechbal/model/rigid_body.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace mechbal {

void validate_rigid_body(const RigidBody& body, const char* field) {
  std::ostringstream msg;
  if (!std::isfinite(body.mass) || body.mass < 0.0) {
    msg << field << ".mass must be a finite number >= 0, got " << body.mass;
    throw std::invalid_argument(msg.str());
  }
  const Mat3& I = body.inertia_body;
  if (!I.allFinite()) {
    msg << field << ".inertia must be finite, got [" << I.format(Eigen::IOFormat(6, 0, ", ", "; "))
        << "]";
    throw std::invalid_argument(msg.str());
  }
  const double scale = std::max(1.0, I.cwiseAbs().maxCoeff());
  if ((I - I.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale) {
    msg << field << ".inertia must be symmetric, got ["
        << I.format(Eigen::IOFormat(6, 0, ", ", "; ")) << "]";
    throw std::invalid_argument(msg.str());
  }
  Eigen::SelfAdjointEigenSolver<Mat3> eig(I, Eigen::EigenvaluesOnly);
  const Vec3 p = eig.eigenvalues();  // ascending
  const double tol = 1e-12 * scale;
  if (p(0) < -tol) {
    msg << field << ".inertia must be positive semi-definite, smallest principal moment is "
        << p(0);
    throw std::invalid_argument(msg.str());
  }
  if (p(2) > p(0) + p(1) + tol) {
    msg << field << ".inertia violates the triangle inequality of a physical body: principal "
        << "moments " << p(0) << ", " << p(1) << ", " << p(2);
    throw std::invalid_argument(msg.str());
  }
}

}  // namespace mechbal
