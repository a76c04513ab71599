/// \file penalty.hpp
/// `coupling::penalty<Porosity>`: Lagrangian-in-Eulerian penalty coupling of membrane
/// triangles to the cell-centred fluid (the paper's method, LS-DYNA
/// *CONSTRAINED_LAGRANGE_IN_SOLID analogue; methods §4.3–4.7, §8.3).
///
/// Per coupling point c (coupling_points.hpp), every structure substep of length Δt_s:
///   x_c = Σ N_a x_a,  v_s = Σ N_a v_a,  ξ = Rᵀ(τ)(x_c − X(τ))      (box pose at the substep)
///   v_f = Σ w u_cell,  K_f = Σ w γ p_cell,  ρ_f = Σ w ρ_cell       (fluid frozen at tⁿ)
///   v_rn = (v_f − v_s)·n                                             (relative normal velocity)
///   k_c = PFAC · K_f · A_c / h  · s_c · [1 + (|d|/(λ h))²]           (λ: optional stiffening)
///   Δp_c = k_c d / A_c,   u_p = u_p(Δp_c)                            (porosity law inverse)
///   ḋ = (v_rn − u_p) / (1 + Δt_s (k_c/A_c) du_p/dΔp)                 (linearised backward Euler)
///   d ← d + ḋ Δt_s                                                   (two-sided: d keeps its sign)
///   F_s = (k_c d + c_c ḋ) n,   c_c = ζ · 2√(k_c m_eff)               (force on the structure)
/// The porous leak reduces the penetration rate by the through-flow the fabric law
/// allows (the "hybrid" porous mode of methods §4.7, after Tutt 2006 and Aquelet & Tutt
/// 2007): in a steady state ḋ = 0, so v_rn = u_p(Δp_c) and the pressure jump the spring
/// carries, k_c d/A_c, is exactly the fabric law Δp(v_rn). For `porosity::impermeable`
/// u_p ≡ 0 and this is the plain penalty spring.
///
/// Spreading (adjoint of the interpolation, the same weights):
///   structure nodes  f_a += N_a F_s                         (assembly load hook)
///   fluid cells      J_cell += −w F_s Δt̄,  W_cell += −w F_s·u_cell Δt̄
/// with Δt̄ the central-difference kick length of the substep (½(Δt_prev + Δt_s)), so
/// the structure's momentum change Σ N_a F_s Δt̄ and the fluid's Σ J are equal and
/// opposite to round-off. After the substeps the impulses become the fluid's sources
/// S = (J, W)/(Δt_f V_cell), constant over the fluid step.
///
/// Stiffness default (methods §4.4): k_c = PFAC K A_c/h with PFAC = 0.1 and
/// h = V_cell^{1/3}: the equilibrium penetration is d = Δp h/(PFAC K) independent of
/// the point density (Δp = 370 Pa, h = 5 cm: d ≈ 0.03 h). Stability (methods §4.6):
///   - fluid side: Σ_{points} w k_c Δt_f²/(ρ V_cell) ≤ fluid_cap (default 1) per cell;
///     where it is exceeded (folded canopy: many layers in a cell, or a large PFAC)
///     every k_c touching the cell is scaled down (s_c < 1, reported);
///   - structure side: the substep is limited by the Gershgorin bound over free nodes,
///     Δt_s ≤ 2√(m_a / Σ_c N_a k_c) (√(1 + ζ²) − ζ);
///   - a point must not cross more than `max_cells_per_step` cells relative to the
///     grid in one fluid step: a larger step is rejected with a message.
/// m_eff = m_s m_f/(m_s + m_f), m_s the point's share of its free nodes' mass, m_f =
/// ρ h A_c (one cell of air over the point's area).
///
/// References: Aquelet N., Souli M., Olovsson L. (2006) CMAME 195:110 (coupling with
///   damping); Aquelet N., Tutt B. (2007) Int. J. Multiphysics 1:1,
///   doi:10.1260/175095407780130517 (porous coupling, Ergun law); Tutt B. (2006) 9th Int.
///   LS-DYNA Users Conf. (material porosity algorithm); Souli M., Benson D. (2013)
///   Arbitrary Lagrangian Eulerian and Fluid-Structure Interaction, Wiley.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "../fluid/solver.hpp"
#include "../fluid/view.hpp"
#include "../structure/assembly.hpp"
#include "../structure/nodes.hpp"
#include "coupling_points.hpp"
#include "detail/fluid_mesh.hpp"
#include "detail/membrane_coupling.hpp"
#include "kinds.hpp"
#include "porosity/impermeable.hpp"

