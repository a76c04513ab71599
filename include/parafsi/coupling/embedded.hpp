/// \file embedded.hpp
/// `coupling::embedded<Porosity>`: membrane-aware face fluxes (an embedded-boundary
/// coupling, after FIVER: Wang, Farhat et al., IJNMF 67:1175 (2011); methods §4.8
/// "option B"). No numerical leak by construction: wherever a membrane lies between
/// two cell centres, the scheme's flux through that face is replaced by one-sided
/// wall fluxes plus the porous through-flow of the fabric law.
///
/// Faces. Every step, at the structure positions of tⁿ and the box pose of tⁿ, the
/// interior faces whose centre-to-centre segment crosses a blocking triangle are
/// found: per triangle, per axis d, the cells in the triangle's bounding box in index
/// space (O(elements × cells per element)), an exact segment–triangle test on the
/// axis-parallel segment (projected 2-D barycentrics λ of the segment's transverse
/// position, then the crossing coordinate z = Σ λ_a ξ_a,d ∈ [x_c,i−1, x_c,i)).
/// Crossings of one face at the same z (a segment through a shared edge or vertex)
/// count once. Elements marked open (vents) are skipped.
///
/// Face flux (per unit area; n the face normal, low → high; states L, R on each side: the
/// cells' own, or one-sided reconstructed with OneSided; w = n·v_s the membrane's normal
/// velocity at the crossing, the mean over the layers; w_g the grid's normal speed). Unknown: the through-velocity
/// u_p of the air relative to the membrane; the air at the membrane moves at
/// u_m = w + u_p. Each side sees a piston moving at u_m: its wall pressure p*_K comes
/// from the exact one-sided Riemann problem (Toro §4.2: rarefaction or shock branch,
/// both inverted in closed form). The fabric law closes the system:
///   p*_L(u_m) − p*_R(u_m) = k Δp_por(u_n),   u_p = c u_n + σ   (k layers in series)
/// with the law on the cloth's own normal through-velocity u_n (`law_on = cloth_normal`,
/// the default). A cloth of unit normal m (oriented along n, c = m·n ∈ [0, 1]) inclined to
/// the grid crosses a staircase of faces of all three axes (area A Σ|m_d| for cloth area A).
/// The air crossing it moves relative to the cloth at u_n m + s, s ⊥ m, so its face-normal
/// velocity is u_p = c u_n + s·n. The staircase carries the part of the flow along the cloth
/// the two sides have in common:
///   σ = minmod(σ_L, σ_R),   σ_K = n·[r_K − (r_K·m) m],   r_K = u_K − v_s
/// (v_s the membrane's velocity at the crossing). In a uniform stream through an inclined
/// screen σ_L = σ_R, the law holds on u_n, and Σ_faces σ A_face = 0 over a plane staircase;
/// in a shear layer along the cloth (a stream on one side, still air on the other) σ = 0,
/// so no air crosses where the law lets none through. Normal to the face c = 1, σ = 0.
/// `law_on = face_velocity`: the law on u_p itself (σ = 0, c = 1), which the staircase of
/// an inclined cloth makes too permeable (−6 % and −7.5 % in Δp at 30° and 45°,
/// test_coupling_screen; docs/coupling.md §7 has the rules tried before this one).
/// The left side falls and the right rises with u_m, the law rises with u_n, so the
/// root (in u_n) is unique; it is bracketed and found by the Illinois method. For
/// `porosity::impermeable` u_p = 0 (an exact moving wall). As the resistance → 0 this
/// becomes the exact Godunov flux (a transparent screen); as it → ∞ the wall.
/// With W*_K = (ρ*_K, u_K + (u_m − u_K·n) n, p*_K) the star states:
///   F_K = [ρ*_K (w − w_g),  ρ*_K u*_K (w − w_g) + p*_K n,  E*_K (w − w_g) + p*_K w] + P
///   P   = [ρ* u_p,  ρ* u* u_p,  (E* + p*) u_p]   of the upwind star state
/// F_L is what the low cell sends, F_R what the high cell receives. The porous part P
/// leaves one side and enters the other identically (mass, momentum and energy of the
/// through-flow are conserved; the fabric's dissipation stays in the air as heat).
///
/// Load and balance. The membrane receives, per face and RK stage s (weight β_s of the
/// stage in the step, β_s = Π_{r ≥ s} b_r of the Shu–Osher form),
///   J_face = Σ_s β_s Δt A (F_L − F_R).m  =  (p*_L − p*_R) n A Δt + swept terms,
/// exactly what the air loses, spread to the crossing element's nodes with the
/// barycentric weights λ of the crossing point (shared equally by the k layers). The
/// fluid step runs first in the stepper step (`fluid_first`), then the structure
/// substeps apply J as constant forces J/Σ kick, so the structure's momentum change is
/// J to round-off, every step. Energy: the air gives Σ β Δt A (F_L − F_R).E, which is
/// the pressure work (p*_L − p*_R) w A Δt exactly when the membrane moves with the grid
/// (w = w_g); the swept terms ∝ (w − w_g) are first order in the membrane's motion
/// through the grid (reported: `work_fluid` vs `work_structure`, `mass_defect`).
///
/// Rules and limits. A face crossed by k blocking layers is ONE wall: the layers are
/// in series (Δp = k Δp_por(u_p); any impermeable layer seals it), w is their mean
/// normal velocity and the load is shared equally. Several layers in one cell thus
/// isolate that cell (it keeps its own state), which is stable. A membrane that moves
/// more than `max_cells_per_step` cells relative to the grid in a step is rejected.
/// Only faces between two interior cells are patched: a membrane in the outermost half
/// cell of the box is not seen. By default the states L, R are the cells' own (first order)
/// and the solver's MUSCL slopes of those cells read across the membrane; with
/// `embedded<P, true>` the cells beside it are reconstructed from their own side
/// (`one_sided_reconstruction`, fluid/detail/patch_faces.hpp): L, R are second order.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "../fluid/patch.hpp"
#include "../fluid/solver.hpp"
#include "../fluid/view.hpp"
#include "../structure/assembly.hpp"
#include "../structure/nodes.hpp"
#include "detail/fluid_mesh.hpp"
#include "detail/membrane_coupling.hpp"
#include "kinds.hpp"
#include "porosity/impermeable.hpp"

