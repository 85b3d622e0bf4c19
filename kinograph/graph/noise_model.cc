#include "kinograph/graph/noise_model.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kinograph::graph {

IsotropicNoise::IsotropicNoise(int dim, double sigma)
    : NoiseModel(dim), sigma_(sigma), inv_sigma_(1.0 / sigma) {
  if (!(sigma > 0) || !std::isfinite(sigma) || dim < 1) {
    throw std::invalid_argument("IsotropicNoise: need dim >= 1 and finite sigma > 0, got sigma " +
                                std::to_string(sigma));
  }
}

void IsotropicNoise::whiten_residual(Eigen::Ref<Eigen::VectorXd> e) const { e *= inv_sigma_; }

void IsotropicNoise::whiten_system(Eigen::Ref<Eigen::VectorXd> e,
                                   Eigen::Ref<Eigen::MatrixXd> J) const {
  e *= inv_sigma_;
  J *= inv_sigma_;
}

DiagonalNoise::DiagonalNoise(const Eigen::Ref<const Eigen::VectorXd>& sigmas)
    : NoiseModel(static_cast<int>(sigmas.size())), sigmas_(sigmas) {
  if (sigmas.size() == 0 || !(sigmas.array() > 0).all() || !sigmas.allFinite()) {
    throw std::invalid_argument("DiagonalNoise: every sigma must be finite and > 0");
  }
  inv_sigmas_ = sigmas_.cwiseInverse();
}

void DiagonalNoise::whiten_residual(Eigen::Ref<Eigen::VectorXd> e) const {
  e.array() *= inv_sigmas_.array();
}

void DiagonalNoise::whiten_system(Eigen::Ref<Eigen::VectorXd> e,
                                  Eigen::Ref<Eigen::MatrixXd> J) const {
  e.array() *= inv_sigmas_.array();
  J.array().colwise() *= inv_sigmas_.array();
}

namespace {
Eigen::MatrixXd upper_cholesky(const Eigen::MatrixXd& M, const char* what) {
  if (M.rows() != M.cols() || M.rows() == 0 || !M.allFinite()) {
    throw std::invalid_argument(std::string("GaussianNoise: ") + what +
                                " must be a finite non-empty square matrix");
  }
  if (!M.isApprox(M.transpose(), 1e-9)) {
    throw std::invalid_argument(std::string("GaussianNoise: ") + what + " is not symmetric");
  }
  Eigen::LLT<Eigen::MatrixXd> llt(M);
  if (llt.info() != Eigen::Success) {
    throw std::invalid_argument(std::string("GaussianNoise: ") + what +
                                " is not positive definite");
  }
  return llt.matrixU();
}
}  // namespace

GaussianNoise::GaussianNoise(Eigen::MatrixXd sqrt_information)
    : NoiseModel(static_cast<int>(sqrt_information.rows())), R_(std::move(sqrt_information)) {
  if (R_.rows() != R_.cols() || R_.rows() == 0) {
    throw std::invalid_argument("GaussianNoise: square-root information must be square");
  }
}

std::shared_ptr<GaussianNoise> GaussianNoise::from_information(const Eigen::MatrixXd& information) {
  return std::make_shared<GaussianNoise>(upper_cholesky(information, "information"));
}

std::shared_ptr<GaussianNoise> GaussianNoise::from_covariance(const Eigen::MatrixXd& covariance) {
  // Σ = LLᵀ ⇒ Σ⁻¹ = L⁻ᵀL⁻¹, so R = L⁻¹ gives RᵀR = Σ⁻¹ but is lower triangular; factor the
  // information instead to keep R upper triangular (cheaper products, as documented).
  upper_cholesky(covariance, "covariance");  // validates
  const Eigen::MatrixXd information =
      covariance.llt().solve(Eigen::MatrixXd::Identity(covariance.rows(), covariance.cols()));
  return std::make_shared<GaussianNoise>(
      upper_cholesky(0.5 * (information + information.transpose()), "covariance's inverse"));
}

// In place: row i of R e only reads e_j for j >= i, which are still unmodified when going
// down the rows, so no temporary (and no allocation) is needed.
void GaussianNoise::whiten_residual(Eigen::Ref<Eigen::VectorXd> e) const {
  const Eigen::Index n = R_.rows();
  for (Eigen::Index i = 0; i < n; ++i) e[i] = R_.row(i).tail(n - i).dot(e.tail(n - i));
}

