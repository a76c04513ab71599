/// \file cable.hpp
/// Tension-only discrete cable elements (the paper's Eq. 5; methods §6.1), serving
/// suspension lines, risers and seatbelt-style tapes alike (the material decides):
///   L = |x1 − x0|,  e = (x1 − x0)/L,  L̇ = e·(v1 − v0),  k = EA/L0,
///   T_e = max(0, T0 + k (L − L0)),   T = max(0, T_e + c_d L̇ [T_e > 0]),
///   f0 = +T e,  f1 = −T e,   c_d = 2 ξ √(k m_eff),  m_eff = m0 m1/(m0 + m1)
///   (the free end's mass when the other end is constrained or attached),
///   strain energy U = T_e²/(2k),  lumped mass ρ_l L0/2 per end.
/// A slack element carries nothing and is not damped; damping never makes the line push.
/// Critical step: the nodal estimate Δt_a = (√(1+ξ²) − ξ) √(2 m_a / Σ_e k_e), exact for a
/// uniform chain (= L0/√(EA/ρ_l)); computed by the assembly over all parts, so a node
/// shared by several lines counts all of them.
///
/// References: LS-DYNA Keyword Manual, *MAT_CABLE_DISCRETE_BEAM, *ELEMENT_SEATBELT;
///   Belytschko, Liu, Moran (2000) Nonlinear Finite Elements, §6.2 (nodal time step);
///   Altair Radioss Theory Manual (nodal time step √(2M/K)).
#pragma once
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "../core/simd.hpp"
#include "../core/vec3.hpp"
#include "detail/corner_forces.hpp"
#include "material/cable.hpp"
#include "nodes.hpp"

namespace parafsi::structure {

/// Segments of a cable part (node ids) and optional rest lengths (empty = the distance
/// between the node positions at finalize).
struct line_mesh {
  std::vector<std::array<index_t, 2>> segments;
  std::vector<double> rest_length;
};

template <class Material = material::cable>
class cable {
 public:
  using material_type = Material;
  static constexpr int corners = 2;
  static constexpr const char* name() { return "cable"; }

  cable(line_mesh mesh, Material mat) : mesh_(std::move(mesh)), mat_(mat) {
    mat_.validate();
    n_ = index_t(mesh_.segments.size());
    np_ = index_t(simd::padded(std::size_t(n_)));
    require(mesh_.rest_length.empty() || index_t(mesh_.rest_length.size()) == n_, "cable: rest_length has ",
            mesh_.rest_length.size(), " entries for ", n_, " segments");
  }

  index_t size() const noexcept { return n_; }
  const Material& material() const noexcept { return mat_; }
  double damping_ratio() const noexcept { return mat_.damping_ratio; }

  void finalize(nodes& nd) {
    const index_t N = nd.size();
    for (auto& c : conn_) c.assign(std::size_t(np_) + simd::width, 0);
    L0_.assign(std::size_t(np_) + simd::width, 1.0);
    k_.assign(std::size_t(np_) + simd::width, 0.0);
    cd_.assign(std::size_t(np_) + simd::width, 0.0);
    const double EA = mat_.axial_stiffness(), rl = mat_.linear_density();
    // Without given rest lengths, the lengths at the first finalize are kept.
    if (mesh_.rest_length.empty()) {
      for (index_t e = 0; e < n_; ++e) {
        const auto& s = mesh_.segments[std::size_t(e)];
        require(s[0] >= 0 && s[0] < N && s[1] >= 0 && s[1] < N, "cable: element ", e, " names a node outside [0, ", N,
                ")");
        mesh_.rest_length.push_back((nd.position(s[1]) - nd.position(s[0])).norm());
      }
    }
    for (index_t e = 0; e < n_; ++e) {
      const auto& s = mesh_.segments[std::size_t(e)];
      for (int a = 0; a < 2; ++a)
        require(s[std::size_t(a)] >= 0 && s[std::size_t(a)] < N, "cable: element ", e, " names node ",
                s[std::size_t(a)], " outside [0, ", N, ")");
      require(s[0] != s[1], "cable: element ", e, " joins node ", s[0], " to itself");
      const double L0 = mesh_.rest_length[std::size_t(e)];
      require(L0 > 0 && std::isfinite(L0), "cable: element ", e, " has rest length ", L0, " (must be > 0)");
      conn_[0][std::size_t(e)] = s[0];
      conn_[1][std::size_t(e)] = s[1];
      L0_[std::size_t(e)] = L0;
      k_[std::size_t(e)] = EA / L0;
      nd.add_mass(s[0], 0.5 * rl * L0);
      nd.add_mass(s[1], 0.5 * rl * L0);
    }
    out_.build(conn_, n_, np_, N);
  }
  /// After all masses are known: damping coefficients from the effective end mass.
  void post_finalize(const nodes& nd) {
    const double xi = mat_.damping_ratio;
    for (index_t e = 0; e < n_; ++e) {
      const index_t a = conn_[0][std::size_t(e)], b = conn_[1][std::size_t(e)];
      const bool fa = nd.kind(a) == constraint::free, fb = nd.kind(b) == constraint::free;
      const double ma = nd.mass(a), mb = nd.mass(b);
      double meff = 0;
      if (fa && fb) meff = ma * mb / (ma + mb);
      else if (fa) meff = ma;
      else if (fb) meff = mb;
      cd_[std::size_t(e)] = 2.0 * xi * std::sqrt(k_[std::size_t(e)] * meff);
    }
  }
  /// Σ k_e per node (for the nodal critical step).
  void add_node_stiffness(std::vector<double>& ksum) const {
    for (index_t e = 0; e < n_; ++e) {
      ksum[std::size_t(conn_[0][std::size_t(e)])] += k_[std::size_t(e)];
      ksum[std::size_t(conn_[1][std::size_t(e)])] += k_[std::size_t(e)];
    }
  }
  /// Element estimates are covered by the assembly's nodal estimate.
  double critical_dt(const nodes&) const { return std::numeric_limits<double>::infinity(); }