namespace parafsi::coupling {

/// What velocity the fabric law of a patched face is applied to (file comment, "Face flux").
enum class through_flow_law {
  face_velocity,  ///< the face's own through-velocity u_p (the staircase's; too permeable when inclined)
  cloth_normal    ///< the cloth's normal through-velocity u_n, u_p = c u_n + σ (the default)
};

inline const char* to_string(through_flow_law l) noexcept {
  return l == through_flow_law::face_velocity ? "face" : "cloth";
}

/// The law named "face" or "cloth" (the inverse of to_string; the programs' --through-flow).
inline through_flow_law through_flow_law_named(const std::string& name) {
  require(name == "face" || name == "cloth", "coupling::embedded: through-flow law must be face or cloth, got '", name,
          "'");
  return name == "face" ? through_flow_law::face_velocity : through_flow_law::cloth_normal;
}

struct embedded_options {
  double max_cells_per_step = 1.0;  ///< reject steps where the membrane moves farther (cells)
  /// The velocity the fabric law acts on: the cloth's normal (default) or the face's.
  through_flow_law law_on = through_flow_law::cloth_normal;
  double root_tolerance = 1e-13;  ///< relative tolerance of the through-velocity root
  /// Impedance (added-mass) stabilisation factor ζ ∈ [0, 1]: the structure substeps add
  /// −ζ Σ (ρ_L c_L + ρ_R c_R) A λ n nᵀ (v − vⁿ) to the nodal loads (the linear response of
  /// the face pressures to the membrane's velocity change within the step). 0 (default):
  /// off, exact impulse balance every step; 1: light fabric stable (see the file comment).
  double impedance = 0.0;
  void validate() const {
    require(impedance >= 0 && impedance <= 1, "coupling::embedded: impedance factor must be in [0, 1], got ",
            impedance);
    require(max_cells_per_step > 0 && std::isfinite(max_cells_per_step),
            "coupling::embedded: max_cells_per_step must be > 0, got ", max_cells_per_step);
    require(root_tolerance > 0 && root_tolerance < 1e-3,
            "coupling::embedded: root_tolerance must be in (0, 1e-3), got ", root_tolerance);
  }
};

/// Per-step diagnostics.
struct embedded_diagnostics {
  double max_penetration_over_h = 0;                            ///< always 0: the membrane is a wall in the scheme
  index_t faces = 0;                                            ///< patched faces this step
  index_t crossings = 0;                                        ///< face–element crossings (after merging)
  index_t multi_layer_faces = 0;                                ///< faces crossed by more than one layer
  Eigen::Vector3d impulse_structure = Eigen::Vector3d::Zero();  ///< Σ J of the step (N s)
  /// Impulse of the impedance term this step (N s; included in impulse_structure, zero
  /// when impedance = 0): the momentum in flight between the air and the structure.
  Eigen::Vector3d impulse_impedance = Eigen::Vector3d::Zero();
  double impedance_substep = std::numeric_limits<double>::infinity();  ///< its substep limit (s)
  double work_fluid = 0;             ///< energy the air gave through the patched faces this step (J)
  double work_structure = 0;         ///< Σ F·v_s kick over the substeps (J)
  double mass_defect = 0;            ///< Σ β Δt A (F_L − F_R).ρ: mass not conserved by the swept terms (kg)
  double max_through_velocity = 0;   ///< max |u_p| of the step (m/s)
  std::vector<double> through_flow;  ///< per element: Σ u_p A_face/k along +n_e (m³/s), last stage
};

/// The pressures on the two sides of the cloth seen along a direction e (embedded::cloth_sides),
/// from the wall pressures p*_L, p*_R of the patched faces (file comment, "Face flux"), each the
/// mean over the step's stages with their weights β_s (as the load is). A face of normal n_f
/// and area A_f counts with the weight w_f = A_f |n_f·e|; its windward side is the one whose
/// pressure pushes the cloth along +e: the low side when n_f·e > 0, else the high side. So
///   (windward_pressure − leeward_pressure) · projected_area = Σ_f A_f (p*_L − p*_R) n_f·e,
/// the cloth's pressure load along e (the load without its swept terms ∝ (w − w_g); the
/// porous momentum leaves one side and enters the other, so it is not in the load). The
/// staircase of a plane cloth of area A and unit normal m has the area A |m_d| on the faces
/// of axis d, so projected_area is A Σ_d |m_d| |e_d|: A |m·e| when e is along a grid axis
/// (in the drop the following box's axis turns to the payload's velocity; a fixed box's does
/// not). "The step" is the last step of the coupling: subcycled, the last finest-level step.
struct cloth_side_means {
  double projected_area = 0;     ///< S = Σ_f A_f |n_f·e| (m²)
  double windward_pressure = 0;  ///< Σ_f w_f p*_windward / S (Pa; the fluid's pressure, so scaled with PGS)
  double leeward_pressure = 0;   ///< Σ_f w_f p*_leeward / S (Pa)
  /// Σ_f s_f u_n,f c_f A_f (m³/s): the air crossing the cloth along its elements' normals
  /// (the same for every e). u_n,f = Δp_por⁻¹((p*_L − p*_R)/k) is the fabric law's normal
  /// through-velocity at the face's wall pressure jump (each stage, then the stage-weighted
  /// mean), c_f A_f = |m_f·n_f| A_f the cloth area the face stands for (m_f the unit mean cloth
  /// normal of its layers; a plane cloth: Σ_f c_f A_f = A) and s_f the mean over its layers of
  /// sign(n_element·n_f). Not the faces' own u_p, which also carries the flow along a curved
  /// cloth through its staircase. With the law on the face velocity (law_on = face_velocity)
  /// the law's inverse is each face's own u_p and the faces pass more than this sum.
  double through_flow = 0;
  index_t faces = 0;  ///< the faces with n_f·e ≠ 0
  /// The cloth's pressure load as a vector, Σ_f A_f (p*_low − p*_high) n_f over every face
  /// (N; world frame): along e it is (windward − leeward) · projected_area, across e the
  /// side force of a canopy at an angle to the stream (its lift).
  Eigen::Vector3d pressure_load = Eigen::Vector3d::Zero();
};

/// `OneSided`: reconstruct the cells beside a membrane face from their own side (second
/// order up to the membrane; see `one_sided_reconstruction`; docs/coupling.md §7: an acoustic
/// pulse reflects to order 2.2 instead of 1.3, a flexible porous sheet settles as with
/// first-order states). Off by default because the block solver does not have it; the drop
/// scene turns it on on the box solver.
template <class Porosity = porosity::impermeable, bool OneSided = false>
class embedded : public detail::membrane_coupling<embedded<Porosity, OneSided>, Porosity, embedded_options> {
  using base = detail::membrane_coupling<embedded<Porosity, OneSided>, Porosity, embedded_options>;
  using base::attached_;
  using base::opt_;
  using base::por_;

