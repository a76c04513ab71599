/// \file membrane_tri.hpp
/// Total-Lagrangian constant-strain triangle (CST) membrane, the default fabric element
/// (methods §5.1). Per element, with reference (stress-free) corners X_a mapped to 2-D
/// fibre coordinates (X̂, Ŷ) in the basis E1 = warp direction projected on the element,
/// E2 = N × E1:
///   ∂N_a/∂X̂ = b_a = (Ŷ_b − Ŷ_c)/(2A0),  ∂N_a/∂Ŷ = c_a = (X̂_c − X̂_b)/(2A0)   (a,b,c cyclic)
///   F = [F1 F2] = Σ_a x_a ⊗ (b_a, c_a)               (3×2 deformation gradient)
///   E = ½(FᵀF − I),  S = Q E  (fabric.hpp, Eq. 4),  wrinkling filter (material/wrinkling)
///   S_v = β Q Ė,  Ė = sym(FᵀḞ),  β = ζ Δt_e,min   (stiffness-proportional damping, §5.4)
///   f_a^int = −A0 t [F1 (S11 b_a + S12 c_a) + F2 (S12 b_a + S22 c_a)]   (S incl. S_v)
///   f_a^p   = (p/6) (x_1 − x_0) × (x_2 − x_0)   (pressure p > 0 pushes along the
///             counter-clockwise normal of corners 0,1,2)
///   m_a    += ρ_A A0 / 3   (lumped, reference area)
///   Δt_e    = (√(1+ζ²) − ζ) · (2A0 / max edge0) / (c · max(1, λ_max))   (§5.5; reference
///             altitude, scaled by the largest current stretch — see critical_dt()).
/// The fibre frame comes from the reference geometry and convects with F, so a rigid
/// rotation leaves E (and S) exactly zero and the law is objective. The reference can
/// differ from the initial positions (a folded canopy remembers its cut pattern).
/// Elements with quality q = 4√3 A0/Σ l² below `min_quality` (slivers) are rejected at
/// set-up with their id.
///
/// Kernel: one pointwise body on V = double or simd::pack<double>, node data gathered by
/// index, corner forces written to a per-element buffer and gathered per node
/// (detail/corner_forces.hpp, detail/scatter.hpp), so threads never race and results do
/// not depend on them. Stress, damping, energy, time-step, load and set-up pieces shared
/// with membrane_quad.hpp are in detail/membrane_common.hpp.
///
/// References: Belytschko, Liu, Moran (2000) Nonlinear Finite Elements, §4.5, §5.4;
///   Taylor R.L., Oñate E., Ubach P.-A. (2005) Finite element analysis of membrane
///   structures, in Textile Composites and Inflatable Structures, Springer;
///   LS-DYNA Theory Manual (membrane elements, time step).
#pragma once
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "../core/error.hpp"
#include "../core/simd.hpp"
#include "../core/vec3.hpp"
#include "detail/corner_forces.hpp"
#include "detail/membrane_common.hpp"
#include "material/fabric.hpp"
#include "nodes.hpp"

namespace parafsi::structure {

/// Triangles of a membrane part: node ids (counter-clockwise), and optionally the
/// stress-free reference position of every node (indexed by node id; empty = the node
/// positions at finalize) and a warp direction per element (empty = `warp` for all).
struct triangle_mesh {
  std::vector<std::array<index_t, 3>> triangles;
  std::vector<Eigen::Vector3d> reference;
  std::vector<Eigen::Vector3d> warp_per_element;
  Eigen::Vector3d warp = Eigen::Vector3d::UnitX();
};

struct membrane_options {
  double damping_ratio = 0.0;  ///< ζ: damping ratio in the highest mode (β = ζ Δt_e,min)
  double min_quality = 1e-2;   ///< slivers below this quality are rejected
};

template <class Fabric = material::fabric<>>
class membrane_tri {
 public:
  using material_type = Fabric;
  static constexpr int corners = 3;
  static constexpr const char* name() { return "membrane_tri"; }

  membrane_tri(triangle_mesh mesh, Fabric fabric, membrane_options opt = {})
      : mesh_(std::move(mesh)), mat_(fabric), opt_(opt) {
    mat_.validate();
    impl::check_membrane_options(name(), opt_.damping_ratio, opt_.min_quality);
    impl::check_warp_count(name(), mesh_.warp_per_element.size(), mesh_.triangles.size(), "triangles");
    q_ = mat_.moduli();
    n_ = index_t(mesh_.triangles.size());
    np_ = index_t(simd::padded(std::size_t(n_)));
    p_.assign(std::size_t(np_) + simd::width, 0.0);
  }