namespace parafsi::coupling {

struct penalty_options {
  double pfac = 0.1;                ///< PFAC in k_c = PFAC K A_c / h
  double damping_ratio = 0.0;       ///< ζ of the coupling damper (0 = LS-DYNA default)
  double stiffening = 0.0;          ///< λ: k ← k(1 + (|d|/(λh))²); 0 = off (0.25 recommended)
  double fluid_cap = 1.0;           ///< per-cell Σ w k Δt_f²/(ρV) cap; 0 = no capping
  double max_cells_per_step = 1.0;  ///< reject steps where a point moves farther (cells)
  point_options points{};

  void validate() const {
    require(std::isfinite(pfac) && pfac > 0, "coupling::penalty: PFAC must be > 0, got ", pfac);
    require(damping_ratio >= 0 &&
                damping_ratio <= 1,  // NaN fails both "coupling::penalty: damping ratio must be in [0, 1], got ",
            damping_ratio);
    // The stable substep is bounded with the stiffness at tⁿ; with λ < 0.01 the factor
    // 1 + (d/(λh))² grows by more than 10⁴ while d moves by one hundredth of a cell inside
    // the step, so that bound no longer holds and the spring diverges.
    require(std::isfinite(stiffening) && (stiffening == 0 || stiffening >= 0.01),
            "coupling::penalty: stiffening must be 0 (off) or >= 0.01, got ", stiffening,
            " (a smaller lambda makes the stiffness grow faster within one step than the stable substep allows)");
    require(fluid_cap >= 0 && std::isfinite(fluid_cap), "coupling::penalty: fluid_cap must be >= 0, got ", fluid_cap);
    require(std::isfinite(max_cells_per_step) && max_cells_per_step > 0,
            "coupling::penalty: max_cells_per_step must be > 0, got ", max_cells_per_step);
    points.validate();
  }
};

/// Per-step diagnostics (methods §8.3 step 6).
struct penalty_diagnostics {
  double max_penetration_over_h = 0;                            ///< max |d|/h over points and substeps of the step
  double min_stiffness_scale = 1;                               ///< smallest cap scaling s_c of the step
  Eigen::Vector3d impulse_structure = Eigen::Vector3d::Zero();  ///< Σ F_s Δt̄ of the step (N s)
  double work_fluid = 0;                                        ///< Σ W of the step: energy given to the air (J)
  double work_structure = 0;                                    ///< Σ F_s·v_s Δt̄ of the step (J)
  double coupling_energy = 0;  ///< cumulative Σ F_s·(v_f − v_s) Δt̄ (J): spring + porous loss
  index_t active_points = 0, inactive_points = 0;
  std::vector<double> through_flow;   ///< per element: Σ u_p A_c (m³/s, along +n), last substep
  std::vector<double> relative_flow;  ///< per element: Σ v_rn A_c (m³/s), last substep
};

template <class Porosity = porosity::impermeable>
class penalty : public detail::membrane_coupling<penalty<Porosity>, Porosity, penalty_options> {
  using base = detail::membrane_coupling<penalty<Porosity>, Porosity, penalty_options>;
  using base::attached_;
  using base::opt_;
  using base::por_;

 public:
  static constexpr const char* name() noexcept { return "penalty"; }
  using base::base;

  const coupling_points& points() const noexcept { return pts_; }
  const penalty_diagnostics& diagnostics() const noexcept { return diag_; }
  /// Signed penetration of point c (m).
  double penetration(index_t c) const { return d_[std::size_t(c)]; }
  /// Set the penetration of point c (restart from a checkpoint).
  void set_penetration(index_t c, double d) {
    require(c >= 0 && std::size_t(c) < d_.size() && std::isfinite(d), "coupling::penalty::set_penetration: bad point ",
            c, " or value ", d);
    d_[std::size_t(c)] = d;
  }
  /// Checkpoint (io/archive.hpp; after attach): the coupling settings (compared), the
  /// penetration of every point (state the next step reads) and the cumulative energy.
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& self) {
    ar.check("porosity", std::string(Porosity::name()), "the porosity law");
    ar.check("pfac", self.opt_.pfac, "the penalty factor PFAC");
    ar.check("damping_ratio", self.opt_.damping_ratio, "the coupling damping ratio");
    ar.check("stiffening", self.opt_.stiffening, "the penalty stiffening");
    ar.check("fluid_cap", self.opt_.fluid_cap, "the fluid-side stiffness cap");
    ar.check("points", std::int64_t(self.d_.size()), "the number of penalty coupling points");
    ar("penetration", self.d_);
    ar("coupling_energy", self.diag_.coupling_energy);
  }
  /// Total through-flow Σ_e (m³/s) and coupled area (m²) at the last substep.
  double total_through_flow() const {
    double q = 0;
    for (double v : diag_.through_flow) q += v;
    return q;
  }
  double coupled_area() const { return area_; }