 public:
  /// The fluid step runs before the structure substeps (the loads come from its fluxes).
  static constexpr bool fluid_first = true;
  /// With OneSided, the cells beside a membrane face are reconstructed from their own side
  /// only (fluid/detail/patch_faces.hpp) and the face states L, R are second order; without
  /// it, the membrane Riemann problem takes the two cells' own states (first order).
  static constexpr bool one_sided_reconstruction = OneSided;
  static constexpr const char* name() noexcept { return "embedded"; }
  using base::base;

  /// Mark elements (indices into the coupled triangles) as open: vents, slots. They
  /// do not block the air and carry no load.
  embedded& open(std::vector<index_t> elements) {
    open_list_ = std::move(elements);
    return *this;
  }

  const embedded_diagnostics& diagnostics() const noexcept { return diag_; }
  const std::vector<std::array<index_t, 3>>& triangles() const noexcept { return tris_; }
  bool blocking(index_t e) const { return !open_[std::size_t(e)]; }
  /// Total through-flow Σ_e (m³/s, along the element normals) at the last stage.
  double total_through_flow() const {
    double q = 0;
    for (double v : diag_.through_flow) q += v;
    return q;
  }
  /// Area of the blocking elements (m², current geometry at the last exchange).
  double coupled_area() const { return area_; }
  /// The pressures on the two sides of the cloth along the unit direction `e` (world frame;
  /// the stream's direction relative to the cloth: −V for a canopy falling at V) and the air
  /// crossing it, over the last step (definitions: cloth_side_means).
  cloth_side_means cloth_sides(const Eigen::Vector3d& e) const {
    return cloth_sides(e, [](index_t) { return true; });
  }
  /// The same over the faces whose cloth is element `elem` (of the coupled triangles; a face
  /// crossed by several layers goes by its first) with `select(elem)` true: a part of the
  /// cloth, e.g. a ring of the canopy (the drop's cloth_bands.csv). The parts of a partition
  /// add up to the whole: S, S × each pressure and the through-flow.
  template <class Select>
  cloth_side_means cloth_sides(const Eigen::Vector3d& e, Select&& select) const {
    require(std::isfinite(e.squaredNorm()) && std::fabs(e.norm() - 1.0) < 1e-9,
            "coupling::embedded::cloth_sides: the direction must be a unit vector, got (", e.x(), ", ", e.y(), ", ",
            e.z(), ")");
    cloth_side_means r;
    double pw = 0, pl = 0;
    for (std::size_t i = 0; i < faces_.size() && i < side_p_.size(); ++i) {
      const face_rec& fr = faces_[i];
      if (fr.n < 1 || !select(crossings_[std::size_t(fr.first)].elem)) continue;
      const double ne = face_R_.col(fr.axis).dot(e), w = fr.area * std::fabs(ne);
      const auto& p = side_p_[i];
      r.pressure_load += (fr.area * (p[0] - p[1])) * face_R_.col(fr.axis);
      if (w > 0) {
        r.projected_area += w;
        pw += w * (ne > 0 ? p[0] : p[1]);
        pl += w * (ne > 0 ? p[1] : p[0]);
        ++r.faces;
      }
      Eigen::Vector3d m = Eigen::Vector3d::Zero();
      double sign = 0;
      for (int q = 0; q < fr.n; ++q) {
        m += crossings_[std::size_t(fr.first + q)].m;
        sign += crossings_[std::size_t(fr.first + q)].sign / double(fr.n);
      }
      const double mn = m.norm();
      if (mn > 0)  // the face stands for the cloth area c A_f, c = m·n_f
        r.through_flow += sign * p[2] * fr.area * std::fabs(m.dot(face_R_.col(fr.axis))) / mn;
    }
    if (r.projected_area > 0) {
      r.windward_pressure = pw / r.projected_area;
      r.leeward_pressure = pl / r.projected_area;
    }
    return r;
  }
  /// Checkpoint (io/archive.hpp; after attach): nothing carries over between steps (the
  /// faces, loads and impedance terms are rebuilt by every exchange); the set-up is compared.
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& self) {
    ar.check("porosity", std::string(Porosity::name()), "the porosity law");
    ar.check("impedance", self.opt_.impedance, "the impedance factor");
    ar.check("law_on", std::string(to_string(self.opt_.law_on)), "the velocity the fabric law acts on");
    ar.check("triangles", std::int64_t(self.tris_.size()), "the number of coupled triangles");
    ar.check("open", std::int64_t(self.open_list_.size()), "the number of open elements");
  }

  // ------------------------------------------------------------- stepper hooks
  template <class Fluid, class Asm>
  void attach(Fluid&, Asm& s) {
    tris_ = this->attach_triangles(s);
    const auto& nd = s.node_set();
    // Stage weights β_s = Π_{r ≥ s} b_r (Shu–Osher form of the fluid's RK scheme).
    using Time = typename Fluid::time_type;
    beta_.assign(std::size_t(Time::stages), 1.0);
    for (int st = 0; st < Time::stages; ++st)
      for (int r = st; r < Time::stages; ++r) beta_[std::size_t(st)] *= Time::b[std::size_t(r)];
    beta_sum_ = 0;
    for (double b : beta_) beta_sum_ += b;
    open_.assign(tris_.size(), 0);
    for (index_t e : open_list_) {
      require(e >= 0 && std::size_t(e) < tris_.size(), "coupling::embedded: open element ", e, " outside [0, ",
              tris_.size(), ")");
      open_[std::size_t(e)] = 1;
    }
    diag_.through_flow.assign(tris_.size(), 0.0);
    node_J_.assign(std::size_t(nd.size()), Eigen::Vector3d::Zero());
    attached_ = true;
  }

  /// The faces are found at the pose of tⁿ; the planned motion is not needed.
  template <class Fluid>
  void plan(const Fluid&, const frame::motion&) {}

