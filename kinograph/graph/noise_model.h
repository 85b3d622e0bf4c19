#pragma once
// Noise models turn a factor's raw error e into the whitened residual r whose squared norm is
// the factor's cost (cost = ½‖r‖²), and transform the Jacobian of e into that of r.
#include <Eigen/Core>
#include <memory>

namespace kinograph::graph {

/// Base of all noise models: maps the raw error e (and optionally its Jacobian J = de/dx) to the
/// whitened residual r (and dr/dx), in place.
class NoiseModel {
 public:
  explicit NoiseModel(int dim) : dim_(dim) {}
  virtual ~NoiseModel() = default;

  /// Dimension of the error this model whitens.
  int dim() const { return dim_; }
  /// e ← r(e).
  virtual void whiten_residual(Eigen::Ref<Eigen::VectorXd> e) const = 0;
  /// e ← r(e) and J ← dr/de · J (J has dim() rows and any number of columns).
  virtual void whiten_system(Eigen::Ref<Eigen::VectorXd> e,
                             Eigen::Ref<Eigen::MatrixXd> J) const = 0;
  /// Whether dr/de is a constant (every model but a hinge), so that a factor linear in its
  /// variables keeps a constant whitened Jacobian.
  virtual bool constant_whitening() const { return true; }

 private:
  int dim_;
};

using NoiseModelPtr = std::shared_ptr<const NoiseModel>;

/// Same standard deviation σ on every component: r = e / σ.
class IsotropicNoise final : public NoiseModel {
 public:
  /// Throws std::invalid_argument unless sigma > 0.
  IsotropicNoise(int dim, double sigma);
  double sigma() const { return sigma_; }
  void whiten_residual(Eigen::Ref<Eigen::VectorXd> e) const override;
  void whiten_system(Eigen::Ref<Eigen::VectorXd> e, Eigen::Ref<Eigen::MatrixXd> J) const override;

 private:
  double sigma_;
  double inv_sigma_;
};

/// Independent components with standard deviations σ_i: r_i = e_i / σ_i.
class DiagonalNoise final : public NoiseModel {
 public:
  /// Throws std::invalid_argument unless every sigma > 0.
  explicit DiagonalNoise(const Eigen::Ref<const Eigen::VectorXd>& sigmas);
  const Eigen::VectorXd& sigmas() const { return sigmas_; }
  void whiten_residual(Eigen::Ref<Eigen::VectorXd> e) const override;
  void whiten_system(Eigen::Ref<Eigen::VectorXd> e, Eigen::Ref<Eigen::MatrixXd> J) const override;

 private:
  Eigen::VectorXd sigmas_;
  Eigen::VectorXd inv_sigmas_;
};

/// Correlated Gaussian noise with covariance Σ (e.g. the GP prior's Q): r = R e where
/// RᵀR = Σ⁻¹ (R the upper Cholesky factor of the information matrix), so ‖r‖² = eᵀΣ⁻¹e.
class GaussianNoise final : public NoiseModel {
 public:
  /// From a covariance; throws std::invalid_argument unless it is symmetric positive definite.
  static std::shared_ptr<GaussianNoise> from_covariance(const Eigen::MatrixXd& covariance);
  /// From an information (inverse covariance) matrix; same checks.
  static std::shared_ptr<GaussianNoise> from_information(const Eigen::MatrixXd& information);

  /// The square-root information R (upper triangular).
  const Eigen::MatrixXd& sqrt_information() const { return R_; }
  void whiten_residual(Eigen::Ref<Eigen::VectorXd> e) const override;
  void whiten_system(Eigen::Ref<Eigen::VectorXd> e, Eigen::Ref<Eigen::MatrixXd> J) const override;

  explicit GaussianNoise(Eigen::MatrixXd sqrt_information);

 private:
  Eigen::MatrixXd R_;
};

/// The paper's hinge limit c_limit (its eq. "hinge"), applied per component to the raw value
/// z = e_i of a limited quantity with bounds [lower_i, upper_i]:
///   r_i = a·(lower_i − z + ε)  if z − lower_i ≤ ε,
///   r_i = a·(z − upper_i + ε)  if upper_i − z ≤ ε,
///   r_i = 0                    otherwise.
/// So dr_i/dz is −a, +a or 0. Bounds may be ±infinity for one-sided limits (e.g. a signed
/// distance that must stay above a safety margin). The factor wrapped by it returns z itself.
class HingeNoise final : public NoiseModel {
 public:
  /// Throws std::invalid_argument if sizes differ, epsilon < 0, slope <= 0, or any
  /// lower_i + ε > upper_i − ε (the zero-cost band would be empty).
  HingeNoise(const Eigen::Ref<const Eigen::VectorXd>& lower,
             const Eigen::Ref<const Eigen::VectorXd>& upper, double epsilon, double slope);
  const Eigen::VectorXd& lower() const { return lower_; }
  const Eigen::VectorXd& upper() const { return upper_; }
  double epsilon() const { return epsilon_; }
  double slope() const { return slope_; }
  void whiten_residual(Eigen::Ref<Eigen::VectorXd> e) const override;
  void whiten_system(Eigen::Ref<Eigen::VectorXd> e, Eigen::Ref<Eigen::MatrixXd> J) const override;
  bool constant_whitening() const override { return false; }

 private:
  Eigen::VectorXd lower_;
  Eigen::VectorXd upper_;
  double epsilon_;
  double slope_;
};

/// Shorthands for building shared noise models.
NoiseModelPtr isotropic(int dim, double sigma);
NoiseModelPtr diagonal(const Eigen::Ref<const Eigen::VectorXd>& sigmas);
NoiseModelPtr gaussian_covariance(const Eigen::MatrixXd& covariance);
NoiseModelPtr gaussian_information(const Eigen::MatrixXd& information);
NoiseModelPtr hinge(const Eigen::Ref<const Eigen::VectorXd>& lower,
                    const Eigen::Ref<const Eigen::VectorXd>& upper, double epsilon, double slope);

}  // namespace kinograph::graph