  index_t size() const noexcept { return n_; }
  const Fabric& material() const noexcept { return mat_; }
  double beta() const noexcept { return beta_; }

  // ---------------------------------------------------------------- loads
  /// Uniform pressure on every element (Pa).
  void set_pressure(double p) { impl::set_uniform_pressure(name(), p_, p); }
  /// Per-element pressure (Pa), one value per triangle.
  void set_pressure(std::span<const double> p) { impl::set_element_pressure(name(), p_, n_, p); }
  double* pressure() noexcept { return p_.data(); }
  /// Checkpoint (io/archive.hpp): the per-element pressure load (all slots, padding included).
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& self) {
    ar.array("pressure", self.p_.data(), self.p_.size());
  }

  // ---------------------------------------------------------------- set-up
  /// Reference geometry, fibre frame, lumped mass, scatter map. Called by assembly.
  void finalize(nodes& nd) {
    const index_t N = nd.size();
    for (auto& c : conn_) c.assign(std::size_t(np_) + simd::width, 0);
    for (auto& a : ref_) a.assign(std::size_t(np_) + simd::width, 0.0);
    a0t_.assign(std::size_t(np_) + simd::width, 0.0);
    lc0_.assign(std::size_t(n_), 0.0);
    impl::complete_reference(name(), mesh_.reference, auto_reference_, nd);
    auto X = [&](index_t i) { return mesh_.reference[std::size_t(i)]; };
    double lc_min = std::numeric_limits<double>::infinity();
    const double rhoA = mat_.areal_density;
    for (index_t e = 0; e < n_; ++e) {
      const auto& t = mesh_.triangles[std::size_t(e)];
      impl::check_element_nodes(name(), e, t, N);
      require(t[0] != t[1] && t[1] != t[2] && t[0] != t[2], "membrane_tri: element ", e, " repeats a node");
      const Eigen::Vector3d X0 = X(t[0]), X1 = X(t[1]), X2 = X(t[2]);
      impl::check_reference_finite<3>(name(), e, {X0, X1, X2}, {t[0], t[1], t[2]});
      const Eigen::Vector3d nrm = (X1 - X0).cross(X2 - X0);
      const double A2 = nrm.norm();
      const double l2 = (X1 - X0).squaredNorm() + (X2 - X1).squaredNorm() + (X0 - X2).squaredNorm();
      const double quality = l2 > 0 ? 2.0 * std::sqrt(3.0) * A2 / l2 : 0.0;
      require(quality >= opt_.min_quality && A2 > 0, "membrane_tri: element ", e, " (nodes ", t[0], ",", t[1], ",",
              t[2], ") is a sliver: quality 4*sqrt(3)*A/sum(l^2) = ", quality, " < min_quality ", opt_.min_quality);
      const Eigen::Vector3d Nn = nrm / A2;
      // Warp normal to the element: fall back to edge 0→1.
      const auto [E1, E2] = impl::fibre_axes(Nn, impl::warp_of(name(), mesh_, e), X1 - X0);
      const std::array<Eigen::Vector3d, 3> Xs{X0, X1, X2};
      double xh[3], yh[3];
      for (int a = 0; a < 3; ++a) {
        xh[a] = (Xs[std::size_t(a)] - X0).dot(E1);
        yh[a] = (Xs[std::size_t(a)] - X0).dot(E2);
      }
      for (int a = 0; a < 3; ++a) {
        const int b = (a + 1) % 3, c = (a + 2) % 3;
        ref_[std::size_t(a)][std::size_t(e)] = (yh[b] - yh[c]) / A2;
        ref_[std::size_t(3 + a)][std::size_t(e)] = (xh[c] - xh[b]) / A2;
        conn_[std::size_t(a)][std::size_t(e)] = t[std::size_t(a)];
        nd.add_mass(t[std::size_t(a)], rhoA * 0.5 * A2 / 3.0);
      }
      a0t_[std::size_t(e)] = 0.5 * A2 * mat_.thickness;
      const double lmax = std::sqrt(
          std::max({(X1 - X0).squaredNorm(), (X2 - X1).squaredNorm(), (X0 - X2).squaredNorm()}));
      lc_min = std::min(lc_min, A2 / lmax);
      lc0_[std::size_t(e)] = A2 / lmax;
    }
    beta_ = impl::stiffness_damping(n_, opt_.damping_ratio, lc_min, mat_.wave_speed());
    out_.build(conn_, n_, np_, N);
  }