  /// Find the crossed faces at the structure positions of tⁿ (box pose of tⁿ), check
  /// the membrane's travel, and list the faces this coupling patches in the coming
  /// fluid step (the stepper hands the coupling to the step as its face patcher).
  template <class Fluid, class Asm>
  void exchange(Fluid& f, const Asm& s, double dt_f) {
    this->require_attached();
    space_.refresh(f);  // the index grid is rebuilt only when the mesh's finest extent changed
    const auto& nd = s.node_set();
    const frame::pose& pose = f.pose();
    dt_f_ = dt_f;
    t_n_ = f.time();
    gamma_ = f.gas().gamma;
    // Travel check (relative to the grid, per blocking element).
    for (index_t e = 0; e < index_t(tris_.size()); ++e) {
      if (open_[std::size_t(e)]) continue;
      const auto& t = tris_[std::size_t(e)];
      for (int a = 0; a < 3; ++a) {
        const Eigen::Vector3d x = nd.position(t[std::size_t(a)]);
        const Eigen::Vector3d xi = pose.to_box(x);
        const Eigen::Vector3d vr = nd.velocity(t[std::size_t(a)]) - pose.grid_velocity(xi);
        const double h = detail::local_width(f, xi);
        const double travel = vr.norm() * dt_f / h;
        if (travel > opt_.max_cells_per_step)
          throw numerical_failure(
              parafsi::detail::concat(
                  "coupling::embedded: membrane element ", e, " (node ", t[std::size_t(a)], ") moves ", vr.norm(),
                  " m/s relative to the fluid grid, ", travel, " cells of size ", h, " m in one fluid step of ", dt_f,
                  " s (limit ", opt_.max_cells_per_step,
                  " cell per step); the membrane would jump over cell centres: reduce the time step "
                  "(explicit_stepper::stable_dt() includes this limit)"),
              e, f.time());
      }
    }
    find_faces(nd, pose);
    face_J_.assign(faces_.size(), Eigen::Vector3d::Zero());
    std::fill(diag_.through_flow.begin(), diag_.through_flow.end(), 0.0);
    diag_.impulse_structure.setZero();
    diag_.impulse_impedance.setZero();
    diag_.work_fluid = diag_.work_structure = diag_.mass_defect = 0;
    diag_.max_through_velocity = 0;
    spread_ready_ = false;
    if (opt_.impedance > 0) {
      if constexpr (requires { f.share_cells(shared_); }) {  // a distributed block mesh: the faces' cells everywhere
        shared_.clear();
        for (const auto& fr : faces_) shared_.insert(shared_.end(), {fr.low, fr.high});
        f.share_cells(shared_);
      }
      impedance_setup(f.view(), nd);
    }
    face_R_ = pose.R;
    side_p_.assign(faces_.size(), {0.0, 0.0, 0.0});
    patch_list_.clear();
    for (const auto& fr : faces_) patch_list_.push_back({fr.high, fr.axis});
  }

  // ------------------------------------------------------------- face patcher
  /// The faces found by the last exchange (fluid::face_patcher).
  std::span<const fluid::patch_face> patch_faces() const noexcept { return patch_list_; }

  /// The membrane flux of one patched face at one RK stage (fluid::face_patcher); the
  /// cell states are the stage's, read through the fluid's view.
  void patch(const fluid::face_context& fc, const fluid::view& v, fluid::cons<double>& lo, fluid::cons<double>& hi) {
    record_patch(fc, lo, hi, solve_patch(fc, v, lo, hi));
  }
  /// The two halves of patch() (fluid::recording_face_patcher), so that a mesh split over
  /// processes solves each face on one process and records it on all in list order:
  /// solve_patch (const) sets the membrane fluxes and returns the through-velocity u_p;
  /// record_patch adds the face's impulse, work, mass defect and through-flow (it reads
  /// fc.patch, fc.stage and fc.area).
  double solve_patch(const fluid::face_context& fc, const fluid::view& v, fluid::cons<double>& lo,
                     fluid::cons<double>& hi) const {
    return face_flux(fc, v, lo, hi);
  }
  void record_patch(const fluid::face_context& fc, const fluid::cons<double>& lo, const fluid::cons<double>& hi,
                    double up) {
    const std::size_t fi = fc.patch;
    const int stage = fc.stage;
    require(fi < faces_.size() && stage >= 0 && stage < int(beta_.size()), "coupling::embedded: face ", fi,
            " at stage ", stage, " is not one of this step's patches");
    const face_rec& fr = faces_[fi];
    const Eigen::Vector3d mL(lo.m.x, lo.m.y, lo.m.z), mR(hi.m.x, hi.m.y, hi.m.z);
    const double wdt = beta_[std::size_t(stage)] * dt_f_ * fc.area;
    face_J_[fi] += wdt * (mL - mR);
    diag_.work_fluid += wdt * (lo.E - hi.E);
    diag_.mass_defect += wdt * (lo.rho - hi.rho);
    diag_.max_through_velocity = std::max(diag_.max_through_velocity, std::fabs(up));
    {  // the wall pressures p*_K = F_K.m·n − F_K.ρ u_m (the star states move at u_m along n;
       // n from the exchange's box axes: a block mesh replays a face with patch, stage and area only)
      const Eigen::Vector3d n = face_R_.col(fr.axis);
      const double um = membrane_normal_velocity(fr) + up, b = beta_[std::size_t(stage)] / beta_sum_;
      auto& p = side_p_[fi];
      const double psL = mL.dot(n) - lo.rho * um, psR = mR.dot(n) - hi.rho * um;
      p[0] += b * psL;
      p[1] += b * psR;
      p[2] += b * por_.through_velocity((psL - psR) / double(fr.n));  // the law's u_n: Δp = k Δp_por(u_n)
    }
    if (stage + 1 == int(beta_.size()))
      for (int q = 0; q < fr.n; ++q) {
        const auto& cr = crossings_[std::size_t(fr.first + q)];
        diag_.through_flow[std::size_t(cr.elem)] += up * fc.area / double(fr.n) * cr.sign;
      }
  }

  /// No coupling springs; with the impedance term, its explicit substep limit
  /// min_i m_i / ‖C_i‖ (half the forward-Euler bound 2 m/‖C‖).
  double structure_dt() const noexcept {
    return opt_.impedance > 0 ? diag_.impedance_substep : std::numeric_limits<double>::infinity();
  }