void GaussianNoise::whiten_system(Eigen::Ref<Eigen::VectorXd> e,
                                  Eigen::Ref<Eigen::MatrixXd> J) const {
  whiten_residual(e);
  const Eigen::Index n = R_.rows();
  if (n < 8) {  // small: in place, as whiten_residual, column by column
    for (Eigen::Index k = 0; k < J.cols(); ++k) {
      for (Eigen::Index i = 0; i < n; ++i) {
        J(i, k) = R_.row(i).tail(n - i).dot(J.col(k).tail(n - i));
      }
    }
    return;
  }
  // Large (e.g. the GP prior's 3n×3n): a dense product, whose blocking lives on the stack at
  // these sizes, into a per-thread buffer, so the hot loop allocates nothing after first use.
  thread_local Eigen::VectorXd buffer;  // grows only, so factors of other sizes reuse it
  if (buffer.size() < J.size()) buffer.resize(J.size());
  Eigen::Map<Eigen::MatrixXd> RJ(buffer.data(), J.rows(), J.cols());
  RJ.noalias() = R_ * J;
  J = RJ;
}

HingeNoise::HingeNoise(const Eigen::Ref<const Eigen::VectorXd>& lower,
                       const Eigen::Ref<const Eigen::VectorXd>& upper, double epsilon, double slope)
    : NoiseModel(static_cast<int>(lower.size())),
      lower_(lower),
      upper_(upper),
      epsilon_(epsilon),
      slope_(slope) {
  if (lower.size() == 0 || lower.size() != upper.size()) {
    throw std::invalid_argument("HingeNoise: lower and upper must have the same non-zero size");
  }
  if (!(epsilon >= 0) || !(slope > 0) || !std::isfinite(epsilon) || !std::isfinite(slope)) {
    throw std::invalid_argument("HingeNoise: need epsilon >= 0 and slope > 0");
  }
  for (int i = 0; i < lower.size(); ++i) {
    if (std::isnan(lower[i]) || std::isnan(upper[i]) || lower[i] + epsilon > upper[i] - epsilon) {
      throw std::invalid_argument("HingeNoise: component " + std::to_string(i) +
                                  " has an empty band [lower+eps, upper-eps]");
    }
  }
}

void HingeNoise::whiten_residual(Eigen::Ref<Eigen::VectorXd> e) const {
  for (int i = 0; i < e.size(); ++i) {
    const double z = e[i];
    if (z - lower_[i] <= epsilon_) {
      e[i] = slope_ * (lower_[i] - z + epsilon_);
    } else if (upper_[i] - z <= epsilon_) {
      e[i] = slope_ * (z - upper_[i] + epsilon_);
    } else {
      e[i] = 0;
    }
  }
}

void HingeNoise::whiten_system(Eigen::Ref<Eigen::VectorXd> e, Eigen::Ref<Eigen::MatrixXd> J) const {
  for (int i = 0; i < e.size(); ++i) {
    const double z = e[i];
    if (z - lower_[i] <= epsilon_) {
      e[i] = slope_ * (lower_[i] - z + epsilon_);
      J.row(i) *= -slope_;
    } else if (upper_[i] - z <= epsilon_) {
      e[i] = slope_ * (z - upper_[i] + epsilon_);
      J.row(i) *= slope_;
    } else {
      e[i] = 0;
      J.row(i).setZero();
    }
  }
}

NoiseModelPtr isotropic(int dim, double sigma) {
  return std::make_shared<IsotropicNoise>(dim, sigma);
}
NoiseModelPtr diagonal(const Eigen::Ref<const Eigen::VectorXd>& sigmas) {
  return std::make_shared<DiagonalNoise>(sigmas);
}
NoiseModelPtr gaussian_covariance(const Eigen::MatrixXd& covariance) {
  return GaussianNoise::from_covariance(covariance);
}
NoiseModelPtr gaussian_information(const Eigen::MatrixXd& information) {
  return GaussianNoise::from_information(information);
}
NoiseModelPtr hinge(const Eigen::Ref<const Eigen::VectorXd>& lower,
                    const Eigen::Ref<const Eigen::VectorXd>& upper, double epsilon, double slope) {
  return std::make_shared<HingeNoise>(lower, upper, epsilon, slope);
}

}  // namespace kinograph::graph
