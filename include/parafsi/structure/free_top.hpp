/// \file free_top.hpp
/// Closed-form reference for the torque-free asymmetric top (Euler–Poinsot motion),
/// used to verify rigid_body: the period of the body angular velocity.
///
/// Order the principal moments I1 < I2 < I3 and let 2E = Σ I_i ω_i², M² = Σ I_i² ω_i²
/// (both invariant). For M² > 2E I2 (Landau & Lifshitz, Mechanics §37)
///   ω1 = A1 cn(τ, k),  ω2 = A2 sn(τ, k),  ω3 = A3 dn(τ, k),  τ = λ t,
///   λ² = (I3 − I2)(M² − 2E I1) / (I1 I2 I3),
///   k² = (I2 − I1)(2E I3 − M²) / ((I3 − I2)(M² − 2E I1)),
///   1 − k² = (I3 − I1)(M² − 2E I2) / ((I3 − I2)(M² − 2E I1));
/// for M² < 2E I2 exchange the indices 1 and 3 throughout. The component along the
/// intermediate axis is always the sn one, so it reverses sign ("flips") every 2K/λ
/// and its period is
///   T = 4 K(k) / λ,   K(k) = ∫₀^{π/2} dφ / √(1 − k² sin²φ) = π / (2 AGM(1, √(1 − k²))).
/// Near the separatrix M² = 2E I2, K ≈ ln(4/k'), so T grows logarithmically.
/// Differences M² − 2E I_j = Σ_i I_i (I_i − I_j) ω_i² are formed without cancellation.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Dense>

namespace parafsi::structure {

/// Complete elliptic integral of the first kind K(k) from the complementary modulus
/// k' = √(1 − k²) by the arithmetic–geometric mean (accurate as k' → 0).
inline double complete_elliptic_k_from_complement(double k_prime) {
  double a = 1.0, b = k_prime;
  for (int i = 0; i < 64 && std::abs(a - b) > 1e-16 * a; ++i) {
    const double an = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = an;
  }
  return std::numbers::pi / (a + b);
}

/// Period (s) of the body angular velocity of a torque-free rigid body with principal
/// moments `inertia` (any order) and body angular velocity `omega_body`: the time
/// between successive sign changes of the intermediate-axis component in the same
/// direction (two flips). Returns +infinity when there is no such oscillation (two equal
/// moments or exactly on the separatrix) and quiet NaN for ω = 0.
inline double free_top_period(const Eigen::Vector3d& inertia, const Eigen::Vector3d& omega_body) {
  std::array<int, 3> idx{0, 1, 2};
  std::sort(idx.begin(), idx.end(), [&](int a, int b) { return inertia[a] < inertia[b]; });
  const double I1 = inertia[idx[0]], I2 = inertia[idx[1]], I3 = inertia[idx[2]];
  if (omega_body.squaredNorm() == 0) return std::numeric_limits<double>::quiet_NaN();
  if (!(I1 < I2 && I2 < I3)) return std::numeric_limits<double>::infinity();
  // D_j = M² − 2E I_j.
  auto D = [&](double Ij) {
    double s = 0;
    for (int i = 0; i < 3; ++i) s += inertia[i] * (inertia[i] - Ij) * omega_body[i] * omega_body[i];
    return s;
  };
  const double D1 = D(I1), D2 = D(I2), D3 = D(I3);
  if (D2 == 0) return std::numeric_limits<double>::infinity();
  double lambda2, kp2;
  if (D2 > 0) {
    lambda2 = (I3 - I2) * D1 / (I1 * I2 * I3);
    kp2 = (I3 - I1) * D2 / ((I3 - I2) * D1);
  } else {
    lambda2 = (I2 - I1) * (-D3) / (I1 * I2 * I3);
    kp2 = (I3 - I1) * (-D2) / ((I2 - I1) * (-D3));
  }
  const double K = complete_elliptic_k_from_complement(std::sqrt(std::clamp(kp2, 0.0, 1.0)));
  return 4.0 * K / std::sqrt(lambda2);
}

/// Index (0, 1, 2) of the intermediate principal moment, or −1 if two are equal.
inline int intermediate_axis(const Eigen::Vector3d& inertia) {
  std::array<int, 3> idx{0, 1, 2};
  std::sort(idx.begin(), idx.end(), [&](int a, int b) { return inertia[a] < inertia[b]; });
  if (!(inertia[idx[0]] < inertia[idx[1]] && inertia[idx[1]] < inertia[idx[2]])) return -1;
  return idx[1];
}

}  // namespace parafsi::structure