  /// Largest fluid step keeping every blocking node within max_cells_per_step/2 cells.
  template <class Fluid, class Asm>
  double travel_dt(const Fluid& f, const Asm& s) const {
    if (!attached_) return std::numeric_limits<double>::infinity();
    const auto& nd = s.node_set();
    double dt = std::numeric_limits<double>::infinity();
    for (index_t e = 0; e < index_t(tris_.size()); ++e) {
      if (open_[std::size_t(e)]) continue;
      for (index_t i : tris_[std::size_t(e)]) {
        const Eigen::Vector3d xi = f.pose().to_box(nd.position(i));
        const double v = (nd.velocity(i) - f.pose().grid_velocity(xi)).norm();
        if (v > 0) dt = std::min(dt, 0.5 * opt_.max_cells_per_step * detail::local_width(f, xi) / v);
      }
    }
    return dt;
  }

  /// Structure substep: the step's face impulses J as constant nodal forces J/Σ kick
  /// (Σ kick = first kick + (m − 1) Δt_s), so Σ_k F kick_k = J.
  void apply(structure::load_sink& sink, const structure::nodes& nd, double tau, double dt_kick, double dt_s) {
    if (tau == 0.0 || !spread_ready_) {
      total_kick_ = dt_kick + (dt_f_ - dt_s);
      std::fill(node_J_.begin(), node_J_.end(), Eigen::Vector3d::Zero());
      touched_.clear();
      for (std::size_t fi = 0; fi < faces_.size(); ++fi) {
        const auto& fr = faces_[fi];
        const double share = 1.0 / double(fr.n);
        for (int q = 0; q < fr.n; ++q) {
          const auto& cr = crossings_[std::size_t(fr.first + q)];
          const auto& t = tris_[std::size_t(cr.elem)];
          for (int a = 0; a < 3; ++a) {
            const std::size_t i = std::size_t(t[std::size_t(a)]);
            if (node_J_[i].isZero(0.0)) touched_.push_back(index_t(i));
            node_J_[i] += (share * cr.lambda[std::size_t(a)]) * face_J_[fi];
          }
        }
      }
      std::sort(touched_.begin(), touched_.end());
      touched_.erase(std::unique(touched_.begin(), touched_.end()), touched_.end());
      spread_ready_ = true;
    }
    if (opt_.impedance > 0) apply_nodes<true>(sink, nd, dt_kick);
    else apply_nodes<false>(sink, nd, dt_kick);
  }

  template <class Fluid>
  void finish(Fluid&, double) {}

 private:
  /// The substep's nodal forces; the impedance term chosen once per call.
  template <bool Impedance>
  void apply_nodes(structure::load_sink& sink, const structure::nodes& nd, double dt_kick) {
    const double inv = 1.0 / total_kick_;
    for (index_t i : touched_) {
      Eigen::Vector3d F = node_J_[std::size_t(i)] * inv;
      if constexpr (Impedance) {
        const Eigen::Vector3d Fz = -(node_C_[std::size_t(i)] * (nd.velocity(i) - node_v0_[std::size_t(i)]));
        F += Fz;
        diag_.impulse_impedance += Fz * dt_kick;
      }
      sink.add(i, F);
      diag_.impulse_structure += F * dt_kick;
      diag_.work_structure += F.dot(nd.velocity(i)) * dt_kick;
    }
  }

 public:
  // ------------------------------------------------------------- face physics
  /// Pressure and density behind the wave a piston makes in the state (ρ, p, c) when it
  /// approaches the gas at du (du > 0: compression/shock, du < 0: rarefaction).
  /// Exact (Toro §4.2); vacuum gives p* = ρ* = 0.
  static void wall_state(double rho, double p, double gamma, double du, double& ps, double& rs) noexcept {
    const double c = std::sqrt(gamma * p / rho);
    if (du <= 0.0) {
      const double base = 1.0 + 0.5 * (gamma - 1.0) * du / c;
      if (base <= 0.0) {
        ps = rs = 0.0;
        return;
      }
      ps = p * std::pow(base, 2.0 * gamma / (gamma - 1.0));
      rs = rho * std::pow(base, 2.0 / (gamma - 1.0));
    } else {
      const double A = 2.0 / ((gamma + 1.0) * rho), B = (gamma - 1.0) / (gamma + 1.0) * p;
      const double d2 = du * du;
      const double q = (d2 + std::sqrt(d2 * d2 + 4.0 * A * d2 * (p + B))) / (2.0 * A);
      ps = p + q;
      const double r = ps / p, m = (gamma - 1.0) / (gamma + 1.0);
      rs = rho * (r + m) / (m * r + 1.0);
    }
  }

  /// A face whose membrane Riemann problem has no solution: name the states and the cause.
  [[noreturn]] void fail_face(double rL, double unL, double pL, double rR, double unR, double pR, double w,
                              double g0) const {
    const bool gas = std::isfinite(rL) && std::isfinite(pL) && std::isfinite(unL) && std::isfinite(rR) &&
                     std::isfinite(pR) && std::isfinite(unR) && rL > 0 && pL > 0 && rR > 0 && pR > 0;
    throw numerical_failure(
        parafsi::detail::concat(
            "coupling::embedded: no through-velocity solves a membrane face (pressure balance at zero through-flow ",
            g0, "): ",
            gas ? "the fabric's pressure jump cannot balance the wall pressures (a porosity law that is not monotone "
                  "or not finite?)"
                : "the air next to the membrane is no longer a gas (density or pressure <= 0 or not finite): the "
                  "membrane moved too far in one step or the start is too violent; shorten the step (lower CFL or "
                  "pressure-gradient scaling) or lower the initial speed",
            "; left rho=", rL, " u_n=", unL, " p=", pL, ", right rho=", rR, " u_n=", unR, " p=", pR, ", membrane w=", w,
            " m/s, in the fluid step from t = ", t_n_, " s"),
        -1, t_n_);
  }