  // ---------------------------------------------------------------- forces
  /// Corner forces from positions and velocities (all elements). `Vectorize = false`
  /// runs the scalar instantiation of the same body (reference for tests and bench).
  template <bool Track, bool Vectorize = true>
  void compute_forces(const node_kinematics& k) {
    if (beta_ > 0) run<Track, true, Vectorize>(k);
    else run<Track, false, Vectorize>(k);
  }
  template <bool Track>
  void scatter(nodes& nd) const {
    out_.template scatter<Track>(nd);
  }

  /// Strain energy Σ A0 t ½ S:E (filtered S) from the last tracked evaluation (J).
  double strain_energy() const { return out_.strain_energy(); }

  /// Stable step of the part (s): Δt_e = (√(1+ζ²) − ζ) · L_c0 / (c · max(1, λ_max)), L_c0 = 2A0/max
  /// edge of the reference triangle and λ_max the largest principal stretch now. In the
  /// total-Lagrangian CST the stiffness is A0 t (F∇N)ᵀQ(F∇N), so the highest frequency
  /// scales with λ_max c/L_c0; a folded (slack, crumpled) element does not shrink the
  /// step as a current-altitude estimate would (it may have zero current area).
  double critical_dt(const nodes& nd) const {
    const node_kinematics k = nd.kinematics();
    const double rate = impl::stretch_rate(n_, lc0_, [&](index_t e, double& E11, double& E22, double& E12) {
      vec3<double> F1, F2;
      strains<double>(k, e, F1, F2, E11, E22, E12);
    });  // max λ_max / L_c0
    return impl::membrane_step(rate, opt_.damping_ratio, mat_.wave_speed());
  }

  /// First element with a non-finite corner force (-1 if none), for failure reports.
  index_t first_bad_element() const { return out_.first_bad_element(); }
  /// Green–Lagrange strain (E11, E22, 2E12) and filtered elastic stress (S11, S22, S12)
  /// of element e in its fibre axes, for output and tests.
  std::array<double, 6> strain_stress(const nodes& nd, index_t e) const {
    vec3<double> F1, F2;
    double E11, E22, E12;
    strains<double>(nd.kinematics(), e, F1, F2, E11, E22, E12);
    return impl::strain_stress_of(mat_, q_, E11, E22, E12);
  }
  std::array<index_t, 3> element(index_t e) const {
    return {conn_[0][std::size_t(e)], conn_[1][std::size_t(e)], conn_[2][std::size_t(e)]};
  }
  double reference_area(index_t e) const { return a0t_[std::size_t(e)] / mat_.thickness; }

 private:
  template <bool Track, bool Damped, bool Vectorize>
  void run(const node_kinematics& k) {
    impl::for_each_element<Track, Vectorize>(n_, std::array{&out_.energy_part}, [&](auto tag, index_t e) {
      using V = typename decltype(tag)::type;
      return std::array{kernel<V, Track, Damped>(k, e)};
    });
  }

  template <class V>
  PARAFSI_INLINE void strains(const node_kinematics& k, index_t e, vec3<V>& F1, vec3<V>& F2, V& E11, V& E22,
                              V& E12) const {
    const index_t* i0 = conn_[0].data() + e;
    const index_t* i1 = conn_[1].data() + e;
    const index_t* i2 = conn_[2].data() + e;
    const vec3<V> x0 = impl::gather_position<V>(k, i0), x1 = impl::gather_position<V>(k, i1),
                  x2 = impl::gather_position<V>(k, i2);
    const V b0 = simd::load<V>(ref_[0].data() + e), b1 = simd::load<V>(ref_[1].data() + e),
            b2 = simd::load<V>(ref_[2].data() + e);
    const V c0 = simd::load<V>(ref_[3].data() + e), c1 = simd::load<V>(ref_[4].data() + e),
            c2 = simd::load<V>(ref_[5].data() + e);
    F1 = x0 * b0 + x1 * b1 + x2 * b2;
    F2 = x0 * c0 + x1 * c1 + x2 * c2;
    E11 = V(0.5) * (dot(F1, F1) - V(1.0));
    E22 = V(0.5) * (dot(F2, F2) - V(1.0));
    E12 = V(0.5) * dot(F1, F2);
  }