  template <bool Track, bool Vectorize = true>
  void compute_forces(const node_kinematics& k) {
    impl::for_each_element<Track, Vectorize>(n_, std::array{&out_.energy_part}, [&](auto tag, index_t e) {
      using V = typename decltype(tag)::type;
      return std::array{kernel<V, Track>(k, e)};
    });
  }
  template <bool Track>
  void scatter(nodes& nd) const {
    out_.template scatter<Track>(nd);
  }
  double strain_energy() const { return out_.strain_energy(); }

  index_t first_bad_element() const { return out_.first_bad_element(); }
  /// Current tension of element e (N), elastic + damping, from positions and velocities.
  double tension(const nodes& nd, index_t e) const {
    const index_t a = conn_[0][std::size_t(e)], b = conn_[1][std::size_t(e)];
    const Eigen::Vector3d d = nd.position(b) - nd.position(a);
    const double L = d.norm();
    const double Te = std::max(0.0, mat_.preload + k_[std::size_t(e)] * (L - L0_[std::size_t(e)]));
    const double Ld = d.dot(nd.velocity(b) - nd.velocity(a)) / L;
    return std::max(0.0, Te + (Te > 0 ? cd_[std::size_t(e)] * Ld : 0.0));
  }
  std::array<index_t, 2> element(index_t e) const { return {conn_[0][std::size_t(e)], conn_[1][std::size_t(e)]}; }
  double rest_length(index_t e) const { return L0_[std::size_t(e)]; }
  double stiffness(index_t e) const { return k_[std::size_t(e)]; }

 private:
  template <class V, bool Track>
  PARAFSI_INLINE V kernel(const node_kinematics& k, index_t e) {
    const index_t* i0 = conn_[0].data() + e;
    const index_t* i1 = conn_[1].data() + e;
    const vec3<V> x0 = impl::gather_position<V>(k, i0), x1 = impl::gather_position<V>(k, i1);
    const vec3<V> v0 = impl::gather_velocity<V>(k, i0), v1 = impl::gather_velocity<V>(k, i1);
    const V L0 = simd::load<V>(L0_.data() + e), kk = simd::load<V>(k_.data() + e), cd = simd::load<V>(cd_.data() + e);
    // Step 1. Geometry and elongation rate.
    const vec3<V> d = x1 - x0;
    const V L = simd::sqrt(dot(d, d));
    const V Linv = V(1.0) / simd::max(L, V(1e-300));
    const vec3<V> u = d * Linv;
    const V Ld = dot(u, v1 - v0);
    // Step 2. Tension (Eq. 5): elastic, then damping while taut, never compressive.
    const V Te = simd::max(V(0.0), V(mat_.preload) + kk * (L - L0));
    const V Tt = simd::max(V(0.0), Te + simd::select(Te > V(0.0), cd * Ld, V(0.0)));
    // Step 3. Corner forces.
    const vec3<V> f = u * Tt;
    const vec3<V> zero{V(0.0), V(0.0), V(0.0)};
    out_.store<V>(out_.total, 0, e, f);
    out_.store<V>(out_.total, 1, e, zero - f);
    if constexpr (Track) {
      const vec3<V> fd = u * (Tt - Te);
      out_.store<V>(out_.damping, 0, e, fd);
      out_.store<V>(out_.damping, 1, e, zero - fd);
      out_.store<V>(out_.external, 0, e, zero);
      out_.store<V>(out_.external, 1, e, zero);
      return V(0.5) * Te * Te / simd::max(kk, V(1e-300));
    } else {
      return V(0.0);
    }
  }

  line_mesh mesh_;
  Material mat_;
  index_t n_ = 0, np_ = 0;
  std::array<simd::aligned_vector<index_t>, 2> conn_;
  simd::aligned_vector<double> L0_, k_, cd_;
  impl::corner_forces<2> out_;
};

}  // namespace parafsi::structure