  /// The membrane Riemann problem of one face: through-velocity u_p (relative to the
  /// membrane, along the face normal) and the two wall pressures, given the normal
  /// velocities of the cell states, the membrane's normal velocity w and k layers.
  /// With the cloth's normal: c = m·n and σ the common along-cloth part (file comment); the
  /// unknown is then u_n and u_p = c u_n + σ (c = 1, σ = 0: the law on u_p).
  struct face_solution {
    double up = 0, psL = 0, rsL = 0, psR = 0, rsR = 0;
    double un = 0;  ///< the through-velocity the law acts on (u_n; = up when c = 1, σ = 0)
  };
  face_solution solve_face(double rL, double unL, double pL, double rR, double unR, double pR, double w, int layers,
                           double c = 1.0, double sigma = 0.0) const {
    face_solution s;
    auto eval = [&](double un, face_solution& o) {
      const double up = c * un + sigma;
      const double um = w + up;
      wall_state(rL, pL, gamma_, unL - um, o.psL, o.rsL);
      wall_state(rR, pR, gamma_, um - unR, o.psR, o.rsR);
      o.up = up;
      o.un = un;
      double g = o.psL - o.psR;
      if constexpr (Porosity::permeable) g -= double(layers) * por_.pressure_jump(un);
      return g;
    };
    const double g0 = eval(0.0, s);
    if (!std::isfinite(g0)) fail_face(rL, unL, pL, rR, unR, pR, w, g0);
    if constexpr (!Porosity::permeable) {
      return s;
    } else {
      if (g0 == 0.0) return s;
      const double sgn = g0 > 0 ? 1.0 : -1.0;
      const double cL = std::sqrt(gamma_ * pL / rL), cR = std::sqrt(gamma_ * pR / rR);
      // Acoustic estimate of the through-velocity without the fabric: a first bracket end.
      double b = sgn * std::max(std::fabs(g0) / (rL * cL + rR * cR), 1e-12 * (cL + cR));
      face_solution sb;
      double gb = eval(b, sb);
      double a = 0.0, ga = g0;
      for (int it = 0; it < 200 && gb * sgn > 0; ++it) {
        a = b;
        ga = gb;
        b *= 2.0;
        gb = eval(b, sb);
      }
      if (!(gb * sgn <= 0)) fail_face(rL, unL, pL, rR, unR, pR, w, g0);
      if (gb == 0.0) return sb;
      // Illinois (modified regula falsi) on [a, b], ga and gb of opposite signs.
      int side = 0;
      face_solution sx = sb;
      for (int it = 0; it < 200; ++it) {
        const double x = (a * gb - b * ga) / (gb - ga);
        const double gx = eval(x, sx);
        if (gx == 0.0 || std::fabs(b - a) <= opt_.root_tolerance * std::max(std::fabs(a), std::fabs(b))) break;
        if (gx * gb < 0) {
          a = b;
          ga = gb;
          b = x;
          gb = gx;
          side = 0;
        } else {
          b = x;
          gb = gx;
          if (side == 1) ga *= 0.5;
          side = 1;
        }
        if (std::fabs(b - a) <= opt_.root_tolerance * std::max(std::fabs(a), std::fabs(b))) break;
      }
      return sx;
    }
  }

 private:
  struct crossing {
    index_t elem;
    std::array<double, 3> lambda;                  ///< barycentric weights of the crossing point
    double z;                                      ///< crossing coordinate along the face axis (box)
    double wn = 0;                                 ///< membrane velocity at the crossing · face normal (m/s)
    double sign = 1;                               ///< sign of n_element · n_face
    Eigen::Vector3d vs = Eigen::Vector3d::Zero();  ///< membrane velocity at the crossing (m/s)
    Eigen::Vector3d m = Eigen::Vector3d::Zero();   ///< unit cloth normal, oriented along n_face
  };
  struct face_rec {
    index_t high;  ///< the fluid's cell above the face (flat index of its arrays)
    int axis;
    index_t first;  ///< first crossing in crossings_
    int n;          ///< layers
    index_t low;    ///< the fluid's cell below the face
    double area;    ///< face area (m²)
  };
  struct raw_crossing {
    index_t high;
    int axis;
    crossing c;
  };

  /// Impedance matrices C_i = ζ Σ_faces (ρ_L c_L + ρ_R c_R) A (λ_a / k) n nᵀ of the nodes
  /// of crossed elements (cell states of tⁿ), their velocities vⁿ and the substep limit.
  void impedance_setup(const fluid::view& fv, const structure::nodes& nd) {
    const frame::pose& pose = *fv.pose;
    node_C_.assign(std::size_t(nd.size()), Eigen::Matrix3d::Zero());
    node_v0_.resize(std::size_t(nd.size()));
    for (index_t i = 0; i < nd.size(); ++i) node_v0_[std::size_t(i)] = nd.velocity(i);
    auto impedance = [&](index_t c) {
      const double r = fv.density(c), p = fv.pressure(c);
      return std::sqrt(gamma_ * std::max(p, 0.0) * r);  // ρ c
    };
    for (const auto& fr : faces_) {
      const int d = fr.axis;
      const double area = fr.area;
      const double Z = opt_.impedance * (impedance(fr.low) + impedance(fr.high));
      const Eigen::Vector3d n = pose.R.col(d);
      const Eigen::Matrix3d nn = n * n.transpose();
      for (int q = 0; q < fr.n; ++q) {
        const auto& cr = crossings_[std::size_t(fr.first + q)];
        const auto& t = tris_[std::size_t(cr.elem)];
        for (int a = 0; a < 3; ++a)
          node_C_[std::size_t(t[std::size_t(a)])] += (Z * area * cr.lambda[std::size_t(a)] / double(fr.n)) * nn;
      }
    }
    double dt = std::numeric_limits<double>::infinity();
    for (index_t i = 0; i < nd.size(); ++i) {
      const double c = node_C_[std::size_t(i)].trace();  // ≥ the largest eigenvalue (C is PSD)
      if (c > 0 && nd.mass(i) > 0) dt = std::min(dt, nd.mass(i) / c);
    }
    diag_.impedance_substep = dt;
  }