  /// One element (or one pack of elements): corner forces to the buffers; returns the
  /// strain energy when tracking.
  template <class V, bool Track, bool Damped>
  PARAFSI_INLINE V kernel(const node_kinematics& k, index_t e) {
    const index_t* i0 = conn_[0].data() + e;
    const index_t* i1 = conn_[1].data() + e;
    const index_t* i2 = conn_[2].data() + e;
    const vec3<V> x0 = impl::gather_position<V>(k, i0), x1 = impl::gather_position<V>(k, i1),
                  x2 = impl::gather_position<V>(k, i2);
    const V b0 = simd::load<V>(ref_[0].data() + e), b1 = simd::load<V>(ref_[1].data() + e),
            b2 = simd::load<V>(ref_[2].data() + e);
    const V c0 = simd::load<V>(ref_[3].data() + e), c1 = simd::load<V>(ref_[4].data() + e),
            c2 = simd::load<V>(ref_[5].data() + e);
    // Step 1. Deformation gradient and Green–Lagrange strain.
    const vec3<V> F1 = x0 * b0 + x1 * b1 + x2 * b2;
    const vec3<V> F2 = x0 * c0 + x1 * c1 + x2 * c2;
    const V E11 = V(0.5) * (dot(F1, F1) - V(1.0));
    const V E22 = V(0.5) * (dot(F2, F2) - V(1.0));
    const V E12 = V(0.5) * dot(F1, F2);
    // Step 2. Elastic second Piola–Kirchhoff stress (Eq. 4).
    V S11, S22, S12;
    impl::elastic_stress(q_, E11, E22, E12, S11, S22, S12);
    // Step 3. Stiffness-proportional viscous stress β Q Ė.
    V D11(0.0), D22(0.0), D12(0.0);
    if constexpr (Damped) {
      const vec3<V> v0 = impl::gather_velocity<V>(k, i0);
      const vec3<V> v1 = impl::gather_velocity<V>(k, i1);
      const vec3<V> v2 = impl::gather_velocity<V>(k, i2);
      const vec3<V> G1 = v0 * b0 + v1 * b1 + v2 * b2;
      const vec3<V> G2 = v0 * c0 + v1 * c1 + v2 * c2;
      const V R11 = dot(F1, G1), R22 = dot(F2, G2), R12 = V(0.5) * (dot(F1, G2) + dot(F2, G1));
      impl::viscous_stress(q_, V(beta_), R11, R22, R12, D11, D22, D12);
    }
    // Step 4. Wrinkling (no compression).
    mat_.wrinkling.apply(S11, S22, S12, D11, D22, D12, E11, E22, E12, q_);
    // Step 5. Nodal forces f_a = −A0 t (P1 b_a + P2 c_a), P = F (S + S_v).
    const V at = simd::load<V>(a0t_.data() + e);
    const V T11 = S11 + D11, T22 = S22 + D22, T12 = S12 + D12;
    const vec3<V> P1 = (F1 * T11 + F2 * T12) * at;
    const vec3<V> P2 = (F1 * T12 + F2 * T22) * at;
    // Pressure: (p/6) (x1 − x0) × (x2 − x0) on each corner.
    const V p6 = simd::load<V>(p_.data() + e) * V(1.0 / 6.0);
    const vec3<V> fp = cross(x1 - x0, x2 - x0) * p6;
    out_.store<V>(out_.total, 0, e, fp - (P1 * b0 + P2 * c0));
    out_.store<V>(out_.total, 1, e, fp - (P1 * b1 + P2 * c1));
    out_.store<V>(out_.total, 2, e, fp - (P1 * b2 + P2 * c2));
    if constexpr (Track) {
      const vec3<V> Q1 = (F1 * D11 + F2 * D12) * at;
      const vec3<V> Q2 = (F1 * D12 + F2 * D22) * at;
      const vec3<V> zero{V(0.0), V(0.0), V(0.0)};
      out_.store<V>(out_.damping, 0, e, zero - (Q1 * b0 + Q2 * c0));
      out_.store<V>(out_.damping, 1, e, zero - (Q1 * b1 + Q2 * c1));
      out_.store<V>(out_.damping, 2, e, zero - (Q1 * b2 + Q2 * c2));
      out_.store<V>(out_.external, 0, e, fp);
      out_.store<V>(out_.external, 1, e, fp);
      out_.store<V>(out_.external, 2, e, fp);
      return impl::membrane_energy(at, S11, S22, S12, E11, E22, E12);
    } else {
      return V(0.0);
    }
  }

  triangle_mesh mesh_;
  Fabric mat_;
  membrane_options opt_;
  fabric_moduli q_{};
  index_t n_ = 0, np_ = 0;
  double beta_ = 0.0;
  bool auto_reference_ = false;
  std::array<simd::aligned_vector<index_t>, 3> conn_;
  std::array<simd::aligned_vector<double>, 6> ref_;  // b0 b1 b2 c0 c1 c2
  simd::aligned_vector<double> a0t_, p_;
  std::vector<double> lc0_;  // reference altitude 2A0/max edge
  impl::corner_forces<3> out_;
};

}  // namespace parafsi::structure
