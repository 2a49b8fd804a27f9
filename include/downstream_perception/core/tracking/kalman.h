// Constant-velocity Kalman filter over a D-dimensional position (D = 2: a metric x, y; D = 4: an
// image box's centre and size). State [p, v] (2D), white-noise acceleration process model.
#pragma once

#include <algorithm>

#include <Eigen/Cholesky>
#include <Eigen/Core>

namespace downstream_perception {

template <int D>
class ConstantVelocityKalman {
 public:
  using Vec = Eigen::Matrix<double, D, 1>;
  using Mat = Eigen::Matrix<double, D, D>;
  using State = Eigen::Matrix<double, 2 * D, 1>;
  using Cov = Eigen::Matrix<double, 2 * D, 2 * D>;

  ConstantVelocityKalman() = default;
  /// Starts at `position` (covariance `position_cov`) with zero velocity of standard deviation
  /// `velocity_std` per axis.
  ConstantVelocityKalman(const Vec& position, const Mat& position_cov, double velocity_std) {
    x_.setZero();
    x_.template head<D>() = position;
    P_.setZero();
    P_.template topLeftCorner<D, D>() = position_cov;
    P_.template bottomRightCorner<D, D>() = Mat::Identity() * velocity_std * velocity_std;
  }

  /// Advances by dt seconds. `accel_psd` is the spectral density q of the white acceleration
  /// noise per axis (units of position^2 / s^3): Q = q [dt^3/3, dt^2/2; dt^2/2, dt] per axis.
  void predict(double dt, double accel_psd) { predict(dt, Vec::Constant(accel_psd)); }
  void predict(double dt, const Vec& accel_psd) {
    if (dt <= 0.0) return;
    x_.template head<D>() += dt * x_.template tail<D>();
    // P <- F P F' with F = [I, dt I; 0, I], written out block-wise.
    const Mat pp = P_.template topLeftCorner<D, D>();
    const Mat pv = P_.template topRightCorner<D, D>();
    const Mat vv = P_.template bottomRightCorner<D, D>();
    const Mat new_pv = pv + dt * vv;
    P_.template topLeftCorner<D, D>() = pp + dt * (pv + pv.transpose()) + dt * dt * vv;
    P_.template topRightCorner<D, D>() = new_pv;
    P_.template bottomLeftCorner<D, D>() = new_pv.transpose();
    const double dt2 = dt * dt;
    for (int k = 0; k < D; ++k) {
      const double q = accel_psd(k);
      P_(k, k) += q * dt2 * dt / 3.0;
      P_(k, D + k) += q * dt2 / 2.0;
      P_(D + k, k) += q * dt2 / 2.0;
      P_(D + k, D + k) += q * dt;
    }
  }

  /// Innovation covariance S = H P H' + R for a position measurement with covariance R.
  Mat innovationCov(const Mat& R) const { return P_.template topLeftCorner<D, D>() + R; }
  /// Squared Mahalanobis distance of a position measurement z: r' S^-1 r.
  double mahalanobis2(const Vec& z, const Mat& R) const {
    const Vec r = z - x_.template head<D>();
    return r.dot(innovationCov(R).ldlt().solve(r));
  }
  /// Same with a precomputed S^-1 (gating many detections against one track).
  double mahalanobis2(const Vec& z, const Mat& s_inverse, bool) const {
    const Vec r = z - x_.template head<D>();
    return r.dot(s_inverse * r);
  }

  /// Position measurement update (Joseph form: P stays symmetric positive semi-definite).
  void update(const Vec& z, const Mat& R) {
    const Mat S = innovationCov(R);
    // K = P H' S^-1, with H = [I 0]: P H' = the left D columns of P.
    const Eigen::Matrix<double, 2 * D, D> PHt = P_.template leftCols<D>();
    const Eigen::Matrix<double, 2 * D, D> K = S.ldlt().solve(PHt.transpose()).transpose();
    x_ += K * (z - x_.template head<D>());
    Cov I_KH = Cov::Identity();
    I_KH.template leftCols<D>() -= K;
    P_ = I_KH * P_ * I_KH.transpose() + K * R * K.transpose();
  }

  Vec position() const { return x_.template head<D>(); }
  Vec velocity() const { return x_.template tail<D>(); }
  Mat positionCov() const { return P_.template topLeftCorner<D, D>(); }
  Mat velocityCov() const { return P_.template bottomRightCorner<D, D>(); }
  const State& state() const { return x_; }
  /// Keeps position axis k at least `floor`: a state below it is raised to it and its velocity
  /// along k stops falling (a coasting box that shrinks must not turn inside out).
  void clampPositionBelow(int k, double floor) {
    if (!(x_(k) < floor)) return;
    x_(k) = floor;
    x_(D + k) = std::max(0.0, x_(D + k));
  }
  const Cov& covariance() const { return P_; }

 private:
  State x_ = State::Zero();
  Cov P_ = Cov::Identity();
};

/// Chi-square quantile: the squared Mahalanobis gate for `dof` dimensions at `confidence`
/// (2 dof, 0.99 -> 9.21). Throws std::invalid_argument outside dof >= 1, 0 < confidence < 1.
double chiSquareQuantile(int dof, double confidence);

}  // namespace downstream_perception