  void find_faces(const structure::nodes& nd, const frame::pose& pose) {
    const fluid::rectilinear_grid& g = space_.grid();
    std::vector<raw_crossing>& found = found_;
    found.clear();
    area_ = 0;
    for (index_t e = 0; e < index_t(tris_.size()); ++e) {
      if (open_[std::size_t(e)]) continue;
      const auto& t = tris_[std::size_t(e)];
      std::array<Eigen::Vector3d, 3> X, Vn;
      for (int a = 0; a < 3; ++a) {
        X[std::size_t(a)] = pose.to_box(nd.position(t[std::size_t(a)]));
        Vn[std::size_t(a)] = nd.velocity(t[std::size_t(a)]);
      }
      const Eigen::Vector3d ne = (nd.position(t[1]) - nd.position(t[0])).cross(nd.position(t[2]) - nd.position(t[0]));
      area_ += 0.5 * (X[1] - X[0]).cross(X[2] - X[0]).norm();
      Eigen::Vector3d lo = X[0].cwiseMin(X[1]).cwiseMin(X[2]), hi = X[0].cwiseMax(X[1]).cwiseMax(X[2]);
      for (int d = 0; d < 3; ++d) {
        if (g.n(d) < 2) continue;
        const int a1 = (d + 1) % 3, a2 = (d + 2) % 3;
        // Projected (signed, doubled) area in the (a1, a2) plane.
        const double x0 = X[0][a1], y0 = X[0][a2], x1 = X[1][a1], y1 = X[1][a2], x2 = X[2][a1], y2 = X[2][a2];
        const double A2 = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
        const double scale = std::max({std::fabs(x1 - x0), std::fabs(x2 - x0), std::fabs(y1 - y0), std::fabs(y2 - y0)});
        if (std::fabs(A2) <= 1e-14 * scale * scale) continue;  // parallel to the axis: no crossing
        const double* c1 = g.centres(a1);
        const double* c2 = g.centres(a2);
        const double* cd = g.centres(d);
        const index_t n1 = g.n(a1), n2 = g.n(a2), nD = g.n(d);
        const index_t i1b = index_t(std::lower_bound(c1, c1 + n1, lo[a1]) - c1);
        const index_t i1e = index_t(std::upper_bound(c1, c1 + n1, hi[a1]) - c1);
        const index_t i2b = index_t(std::lower_bound(c2, c2 + n2, lo[a2]) - c2);
        const index_t i2e = index_t(std::upper_bound(c2, c2 + n2, hi[a2]) - c2);
        // High cells i with x_c,i−1 <= hi_d and x_c,i > lo_d, i in [1, n − 1].
        index_t idb = index_t(std::upper_bound(cd, cd + nD, lo[d]) - cd);
        index_t ide = index_t(std::upper_bound(cd, cd + nD, hi[d]) - cd) + 1;
        idb = std::max<index_t>(idb, 1);
        ide = std::min<index_t>(ide, nD);
        if (idb >= ide) continue;
        const double inv = 1.0 / A2;
        for (index_t q2 = i2b; q2 < i2e; ++q2)
          for (index_t q1 = i1b; q1 < i1e; ++q1) {
            const double px = c1[q1], py = c2[q2];
            const double l1 = ((px - x0) * (y2 - y0) - (x2 - x0) * (py - y0)) * inv;
            const double l2 = ((x1 - x0) * (py - y0) - (px - x0) * (y1 - y0)) * inv;
            const double l0 = 1.0 - l1 - l2;
            constexpr double tol = -1e-12;
            if (l0 < tol || l1 < tol || l2 < tol) continue;
            const double z = l0 * X[0][d] + l1 * X[1][d] + l2 * X[2][d];
            for (index_t id = idb; id < ide; ++id) {
              if (!(z >= cd[id - 1] && z < cd[id])) continue;
              index_t ijk[3];
              ijk[d] = id;
              ijk[a1] = q1;
              ijk[a2] = q2;
              const double s0 = std::max(l0, 0.0), s1 = std::max(l1, 0.0), s2 = std::max(l2, 0.0);
              const double ss = s0 + s1 + s2;
              crossing cr{e, {s0 / ss, s1 / ss, s2 / ss}, z};
              const Eigen::Vector3d nf = pose.R.col(d);
              cr.vs = cr.lambda[0] * Vn[0] + cr.lambda[1] * Vn[1] + cr.lambda[2] * Vn[2];
              cr.wn = nf.dot(cr.vs);
              cr.sign = ne.dot(nf) >= 0 ? 1.0 : -1.0;
              cr.m = (cr.sign / ne.norm()) * ne;
              found.push_back({g.index(ijk[0], ijk[1], ijk[2]), d, cr});
            }
          }
      }
    }
    std::sort(found.begin(), found.end(), [](const raw_crossing& a, const raw_crossing& b) {
      if (a.axis != b.axis) return a.axis < b.axis;
      if (a.high != b.high) return a.high < b.high;
      if (a.c.z != b.c.z) return a.c.z < b.c.z;
      return a.c.elem < b.c.elem;
    });
    faces_.clear();
    crossings_.clear();
    diag_.multi_layer_faces = 0;
    const double ztol = 1e-9 * g.min_width();
    for (std::size_t i = 0; i < found.size();) {
      std::size_t j = i;
      face_rec fr{found[i].high, found[i].axis, index_t(crossings_.size()), 0, 0, 0.0};
      double zlast = -std::numeric_limits<double>::infinity();
      while (j < found.size() && found[j].high == fr.high && found[j].axis == fr.axis) {
        if (found[j].c.z - zlast > ztol) {  // a new layer (same z: shared edge or vertex)
          crossings_.push_back(found[j].c);
          ++fr.n;
          zlast = found[j].c.z;
        }
        ++j;
      }
      if (fr.n > 1) ++diag_.multi_layer_faces;
      const int d = fr.axis, a1 = (d + 1) % 3, a2 = (d + 2) % 3;
      const auto ijk = g.ijk(fr.high);
      fr.area = g.width(a1, ijk[std::size_t(a1)]) * g.width(a2, ijk[std::size_t(a2)]);
      fr.low = space_.cell(fr.high - g.stride(d));
      fr.high = space_.cell(fr.high);
      if (fr.low < 0 || fr.high < 0) {
        const auto& cr = crossings_[std::size_t(fr.first)];
        Eigen::Vector3d x(g.centre(0, ijk[0]), g.centre(1, ijk[1]), g.centre(2, ijk[2]));
        x[d] = cr.z;
        throw numerical_failure(
            parafsi::detail::concat("coupling::embedded: membrane element ", cr.elem,
                                    " crosses the face at box point (", x[0], ", ", x[1], ", ", x[2],
                                    ") off the finest level of the block mesh: the membrane must lie in finest-level "
                                    "cells (refine around it more often or with a wider buffer)"),
            cr.elem, t_n_);
      }
      faces_.push_back(fr);
      i = j;
    }
    diag_.faces = index_t(faces_.size());
    diag_.crossings = index_t(crossings_.size());
  }

  /// c = m·n and σ = minmod(σ_L, σ_R) of a face (file comment), m and v_s the means over
  /// its layers.
  void cloth_normal_terms(const face_rec& fr, const Eigen::Vector3d& n, const Eigen::Vector3d& uL,
                          const Eigen::Vector3d& uR, double& c, double& sigma) const {
    Eigen::Vector3d m = Eigen::Vector3d::Zero(), vs = Eigen::Vector3d::Zero();
    for (int q = 0; q < fr.n; ++q) {
      const auto& cr = crossings_[std::size_t(fr.first + q)];
      m += cr.m;
      vs += cr.vs;
    }
    const double mn = m.norm();
    if (!(mn > 0)) return;  // layers of opposite normals: keep the law on the face velocity
    m /= mn;
    vs /= double(fr.n);
    c = std::clamp(m.dot(n), 0.0, 1.0);
    sigma = common_along_cloth(n, m, vs, uL, uR);
  }