  // ------------------------------------------------------------- stepper hooks
  /// Build the points from the assembly's membranes and enable the fluid sources.
  template <class Fluid, class Asm>
  void attach(Fluid& f, Asm& s) {
    f.enable_sources();
    loc_ = mesh_locator::of(f);
    const std::vector<detail::triangle> tris = this->attach_triangles(s);
    const auto& nd = s.node_set();
    pts_.build(
        tris, [&](index_t i) { return nd.position(i); }, loc_, f.pose(), opt_.points);
    const index_t n = pts_.size();
    d_.assign(std::size_t(n), 0.0);
    scale_.assign(std::size_t(n), 1.0);
    // Share of every node's weight (for the point mass share m_s).
    node_wsum_.assign(std::size_t(nd.size()), 0.0);
    for (index_t c = 0; c < n; ++c)
      for (int a = 0; a < 3; ++a)
        node_wsum_[std::size_t(pts_.nodes_of(pts_.element(c))[std::size_t(a)])] += pts_.weight(c, a);
    node_k_.assign(std::size_t(nd.size()), 0.0);
    diag_.through_flow.assign(std::size_t(pts_.elements()), 0.0);
    diag_.relative_flow.assign(std::size_t(pts_.elements()), 0.0);
    kraw_.assign(std::size_t(n), 0.0);
    st_.assign(std::size_t(n), stencil{});
    attached_ = true;
  }

  /// Move-frame phase: the box pose at tⁿ with the motion the stepper planned for the
  /// step (the fluid step applies the same motion), used to locate points at each substep.
  template <class Fluid>
  void plan(const Fluid& f, const frame::motion& m) {
    pose_ = f.pose();
    pose_.set_motion(m);
  }

