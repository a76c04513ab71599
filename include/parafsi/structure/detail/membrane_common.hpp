/// \file membrane_common.hpp
/// Pieces shared by the membrane elements (membrane_tri.hpp, membrane_quad.hpp), which
/// differ only in their kinematics:
///   fibre axes   E1 = warp projected on the element (a reference edge where the warp
///                is normal to it), E2 = N × E1;
///   stress       S = Q E (fabric.hpp, Eq. 4), S_v = β Q Ė (stiffness-proportional
///                damping, methods §5.4), wrinkling filter on both (material/wrinkling);
///   energy       ½ A0 t S:E per element;
///   time step    Δt = (√(1+ζ²) − ζ) / (c · max_e λ_max,e / L_c0,e)   (methods §5.5),
///                λ_max² the largest eigenvalue of C = I + 2E; β = ζ min_e L_c0,e / c;
///   loads        uniform or per-element pressure, checked finite;
///   set-up       option ranges, per-element warp count, node ids in range, the
///                stress-free reference (by default the positions at the first finalize).
///
/// References: Belytschko, Liu, Moran (2000) Nonlinear Finite Elements, §5.4, §6.2;
///   LS-DYNA Theory Manual (membrane elements, time step).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "../../core/error.hpp"
#include "../../core/simd.hpp"
#include "../material/fabric.hpp"
#include "../nodes.hpp"