 public:
  /// σ = minmod(σ_L, σ_R), σ_K = n·[r_K − (r_K·m) m], r_K = u_K − v_s: the face-normal part of
  /// the flow along the cloth (unit normal m, velocity v_s) that both sides carry (file comment).
  static double common_along_cloth(const Eigen::Vector3d& n, const Eigen::Vector3d& m, const Eigen::Vector3d& vs,
                                   const Eigen::Vector3d& uL, const Eigen::Vector3d& uR) noexcept {
    auto along = [&](const Eigen::Vector3d& u) {
      const Eigen::Vector3d r = u - vs;
      return n.dot(r - r.dot(m) * m);
    };
    const double sL = along(uL), sR = along(uR);
    return sL * sR > 0 ? (std::fabs(sL) < std::fabs(sR) ? sL : sR) : 0.0;
  }

 private:
  /// The membrane's normal velocity w at a face's crossing, the mean over its layers.
  double membrane_normal_velocity(const face_rec& fr) const noexcept {
    double w = 0;
    for (int q = 0; q < fr.n; ++q) w += crossings_[std::size_t(fr.first + q)].wn;
    return w / double(fr.n);
  }

  /// The membrane flux of patched face fc.patch at stage fc.stage; returns u_p.
  double face_flux(const fluid::face_context& fc, const fluid::view& v, fluid::cons<double>& lo,
                   fluid::cons<double>& hi) const {
    const std::size_t fi = fc.patch;
    const int stage = fc.stage;
    require(fi < faces_.size() && stage >= 0 && stage < int(beta_.size()), "coupling::embedded: face ", fi,
            " at stage ", stage, " is not one of this step's patches");
    const face_rec& fr = faces_[fi];
    require(fc.high == fr.high && fc.axis == fr.axis, "coupling::embedded: patched face ", fi,
            " does not match the face list of the last exchange");
    const Eigen::Vector3d n(fc.n.x, fc.n.y, fc.n.z);
    // Membrane normal velocity at the crossing (mean over the layers).
    const double w = membrane_normal_velocity(fr);
    // The face states on each side: one-sided reconstructed (OneSided), else the cells' own
    // (first order: the sweeps' face values would carry slopes read across the membrane).
    double rL, pL, rR, pR;
    Eigen::Vector3d uL, uR;
    if constexpr (OneSided) {
      (void)v;
      rL = fc.L.rho, pL = fc.L.p, rR = fc.R.rho, pR = fc.R.p;
      uL = Eigen::Vector3d(fc.L.u.x, fc.L.u.y, fc.L.u.z);
      uR = Eigen::Vector3d(fc.R.u.x, fc.R.u.y, fc.R.u.z);
    } else {
      rL = v.density(fc.low), uL = v.velocity(fc.low), pL = v.pressure(fc.low);
      rR = v.density(fc.high), uR = v.velocity(fc.high), pR = v.pressure(fc.high);
    }
    const double unL = uL.dot(n), unR = uR.dot(n);
    double c = 1.0, sigma = 0.0;
    if (Porosity::permeable && opt_.law_on == through_flow_law::cloth_normal)
      cloth_normal_terms(fr, n, uL, uR, c, sigma);
    const face_solution s = solve_face(rL, unL, pL, rR, unR, pR, w, fr.n, c, sigma);
    const double um = w + s.up, sw = w - fc.wn;
    const Eigen::Vector3d usL = uL + (um - unL) * n, usR = uR + (um - unR) * n;
    const double g1 = 1.0 / (gamma_ - 1.0);
    const double EL = s.psL * g1 + 0.5 * s.rsL * usL.squaredNorm();
    const double ER = s.psR * g1 + 0.5 * s.rsR * usR.squaredNorm();
    // Swept (wall) parts.
    Eigen::Vector3d mL = s.rsL * sw * usL + s.psL * n, mR = s.rsR * sw * usR + s.psR * n;
    double fL = s.rsL * sw, fR = s.rsR * sw;
    double eL = EL * sw + s.psL * w, eR = ER * sw + s.psR * w;
    // Porous part (upwind star state), identical on both sides.
    if (s.up != 0.0) {
      const bool fromL = s.up > 0;
      const double r = fromL ? s.rsL : s.rsR, p = fromL ? s.psL : s.psR, E = fromL ? EL : ER;
      const Eigen::Vector3d& u = fromL ? usL : usR;
      const double mf = r * s.up;
      fL += mf;
      fR += mf;
      mL += mf * u;
      mR += mf * u;
      eL += (E + p) * s.up;
      eR += (E + p) * s.up;
    }
    lo = {fL, {mL.x(), mL.y(), mL.z()}, eL};
    hi = {fR, {mR.x(), mR.y(), mR.z()}, eR};
    return s.up;
  }

  std::vector<detail::triangle> tris_;
  std::vector<index_t> open_list_;
  std::vector<char> open_;
  double dt_f_ = 0, t_n_ = 0, gamma_ = 1.4, area_ = 0, total_kick_ = 1;
  std::vector<face_rec> faces_;
  std::vector<crossing> crossings_;
  std::vector<Eigen::Vector3d> face_J_, node_J_, node_v0_;
  /// Per face, the step's stage-weighted means of p*_L, p*_R and the fabric law's u_n (cloth_sides).
  std::vector<std::array<double, 3>> side_p_;
  Eigen::Matrix3d face_R_ = Eigen::Matrix3d::Identity();  ///< the box axes at the last exchange
  double beta_sum_ = 1;                                   ///< Σ_s β_s
  std::vector<Eigen::Matrix3d> node_C_;
  std::vector<index_t> touched_;
  std::vector<double> beta_;
  std::vector<raw_crossing> found_;            ///< find_faces scratch
  std::vector<index_t> shared_;                ///< the impedance term's cells (share_cells)
  std::vector<fluid::patch_face> patch_list_;  ///< the faces patched in the coming fluid step
  face_space space_{};                         ///< where the faces are found (the last exchange's mesh)
  bool spread_ready_ = false;
  embedded_diagnostics diag_{};
};

template <class P>
embedded(P) -> embedded<P, false>;
template <class P>
embedded(P, embedded_options) -> embedded<P, false>;

}  // namespace parafsi::coupling