  /// Exchange phase: snapshot the fluid at tⁿ, set stiffness scalings and the substep
  /// limit, check the travel per step, clear the fluid's source arrays (they collect
  /// the impulses of the substeps).
  template <class Fluid, class Asm>
  void exchange(Fluid& f, const Asm& s, double dt_f) {
    this->require_attached();
    // Fluid snapshot (inertial velocity, bulk modulus, density) on interior cells.
    const index_t N = detail::cell_count(f);
    if (index_t(u_[0].size()) != N)
      for (auto* a : {&u_[0], &u_[1], &u_[2], &K_, &rho_}) a->assign(std::size_t(N), 0.0);
    const fluid::view fv = f.view();
    detail::for_each_interior_cell(f, [&](index_t c, double) {
      const Eigen::Vector3d u = fv.velocity(c);
      u_[0][std::size_t(c)] = u.x();
      u_[1][std::size_t(c)] = u.y();
      u_[2][std::size_t(c)] = u.z();
      K_[std::size_t(c)] = fv.bulk_modulus(c);
      rho_[std::size_t(c)] = fv.density(c);
    });
    // Clear the source arrays (they accumulate impulses until finish()).
    for (int q = 0; q < 4; ++q) {
      double* sq = f.source(q);
      parallel::for_range(0, N, [&](index_t c) { sq[c] = 0.0; });
      src_[std::size_t(q)] = sq;
    }
    // Stiffness at tⁿ, per-cell cap, nodal stiffness, travel check.
    const auto& nd = s.node_set();
    const index_t n = pts_.size();
    if (opt_.fluid_cap > 0 && index_t(ksum_.size()) != N) ksum_.assign(std::size_t(N), 0.0);
    std::fill(node_k_.begin(), node_k_.end(), 0.0);
    std::vector<double>& kraw = kraw_;
    std::vector<stencil>& st = st_;
    diag_.min_stiffness_scale = 1.0;
    for (index_t e = 0; e < pts_.elements(); ++e) {
      const auto geo = element_geometry(nd, e);
      for (index_t c = pts_.first(e); c < pts_.first(e + 1); ++c) {
        const Eigen::Vector3d x = point_position(geo, c);
        const stencil sc = loc_.locate(pose_.to_box(x));
        st[std::size_t(c)] = sc;
        if (!sc.inside) continue;
        if constexpr (block_fluid<Fluid>)  // the same answer on every process of a distributed mesh
          for (index_t cell : sc.cell)
            require(f.computed_everywhere(cell / f.stride()), "coupling::penalty: point ", c, " of element ", e,
                    " reads block ", cell / f.stride(),
                    ", which not every process computes: on a distributed block mesh the penalty coupling needs the "
                    "structure's blocks on every process (mpi::block_halo's replicate_finest)");
        const double K = interp(K_, sc);
        const double Ac = geo.area / pts_.nquad(e) / pts_.nquad(e);
        double k = opt_.pfac * K * Ac / sc.h;
        if (opt_.stiffening > 0) {
          const double q = d_[std::size_t(c)] / (opt_.stiffening * sc.h);
          k *= 1.0 + q * q;
        }
        kraw[std::size_t(c)] = k;
        if (opt_.fluid_cap > 0)
          for (int a = 0; a < 8; ++a) ksum_[std::size_t(sc.cell[std::size_t(a)])] += sc.weight(a) * k;
        // Travel relative to the grid over the step.
        const Eigen::Vector3d vs = point_velocity(geo, c);
        const Eigen::Vector3d wg = pose_.grid_velocity(pose_.to_box(x));
        const double travel = (vs - wg).norm() * dt_f / sc.h;
        if (travel > opt_.max_cells_per_step)
          throw numerical_failure(
              parafsi::detail::concat(
                  "coupling::penalty: membrane element ", e, " moves ", (vs - wg).norm(),
                  " m/s relative to the fluid grid, ", travel, " cells of size ", sc.h, " m in one fluid step of ",
                  dt_f, " s (limit ", opt_.max_cells_per_step,
                  " cell per step); the coupling would skip cells: reduce the time step (explicit_stepper::"
                  "stable_dt() includes this limit)"),
              e, f.time());
      }
    }
    for (index_t c = 0; c < n; ++c) {
      const stencil& sc = st[std::size_t(c)];
      double sfac = 1.0;
      if (sc.inside && opt_.fluid_cap > 0) {
        for (int a = 0; a < 8; ++a) {
          if (sc.weight(a) <= 0) continue;
          const index_t cell = sc.cell[std::size_t(a)];
          const double vol = detail::cell_volume(f, cell);
          const double ks = ksum_[std::size_t(cell)];
          if (ks > 0) sfac = std::min(sfac, opt_.fluid_cap * rho_[std::size_t(cell)] * vol / (dt_f * dt_f * ks));
        }
      }
      scale_[std::size_t(c)] = sfac;
      diag_.min_stiffness_scale = std::min(diag_.min_stiffness_scale, sfac);
      const auto& tri = pts_.nodes_of(pts_.element(c));
      for (int a = 0; a < 3; ++a)
        node_k_[std::size_t(tri[std::size_t(a)])] += pts_.weight(c, a) * kraw[std::size_t(c)] * sfac;
    }
    if (opt_.fluid_cap > 0)
      for (index_t c = 0; c < n; ++c)
        if (st[std::size_t(c)].inside)
          for (int a = 0; a < 8; ++a) ksum_[std::size_t(st[std::size_t(c)].cell[std::size_t(a)])] = 0.0;
    // Structure-side substep limit (Gershgorin over free nodes).
    dt_struct_ = std::numeric_limits<double>::infinity();
    const double z = opt_.damping_ratio;
    for (index_t i = 0; i < nd.size(); ++i)
      if (nd.kind(i) == structure::constraint::free && node_k_[std::size_t(i)] > 0)
        dt_struct_ = std::min(dt_struct_, 2.0 * std::sqrt(nd.mass(i) / node_k_[std::size_t(i)]));
    dt_struct_ *= std::sqrt(1.0 + z * z) - z;
    // Step diagnostics.
    diag_.max_penetration_over_h = 0;
    diag_.impulse_structure.setZero();
    diag_.work_fluid = diag_.work_structure = 0;
    dt_f_ = dt_f;
  }

  /// Largest substep the coupling springs allow (after exchange()).
  double structure_dt() const noexcept { return dt_struct_; }

