/// \file membrane_quad.hpp
/// Belytschko–Tsay one-point quadrilateral membrane with Flanagan–Belytschko hourglass
/// control, the option beside the constant-strain triangle (methods §5.2). Same
/// conventions, material, wrinkling, damping, loads and scatter as membrane_tri.hpp.
///
/// Reference (stress-free) corners X_I (I = 0..3, counter-clockwise about n0):
///   n0 = (X2 − X0) × (X3 − X1),  N = n0/|n0|,  A0 = |n0|/2,  E1 = warp ⊥ N,  E2 = N × E1,
///   (X̂_I, Ŷ_I, Ẑ_I) = (X_I − X̄)·(E1, E2, N)        (co-rotational frame of Belytschko,
///   Lin & Tsay 1984 at t = 0: normal from the diagonals, in-plane axes = fibre axes)
/// One-point (mean-quadrature) gradients, 2A0 = X̂20 Ŷ31 − X̂31 Ŷ20:
///   b = (Ŷ13, Ŷ20, Ŷ31, Ŷ02)/(2A0),  c = (X̂31, X̂02, X̂13, X̂20)/(2A0)     (Ŷij = Ŷi − Ŷj)
/// Kinematics at the element centre (total form in the co-rotational frame):
///   F = [F1 F2] = Σ_I x_I ⊗ (b_I, c_I),  E = ½(FᵀF − I),  S = Q E (fabric.hpp, Eq. 4),
///   wrinkling filter on S,  S_v = β Q Ė,  β = ζ Δt_e,min   (as for the triangle).
///   Because the normal offsets of the corners in the current BLT frame
///   (ê3 ∥ (x2 − x0) × (x3 − x1)) are z̄ + δ h_I and Σ b_I = Σ b_I h_I = 0 (same for c),
///   F equals [ê1 ê2] F̂ with F̂ the in-plane gradient of the BLT projection: the kernel
///   forms F in global components and needs ê3 only for the hourglass split below.
///   Unlike BLT's hypoelastic update (σ̂ⁿ⁺¹ = σ̂ⁿ + Q d̂ Δt) the stress is the total
///   St Venant–Kirchhoff S(E): exact objectivity, a stored energy for the ledger, and a
///   reference geometry distinct from the initial one (folded starts), as in the CST.
///   f_I^int = −A0 t [F1 (S11 b_I + S12 c_I) + F2 (S12 b_I + S22 c_I)]   (S incl. S_v)
/// Hourglass control (Flanagan & Belytschko 1981; BLT 1984), h = (1, −1, 1, −1):
///   γ_I = h_I − (h·X̂) b_I − (h·Ŷ) c_I      (γ ⟂ 1, X̂, Ŷ: linear fields carry none)
///   q = Σ_I γ_I x_I,  q_n = q·ê3 − w0,  w0 = Σ_I γ_I Ẑ_I
///   (ê3 ∥ (x2 − x0) × (x3 − x1); w0 the reference warp, 0 for a flat quad)
///   in-plane (membrane) mode, elastic stiffness form (methods §5.2) on the convected
///   components a = Fᵀq (= the in-plane part of q in the BLT frame at small strain, since
///   F_α·ê3 = 0 exactly):  U_m = ½ k_m |Fᵀq|²,
///     k_m = r_hg Q_max t A0 Σ_I(b_I² + c_I²)/8,  r_hg = 0.05 default (0.05–0.1 usual).
///     Measuring q in the convected tangents F1, F2 instead of a frame normalised by the
///     current area keeps the spring well conditioned when elements are crumpled (a
///     projection with ê3 = n/|n| made folded starts unstable at the nominal step).
///   out-of-plane (w) mode: a membrane has no elastic w stiffness (BLT's bending term
///     ∝ E t³/192 is negligible for fabric) but the fully integrated element stiffens
///     the bilinear w = δ ξη mode through the second-order strain ½∇w⊗∇w. Its element
///     mean, exact for rectangles, is added to the one-point strain:
///       E += r_w q_n² G/24,  G = [Σb², Σbc; Σbc, Σc²],  r_w = 1 default,
///     so the w mode is held by the (filtered) membrane stress with the geometric
///     stiffness k_g = r_w A0 t (S:G)/12 — slack fabric offers none, as physically —
///     and the energy stays the potential ½ A0 t S:E (conservative up to frozen ê3).
///   viscous form (FB): c_v = r_v · 2√(k_1 m_I)/|γ|, k_1 = k_m(r_hg = 1), m_I = ρ_A A0/4
///     (r_v = damping ratio of the mode against a unit-r spring; r_v = 0 default)
///   Forces, with a = Fᵀq, q̇ = Σ_I γ_I v_I, T = S + S_v (S_v includes the w-mode rate),
///   Q_w = r_w A0 t q_n (T:G)/12 and w = (q − (q·ê3)ê3)/|n|:
///     f_I^hg = −γ_I [k_m F a + Q_w ê3 + β k_m F Fᵀq̇ + c_v q̇] − k_m q (a1 b_I + a2 c_I)
///              ± Q_w (d2 × w) at corners 0/2, ± Q_w (w × d1) at corners 1/3
///     (the last terms are the rotation of ê3, ∂(q·ê3)/∂x; d1 = x2 − x0, d2 = x3 − x1),
///   so the elastic forces are the exact gradient of
///     U = ½ A0 t S:E + ½ k_m |Fᵀq|²,   U_hg = ½ k_m |Fᵀq|² + ½ A0 t S:(r_w q_n² G/24)
///   (U_hg is reported by hourglass_energy(), U by strain_energy()).
///   For a flat reference every linear field x = R F0 X + c has q = 0: the patch test is
///   exact; for a warped one a rigid motion gives q = w0 ê3 (Fᵀq = 0, q_n = 0).
///   f_I^p = (p/8) (x2 − x0) × (x3 − x1)   (p/4 of the quad's area vector per corner;
///          p > 0 pushes along n0's side; uniform or per element)
///   m_I  += ρ_A A0/4   (lumped, reference area)
///   Δt_e  = (√(1+ζ²) − ζ) · (A0/max edge0) / (c · max(1, λ_max) · √(1 + r_hg))
///          (methods §5.5 quad rule L_c = A/max edge, in the reference like the CST;
///          the √(1 + r_hg) covers the hourglass spring; checked against the exact
///          single-element ω_max in tests/test_structure_quad.cpp).
/// Set-up rejects, with the element id and its nodes: repeated or out-of-range nodes,
/// zero-area (collapsed) quads, and degenerate, re-entrant or self-intersecting
/// ("inverted") quads whose smallest corner sine (seen from N) is below min_quality.
///
/// Kernel: one pointwise body on V = double or simd::pack<double> (core/simd.hpp), node
/// data gathered by index, corner forces written to a per-element buffer and gathered
/// per node (detail/corner_forces.hpp, detail/scatter.hpp): race-free and thread-count
/// independent. Stress, damping, energy, time-step, load and set-up pieces shared with
/// membrane_tri.hpp are in detail/membrane_common.hpp.
///
/// References: Belytschko T., Lin J.I., Tsay C.-S. (1984) CMAME 42:225–251;
///   Flanagan D.P., Belytschko T. (1981) IJNME 17:679–706;
///   Belytschko T., Liu W.K., Moran B. (2000) Nonlinear Finite Elements, §8.6–8.7, §9.5;
///   Hallquist J.O., LS-DYNA Theory Manual (Belytschko–Tsay shell, hourglass types 1–5,
///   shell time step).
#pragma once
#include <algorithm>
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