namespace parafsi::structure::impl {

// ---------------------------------------------------------------- set-up
/// Ranges of the options both membrane elements have.
inline void check_membrane_options(const char* part, double damping_ratio, double min_quality) {
  require(damping_ratio >= 0 && damping_ratio < 1, part, ": damping ratio must be in [0, 1), got ", damping_ratio);
  require(min_quality >= 0 && min_quality < 1, part, ": min_quality must be in [0, 1), got ", min_quality);
}

/// warp_per_element is empty or has one direction per element (`elements`: their name).
inline void check_warp_count(const char* part, std::size_t n_warp, std::size_t n_elem, const char* elements) {
  require(n_warp == 0 || n_warp == n_elem, part, ": warp_per_element has ", n_warp, " entries for ", n_elem, " ",
          elements);
}

/// Warp direction of element e of a mesh (per element, or the mesh's common one),
/// refused if not finite (`part`: the element part's name).
template <class Mesh>
Eigen::Vector3d warp_of(const char* part, const Mesh& mesh, index_t e) {
  const Eigen::Vector3d w = mesh.warp_per_element.empty() ? mesh.warp : mesh.warp_per_element[std::size_t(e)];
  require(w.allFinite(), part, ": element ", e, " has a non-finite warp direction (", w.x(), ", ", w.y(), ", ", w.z(),
          ")");
  return w;
}

/// The reference positions of an element's nodes must be finite (a NaN is not a sliver).
template <std::size_t K>
void check_reference_finite(const char* part, index_t e, const std::array<Eigen::Vector3d, K>& X,
                            const std::array<index_t, K>& nodes_of) {
  for (std::size_t a = 0; a < K; ++a)
    require(X[a].allFinite(), part, ": element ", e, " has a non-finite reference position at node ", nodes_of[a], " (",
            X[a].x(), ", ", X[a].y(), ", ", X[a].z(), ")");
}

/// Without a given reference, the node positions at the first finalize become the
/// stress-free state (kept for later re-finalizes, e.g. after pinning a node); then the
/// reference must name every node.
inline void complete_reference(const char* part, std::vector<Eigen::Vector3d>& reference, bool& auto_reference,
                               const nodes& nd) {
  const index_t N = nd.size();
  if (reference.empty()) auto_reference = true;
  if (auto_reference)
    for (index_t i = index_t(reference.size()); i < N; ++i) reference.push_back(nd.position(i));
  require(index_t(reference.size()) == N, part, ": reference has ", reference.size(), " positions for ", N, " nodes");
}

/// Every node id of element e lies in [0, N).
template <std::size_t K>
void check_element_nodes(const char* part, index_t e, const std::array<index_t, K>& ids, index_t N) {
  for (std::size_t a = 0; a < K; ++a)
    require(ids[a] >= 0 && ids[a] < N, part, ": element ", e, " names node ", ids[a], " outside [0, ", N, ")");
}

/// Fibre axes (E1, E2) of an element with unit normal Nn: E1 = warp d projected on the
/// element, `fallback` (an in-plane reference edge) where d is normal to it; E2 = Nn × E1.
inline std::pair<Eigen::Vector3d, Eigen::Vector3d> fibre_axes(const Eigen::Vector3d& Nn, Eigen::Vector3d d,
                                                              const Eigen::Vector3d& fallback) {
  d -= d.dot(Nn) * Nn;
  if (d.norm() < 1e-6) d = fallback;
  const Eigen::Vector3d E1 = d.normalized(), E2 = Nn.cross(E1);
  return {E1, E2};
}

/// β = ζ L_c0,min / c (0 for an empty part): the damping ratio ζ in the highest mode.
inline double stiffness_damping(index_t n, double zeta, double lc_min, double wave_speed) {
  return n > 0 ? zeta * lc_min / wave_speed : 0.0;
}

// ---------------------------------------------------------------- loads
/// Uniform pressure p (Pa) in every slot of p_elem.
inline void set_uniform_pressure(const char* part, simd::aligned_vector<double>& p_elem, double p) {
  require(std::isfinite(p), part, "::set_pressure: non-finite pressure ", p);
  std::fill(p_elem.begin(), p_elem.end(), p);
}
/// Per-element pressure (Pa), one value for each of the n elements.
inline void set_element_pressure(const char* part, simd::aligned_vector<double>& p_elem, index_t n,
                                 std::span<const double> p) {
  require(index_t(p.size()) == n, part, "::set_pressure: got ", p.size(), " values for ", n, " elements");
  for (index_t e = 0; e < n; ++e) {
    require(std::isfinite(p[std::size_t(e)]), part, "::set_pressure: non-finite pressure at element ", e);
    p_elem[std::size_t(e)] = p[std::size_t(e)];
  }
}

// ---------------------------------------------------------------- stress
/// Elastic second Piola–Kirchhoff stress S = Q E in the fibre axes (Eq. 4; E12 tensorial).
template <class V>
PARAFSI_INLINE void elastic_stress(const fabric_moduli& q, const V& E11, const V& E22, const V& E12, V& S11, V& S22,
                                   V& S12) {
  S11 = V(q.Q11) * E11 + V(q.Q12) * E22;
  S22 = V(q.Q12) * E11 + V(q.Q22) * E22;
  S12 = V(2.0 * q.Q66) * E12;
}

/// Viscous stress S_v = β Q Ė from the strain rate (R11, R22, R12) = Ė.
template <class V>
PARAFSI_INLINE void viscous_stress(const fabric_moduli& q, const V& bt, const V& R11, const V& R22, const V& R12,
                                   V& D11, V& D22, V& D12) {
  D11 = bt * (V(q.Q11) * R11 + V(q.Q12) * R22);
  D22 = bt * (V(q.Q12) * R11 + V(q.Q22) * R22);
  D12 = bt * V(2.0 * q.Q66) * R12;
}

/// Stored energy ½ A0 t S:E of an element (at = A0 t).
template <class V>
PARAFSI_INLINE V membrane_energy(const V& at, const V& S11, const V& S22, const V& S12, const V& E11, const V& E22,
                                 const V& E12) {
  return V(0.5) * at * (S11 * E11 + S22 * E22 + V(2.0) * S12 * E12);
}

/// Green–Lagrange strain (E11, E22, 2E12) and filtered elastic stress (S11, S22, S12)
/// for output and tests.
template <class Fabric>
std::array<double, 6> strain_stress_of(const Fabric& mat, const fabric_moduli& q, double E11, double E22, double E12) {
  double S11, S22, S12, D11 = 0, D22 = 0, D12 = 0;
  elastic_stress(q, E11, E22, E12, S11, S22, S12);
  mat.wrinkling.apply(S11, S22, S12, D11, D22, D12, E11, E22, E12, q);
  return {E11, E22, 2.0 * E12, S11, S22, S12};
}

// ---------------------------------------------------------------- time step
/// max_e λ_max,e / L_c0,e over the n elements, with λ_max = √max(1, λ²_max(C)) and
/// strains(e, E11, E22, E12) the current Green–Lagrange strain of element e.
template <class Strains>
double stretch_rate(index_t n, const std::vector<double>& lc0, Strains&& strains) {
  double rate = 0;
  for (index_t e = 0; e < n; ++e) {
    double E11, E22, E12;
    strains(e, E11, E22, E12);
    const double C11 = 1 + 2 * E11, C22 = 1 + 2 * E22, C12 = 2 * E12;
    const double l2 = 0.5 * (C11 + C22) + std::sqrt(0.25 * (C11 - C22) * (C11 - C22) + C12 * C12);
    rate = std::max(rate, std::sqrt(std::max(1.0, l2)) / lc0[std::size_t(e)]);
  }
  return rate;
}

/// Δt = (√(1+ζ²) − ζ) / (rate · c); infinite for an empty part.
inline double membrane_step(double rate, double zeta, double wave_speed) {
  return rate > 0 ? (std::sqrt(1.0 + zeta * zeta) - zeta) / (rate * wave_speed)
                  : std::numeric_limits<double>::infinity();
}

}  // namespace parafsi::structure::impl