  /// Largest fluid step keeping every point within max_cells_per_step/2 cells of travel.
  template <class Fluid, class Asm>
  double travel_dt(const Fluid& f, const Asm& s) const {
    if (!attached_) return std::numeric_limits<double>::infinity();
    const auto& nd = s.node_set();
    double dt = std::numeric_limits<double>::infinity();
    for (index_t e = 0; e < pts_.elements(); ++e) {
      const auto geo = element_geometry(nd, e);
      double vmax = 0;
      for (int a = 0; a < 3; ++a) {
        const Eigen::Vector3d x = geo.x[std::size_t(a)];
        vmax = std::max(vmax, (geo.v[std::size_t(a)] - f.pose().grid_velocity(f.pose().to_box(x))).norm());
      }
      if (vmax <= 0) continue;
      const stencil sc = loc_.locate(f.pose().to_box((geo.x[0] + geo.x[1] + geo.x[2]) / 3.0));
      dt = std::min(dt, 0.5 * opt_.max_cells_per_step * sc.h / vmax);
    }
    return dt;
  }

  /// Coupling forces of one substep at offset tau from tⁿ; adds N_a F to the nodes
  /// through `sink` and −w F Δt̄ (and its work) to the fluid impulse arrays.
  void apply(structure::load_sink& sink, const structure::nodes& nd, double tau, double dt_kick, double dt_s) {
    const bool damped = opt_.damping_ratio > 0, stiffened = opt_.stiffening > 0;
    if (damped && stiffened) apply_points<true, true>(sink, nd, tau, dt_kick, dt_s);
    else if (damped) apply_points<true, false>(sink, nd, tau, dt_kick, dt_s);
    else if (stiffened) apply_points<false, true>(sink, nd, tau, dt_kick, dt_s);
    else apply_points<false, false>(sink, nd, tau, dt_kick, dt_s);
  }

  /// Turn the accumulated impulses into the fluid sources S = (J, W)/(Δt_f V_cell).
  template <class Fluid>
  void finish(Fluid& f, double dt_f) {
    const double inv_dt = 1.0 / dt_f;
    detail::for_each_interior_cell(f, [&](index_t c, double vol) {
      const double s = inv_dt / vol;
      for (int q = 0; q < 4; ++q) src_[std::size_t(q)][c] *= s;
    });
  }

 private:
  /// The substep's point loop; damping and stiffening chosen once per call.
  template <bool Damped, bool Stiffened>
  void apply_points(structure::load_sink& sink, const structure::nodes& nd, double tau, double dt_kick, double dt_s) {
    frame::pose pz = pose_;
    if (tau > 0 && (pz.V.squaredNorm() > 0 || pz.Omega.squaredNorm() > 0)) pz.advance(tau);
    double* sx = src_[0];
    double* sy = src_[1];
    double* sz = src_[2];
    double* sE = src_[3];
    [[maybe_unused]] const double z = opt_.damping_ratio;
    index_t active = 0;
    area_ = 0;
    for (index_t e = 0; e < pts_.elements(); ++e) {
      const auto geo = element_geometry(nd, e);
      const int nq = pts_.nquad(e);
      const double Ac = geo.area / double(nq * nq);
      const Eigen::Vector3d& nrm = geo.n;
      double qe = 0, qr = 0;
      // Free-node mass share of the points (for damping).
      for (index_t c = pts_.first(e); c < pts_.first(e + 1); ++c) {
        const Eigen::Vector3d x = point_position(geo, c);
        const stencil sc = loc_.locate(pz.to_box(x));
        double& d = d_[std::size_t(c)];
        if (!sc.inside) {
          d = 0;
          continue;
        }
        ++active;
        area_ += Ac;
        double w[8];
        Eigen::Vector3d vf = Eigen::Vector3d::Zero();
        double K = 0, rho = 0;
        for (int a = 0; a < 8; ++a) {
          w[a] = sc.weight(a);
          const std::size_t cell = std::size_t(sc.cell[std::size_t(a)]);
          vf += w[a] * Eigen::Vector3d(u_[0][cell], u_[1][cell], u_[2][cell]);
          K += w[a] * K_[cell];
          rho += w[a] * rho_[cell];
        }
        const Eigen::Vector3d vs = point_velocity(geo, c);
        const double vrn = (vf - vs).dot(nrm);
        double k = opt_.pfac * K * Ac / sc.h * scale_[std::size_t(c)];
        if constexpr (Stiffened) {
          const double q = d / (opt_.stiffening * sc.h);
          k *= 1.0 + q * q;
        }
        const double dp = k * d / Ac;
        const double up = por_.through_velocity(dp);
        const double comp = por_.compliance(dp);
        const double ddot = (vrn - up) / (1.0 + dt_s * (k / Ac) * comp);
        d += ddot * dt_s;
        double cdamp = 0;
        if constexpr (Damped) {
          double ms = 0;
          bool any_free = false;
          for (int a = 0; a < 3; ++a) {
            const index_t i = geo.id[std::size_t(a)];
            if (nd.kind(i) != structure::constraint::free) continue;
            any_free = true;
            ms += pts_.weight(c, a) * nd.mass(i) / node_wsum_[std::size_t(i)];
          }
          const double mf = rho * sc.h * Ac;
          const double meff = any_free ? ms * mf / (ms + mf) : mf;
          cdamp = z * 2.0 * std::sqrt(k * meff);
        }
        const double Fn = k * d + cdamp * ddot;
        const Eigen::Vector3d F = Fn * nrm;
        for (int a = 0; a < 3; ++a) sink.add(geo.id[std::size_t(a)], pts_.weight(c, a) * F);
        const Eigen::Vector3d J = -F * dt_kick;
        double wf = 0;
        for (int a = 0; a < 8; ++a) {
          const std::size_t cell = std::size_t(sc.cell[std::size_t(a)]);
          const Eigen::Vector3d Jw = w[a] * J;
          sx[cell] += Jw.x();
          sy[cell] += Jw.y();
          sz[cell] += Jw.z();
          const double W = Jw.x() * u_[0][cell] + Jw.y() * u_[1][cell] + Jw.z() * u_[2][cell];
          sE[cell] += W;
          wf += W;
        }
        diag_.impulse_structure += F * dt_kick;
        diag_.work_fluid += wf;
        diag_.work_structure += F.dot(vs) * dt_kick;
        diag_.coupling_energy += F.dot(vf - vs) * dt_kick;
        diag_.max_penetration_over_h = std::max(diag_.max_penetration_over_h, std::fabs(d) / sc.h);
        qe += por_.through_velocity(k * d / Ac) * Ac;
        qr += vrn * Ac;
      }
      diag_.through_flow[std::size_t(e)] = qe;
      diag_.relative_flow[std::size_t(e)] = qr;
    }
    diag_.active_points = active;
    diag_.inactive_points = pts_.size() - active;
  }