/// Quadrilaterals of a membrane part: node ids (counter-clockwise about the side the
/// pressure pushes to), optional reference positions (indexed by node id; empty = the
/// node positions at finalize) and warp directions per element (empty = `warp`).
struct quad_mesh {
  std::vector<std::array<index_t, 4>> quads;
  std::vector<Eigen::Vector3d> reference;
  std::vector<Eigen::Vector3d> warp_per_element;
  Eigen::Vector3d warp = Eigen::Vector3d::UnitX();
};

struct quad_options {
  double damping_ratio = 0.0;           ///< ζ: damping ratio in the highest mode (β = ζ Δt_e,min)
  double min_quality = 0.05;            ///< smallest allowed corner sine (reference, about N)
  double hourglass_stiffness = 0.05;    ///< r_hg (Flanagan–Belytschko stiffness form)
  double hourglass_viscosity = 0.0;     ///< r_v (Flanagan–Belytschko viscous form)
  double hourglass_out_of_plane = 1.0;  ///< r_w: scales the w-mode strain (1 = fully integrated)
};

template <class Fabric = material::fabric<>>
class membrane_quad {
 public:
  using material_type = Fabric;
  static constexpr int corners = 4;
  static constexpr const char* name() { return "membrane_quad"; }

  membrane_quad(quad_mesh mesh, Fabric fabric, quad_options opt = {})
      : mesh_(std::move(mesh)), mat_(fabric), opt_(opt) {
    mat_.validate();
    impl::check_membrane_options(name(), opt_.damping_ratio, opt_.min_quality);
    require(opt_.hourglass_stiffness >= 0 && opt_.hourglass_stiffness <= 1,
            "membrane_quad: hourglass_stiffness must be in [0, 1], got ", opt_.hourglass_stiffness);
    require(opt_.hourglass_viscosity >= 0 && opt_.hourglass_viscosity <= 1,
            "membrane_quad: hourglass_viscosity must be in [0, 1], got ", opt_.hourglass_viscosity);
    require(opt_.hourglass_out_of_plane >= 0 && opt_.hourglass_out_of_plane <= 10,
            "membrane_quad: hourglass_out_of_plane must be in [0, 10], got ", opt_.hourglass_out_of_plane);
    impl::check_warp_count(name(), mesh_.warp_per_element.size(), mesh_.quads.size(), "quads");
    q_ = mat_.moduli();
    n_ = index_t(mesh_.quads.size());
    np_ = index_t(simd::padded(std::size_t(n_)));
    p_.assign(std::size_t(np_) + simd::width, 0.0);
  }