  struct elem_geo {
    std::array<index_t, 3> id;
    std::array<Eigen::Vector3d, 3> x, v;
    Eigen::Vector3d n;
    double area;
  };
  elem_geo element_geometry(const structure::nodes& nd, index_t e) const {
    elem_geo g;
    g.id = pts_.nodes_of(e);
    for (int a = 0; a < 3; ++a) {
      g.x[std::size_t(a)] = nd.position(g.id[std::size_t(a)]);
      g.v[std::size_t(a)] = nd.velocity(g.id[std::size_t(a)]);
    }
    const Eigen::Vector3d c = (g.x[1] - g.x[0]).cross(g.x[2] - g.x[0]);
    const double a2 = c.norm();
    g.area = 0.5 * a2;
    g.n = a2 > 0 ? Eigen::Vector3d(c / a2) : Eigen::Vector3d::Zero();
    return g;
  }
  Eigen::Vector3d point_position(const elem_geo& g, index_t c) const {
    return pts_.weight(c, 0) * g.x[0] + pts_.weight(c, 1) * g.x[1] + pts_.weight(c, 2) * g.x[2];
  }
  Eigen::Vector3d point_velocity(const elem_geo& g, index_t c) const {
    return pts_.weight(c, 0) * g.v[0] + pts_.weight(c, 1) * g.v[1] + pts_.weight(c, 2) * g.v[2];
  }
  double interp(const std::vector<double>& a, const stencil& s) const {
    double v = 0;
    for (int q = 0; q < 8; ++q) v += s.weight(q) * a[std::size_t(s.cell[std::size_t(q)])];
    return v;
  }
  mesh_locator loc_;
  coupling_points pts_;
  std::vector<double> d_, scale_, node_wsum_, node_k_, ksum_;
  std::array<std::vector<double>, 3> u_;
  std::vector<double> K_, rho_;
  std::vector<double> kraw_;  ///< per point: stiffness before capping (exchange scratch)
  std::vector<stencil> st_;   ///< per point: stencil at tⁿ (exchange scratch)
  std::array<double*, 4> src_{};
  frame::pose pose_{};
  double dt_struct_ = std::numeric_limits<double>::infinity();
  double dt_f_ = 0;
  double area_ = 0;
  penalty_diagnostics diag_{};
};

template <class P>
penalty(P) -> penalty<P>;
template <class P>
penalty(P, penalty_options) -> penalty<P>;

}  // namespace parafsi::coupling