  index_t size() const noexcept { return n_; }
  const Fabric& material() const noexcept { return mat_; }
  const quad_options& options() const noexcept { return opt_; }
  double beta() const noexcept { return beta_; }

  // ---------------------------------------------------------------- loads
  /// Uniform pressure on every element (Pa).
  void set_pressure(double p) { impl::set_uniform_pressure(name(), p_, p); }
  /// Per-element pressure (Pa), one value per quad.
  void set_pressure(std::span<const double> p) { impl::set_element_pressure(name(), p_, n_, p); }
  double* pressure() noexcept { return p_.data(); }
  /// Checkpoint (io/archive.hpp): the per-element pressure load (all slots, padding included).
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& self) {
    ar.array("pressure", self.p_.data(), self.p_.size());
  }

  // ---------------------------------------------------------------- set-up
  /// Reference geometry, fibre frame, hourglass vectors, lumped mass, scatter map.
  /// Called by assembly.
  void finalize(nodes& nd) {
    const index_t N = nd.size();
    const std::size_t pad = std::size_t(np_) + simd::width;
    for (auto& c : conn_) c.assign(pad, 0);
    for (auto& a : ref_) a.assign(pad, 0.0);
    for (auto& a : gam_) a.assign(pad, 0.0);
    a0t_.assign(pad, 0.0);
    khg_.assign(pad, 0.0);
    cv_.assign(pad, 0.0);
    w0_.assign(pad, 0.0);
    gbb_.assign(pad, 0.0);
    gbc_.assign(pad, 0.0);
    gcc_.assign(pad, 0.0);
    lc0_.assign(std::size_t(n_), 0.0);
    impl::complete_reference(name(), mesh_.reference, auto_reference_, nd);
    const double rhoA = mat_.areal_density, Qmax = std::max(q_.Q11, q_.Q22), t = mat_.thickness;
    double lc_min = std::numeric_limits<double>::infinity();
    for (index_t e = 0; e < n_; ++e) {
      const auto& qd = mesh_.quads[std::size_t(e)];
      impl::check_element_nodes(name(), e, qd, N);
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b)
          require(qd[std::size_t(a)] != qd[std::size_t(b)], "membrane_quad: element ", e, " repeats node ",
                  qd[std::size_t(a)], " (a collapsed quad; use a triangle)");
      std::array<Eigen::Vector3d, 4> X;
      for (int a = 0; a < 4; ++a) X[std::size_t(a)] = mesh_.reference[std::size_t(qd[std::size_t(a)])];
      impl::check_reference_finite<4>(name(), e, X, {qd[0], qd[1], qd[2], qd[3]});
      const Eigen::Vector3d n0 = (X[2] - X[0]).cross(X[3] - X[1]);
      const double A2 = n0.norm();
      double lmax = 0;
      for (int a = 0; a < 4; ++a) lmax = std::max(lmax, (X[std::size_t((a + 1) % 4)] - X[std::size_t(a)]).norm());
      require(A2 > 1e-14 * lmax * lmax && lmax > 0, "membrane_quad: element ", e, " (nodes ", qd[0], ",", qd[1], ",",
              qd[2], ",", qd[3], ") has zero area (degenerate)");
      const Eigen::Vector3d Nn = n0 / A2;
      const Eigen::Vector3d Xc = 0.25 * (X[0] + X[1] + X[2] + X[3]);
      double xh[4], yh[4], zh[4];
      // Warp normal to the element: fall back to edge 0→1 projected on it.
      const auto [E1, E2] = impl::fibre_axes(Nn, impl::warp_of(name(), mesh_, e),
                                             (X[1] - X[0]) - (X[1] - X[0]).dot(Nn) * Nn);
      for (int a = 0; a < 4; ++a) {
        xh[a] = (X[std::size_t(a)] - Xc).dot(E1);
        yh[a] = (X[std::size_t(a)] - Xc).dot(E2);
        zh[a] = (X[std::size_t(a)] - Xc).dot(Nn);
      }
      // Corner sines about N: ≤ 0 for re-entrant or self-intersecting quads.
      double qmin = 1.0;
      int worst = 0;
      for (int a = 0; a < 4; ++a) {
        const int nx = (a + 1) % 4, pv = (a + 3) % 4;
        const double ax = xh[nx] - xh[a], ay = yh[nx] - yh[a], bx = xh[pv] - xh[a], by = yh[pv] - yh[a];
        const double la = std::hypot(ax, ay), lb = std::hypot(bx, by);
        const double s = (la > 0 && lb > 0) ? (ax * by - ay * bx) / (la * lb) : 0.0;
        if (s < qmin) {
          qmin = s;
          worst = a;
        }
      }
      require(qmin >= opt_.min_quality, "membrane_quad: element ", e, " (nodes ", qd[0], ",", qd[1], ",", qd[2], ",",
              qd[3], ") is degenerate or inverted: corner ", worst, " has sine ", qmin, " < min_quality ",
              opt_.min_quality, " (re-entrant, self-intersecting or nearly collapsed)");
      const double inv2A = 1.0 / A2;  // 2A0 = |n0|
      const double b[4] = {(yh[1] - yh[3]) * inv2A, (yh[2] - yh[0]) * inv2A, (yh[3] - yh[1]) * inv2A,
                           (yh[0] - yh[2]) * inv2A};
      const double c[4] = {(xh[3] - xh[1]) * inv2A, (xh[0] - xh[2]) * inv2A, (xh[1] - xh[3]) * inv2A,
                           (xh[2] - xh[0]) * inv2A};
      const double h[4] = {1, -1, 1, -1};
      double hx = 0, hy = 0, sbb = 0, sbc = 0, scc = 0;
      for (int a = 0; a < 4; ++a) {
        hx += h[a] * xh[a];
        hy += h[a] * yh[a];
        sbb += b[a] * b[a];
        sbc += b[a] * c[a];
        scc += c[a] * c[a];
      }
      const double bb = sbb + scc;
      double w0 = 0, gg = 0;
      const double A0 = 0.5 * A2;
      for (int a = 0; a < 4; ++a) {
        const double g = h[a] - hx * b[a] - hy * c[a];
        gam_[std::size_t(a)][std::size_t(e)] = g;
        w0 += g * zh[a];
        gg += g * g;
        ref_[std::size_t(a)][std::size_t(e)] = b[a];
        ref_[std::size_t(4 + a)][std::size_t(e)] = c[a];
        conn_[std::size_t(a)][std::size_t(e)] = qd[std::size_t(a)];
        nd.add_mass(qd[std::size_t(a)], rhoA * A0 / 4.0);
      }
      w0_[std::size_t(e)] = w0;
      a0t_[std::size_t(e)] = A0 * t;
      const double g = opt_.hourglass_out_of_plane / 24.0;  // mean strain of the w mode per q_n²
      gbb_[std::size_t(e)] = g * sbb;
      gbc_[std::size_t(e)] = g * sbc;
      gcc_[std::size_t(e)] = g * scc;
      const double k1 = Qmax * t * A0 * bb / 8.0;  // r_hg = 1
      khg_[std::size_t(e)] = opt_.hourglass_stiffness * k1;
      cv_[std::size_t(e)] = opt_.hourglass_viscosity * 2.0 * std::sqrt(k1 * rhoA * A0 / 4.0) / std::sqrt(gg);
      lc0_[std::size_t(e)] = A0 / lmax;
      lc_min = std::min(lc_min, A0 / lmax);
    }
    beta_ = impl::stiffness_damping(n_, opt_.damping_ratio, lc_min, mat_.wave_speed());
    out_.build(conn_, n_, np_, N);
    hg_part_.assign(std::size_t(impl::chunk_count(n_)), 0.0);
  }

  // ---------------------------------------------------------------- forces
  /// Corner forces from positions and velocities (all elements). `Vectorize = false`
  /// runs the scalar instantiation of the same body.
  template <bool Track, bool Vectorize = true>
  void compute_forces(const node_kinematics& k) {
    if (beta_ > 0 || opt_.hourglass_viscosity > 0) run<Track, true, Vectorize>(k);
    else run<Track, false, Vectorize>(k);
  }
  template <bool Track>
  void scatter(nodes& nd) const {
    out_.template scatter<Track>(nd);
  }

  /// Strain energy Σ [A0 t ½ S:E + U_hg] from the last tracked evaluation (J).
  double strain_energy() const { return out_.strain_energy(); }
  /// The hourglass part Σ U_hg of strain_energy() (J).
  double hourglass_energy() const { return impl::ordered_sum(hg_part_); }

  /// Stable step of the part (s), see the header: the CST rule with L_c0 = A0/max edge
  /// and the hourglass spring's share √(1 + r_hg).
  double critical_dt(const nodes& nd) const {
    const node_kinematics k = nd.kinematics();
    const double rate = impl::stretch_rate(n_, lc0_, [&](index_t e, double& E11, double& E22, double& E12) {
      vec3<double> F1, F2;
      strains<double>(k, e, F1, F2, E11, E22, E12);
    });
    return impl::membrane_step(rate * std::sqrt(1.0 + opt_.hourglass_stiffness), opt_.damping_ratio, mat_.wave_speed());
  }

  /// First element with a non-finite corner force (-1 if none), for failure reports.
  index_t first_bad_element() const { return out_.first_bad_element(); }
  /// Green–Lagrange strain (E11, E22, 2E12) and filtered elastic stress (S11, S22, S12)
  /// at the centre of element e in its fibre axes, for output and tests.
  std::array<double, 6> strain_stress(const nodes& nd, index_t e) const {
    const node_kinematics k = nd.kinematics();
    vec3<double> F1, F2;
    double E11, E22, E12;
    strains<double>(k, e, F1, F2, E11, E22, E12);
    double D11 = 0, D22 = 0, D12 = 0;
    double S11 = q_.Q11 * E11 + q_.Q12 * E22, S22 = q_.Q12 * E11 + q_.Q22 * E22, S12 = 2.0 * q_.Q66 * E12;
    mat_.wrinkling.apply(S11, S22, S12, D11, D22, D12, E11, E22, E12, q_);
    return {E11, E22, 2.0 * E12, S11, S22, S12};
  }
  /// Hourglass displacement q − w0 ê3 of element e (m), for tests.
  Eigen::Vector3d hourglass_mode(const nodes& nd, index_t e) const {
    const node_kinematics k = nd.kinematics();
    Eigen::Vector3d q = Eigen::Vector3d::Zero();
    Eigen::Vector3d x[4];
    for (int a = 0; a < 4; ++a) {
      const index_t i = conn_[std::size_t(a)][std::size_t(e)];
      x[a] = {k.x[i], k.y[i], k.z[i]};
      q += gam_[std::size_t(a)][std::size_t(e)] * x[a];
    }
    const Eigen::Vector3d n = (x[2] - x[0]).cross(x[3] - x[1]);
    return q - w0_[std::size_t(e)] * n.normalized();
  }
  std::array<index_t, 4> element(index_t e) const {
    return {conn_[0][std::size_t(e)], conn_[1][std::size_t(e)], conn_[2][std::size_t(e)], conn_[3][std::size_t(e)]};
  }
  double reference_area(index_t e) const { return a0t_[std::size_t(e)] / mat_.thickness; }
  double hourglass_spring(index_t e) const { return khg_[std::size_t(e)]; }

 private:
  template <bool Track, bool Damped, bool Vectorize>
  void run(const node_kinematics& k) {
    impl::for_each_element<Track, Vectorize>(n_, std::array{&out_.energy_part, &hg_part_}, [&](auto tag, index_t e) {
      using V = typename decltype(tag)::type;
      V hg(0.0);
      const V w = kernel<V, Track, Damped>(k, e, hg);
      return std::array{w, hg};
    });
  }

  /// Centre strain of element e incl. the w-mode term (scalar: tests, output, time step).
  template <class V>
  PARAFSI_INLINE void strains(const node_kinematics& k, index_t e, vec3<V>& F1, vec3<V>& F2, V& E11, V& E22,
                              V& E12) const {
    F1 = {V(0.0), V(0.0), V(0.0)};
    F2 = F1;
    vec3<V> x[4], qh = F1;
    for (int a = 0; a < 4; ++a) {
      const index_t* ia = conn_[std::size_t(a)].data() + e;
      x[a] = impl::gather_position<V>(k, ia);
      F1 += x[a] * simd::load<V>(ref_[std::size_t(a)].data() + e);
      F2 += x[a] * simd::load<V>(ref_[std::size_t(4 + a)].data() + e);
      qh += x[a] * simd::load<V>(gam_[std::size_t(a)].data() + e);
    }
    const vec3<V> n = cross(x[2] - x[0], x[3] - x[1]);
    const V nn = simd::sqrt(dot(n, n));
    const V dn = dot(qh, n) / simd::max(nn, V(std::numeric_limits<double>::min())) - simd::load<V>(w0_.data() + e);
    const V dn2 = dn * dn;
    E11 = V(0.5) * (dot(F1, F1) - V(1.0)) + dn2 * simd::load<V>(gbb_.data() + e);
    E22 = V(0.5) * (dot(F2, F2) - V(1.0)) + dn2 * simd::load<V>(gcc_.data() + e);
    E12 = V(0.5) * dot(F1, F2) + dn2 * simd::load<V>(gbc_.data() + e);
  }

  /// One element (or one pack): corner forces to the buffers; returns the strain energy
  /// (elastic + hourglass) and its hourglass part in `hg` when tracking.
  template <class V, bool Track, bool Damped>
  PARAFSI_INLINE V kernel(const node_kinematics& k, index_t e, V& hg) {
    const index_t* i0 = conn_[0].data() + e;
    const index_t* i1 = conn_[1].data() + e;
    const index_t* i2 = conn_[2].data() + e;
    const index_t* i3 = conn_[3].data() + e;
    const vec3<V> x0 = impl::gather_position<V>(k, i0), x1 = impl::gather_position<V>(k, i1);
    const vec3<V> x2 = impl::gather_position<V>(k, i2), x3 = impl::gather_position<V>(k, i3);
    const V b0 = simd::load<V>(ref_[0].data() + e), b1 = simd::load<V>(ref_[1].data() + e);
    const V b2 = simd::load<V>(ref_[2].data() + e), b3 = simd::load<V>(ref_[3].data() + e);
    const V c0 = simd::load<V>(ref_[4].data() + e), c1 = simd::load<V>(ref_[5].data() + e);
    const V c2 = simd::load<V>(ref_[6].data() + e), c3 = simd::load<V>(ref_[7].data() + e);
    const V g0 = simd::load<V>(gam_[0].data() + e), g1 = simd::load<V>(gam_[1].data() + e);
    const V g2 = simd::load<V>(gam_[2].data() + e), g3 = simd::load<V>(gam_[3].data() + e);
    // Step 1. Deformation gradient at the centre; hourglass displacement q split about
    // the current BLT normal ê3 ∥ n = (x2 − x0) × (x3 − x1) (n also carries the pressure).
    const vec3<V> F1 = x0 * b0 + x1 * b1 + x2 * b2 + x3 * b3;
    const vec3<V> F2 = x0 * c0 + x1 * c1 + x2 * c2 + x3 * c3;
    const vec3<V> d1 = x2 - x0, d2 = x3 - x1;
    const vec3<V> n = cross(d1, d2);
    const V nn = simd::sqrt(dot(n, n));
    const V inn = V(1.0) / simd::max(nn, V(std::numeric_limits<double>::min()));
    const vec3<V> e3 = n * inn;
    const vec3<V> qh = x0 * g0 + x1 * g1 + x2 * g2 + x3 * g3;
    const V qn = dot(qh, e3);
    const V a1 = dot(F1, qh), a2 = dot(F2, qh);       // in-plane (membrane) hourglass, Fᵀq
    const V dn = qn - simd::load<V>(w0_.data() + e);  // out-of-plane (w) hourglass
    const V km = simd::load<V>(khg_.data() + e);
    const V Gb = simd::load<V>(gbb_.data() + e), Gx = simd::load<V>(gbc_.data() + e),
            Gc = simd::load<V>(gcc_.data() + e);
    // Step 2. Green–Lagrange strain at the centre + mean second-order strain of the w mode.
    const V dn2 = dn * dn;
    const V E11 = V(0.5) * (dot(F1, F1) - V(1.0)) + dn2 * Gb;
    const V E22 = V(0.5) * (dot(F2, F2) - V(1.0)) + dn2 * Gc;
    const V E12 = V(0.5) * dot(F1, F2) + dn2 * Gx;
    // Step 3. Elastic second Piola–Kirchhoff stress (Eq. 4).
    V S11, S22, S12;
    impl::elastic_stress(q_, E11, E22, E12, S11, S22, S12);
    // Step 4. Stiffness-proportional viscous stress β Q Ė; hourglass damping.
    V D11(0.0), D22(0.0), D12(0.0);
    vec3<V> Qd{V(0.0), V(0.0), V(0.0)};
    if constexpr (Damped) {
      const vec3<V> v0 = impl::gather_velocity<V>(k, i0), v1 = impl::gather_velocity<V>(k, i1);
      const vec3<V> v2 = impl::gather_velocity<V>(k, i2), v3 = impl::gather_velocity<V>(k, i3);
      const vec3<V> G1 = v0 * b0 + v1 * b1 + v2 * b2 + v3 * b3;
      const vec3<V> G2 = v0 * c0 + v1 * c1 + v2 * c2 + v3 * c3;
      const vec3<V> qd = v0 * g0 + v1 * g1 + v2 * g2 + v3 * g3;
      const V qdn = dot(qd, e3);
      const V r2 = V(2.0) * dn * qdn;  // d(dn²)/dt
      const V R11 = dot(F1, G1) + r2 * Gb, R22 = dot(F2, G2) + r2 * Gc;
      const V R12 = V(0.5) * (dot(F1, G2) + dot(F2, G1)) + r2 * Gx;
      const V bt(beta_);
      impl::viscous_stress(q_, bt, R11, R22, R12, D11, D22, D12);
      Qd = (F1 * dot(F1, qd) + F2 * dot(F2, qd)) * (bt * km) + qd * simd::load<V>(cv_.data() + e);
    }
    // Step 5. Wrinkling (no compression).
    mat_.wrinkling.apply(S11, S22, S12, D11, D22, D12, E11, E22, E12, q_);
    // Step 6. Corner forces: −A0 t (P1 b_I + P2 c_I) − γ_I (k_m q_m + Q_w ê3 + Q_d) + p/8 n,
    // Q_w = 2 A0 t q_n (T11 G11 + T22 G22 + 2 T12 G12)  (the w-mode term of ∂E/∂x).
    const V at = simd::load<V>(a0t_.data() + e);
    const V T11 = S11 + D11, T22 = S22 + D22, T12 = S12 + D12;
    // In-plane spring ½k_m|Fᵀq|²: ∂/∂x_I = k_m [γ_I F Fᵀq + q (a1 b_I + a2 c_I)].
    const vec3<V> P1 = (F1 * T11 + F2 * T12) * at + qh * (km * a1);
    const vec3<V> P2 = (F1 * T12 + F2 * T22) * at + qh * (km * a2);
    const V Qw = V(2.0) * at * dn * (T11 * Gb + T22 * Gc + V(2.0) * T12 * Gx);
    const vec3<V> QT = (F1 * a1 + F2 * a2) * km + e3 * Qw + Qd;
    // Rotation of ê3 in the w-mode strain: ∂(q·ê3)/∂x = ±d2 × w (corners 2, 0), ±w × d1
    // (corners 3, 1), w = (q − (q·ê3)ê3)/|n|: the forces are exact gradients.
    const vec3<V> wq = (qh - e3 * qn) * inn;
    const vec3<V> r2 = cross(d2, wq), r3 = cross(wq, d1);
    const V sn = Qw;
    const vec3<V> fp = n * (simd::load<V>(p_.data() + e) * V(0.125));
    out_.store<V>(out_.total, 0, e, fp - (P1 * b0 + P2 * c0 + QT * g0 - r2 * sn));
    out_.store<V>(out_.total, 1, e, fp - (P1 * b1 + P2 * c1 + QT * g1 - r3 * sn));
    out_.store<V>(out_.total, 2, e, fp - (P1 * b2 + P2 * c2 + QT * g2 + r2 * sn));
    out_.store<V>(out_.total, 3, e, fp - (P1 * b3 + P2 * c3 + QT * g3 + r3 * sn));
    if constexpr (Track) {
      const vec3<V> Q1 = (F1 * D11 + F2 * D12) * at;
      const vec3<V> Q2 = (F1 * D12 + F2 * D22) * at;
      const V Qwd = V(2.0) * at * dn * (D11 * Gb + D22 * Gc + V(2.0) * D12 * Gx);
      const vec3<V> Qdt = e3 * Qwd + Qd;
      const vec3<V> zero{V(0.0), V(0.0), V(0.0)};
      out_.store<V>(out_.damping, 0, e, zero - (Q1 * b0 + Q2 * c0 + Qdt * g0 - r2 * Qwd));
      out_.store<V>(out_.damping, 1, e, zero - (Q1 * b1 + Q2 * c1 + Qdt * g1 - r3 * Qwd));
      out_.store<V>(out_.damping, 2, e, zero - (Q1 * b2 + Q2 * c2 + Qdt * g2 + r2 * Qwd));
      out_.store<V>(out_.damping, 3, e, zero - (Q1 * b3 + Q2 * c3 + Qdt * g3 + r3 * Qwd));
      for (index_t c = 0; c < 4; ++c) out_.store<V>(out_.external, c, e, fp);
      const V um = V(0.5) * km * (a1 * a1 + a2 * a2);
      hg = um + V(0.5) * at * dn2 * (S11 * Gb + S22 * Gc + V(2.0) * S12 * Gx);
      return impl::membrane_energy(at, S11, S22, S12, E11, E22, E12) + um;
    } else {
      return V(0.0);
    }
  }

  quad_mesh mesh_;
  Fabric mat_;
  quad_options opt_;
  fabric_moduli q_{};
  index_t n_ = 0, np_ = 0;
  double beta_ = 0.0;
  bool auto_reference_ = false;
  std::array<simd::aligned_vector<index_t>, 4> conn_;
  std::array<simd::aligned_vector<double>, 8> ref_;  // b0..b3 c0..c3
  std::array<simd::aligned_vector<double>, 4> gam_;  // hourglass shape vectors γ_I
  simd::aligned_vector<double> a0t_, khg_, cv_, w0_, gbb_, gbc_, gcc_, p_;
  std::vector<double> lc0_;  // reference A0 / max edge
  impl::corner_forces<4> out_;
  std::vector<double> hg_part_;
};

}  // namespace parafsi::structure
